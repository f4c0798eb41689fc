// spritestation bench synth-motion: how the synthetic subjects move (synth/motion_stats.h),
// over a session's truth/subjects.csv or a behaviour run simulated without rendering.
//   spritestation bench synth-motion --truth SESSION [--json]
//   spritestation bench synth-motion [--kind animal|fly] [--seconds S] [--seed N] [--subjects M]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_registry.h"
#include "core/error.h"
#include "synth/directors.h"
#include "synth/motion_stats.h"
#include "synth/scene.h"

namespace ss::bench::synth_motion_bench {
namespace {

struct Args {
  std::string truth;  // a session folder or its subjects.csv
  std::string kind = "animal";
  double seconds = 600;
  uint64_t seed = 1;
  int subjects = 1;
  double fps = 30;
  bool json = false;
};

Args Parse(const std::vector<std::string>& argv) {
  Args a;
  for (size_t k = 0; k < argv.size(); ++k) {
    std::string s = argv[k], inline_value;
    const bool has_inline = s.find('=') != std::string::npos;
    if (has_inline) {
      inline_value = s.substr(s.find('=') + 1);
      s = s.substr(0, s.find('='));
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (k + 1 >= argv.size()) throw InputError("bench synth-motion", s + " needs a value");
      return argv[++k];
    };
    if (s == "--truth")
      a.truth = value();
    else if (s == "--kind")
      a.kind = value();
    else if (s == "--seconds")
      a.seconds = std::stod(value());
    else if (s == "--seed")
      a.seed = std::stoull(value());
    else if (s == "--subjects")
      a.subjects = std::stoi(value());
    else if (s == "--json")
      a.json = true;
    else
      throw InputError("bench synth-motion",
                       "unknown argument " + s +
                           " (--truth SESSION | --kind animal|fly --seconds S --seed N "
                           "--subjects M; --json)");
  }
  if (a.kind != "animal" && a.kind != "fly")
    throw InputError("bench synth-motion", "--kind: expected animal or fly, got '" + a.kind + "'");
  return a;
}

int Run(const std::vector<std::string>& argv) {
  const Args a = Parse(argv);
  const synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, a.seed);
  std::vector<synth::MotionSample> samples;
  double fps = a.fps;
  std::string what;
  if (!a.truth.empty()) {
    std::filesystem::path csv = a.truth;
    if (std::filesystem::is_directory(csv)) csv = csv / "truth" / "subjects.csv";
    samples = synth::ReadSubjectsCsv(csv.string());
    // The frame rate from truth.json beside it (30 without one).
    std::ifstream meta(csv.parent_path() / "truth.json");
    if (meta) fps = nlohmann::json::parse(meta).value("fps", fps);
    what = csv.string();
  } else {
    synth::DirectorOptions o;
    o.seed = a.seed;
    o.subjects = a.subjects;
    o.fps = fps;
    const auto cameras = synth::MakeCameras(studio, 1, 640, 480, a.seed);
    auto director = a.kind == "fly" ? synth::MakeFlyDirector(studio, o)
                                    : synth::MakeAnimalDirector(studio, cameras, o);
    synth::FrameSnapshot snap;
    const int frames = static_cast<int>(a.seconds * fps);
    for (int f = 0; f < frames; ++f) {
      director->Frame(f / fps, &snap);
      for (size_t i = 0; i < snap.subjects.size(); ++i) {
        const synth::SubjectTruth& t = snap.subjects[i];
        samples.push_back({f, static_cast<int>(i), t.position, t.heading_rad, t.speed_mps, t.pose,
                           t.touches_wall});
      }
    }
    what = "simulated " + a.kind + ", " + std::to_string(a.subjects) + " subject(s), " +
           std::to_string(a.seconds) + " s, seed " + std::to_string(a.seed);
  }
  const synth::MotionStats s = synth::MeasureMotion(samples, fps, studio.half_x, studio.half_y);
  if (a.json) {
    std::printf("%s\n", synth::MotionStatsJson(s).c_str());
  } else {
    std::printf("%s\n%s", what.c_str(), synth::MotionStatsText(s).c_str());
  }
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"synth-motion",
     "synthetic subjects' speed, turn, pose and floor distributions (truth or simulated)", &Run});

}  // namespace
}  // namespace ss::bench::synth_motion_bench
