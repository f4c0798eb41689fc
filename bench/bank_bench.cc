// spritestation bench bank: sprite bank append rate and feature-load time.
//   bank/append/originals      batches of 100 original sprites, each a 64x64 BGRA+shadow billboard
//   bank/append/with_mirrors   batches of 50 originals + their 50 mirrored copies (as the pipeline
//   stores them) bank/baseline/compress     the same 100 billboards only zstd-compressed (what
//   appending cannot beat) bank/load_features_60k     Bank::LoadFeatures on a bank of 60,000
//   sprites (30,000 + mirrors) bank/baseline/scan_60k     a bare sqlite3 scan of the same rows and
//   columns bank/load_pixels           Bank::LoadPixels of random sprites of that bank
//   bank/postgres/append_4_writers  four writers at once (threads, a session each) appending
//   batches of
//                              50 originals + 50 mirrors into one PostgreSQL bank; only when
//                              SPRITESTATION_BENCH_POSTGRES names one (scripts/bench-postgres.sh
//                              starts a private server for it): compared with
//                              bank/append/with_mirrors, one SQLite writer, in the same run
// Figures: sprites/s and ms, then each case as a ratio to its baseline from the same run.
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "core/bank.h"
#include "core/bank_pixels.h"
#include "core/posix.h"

namespace ss::bench::bank_bench {
namespace {

namespace fs = std::filesystem;

constexpr int kBillboardPx = 64;
constexpr int kBatch = 100;
constexpr int kFeatureBankSprites = 60'000;

fs::path ScratchFolder() {
  static const fs::path dir = [] {
    fs::path d =
        fs::temp_directory_path() / ("spritestation-bank-bench-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// A keyed billboard: an upright elliptical subject with a soft edge, textured colour with
// sensor noise inside the matte, zero colour outside, and a contact shadow under the feet.
SpritePixels RealisticBillboard(uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 3.0);
  SpritePixels p;
  p.bgra = cv::Mat::zeros(kBillboardPx, kBillboardPx, CV_8UC4);
  p.shadow = cv::Mat::zeros(kBillboardPx, kBillboardPx, CV_8UC1);
  const double cx = kBillboardPx / 2.0 + (seed % 5), cy = kBillboardPx * 0.45;
  for (int y = 0; y < kBillboardPx; ++y) {
    for (int x = 0; x < kBillboardPx; ++x) {
      const double dx = (x - cx) / (kBillboardPx * 0.22), dy = (y - cy) / (kBillboardPx * 0.42);
      const double r = std::sqrt(dx * dx + dy * dy);
      const double alpha = std::clamp((1.05 - r) * 10.0, 0.0, 1.0);
      if (alpha > 0) {
        auto c = [&](double v) {
          return static_cast<uint8_t>(std::clamp(v + noise(rng), 0.0, 255.0));
        };
        const double stripe = (y / 6 + seed) % 2 ? 40 : 0;
        p.bgra.at<cv::Vec4b>(y, x) = {c(60 + stripe), c(90 + 0.5 * y), c(150 - stripe),
                                      static_cast<uint8_t>(alpha * 255)};
      }
      const double sx = (x - cx) / (kBillboardPx * 0.3),
                   sy = (y - kBillboardPx * 0.9) / (kBillboardPx * 0.06);
      const double s = 1.0 - (sx * sx + sy * sy);
      if (s > 0)
        p.shadow.at<uint8_t>(y, x) =
            static_cast<uint8_t>(std::clamp(s * 120 + noise(rng), 0.0, 255.0));
    }
  }
  return p;
}

SpriteRecord Sprite(int64_t frame, const SpritePixels& pixels) {
  SpriteRecord s;
  s.frame = frame;
  s.timestamp_ns = frame * 16'666'667;
  s.ground_x_m = 0.5 + 0.01 * frame;
  s.ground_y_m = 1.0;
  s.velocity_x_m_s = 0.6;
  s.velocity_y_m_s = 0.05 * std::sin(frame * 0.1);
  s.mean_r = 150;
  s.mean_g = 110;
  s.mean_b = 80;
  s.area_px = 1900 + frame % 50;
  s.eccentricity = 0.8;
  s.bbox_in_image = cv::Rect(300, 200, 120, 260);
  s.billboard_width_px = s.billboard_height_px = kBillboardPx;
  s.px_per_m = 40;
  s.anchor_x_px = 32;
  s.anchor_y_px = 62;
  s.pixels = pixels;
  return s;
}

SpriteRecord Mirror(const SpriteRecord& o) {
  SpriteRecord m = o;
  m.mirrored = true;
  m.velocity_x_m_s = -o.velocity_x_m_s;
  m.anchor_x_px = kBillboardPx - o.anchor_x_px;
  m.pixels = {};
  return m;
}

const std::vector<SpritePixels>& Billboards() {
  static const std::vector<SpritePixels> all = [] {
    std::vector<SpritePixels> v;
    v.reserve(kBatch);
    for (int i = 0; i < kBatch; ++i) v.push_back(RealisticBillboard(static_cast<uint32_t>(i)));
    return v;
  }();
  return all;
}

void AppendCase(benchmark::State& state, bool mirrors) {
  const fs::path path = ScratchFolder() / (mirrors ? "append_mirrors.db" : "append.db");
  fs::remove(path);
  BankWriter writer(path.string());
  const int64_t session = writer.AddSession({0, "bench", "bench", "", ""});
  const int64_t camera = writer.AddCamera(session, {0, 0, "cam0", "", 1280, 720});
  int64_t track = 0;
  int64_t bytes = 0;
  for (auto _ : state) {
    std::vector<SpriteRecord> batch;
    state.PauseTiming();
    const int originals = mirrors ? kBatch / 2 : kBatch;
    for (int i = 0; i < originals; ++i) {
      batch.push_back(Sprite(i, Billboards()[static_cast<size_t>(i)]));
      if (mirrors) batch.push_back(Mirror(batch.back()));
    }
    ClipRecord clip;
    clip.camera_id = camera;
    clip.track_id = track++;
    clip.complete = true;
    state.ResumeTiming();
    writer.AppendClipBatch(clip, batch);
  }
  bytes = writer.Counts().pixel_bytes;
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["stored_bytes_per_billboard"] =
      static_cast<double>(bytes) /
      static_cast<double>(state.iterations() * (mirrors ? kBatch / 2 : kBatch));
}

void BM_AppendOriginals(benchmark::State& state) { AppendCase(state, false); }
void BM_AppendWithMirrors(benchmark::State& state) { AppendCase(state, true); }

void BM_Compress(benchmark::State& state) {
  PixelCodec codec;
  for (auto _ : state) {
    for (const auto& b : Billboards()) benchmark::DoNotOptimize(codec.Encode(b).size());
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

// The 60k-sprite bank, built once per process (30,000 originals with pixels + their mirrors).
const std::string& FeatureBank() {
  static const std::string path = [] {
    const fs::path p = ScratchFolder() / "features60k.db";
    fs::remove(p);
    BankWriter writer(p.string());
    const int64_t session = writer.AddSession({0, "bench60k", "bench60k", "", ""});
    const int64_t camera = writer.AddCamera(session, {0, 0, "cam0", "", 1280, 720});
    constexpr int kClipFrames = 300;
    for (int clip = 0; clip < kFeatureBankSprites / 2 / kClipFrames; ++clip) {
      for (int first = 0; first < kClipFrames; first += kBatch / 2) {
        std::vector<SpriteRecord> batch;
        for (int f = first; f < first + kBatch / 2; ++f) {
          batch.push_back(Sprite(f, Billboards()[static_cast<size_t>(f % kBatch)]));
          batch.push_back(Mirror(batch.back()));
        }
        ClipRecord c;
        c.camera_id = camera;
        c.track_id = clip;
        c.complete = first + kBatch / 2 >= kClipFrames;
        writer.AppendClipBatch(c, batch);
      }
    }
    return p.string();
  }();
  return path;
}

void BM_LoadFeatures(benchmark::State& state) {
  const Bank bank(FeatureBank());
  size_t n = 0;
  for (auto _ : state) {
    const auto features = bank.LoadFeatures();
    n = features.size();
    benchmark::DoNotOptimize(features.data());
  }
  if (n != kFeatureBankSprites)
    state.SkipWithError("the feature bank holds the wrong number of sprites");
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}

void BM_ScanBaseline(benchmark::State& state) {
  sqlite3* db = nullptr;
  sqlite3_open_v2(FeatureBank().c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* stmt = nullptr;
  sqlite3_prepare_v2(
      db,
      "SELECT s.id, s.clip_id, s.frame, s.timestamp_ns, s.mirror_of, s.mirrored, s.ground_x_m, "
      "s.ground_y_m, s.velocity_x_m_s, s.velocity_y_m_s, s.mean_r, s.mean_g, s.mean_b, s.area_px, "
      "s.eccentricity FROM sprites s",
      -1, &stmt, nullptr);
  int64_t rows = 0;
  for (auto _ : state) {
    double sum = 0;
    while (sqlite3_step(stmt) == SQLITE_ROW) {
      for (int c = 0; c < 15; ++c) sum += sqlite3_column_double(stmt, c);
      ++rows;
    }
    sqlite3_reset(stmt);
    benchmark::DoNotOptimize(sum);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  state.SetItemsProcessed(rows);
}

// Stage-2 transition features read billboards one by one: random sprites of the 60k bank.
void BM_LoadPixels(benchmark::State& state) {
  const Bank bank(FeatureBank());
  const auto features = bank.LoadFeatures();
  std::mt19937 rng(1);
  for (auto _ : state) {
    const SpritePixels p = bank.LoadPixels(features[rng() % features.size()].id);
    benchmark::DoNotOptimize(p.bgra.data);
  }
  state.SetItemsProcessed(state.iterations());
}

// Four stations storing into one PostgreSQL bank at once: each thread its own writer, session
// and camera (so their clips never collide), the same batches as bank/append/with_mirrors.
void BM_PostgresFourWriters(benchmark::State& state) {
  const std::string address = Environment("SPRITESTATION_BENCH_POSTGRES").value_or("");
  if (address.empty()) {
    state.SkipWithError(
        "SPRITESTATION_BENCH_POSTGRES is not set (scripts/bench-postgres.sh sets it)");
    return;
  }
  BankWriter writer(address);
  const std::string uid = "bench-" + std::to_string(getpid()) + "-" +
                          std::to_string(state.thread_index()) + "-" +
                          std::to_string(std::random_device{}());
  const int64_t session = writer.AddSession({0, uid, "bench", "", ""});
  const int64_t camera = writer.AddCamera(session, {0, 0, "cam0", "", 1280, 720});
  int64_t track = 0;
  for (auto _ : state) {
    std::vector<SpriteRecord> batch;
    state.PauseTiming();
    for (int i = 0; i < kBatch / 2; ++i) {
      batch.push_back(Sprite(i, Billboards()[static_cast<size_t>(i)]));
      batch.push_back(Mirror(batch.back()));
    }
    ClipRecord clip;
    clip.camera_id = camera;
    clip.track_id = track++;
    clip.complete = true;
    state.ResumeTiming();
    writer.AppendClipBatch(clip, batch);
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

// Wall-clock rates (UseRealTime): appending includes the file writes.
BENCHMARK(BM_AppendOriginals)
    ->Name("bank/append/originals")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK(BM_AppendWithMirrors)
    ->Name("bank/append/with_mirrors")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK(BM_Compress)
    ->Name("bank/baseline/compress")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_LoadFeatures)
    ->Name("bank/load_features_60k")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ScanBaseline)
    ->Name("bank/baseline/scan_60k")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_LoadPixels)->Name("bank/load_pixels")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_PostgresFourWriters)
    ->Name("bank/postgres/append_4_writers")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->Threads(4)
    ->UseRealTime();

// Keeps what each case measured so the suite can print ratios after the table.
class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const auto it = r.counters.find("items_per_second");
      const std::string& name = r.run_name.function_name;  // without "/min_time:..." suffixes
      if (it != r.counters.end()) items_per_second[name] = it->second.value;
      ms_per_iteration[name] = r.GetAdjustedRealTime();  // in the case's unit (ms)
      cpu_share[name] = r.GetAdjustedCPUTime() / r.GetAdjustedRealTime();
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> items_per_second, ms_per_iteration;
  std::map<std::string, double>
      cpu_share;  // CPU time / wall time: below 1 when the machine is busy
};

int Run(const std::vector<std::string>& args) {
  Collector collector;
  if (const int status = RunGoogleBenchmarks("bank/", args, &collector)) return status;
  std::error_code ec;
  fs::remove_all(ScratchFolder(), ec);

  // Ratios use CPU time: on a shared machine wall time swings between cases of the same run.
  auto& ms = collector.ms_per_iteration;
  auto cpu_rate = [&](const std::string& name) {
    return collector.items_per_second[name] / collector.cpu_share[name];
  };
  auto has = [&](const std::string& name) { return collector.items_per_second.count(name) > 0; };
  std::printf(
      "\nbank figures (one thread; wall clock, and per CPU-second since the machine may be "
      "shared):\n");
  for (const char* name : {"bank/append/originals", "bank/append/with_mirrors"}) {
    if (!has(name)) continue;
    std::printf("  %-26s %7.0f sprites/s wall, %7.0f per CPU-second", name,
                collector.items_per_second[name], cpu_rate(name));
    if (has("bank/baseline/compress")) {
      std::printf("  = %.2f x zstd-compressing alone (%.0f billboards per CPU-second)",
                  cpu_rate(name) / cpu_rate("bank/baseline/compress"),
                  cpu_rate("bank/baseline/compress"));
    }
    std::printf("\n");
  }
  if (has("bank/load_features_60k")) {
    const std::string f = "bank/load_features_60k", b = "bank/baseline/scan_60k";
    std::printf("  %-26s %7.1f ms wall, %7.1f ms CPU for 60,000 sprites", f.c_str(), ms[f],
                ms[f] * collector.cpu_share[f]);
    if (has(b)) {
      std::printf("  = %.2f x a bare sqlite3 scan (%.1f ms CPU)", cpu_rate(b) / cpu_rate(f),
                  ms[b] * collector.cpu_share[b]);
    }
    std::printf("\n");
  }
  const std::string pg = "bank/postgres/append_4_writers", lite = "bank/append/with_mirrors";
  if (has(pg)) {
    // Four threads' items together, per second of wall clock (the server and the writers share the
    // cores).
    std::printf("  %-26s %7.0f sprites/s wall, four writers together", pg.c_str(),
                collector.items_per_second[pg]);
    if (has(lite)) {
      std::printf("  = %.2f x one SQLite writer (%.0f sprites/s wall)",
                  collector.items_per_second[pg] / collector.items_per_second[lite],
                  collector.items_per_second[lite]);
    }
    std::printf("\n");
  }
  if (has("bank/load_pixels")) {
    std::printf(
        "  %-26s %7.0f billboards/s wall, %7.0f per CPU-second (decompressed; mirrors flipped)\n",
        "bank/load_pixels", collector.items_per_second["bank/load_pixels"],
        cpu_rate("bank/load_pixels"));
  }
  return 0;
}

const bool kRegistered =
    RegisterSuite({"bank", "sprite bank: append rate (sprites/s) and 60k feature load", &Run});

}  // namespace
}  // namespace ss::bench::bank_bench
