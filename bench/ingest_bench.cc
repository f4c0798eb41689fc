// spritestation bench ingest: how fast one 1080p camera's recording is ingested, per codec.
//   ingest/decode_only/CODEC            the session's video through a bare VideoReader with one
//   decoder
//                                       (no pipeline, no bank): the plain decode each ingest is
//                                       divided by
//   ingest/decode_threads/CODEC         the same with one decoder thread per core (decoding alone)
//   ingest/CODEC_1080p                  IngestSession (replay, pipeline, bank; no transitions), one
//   decoder
//                                       thread per core: what `spritestation ingest` does
//   ingest/CODEC_1080p/one_decoder      the same with --decode-threads 1: frames decoded one after
//   another
//                                       (FFmpeg's slice threads for FFV1), the path before issue 19
//   ingest/ffv1_1080p/one_core          the one-decoder ingest with every thread of the process
//                                       pinned to one core: what a core does (issue 19's "about 7
//                                       frames/s a core"), the baseline of the FFV1 goal
// CODEC: ffv1 and ffvhuff (core/recording_codecs.h). Session: `synth` animal, 1920x1080 RGB8, 4 s
// at 30 fps (1 s of empty enclosure for the keyer), seed 4, made once per codec and cached in the
// temp dir. Each case runs once (an ingest takes seconds); --benchmark_repetitions=N repeats them.
// Figures: frames/s of wall time, frames per CPU-second of the whole process, MB a frame on disk,
// ratios to the plain decode of the same file and to the one-decoder FFV1 ingest of this run, and
// the load average before and after (the machine is shared).
#include <sched.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "capture/recording/video_reader.h"
#include "config/station_config.h"
#include "core/log.h"
#include "pipeline/run/ingest.h"
#include "synth/studio_session.h"

namespace ss::bench::ingest_bench {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 1920;
constexpr int kHeight = 1080;

double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = 0, five = 0, fifteen = 0;
  in >> one >> five >> fifteen;
  char text[64];
  std::snprintf(text, sizeof(text), "%.2f %.2f %.2f", one, five, fifteen);
  return text;
}

fs::path ScratchFolder() {
  static const fs::path dir = [] {
    fs::path d =
        fs::temp_directory_path() / ("spritestation-ingest-bench-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// The 1080p session in `codec`, rendered once (the same footage for every codec) and kept.
const std::string& Session(const std::string& codec) {
  static std::map<std::string, std::string> dirs;
  auto it = dirs.find(codec);
  if (it != dirs.end()) return it->second;
  const fs::path dir = fs::temp_directory_path() / ("spritestation-ingest-bench-1080p-" + codec);
  if (!fs::exists(dir / "session.json")) {
    fs::remove_all(dir);
    synth::SynthOptions o;
    o.out_dir = dir.string();
    o.seconds = 4;
    o.fps = 30;
    o.width = kWidth;
    o.height = kHeight;
    o.cameras = 1;
    o.subjects = 1;
    o.seed = 4;
    o.empty_lead_in_s = 1;
    o.write_mattes = false;
    o.codec = codec;
    std::fprintf(stderr, "bench ingest: rendering the 1080p %s session into %s (once)...\n",
                 codec.c_str(), o.out_dir.c_str());
    synth::RenderStudioSession(o);
  }
  return dirs.emplace(codec, dir.string()).first->second;
}

std::string Video(const std::string& codec) { return Session(codec) + "/cam0.mkv"; }

void SetCounters(benchmark::State& state, int64_t frames, double cpu_s, const std::string& codec) {
  state.SetItemsProcessed(frames);
  state.counters["frames_per_cpu_s"] = cpu_s > 0 ? static_cast<double>(frames) / cpu_s : 0;
  const double frames_per_pass =
      static_cast<double>(frames) / static_cast<double>(state.iterations());
  state.counters["MB_per_frame_on_disk"] =
      frames_per_pass > 0 ? static_cast<double>(fs::file_size(Video(codec))) / frames_per_pass / 1e6
                          : 0;
}

void BM_Decode(benchmark::State& state, const std::string& codec, int decode_threads) {
  const std::string video = Video(codec);
  std::vector<uint8_t> pixels;
  int64_t frames = 0;
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    VideoReader reader(video, PixelFormat::kRGB8, kWidth, kHeight, decode_threads);
    while (reader.Next(pixels).status == VideoReader::Status::kFrame) ++frames;
    benchmark::DoNotOptimize(pixels.data());
  }
  SetCounters(state, frames, ProcessCpuSeconds() - cpu_start, codec);
}

void BM_Ingest(benchmark::State& state, const std::string& codec, int decode_threads) {
  const std::string session = Session(codec);
  int64_t frames = 0;
  int run = 0;
  double cpu_s = 0;
  for (auto _ : state) {
    IngestOptions options;
    options.session_dir = session;
    options.bank_path = (ScratchFolder() / ("run" + std::to_string(run++) + ".bank")).string();
    options.transitions = false;
    options.decode_threads = decode_threads;
    options.pipeline = DefaultPipelineOptions();  // the config's defaults
    const double cpu_start = ProcessCpuSeconds();
    const IngestSummary summary = IngestSession(options);
    cpu_s += ProcessCpuSeconds() - cpu_start;
    frames += static_cast<int64_t>(summary.frames);
    state.PauseTiming();
    if (summary.sprites_kept == 0) state.SkipWithError("ingest kept no sprite");
    if (summary.source.errors != 0) state.SkipWithError(summary.source.last_error.c_str());
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(options.bank_path + suffix, ec);
    state.ResumeTiming();
  }
  SetCounters(state, frames, cpu_s, codec);
}

#define SS_INGEST_CASE(fn, codec, threads, name)                         \
  BENCHMARK_CAPTURE(fn, codec##_##threads, std::string(#codec), threads) \
      ->Name(name)                                                       \
      ->Unit(benchmark::kMillisecond)                                    \
      ->UseRealTime()                                                    \
      ->Iterations(1)

// Every thread of this process, and so every thread they start, on the CPUs of `mask`.
void PinProcess(const cpu_set_t& mask) {
  for (const auto& task : fs::directory_iterator("/proc/self/task")) {
    const pid_t tid = static_cast<pid_t>(std::stol(task.path().filename().string()));
    sched_setaffinity(tid, sizeof(mask), &mask);  // a thread that just ended: nothing to pin
  }
}

// BM_Ingest with the whole process on the first CPU it may use, then as it was.
void BM_IngestOneCore(benchmark::State& state, const std::string& codec, int decode_threads) {
  cpu_set_t all;
  CPU_ZERO(&all);
  if (sched_getaffinity(0, sizeof(all), &all) != 0) {
    state.SkipWithError("sched_getaffinity failed");
    return;
  }
  int first = 0;
  while (first < CPU_SETSIZE && !CPU_ISSET(first, &all)) ++first;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  PinProcess(one);
  BM_Ingest(state, codec, decode_threads);
  PinProcess(all);
}

SS_INGEST_CASE(BM_Decode, ffv1, 1, "ingest/decode_only/ffv1");
SS_INGEST_CASE(BM_Decode, ffv1, 0, "ingest/decode_threads/ffv1");
SS_INGEST_CASE(BM_Ingest, ffv1, 1, "ingest/ffv1_1080p/one_decoder");
SS_INGEST_CASE(BM_Ingest, ffv1, 0, "ingest/ffv1_1080p");
SS_INGEST_CASE(BM_IngestOneCore, ffv1, 1, "ingest/ffv1_1080p/one_core");
SS_INGEST_CASE(BM_Decode, ffvhuff, 1, "ingest/decode_only/ffvhuff");
SS_INGEST_CASE(BM_Decode, ffvhuff, 0, "ingest/decode_threads/ffvhuff");
SS_INGEST_CASE(BM_Ingest, ffvhuff, 1, "ingest/ffvhuff_1080p/one_decoder");
SS_INGEST_CASE(BM_Ingest, ffvhuff, 0, "ingest/ffvhuff_1080p");

// Keeps each case's figures so the suite can print ratios after the table.
class Collector : public benchmark::ConsoleReporter {
 public:
  struct Figures {
    double fps = 0;
    double fps_cpu = 0;
    double mb = 0;
  };
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      Figures& f = figures[r.run_name.function_name];
      const auto get = [&](const char* counter) {
        const auto it = r.counters.find(counter);
        return it == r.counters.end() ? 0.0 : it->second.value;
      };
      // With --benchmark_repetitions the last repetition's figures are kept.
      f.fps = get("items_per_second");
      f.fps_cpu = get("frames_per_cpu_s");
      f.mb = get("MB_per_frame_on_disk");
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, Figures> figures;
};

int Run(const std::vector<std::string>& args) {
  std::vector<std::string> storage = {"spritestation-bench", "--benchmark_filter=^ingest/"};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(storage.size());
  for (auto& s : storage) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  if (benchmark::ReportUnrecognizedArguments(argc, argv.data())) return 2;
  SetLogLevel("error");  // the keyer's warnings about the synthetic enclosure are not figures
  for (const char* codec : {"ffv1", "ffvhuff"})
    Session(codec);  // rendered before anything is timed
  const std::string load_before = LoadAverage();
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();
  const std::string load_after = LoadAverage();
  std::error_code ec;
  fs::remove_all(ScratchFolder(), ec);

  auto& figures = collector.figures;
  const char* today = "ingest/ffv1_1080p/one_decoder";
  std::printf(
      "\ningest figures (one 1920x1080 RGB8 camera, %ld cores; load average %s before, %s "
      "after):\n",
      sysconf(_SC_NPROCESSORS_ONLN), load_before.c_str(), load_after.c_str());
  std::printf("  %-36s %9s %12s %10s %14s %10s\n", "case", "frames/s", "per CPU-s", "x decode",
              "x ffv1 1 dec", "MB/frame");
  for (const char* codec : {"ffv1", "ffvhuff"}) {
    const std::string plain = std::string("ingest/decode_only/") + codec;
    for (const std::string& name : {plain, std::string("ingest/decode_threads/") + codec,
                                    std::string("ingest/") + codec + "_1080p/one_core",
                                    std::string("ingest/") + codec + "_1080p/one_decoder",
                                    std::string("ingest/") + codec + "_1080p"}) {
      if (!figures.count(name)) continue;
      const Collector::Figures& f = figures[name];
      std::printf("  %-36s %9.1f %12.1f", name.c_str(), f.fps, f.fps_cpu);
      if (figures.count(plain) && figures[plain].fps > 0) {
        std::printf(" %9.2fx", f.fps / figures[plain].fps);
      } else {
        std::printf(" %10s", "");
      }
      if (figures.count(today) && figures[today].fps > 0) {
        std::printf(" %13.2fx", f.fps / figures[today].fps);
      } else {
        std::printf(" %14s", "");
      }
      std::printf(" %10.2f\n", f.mb);
    }
  }
  std::printf(
      "  (x decode: to the plain one-decoder decode of the same file; x ffv1 1 dec: to %s)\n",
      today);
  const char* one_core = "ingest/ffv1_1080p/one_core";
  const char* ffv1 = "ingest/ffv1_1080p";
  if (figures.count(one_core) && figures.count(ffv1) && figures[one_core].fps > 0) {
    std::printf("  FFV1 ingest = %.2f x the same ingest on one core (issue 19's goal: >= 1.8 x)\n",
                figures[ffv1].fps / figures[one_core].fps);
  }
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"ingest", "one 1080p camera's ingest per codec (frames/s) vs a plain decode of the same file",
     &Run});

}  // namespace
}  // namespace ss::bench::ingest_bench
