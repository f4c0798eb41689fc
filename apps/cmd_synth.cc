// spritestation synth --out DIR [--kind animal|figure|calibration] [--seconds S]
// [--fps F] [--size WxH] [--cameras K] [--subjects M] [--seed N]
// [--pixel-format rgb8|bayer_rg8|bgr8|mono8] [--json] ...: renders a synthetic
// studio session with ground truth (docs/synth.md). Deterministic per seed.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/enum_text.h"
#include "core/error.h"
#include "synth/studio_session.h"

namespace ss::apps {
namespace {

struct SynthArgs {
  synth::SynthOptions options;
  std::string kind = "animal";
  std::string studio;  // "": the kind's
  std::string view = "oblique";
  std::string size = "640x480";
  std::string pixel_format = "rgb8";
  bool json = false;
  double empty_lead_in_s = -1;  // < 0: the kind's default
};

void RunSynth(SynthArgs args) {
  synth::SynthOptions& o = args.options;
  if (!FromText(args.kind, synth::kSynthKindTexts, o.kind)) {
    throw InputError("--kind",
                     "expected " + TextsOf(synth::kSynthKindTexts) + ", got '" + args.kind + "'");
  }
  synth::StudioKind studio{};
  if (!args.studio.empty()) {
    if (!FromText(args.studio, synth::kStudioKindTexts, studio)) {
      throw InputError("--studio", "expected " + TextsOf(synth::kStudioKindTexts) + ", got '" +
                                       args.studio + "'");
    }
    o.studio = studio;
  }
  if (!FromText(args.view, synth::kCameraViewTexts, o.view)) {
    throw InputError("--view",
                     "expected " + TextsOf(synth::kCameraViewTexts) + ", got '" + args.view + "'");
  }
  o.empty_lead_in_s =
      args.empty_lead_in_s >= 0
          ? args.empty_lead_in_s
          : (o.kind == synth::SynthKind::kAnimal || o.kind == synth::SynthKind::kFly ? 1.0 : 0.0);
  int w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(args.size.c_str(), "%dx%d%c", &w, &h, &tail) != 2) {
    throw InputError("--size", "expected WIDTHxHEIGHT such as 640x480, got '" + args.size + "'");
  }
  o.width = w;
  o.height = h;
  const auto format = ParsePixelFormat(args.pixel_format);
  if (!format)
    throw InputError("--pixel-format", "unknown pixel format '" + args.pixel_format + "'");
  o.pixel_format = *format;

  const synth::SynthSummary s = synth::RenderStudioSession(o);
  if (args.json) {
    nlohmann::json out = {{"session", s.out_dir},
                          {"kind", args.kind},
                          {"frames", s.frames},
                          {"cameras", s.cameras},
                          {"subjects", s.subjects},
                          {"fps", s.fps},
                          {"seed", o.seed},
                          {"wall_seconds", s.wall_s},
                          {"cpu_seconds", s.cpu_s},
                          {"real_time_factor", s.RealTimeFactor()},
                          {"camera_seconds_per_cpu_second", s.CpuRealTimeFactor()},
                          {"stage_seconds",
                           {{"simulate", s.simulate_s},
                            {"render", s.render_s},
                            {"sensor", s.sensor_s},
                            {"encode", s.encode_s},
                            {"truth", s.truth_s}}},
                          {"pose_frames", s.pose_frames},
                          {"wall_touch_frames", s.wall_touch_frames}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("synth: %s session in %s: %d frames x %d camera(s), %d subject(s), seed %llu\n",
                args.kind.c_str(), s.out_dir.c_str(), s.frames, s.cameras, s.subjects,
                static_cast<unsigned long long>(o.seed));
    std::printf(
        "  %.2f s wall (%.2fx real time), %.2f s CPU (%.2f camera-seconds per CPU-second)\n",
        s.wall_s, s.RealTimeFactor(), s.cpu_s, s.CpuRealTimeFactor());
    std::printf("  CPU s: simulate %.2f, render %.2f, sensor %.2f, encode %.2f, truth %.2f\n",
                s.simulate_s, s.render_s, s.sensor_s, s.encode_s, s.truth_s);
    if (!s.pose_frames.empty()) {
      std::printf("  subject-frames per pose:");
      for (const auto& [pose, n] : s.pose_frames) std::printf(" %s %d", pose.c_str(), n);
      std::printf("; touching a wall %d\n", s.wall_touch_frames);
    }
  }
  std::fflush(stdout);
}

}  // namespace

void AddSynthCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("synth", "Render a synthetic studio session with ground truth (truth/)");
  auto args = std::make_shared<SynthArgs>();
  synth::SynthOptions& o = args->options;
  cmd->add_option("--out", o.out_dir, "Session folder to create (must not exist or be empty)")
      ->required();
  cmd->add_option("--kind", args->kind, TextsOf(synth::kSynthKindTexts));
  cmd->add_option(
      "--studio", args->studio,
      TextsOf(synth::kStudioKindTexts) + " (default: stage for figures, else enclosure)");
  cmd->add_option("--view", args->view,
                  TextsOf(synth::kCameraViewTexts) +
                      ": cameras around the floor looking obliquely down at it (the default), or "
                      "above it looking straight down (the enclosure only)");
  cmd->add_option("--seconds", o.seconds, "Length of the session");
  cmd->add_option("--fps", o.fps, "Frames per second");
  cmd->add_option("--size", args->size, "Image size WIDTHxHEIGHT");
  cmd->add_option("--cameras", o.cameras, "Number of cameras (1..8)");
  cmd->add_option("--subjects", o.subjects, "Animals, flies or figures (0..8)");
  cmd->add_option("--seed", o.seed, "Seed: the same seed gives the same session");
  cmd->add_option("--pixel-format", args->pixel_format, "rgb8, bgr8, bayer_rg8 or mono8");
  cmd->add_option("--noise", o.noise, "Sensor noise scale (0: none, 1: typical)");
  cmd->add_flag("--motion-blur", o.motion_blur,
                "Blur moving subjects over half the frame interval");
  cmd->add_flag("--crossing", o.crossing,
                "Animals ignore each other: their paths cross and their silhouettes meet in view");
  cmd->add_option("--figure-variant", o.figure_variant,
                  "Figure proportions: 0 reference, 1 the other figure");
  cmd->add_option("--threads", o.threads, "Cameras rendered in parallel");
  cmd->add_option(
      "--empty-lead-in", args->empty_lead_in_s,
      "Seconds of empty enclosure before the subjects appear (keyer training; default 1 for animal "
      "and fly sessions, 0 otherwise)");
  cmd->add_option(
      "--codec", o.codec,
      "Video codec: ffv1 (lossless, the default), ffvhuff (lossless, faster to decode), "
      "mjpeg or h264");
  cmd->add_flag(
      "--no-mattes", [&o](int64_t) { o.write_mattes = false; },
      "Skip the per-frame matte PNGs in truth/");
  cmd->add_flag("--json", args->json, "Print the report as JSON");
  cmd->callback([args] { RunSynth(*args); });
}

}  // namespace ss::apps
