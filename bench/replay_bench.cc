// spritestation bench replay: how fast a recorded session replays and records, per codec.
//   replay/CODEC_1080p_bgr8          ReplaySource over a 1920x1080 BGR8 session, as fast as
//   possible replay/decode_only/CODEC         the same video through a bare VideoReader (no CSV, no
//   queue, no thread);
//                                    decode_only/ffv1 is the baseline the others are divided by
//   replay/baseline/memcpy_1080p     the same frames memcpy'd from memory into a reused buffer
//   replay/record_CODEC_1080p_bgr8   SessionWriter recording those frames (can a station keep up
//   live?)
// CODEC: ffv1 (the default: Golomb-Rice coder) and ffvhuff (core/recording_codecs.h).
// Content: a green-screen studio frame (lit backdrop, a moving subject, sensor noise sigma 2).
// Figures: frames/s, bytes a frame on disk, and each decode as a ratio to the baseline of the same
// run.
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench_registry.h"
#include "capture/recording/session_writer.h"
#include "capture/recording/video_reader.h"
#include "capture/recording/video_writer.h"
#include "capture/replay/replay_source.h"

namespace ss::bench::replay_bench {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 1920;
constexpr int kHeight = 1080;
constexpr int kFrames = 24;

fs::path ScratchFolder() {
  static const fs::path dir = [] {
    fs::path d =
        fs::temp_directory_path() / ("spritestation-replay-bench-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// One studio frame: a green backdrop lit brighter in the middle, a walking
// subject (a warm ellipse with a darker stripe), and Gaussian sensor noise.
cv::Mat StudioFrame(int i) {
  cv::Mat frame(kHeight, kWidth, CV_8UC3);
  for (int y = 0; y < kHeight; ++y) {
    auto* row = frame.ptr<cv::Vec3b>(y);
    for (int x = 0; x < kWidth; ++x) {
      const double dx = (x - kWidth / 2.0) / kWidth;
      const double dy = (y - kHeight / 2.0) / kHeight;
      const double light = 1.0 - 0.6 * (dx * dx + dy * dy);
      row[x] = cv::Vec3b(static_cast<uint8_t>(40 * light), static_cast<uint8_t>(170 * light),
                         static_cast<uint8_t>(60 * light));
    }
  }
  const cv::Point centre(300 + i * 40, 600);
  cv::ellipse(frame, centre, cv::Size(90, 260), 0, 0, 360, cv::Scalar(70, 110, 190), cv::FILLED,
              cv::LINE_AA);
  cv::rectangle(frame, cv::Rect(centre.x - 90, centre.y - 40, 180, 30), cv::Scalar(50, 60, 120),
                cv::FILLED);
  cv::Mat noise(kHeight, kWidth, CV_16SC3);
  cv::randn(noise, 0, 2.0);
  cv::Mat noisy;
  frame.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(frame, CV_8UC3);
  return frame;
}

const std::vector<cv::Mat>& Frames() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> v;
    cv::setRNGSeed(7);
    v.reserve(kFrames);
    for (int i = 0; i < kFrames; ++i) v.push_back(StudioFrame(i));
    return v;
  }();
  return frames;
}

Frame AsFrame(const cv::Mat& m, int i) {
  Frame f = Frame::Borrowed(PixelFormat::kBGR8, kWidth, kHeight, m.data, m.total() * m.elemSize(),
                            nullptr);
  f.sequence = static_cast<uint64_t>(i);
  f.timestamp_ns = i * 33'333'333LL;
  return f;
}

void Record(const std::string& dir, const std::string& codec) {
  SourceCamera cam;
  cam.name = "cam0";
  cam.width = kWidth;
  cam.height = kHeight;
  cam.format = PixelFormat::kBGR8;
  cam.fps = 30;
  RecordingOptions options;
  options.codec = codec;
  SessionWriter writer(dir, "bench", options);
  const int index = writer.AddCamera(cam, nullptr);
  for (int i = 0; i < kFrames; ++i) {
    Frame f = AsFrame(Frames()[static_cast<size_t>(i)], i);
    f.camera = index;
    writer.Write(f);
  }
  writer.Close();
}

const std::string& Session(const std::string& codec) {
  static std::map<std::string, std::string> dirs;
  auto it = dirs.find(codec);
  if (it == dirs.end()) {
    const std::string d = (ScratchFolder() / ("session-" + codec)).string();
    Record(d, codec);
    it = dirs.emplace(codec, d).first;
  }
  return it->second;
}

// The frames as one video of `codec`.
const std::string& Video(const std::string& codec) {
  static std::map<std::string, std::string> files;
  auto it = files.find(codec);
  if (it == files.end()) {
    const std::string path = (ScratchFolder() / (codec + ".mkv")).string();
    VideoWriter writer(path, PixelFormat::kBGR8, kWidth, kHeight, 30, codec);
    for (int i = 0; i < kFrames; ++i) {
      const cv::Mat& m = Frames()[static_cast<size_t>(i)];
      writer.Write(m.data, m.total() * m.elemSize(), i * 33);
    }
    writer.Close();
    it = files.emplace(codec, path).first;
  }
  return it->second;
}

void BM_Replay(benchmark::State& state, const std::string& codec) {
  const std::string& dir = Session(codec);
  int64_t frames = 0;
  for (auto _ : state) {
    ReplaySource source(dir);
    while (auto f = source.Next()) {
      benchmark::DoNotOptimize(f->data);
      ++frames;
    }
    if (source.stats().errors != 0) state.SkipWithError(source.stats().last_error.c_str());
  }
  state.SetItemsProcessed(frames);
  state.counters["MB_per_frame_on_disk"] =
      static_cast<double>(fs::file_size(dir + "/cam0.mkv")) / kFrames / 1e6;
}

void BM_DecodeOnly(benchmark::State& state, const std::string& codec) {
  const std::string& video = Video(codec);
  std::vector<uint8_t> pixels;
  int64_t frames = 0;
  for (auto _ : state) {
    VideoReader reader(video, PixelFormat::kBGR8, kWidth, kHeight);
    while (reader.Next(pixels).status == VideoReader::Status::kFrame) ++frames;
    benchmark::DoNotOptimize(pixels.data());
  }
  state.SetItemsProcessed(frames);
  state.counters["MB_per_frame_on_disk"] =
      static_cast<double>(fs::file_size(video)) / kFrames / 1e6;
}

void BM_Memcpy(benchmark::State& state) {
  std::vector<uint8_t> buffer(static_cast<size_t>(kWidth) * kHeight * 3);
  int64_t frames = 0;
  for (auto _ : state) {
    for (const auto& m : Frames()) {
      std::memcpy(buffer.data(), m.data, buffer.size());
      benchmark::DoNotOptimize(buffer.data());
      benchmark::ClobberMemory();
      ++frames;
    }
  }
  state.SetItemsProcessed(frames);
}

void BM_Record(benchmark::State& state, const std::string& codec) {
  Frames();
  int run = 0;
  for (auto _ : state) {
    const std::string dir = (ScratchFolder() / ("record" + std::to_string(run++))).string();
    Record(dir, codec);
    state.PauseTiming();
    fs::remove_all(dir);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
}

BENCHMARK_CAPTURE(BM_Replay, ffv1, std::string("ffv1"))
    ->Name("replay/ffv1_1080p_bgr8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_Replay, ffvhuff, std::string("ffvhuff"))
    ->Name("replay/ffvhuff_1080p_bgr8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_DecodeOnly, ffv1, std::string("ffv1"))
    ->Name("replay/decode_only/ffv1")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_DecodeOnly, ffvhuff, std::string("ffvhuff"))
    ->Name("replay/decode_only/ffvhuff")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(BM_Memcpy)
    ->Name("replay/baseline/memcpy_1080p")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Record, ffv1, std::string("ffv1"))
    ->Name("replay/record_ffv1_1080p_bgr8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Record, ffvhuff, std::string("ffvhuff"))
    ->Name("replay/record_ffvhuff_1080p_bgr8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Keeps each case's frames/s so the suite can print ratios after the table.
class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const auto it = r.counters.find("items_per_second");
      // The case name without its /min_time:.../real_time suffixes.
      if (it != r.counters.end()) frames_per_second[r.run_name.function_name] = it->second.value;
      const auto mb = r.counters.find("MB_per_frame_on_disk");
      if (mb != r.counters.end()) mb_per_frame[r.run_name.function_name] = mb->second.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> frames_per_second;
  std::map<std::string, double> mb_per_frame;
};

int Run(const std::vector<std::string>& args) {
  Collector collector;
  if (const int status = RunGoogleBenchmarks("replay/", args, &collector)) return status;
  std::error_code ec;
  fs::remove_all(ScratchFolder(), ec);

  auto& fps = collector.frames_per_second;
  auto& mb = collector.mb_per_frame;
  const char* baseline = "replay/decode_only/ffv1";
  std::printf("\nreplay figures (1920x1080 BGR8, %ld cores; ratios to %s in this run):\n",
              sysconf(_SC_NPROCESSORS_ONLN), baseline);
  for (const char* name :
       {"replay/decode_only/ffv1", "replay/decode_only/ffvhuff", "replay/ffv1_1080p_bgr8",
        "replay/ffvhuff_1080p_bgr8", "replay/record_ffv1_1080p_bgr8",
        "replay/record_ffvhuff_1080p_bgr8", "replay/baseline/memcpy_1080p"}) {
    if (!fps.count(name)) continue;
    std::printf("  %-40s %8.1f frames/s", name, fps[name]);
    if (fps.count(baseline)) std::printf("  %6.2f x", fps[name] / fps[baseline]);
    if (mb.count(name)) std::printf("  %.2f MB a frame", mb[name]);
    std::printf("\n");
  }
  return 0;
}

const bool kRegistered =
    RegisterSuite({"replay", "session replay throughput at 1080p (frames/s) vs memcpy", &Run});

}  // namespace
}  // namespace ss::bench::replay_bench
