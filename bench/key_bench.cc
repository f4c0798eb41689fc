// spritestation bench key [--json] [google benchmark args]: key + extract on one core.
//   key/key_extract_1080p_rgb8      ChromaKeyer + Extractor on 1920x1080 RGB8 frames, one subject
//   key/baseline/read_1080p_rgb8    a plain read of every byte of the same frames (memory
//   bandwidth) key/ffmpeg_chromakey_1080p      FFmpeg's chromakey filter (libavfilter), one thread,
//   the same frames
//                                   pre-converted (untimed) to its own pixel format, yuva444p
//   key/train_1080p                 ChromaKeyer::Train on the empty frames (frames learnt a second)
// Content: tests/pipeline/key_scene.h at 1080p: uneven, vignetted, tinted green with sensor
// noise; one brown textured subject with legs, spill and a contact shadow, moving across.
// Figures: frames/s, and key + extract as ratios to the read and to FFmpeg of the same run.
#include <emmintrin.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavfilter/avfilter.h>
#include <libavfilter/buffersink.h>
#include <libavfilter/buffersrc.h>
#include <libavutil/frame.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

#include "bench/bench_registry.h"
#include "core/frame.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/key/chroma_keyer.h"
#include "tests/pipeline/key_scene.h"

namespace ss::bench::key_bench {
namespace {

constexpr int kWidth = 1920;
constexpr int kHeight = 1080;
constexpr int kFrames = 12;  // 75 MB of RGB: more than any cache, so every pass reads memory

struct Footage {
  std::vector<cv::Mat> empty_bgr;         // to train the keyer
  std::vector<std::vector<uint8_t>> rgb;  // the frames as a camera delivers them
  std::vector<cv::Mat> bgr;               // the same, for FFmpeg's conversion
};

const Footage& Frames() {
  static const Footage footage = [] {
    testing::SceneOptions o;
    o.size = {kWidth, kHeight};
    o.seed = 11;
    const testing::KeyScene scene(o);
    Footage f;
    for (int i = 0; i < 4; ++i) f.empty_bgr.push_back(scene.Empty(1000 + i));
    for (int i = 0; i < kFrames; ++i) {
      testing::SceneSubject s;
      s.centre = {500.0 + 80.0 * i, 520.0 + 10.0 * i};
      s.rx = 110;
      s.ry = 70;
      for (double dx : {-60.0, -25.0, 25.0, 60.0}) {
        s.bars.push_back({{s.centre.x + dx, s.centre.y + 75}, 60, 12, 90.0 + 8 * (i % 3 - 1)});
      }
      const cv::Mat bgr = scene.Render({s}, i).bgr;
      cv::Mat rgb;
      cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
      f.rgb.emplace_back(rgb.data, rgb.data + rgb.total() * 3);
      f.bgr.push_back(bgr);
    }
    return f;
  }();
  return footage;
}

void BM_KeyExtract(benchmark::State& state) {
  const Footage& f = Frames();
  ChromaKeyer keyer;
  keyer.Train(f.empty_bgr);
  Extractor extractor;
  Matte matte;
  cv::Mat scratch;
  std::vector<Frame> frames;
  for (const auto& bytes : f.rgb) {
    frames.push_back(
        Frame::Borrowed(PixelFormat::kRGB8, kWidth, kHeight, bytes.data(), bytes.size(), nullptr));
  }
  int64_t n = 0, candidates = 0;
  for (auto _ : state) {
    for (const Frame& frame : frames) {
      keyer.Key(frame, scratch, matte);
      candidates += static_cast<int64_t>(extractor.Extract(matte).size());
      benchmark::DoNotOptimize(matte.alpha.data);
      ++n;
    }
  }
  state.SetItemsProcessed(n);
  state.counters["candidates_per_frame"] =
      static_cast<double>(candidates) / std::max<int64_t>(n, 1);
  if (candidates != n) state.SkipWithError("expected exactly one candidate per frame");
}

// Sum of all bytes with SSE2 (x86-64's baseline): 64 bytes per step into four
// independent accumulators, so that the loads, not the adds, set the pace.
uint64_t SumBytes(const uint8_t* p, size_t n) {
  const __m128i zero = _mm_setzero_si128();
  __m128i acc[4] = {zero, zero, zero, zero};
  size_t i = 0;
  for (; i + 64 <= n; i += 64) {
    for (int k = 0; k < 4; ++k) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + i + 16 * k));
      acc[k] = _mm_add_epi64(acc[k], _mm_sad_epu8(v, zero));
    }
  }
  const __m128i s = _mm_add_epi64(_mm_add_epi64(acc[0], acc[1]), _mm_add_epi64(acc[2], acc[3]));
  uint64_t total = static_cast<uint64_t>(_mm_cvtsi128_si64(s)) +
                   static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(s, s)));
  for (; i < n; ++i) total += p[i];
  return total;
}

void BM_Read(benchmark::State& state) {
  const Footage& f = Frames();
  int64_t n = 0;
  for (auto _ : state) {
    for (const auto& bytes : f.rgb) {
      benchmark::DoNotOptimize(SumBytes(bytes.data(), bytes.size()));
      ++n;
    }
  }
  state.SetItemsProcessed(n);
}

// RAII for the libav objects.
struct GraphDeleter {
  void operator()(AVFilterGraph* g) const { avfilter_graph_free(&g); }
};
struct FrameDeleter {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
using AvFrame = std::unique_ptr<AVFrame, FrameDeleter>;

AvFrame ToYuva444(const cv::Mat& bgr) {
  AvFrame out(av_frame_alloc());
  out->format = AV_PIX_FMT_YUVA444P;
  out->width = bgr.cols;
  out->height = bgr.rows;
  if (av_frame_get_buffer(out.get(), 0) < 0) return nullptr;
  SwsContext* sws = sws_getContext(bgr.cols, bgr.rows, AV_PIX_FMT_BGR24, bgr.cols, bgr.rows,
                                   AV_PIX_FMT_YUVA444P, SWS_POINT, nullptr, nullptr, nullptr);
  const uint8_t* src[1] = {bgr.data};
  const int stride[1] = {static_cast<int>(bgr.step)};
  sws_scale(sws, src, stride, 0, bgr.rows, out->data, out->linesize);
  sws_freeContext(sws);
  for (int y = 0; y < bgr.rows; ++y)
    std::fill_n(out->data[3] + y * out->linesize[3], bgr.cols, 255);
  return out;
}

void BM_FfmpegChromakey(benchmark::State& state) {
  const Footage& f = Frames();
  std::vector<AvFrame> inputs;
  for (const cv::Mat& bgr : f.bgr) inputs.push_back(ToYuva444(bgr));
  if (!inputs.front()) {
    state.SkipWithError("av_frame_get_buffer failed");
    return;
  }
  std::unique_ptr<AVFilterGraph, GraphDeleter> graph(avfilter_graph_alloc());
  graph->nb_threads = 1;  // one core, as for the keyer
  graph->thread_type = 0;
  AVFilterContext *src = nullptr, *key = nullptr, *sink = nullptr;
  const std::string src_args =
      "video_size=" + std::to_string(kWidth) + "x" + std::to_string(kHeight) +
      ":pix_fmt=" + std::to_string(AV_PIX_FMT_YUVA444P) + ":time_base=1/30:pixel_aspect=1/1";
  // The scene's mean green (BGR 62, 168, 68 lit), tolerances as in FFmpeg's documentation examples.
  if (avfilter_graph_create_filter(&src, avfilter_get_by_name("buffer"), "in", src_args.c_str(),
                                   nullptr, graph.get()) < 0 ||
      avfilter_graph_create_filter(&key, avfilter_get_by_name("chromakey"), "key",
                                   "color=0x44A83E:similarity=0.12:blend=0.08", nullptr,
                                   graph.get()) < 0 ||
      avfilter_graph_create_filter(&sink, avfilter_get_by_name("buffersink"), "out", nullptr,
                                   nullptr, graph.get()) < 0 ||
      avfilter_link(src, 0, key, 0) < 0 || avfilter_link(key, 0, sink, 0) < 0 ||
      avfilter_graph_config(graph.get(), nullptr) < 0) {
    state.SkipWithError("could not build the buffer -> chromakey -> buffersink graph");
    return;
  }
  AvFrame out(av_frame_alloc());
  int64_t n = 0, pts = 0;
  for (auto _ : state) {
    for (const AvFrame& in : inputs) {
      in->pts = pts++;
      if (av_buffersrc_add_frame_flags(src, in.get(), AV_BUFFERSRC_FLAG_KEEP_REF) < 0 ||
          av_buffersink_get_frame(sink, out.get()) < 0) {
        state.SkipWithError("chromakey filter failed");
        return;
      }
      benchmark::DoNotOptimize(out->data[3]);
      av_frame_unref(out.get());
      ++n;
    }
  }
  state.SetItemsProcessed(n);
}

// Learning the empty enclosure: a one-time cost a camera pays before its first sprite (the
// recording waits for it), per frame learnt.
void BM_Train(benchmark::State& state) {
  const Footage& f = Frames();
  int64_t n = 0;
  for (auto _ : state) {
    ChromaKeyer keyer;
    keyer.Train(f.empty_bgr);
    benchmark::DoNotOptimize(keyer.unkeyable_fraction());
    n += static_cast<int64_t>(f.empty_bgr.size());
  }
  state.SetItemsProcessed(n);
}

BENCHMARK(BM_KeyExtract)
    ->Name("key/key_extract_1080p_rgb8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(BM_Train)
    ->Name("key/train_1080p")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(BM_Read)
    ->Name("key/baseline/read_1080p_rgb8")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_FfmpegChromakey)
    ->Name("key/ffmpeg_chromakey_1080p")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// Keeps each case's frames/s so the suite can print ratios after the table.
class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const auto it = r.counters.find("items_per_second");
      if (it != r.counters.end()) frames_per_second[r.run_name.function_name] = it->second.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> frames_per_second;
};

int Run(const std::vector<std::string>& args) {
  bool json = false;
  std::vector<std::string> storage = {"spritestation-bench", "--benchmark_filter=^key/"};
  for (const std::string& a : args) {
    if (a == "--json") {
      json = true;
    } else {
      storage.push_back(a);
    }
  }
  std::vector<char*> argv;
  argv.reserve(storage.size());
  for (auto& s : storage) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  if (benchmark::ReportUnrecognizedArguments(argc, argv.data())) return 2;
  cv::setNumThreads(1);  // nothing in the key path may spread to other cores
  Frames();              // render the footage before any timing
  Collector collector;
  if (json) collector.SetOutputStream(&std::cerr);  // the table to stderr, the figures to stdout
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();

  auto& fps = collector.frames_per_second;
  const std::string key = "key/key_extract_1080p_rgb8", read = "key/baseline/read_1080p_rgb8",
                    ffmpeg = "key/ffmpeg_chromakey_1080p", train = "key/train_1080p";
  nlohmann::json figures = {{"frame", "1920x1080 rgb8, one subject"}, {"threads", 1}};
  for (const auto& [name, value] : fps) figures["frames_per_second"][name] = value;
  if (fps.count(key) && fps.count(read)) figures["key_over_read"] = fps[key] / fps[read];
  if (fps.count(key) && fps.count(ffmpeg))
    figures["key_over_ffmpeg_chromakey"] = fps[key] / fps[ffmpeg];
  if (fps.count(train) && fps.count(read)) figures["train_over_read"] = fps[train] / fps[read];
  if (json) {
    std::printf("%s\n", figures.dump(2).c_str());
    return 0;
  }
  std::printf("\nkey figures (1920x1080 RGB8, one subject, one thread of %ld cores):\n",
              sysconf(_SC_NPROCESSORS_ONLN));
  for (const std::string& name : {key, train, read, ffmpeg}) {
    if (fps.count(name)) std::printf("  %-32s %10.1f frames/s\n", name.c_str(), fps[name]);
  }
  if (figures.contains("key_over_read")) {
    std::printf("  key + extract = %.3f x the read limit (goal >= 0.25)\n",
                figures["key_over_read"].get<double>());
  }
  if (figures.contains("train_over_read")) {
    std::printf("  training = %.3f x the read limit, per frame learnt\n",
                figures["train_over_read"].get<double>());
  }
  if (figures.contains("key_over_ffmpeg_chromakey")) {
    std::printf("  key + extract = %.1f x FFmpeg chromakey (goal >> 50)\n",
                figures["key_over_ffmpeg_chromakey"].get<double>());
  }
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"key", "key + extract at 1080p on one core vs a plain read and FFmpeg chromakey", &Run});

}  // namespace
}  // namespace ss::bench::key_bench
