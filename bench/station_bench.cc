// spritestation bench station [--cameras=N] [--size=WxH] [--fps=F] [--seconds=S]
// [--preview-streams=N] [--animation-spec=FILE]: the live station on paced replay (the daemon's
// code: CameraRunner threads, bank writer, TransitionWorker), as a Google Benchmark case run once
// for S seconds of wall time. Cameras replay a synthetic animal session (made once, cached under
// the temp dir) in real time, looping.
//   station/live_ffv1_replay_...    cameras replaying the FFV1 session in real time (decoding
//   included) station/live_from_memory_...    cameras delivering pre-decoded frames in real time,
//   as a
//                                   camera does: the station's own capacity. Counters: frames/s
//                                   delivered, frames dropped (queue full / at source),
//                                   capture-to-bank latency p50/p99, transitions pending (max),
//                                   sprites/s stored
//   station/live_from_memory_..._with_N_previews (--preview-streams=N): the same with the
//                                   daemon's HTTP server and N console tiles open (each fetching
//                                   raw / keyed / sprites views at 10 a second, and an event
//                                   stream): an open console must cost no captured frame
//   station/live_from_memory_..._with_animation_jobs (--animation-spec=FILE): the same while
//                                   the studio's animation jobs of that spec run one after the
//                                   other (optimize, judge, render): capture must not notice
//   station/baseline/decode_NxWxH   the same session replayed unpaced by ReplaySource:
//                                   the machine's decode capacity for these cameras
// The ratio printed: frames/s the cameras need / frames/s decoding alone gives.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "bench/bench_registry.h"
#include "capture/replay/replay_source.h"
#include "station/animation_jobs.h"
#include "station/control_server.h"
#include "station/station.h"
#include "station/station_host.h"
#include "synth/studio_session.h"
// Last: <resolv.h>, which it includes, defines _res, a name Eigen's headers use.
#include <httplib.h>

namespace ss::bench::station_bench {
namespace {

namespace fs = std::filesystem;

struct StationBenchArgs {
  int cameras = 4;
  int width = 1280, height = 720;
  double fps = 30;
  double seconds = 20;
  int preview_streams = 0;     // > 0: also the from-memory run with this many open console previews
  std::string animation_spec;  // a spec file: also the from-memory run with animation jobs of it
};
StationBenchArgs g_args;

std::string Tag() {
  return std::to_string(g_args.cameras) + "x" + std::to_string(g_args.width) + "x" +
         std::to_string(g_args.height) + "@" + std::to_string(static_cast<int>(g_args.fps));
}

// A synthetic session with as many cameras as asked, made once per shape. It is rendered beside
// and renamed into place when whole: a render cut off (a bench stopped) left a session.json over
// truncated videos, and every later run replayed that without a sprite.
std::string Session() {
  const fs::path dir = fs::temp_directory_path() / ("spritestation-station-bench-" + Tag());
  if (fs::exists(dir / "session.json")) return dir.string();
  fs::remove_all(dir);
  const fs::path partial = dir.string() + ".partial";
  fs::remove_all(partial);
  synth::SynthOptions o;
  o.out_dir = partial.string();
  o.seconds = 6;
  o.fps = g_args.fps;
  o.width = g_args.width;
  o.height = g_args.height;
  o.cameras = g_args.cameras;
  o.seed = 5;
  o.empty_lead_in_s = 1.5;
  o.write_mattes = false;
  o.threads = 2;
  std::fprintf(stderr, "bench station: rendering a %d-camera %dx%d session into %s (once)...\n",
               o.cameras, o.width, o.height, o.out_dir.c_str());
  synth::RenderStudioSession(o);
  fs::rename(partial, dir);
  return dir.string();
}

// One camera of the session decoded into memory once, then delivered in real time
// (paced by the recorded timestamps) and looping: a camera, without a decoder's cost.
class MemorySource : public FrameSource {
 public:
  MemorySource(std::shared_ptr<const std::vector<Frame>> frames, SourceCamera camera, int index)
      : frames_(std::move(frames)), cameras_{std::move(camera)}, index_(index) {}
  const std::vector<SourceCamera>& cameras() const override { return cameras_; }
  std::optional<Frame> Next() override {
    const std::vector<Frame>& all = *frames_;
    if (all.empty()) return std::nullopt;
    const size_t n = all.size();
    const int64_t span = all.back().timestamp_ns - all.front().timestamp_ns +
                         (all.size() > 1 ? all[1].timestamp_ns - all[0].timestamp_ns : 0);
    Frame f = all[next_ % n];
    const uint64_t pass = next_ / n;
    f.camera = index_;
    f.sequence = next_;
    f.timestamp_ns += static_cast<int64_t>(pass) * span;
    ++next_;
    std::unique_lock lock(mutex_);
    if (next_ == 1) start_ = std::chrono::steady_clock::now();
    const auto due = start_ + std::chrono::nanoseconds(f.timestamp_ns - all.front().timestamp_ns);
    wake_.wait_until(lock, due, [&] { return stopped_; });
    if (stopped_) return std::nullopt;
    ++delivered_;
    return f;
  }
  void Stop() override {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    wake_.notify_all();
  }
  SourceStats stats() const override {
    std::lock_guard lock(mutex_);
    SourceStats s;
    s.frames_delivered = delivered_;
    return s;
  }

 private:
  std::shared_ptr<const std::vector<Frame>> frames_;
  std::vector<SourceCamera> cameras_;
  int index_;
  uint64_t next_ = 0, delivered_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopped_ = false;
  std::chrono::steady_clock::time_point start_;
};

// Every frame of one session camera, decoded (once per run).
std::shared_ptr<const std::vector<Frame>> Decoded(const std::string& session,
                                                  const std::string& camera) {
  static std::map<std::string, std::shared_ptr<const std::vector<Frame>>> cache;
  auto& entry = cache[camera];
  if (!entry) {
    ReplayOptions o;
    o.camera = camera;
    ReplaySource source(session, o);
    auto frames = std::make_shared<std::vector<Frame>>();
    while (auto f = source.Next()) {
      // Own the pixels: the replay reuses its buffers.
      Frame copy = Frame::Owned(f->format, f->width, f->height,
                                std::vector<uint8_t>(f->data, f->data + f->size));
      copy.timestamp_ns = f->timestamp_ns;
      frames->push_back(std::move(copy));
    }
    entry = frames;
  }
  return entry;
}

void Decode(benchmark::State& state) {
  const std::string session = Session();
  uint64_t frames = 0;
  for (auto _ : state) {
    ReplaySource source(session, {});
    while (auto f = source.Next()) {
      benchmark::DoNotOptimize(f->data);
      ++frames;
    }
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

// What an open console costs: `n` browser tabs' worth of preview loops (each a tile fetching
// its camera's raw, keyed or sprites view at 10 a second, as the page does) and one event stream
// per loop, against the daemon's own HTTP server. Counts the images served.
class ConsoleLoad {
 public:
  ConsoleLoad(int port, int n, int cameras) {
    for (int k = 0; k < n; ++k) {
      threads_.emplace_back([this, port, k, cameras] {
        httplib::Client client("127.0.0.1", port);
        client.set_read_timeout(10, 0);
        static const char* kViews[] = {"preview.jpg?view=raw", "preview.jpg?view=keyed",
                                       "sprites.json?x=1"};
        const std::string path =
            "/api/cameras/cam" + std::to_string(k % cameras) + "/" + kViews[k % 3] + "&width=640";
        while (!stop_) {
          const auto start = std::chrono::steady_clock::now();
          if (auto res = client.Get(path.c_str()); res && res->status == 200) ++images_;
          std::this_thread::sleep_until(start + std::chrono::milliseconds(100));
        }
      });
      threads_.emplace_back([this, port] {
        httplib::Client client("127.0.0.1", port);
        client.set_read_timeout(10, 0);
        client.Get("/api/events", [this](const char*, size_t) { return !stop_.load(); });
      });
    }
  }
  ~ConsoleLoad() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }
  uint64_t images() const { return images_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> images_{0};
  std::vector<std::thread> threads_;
};

// Animation jobs of one spec, one after the other, through the station's controller
// (station/animation_jobs.h: optimize, judge, render at the jobs' low priority) for as long as
// it lives: the studio's load on a capturing station (issue 37).
class AnimationLoad {
 public:
  AnimationLoad(const std::string& spec_path, const fs::path& folder) {
    std::ifstream in(spec_path);
    std::stringstream text;
    text << in.rdbuf();
    AnimationJobsOptions options;
    options.folder = (folder / "animations").string();
    options.base_dir = fs::absolute(spec_path).parent_path().string();
    options.roots = {"/"};
    jobs_ = std::make_unique<AnimationJobs>(options);
    thread_ = std::thread([this, spec = text.str()] {
      while (!stop_) {
        const int64_t id = jobs_->Submit(spec);
        while (!stop_) {
          const std::string s = jobs_->Job(id)["state"];
          if (s == "done" || s == "failed" || s == "cancelled") break;
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        ++jobs_done_;
      }
    });
  }
  ~AnimationLoad() {
    stop_ = true;
    thread_.join();
    jobs_->Stop();
  }
  int jobs_done() const { return jobs_done_; }

 private:
  std::unique_ptr<AnimationJobs> jobs_;
  std::atomic<bool> stop_{false};
  std::atomic<int> jobs_done_{0};
  std::thread thread_;
};

void Live(benchmark::State& state, bool from_memory, int preview_streams, bool animation_jobs) {
  const std::string session = Session();
  if (from_memory) {
    for (int c = 0; c < g_args.cameras; ++c) Decoded(session, "cam" + std::to_string(c));
  }
  const fs::path work =
      fs::temp_directory_path() / ("spritestation-station-bench-run-" + std::to_string(getpid()));
  fs::remove_all(work);
  fs::create_directories(work);
  for (auto _ : state) {
    StationOptions options;
    StationConfig& config = options.config;
    for (int c = 0; c < g_args.cameras; ++c) {
      CameraConfig cam = ReplayCameraConfig("cam" + std::to_string(c),
                                            {.session = session, .loop = true, .realtime = true});
      cam.fps = g_args.fps;
      config.cameras.push_back(cam);
    }
    config.storage.bank = (work / "station.bank").string();
    config.storage.recording_dir = (work / "recordings").string();
    config.storage.stop_recording_below_mib = 0;
    config.storage.stop_sprites_below_mib = 0;
    config.logging.level = "warn";
    if (from_memory) {
      options.open_source = [&session](const CameraConfig& camera,
                                       int index) -> std::unique_ptr<FrameSource> {
        auto frames = Decoded(session, camera.name);
        SourceCamera sc;
        sc.name = camera.name;
        sc.width = frames->empty() ? 0 : frames->front().width;
        sc.height = frames->empty() ? 0 : frames->front().height;
        sc.format = frames->empty() ? PixelFormat::kRGB8 : frames->front().format;
        sc.fps = g_args.fps;
        return std::make_unique<MemorySource>(frames, sc, index);
      };
    }
    config.control.port = 0;
    StationHost host(options, {});
    host.Start();
    Station& station = *host.current();
    std::unique_ptr<ControlServer> control;
    std::unique_ptr<ConsoleLoad> console;
    if (preview_streams > 0) {
      control = std::make_unique<ControlServer>(host, ControlServerOptions{config.control});
      console = std::make_unique<ConsoleLoad>(control->Start(), preview_streams, g_args.cameras);
    }
    station.StartSession("bench");
    std::unique_ptr<AnimationLoad> animations;
    if (animation_jobs) animations = std::make_unique<AnimationLoad>(g_args.animation_spec, work);
    int64_t pending_max = 0;
    const auto start = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - start <
           std::chrono::duration<double>(g_args.seconds)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      pending_max = std::max(pending_max, station.Status().transitions_pending);
    }
    const StationStatus status = station.Status();
    if (console) state.counters["preview_images_per_s"] = console->images() / g_args.seconds;
    if (animations) state.counters["animation_jobs"] = animations->jobs_done();
    animations.reset();
    console.reset();
    if (control) control->Stop();
    host.Stop();
    uint64_t captured = 0, queue_full = 0, at_source = 0, learning = 0, processed = 0;
    double seconds_key = 0, seconds_rest = 0;
    for (const CameraStatus& c : status.cameras) {
      captured += c.frames_captured;
      queue_full += c.dropped_queue_full;
      at_source += c.dropped_at_source;
      learning += c.frames_while_learning;
      processed += c.pipeline.frames;
      seconds_key += c.pipeline.seconds_key;
      seconds_rest += c.pipeline.seconds_rest;
    }
    // Wall time a keyed frame spent in the pipeline (keying + extracting, the rest).
    if (processed > 0) {
      state.counters["key_ms_per_frame"] = 1e3 * seconds_key / static_cast<double>(processed);
      state.counters["rest_ms_per_frame"] = 1e3 * seconds_rest / static_cast<double>(processed);
    }
    state.counters["frames_while_learning"] = static_cast<double>(learning);
    state.counters["frames_per_s"] = captured / g_args.seconds;
    state.counters["dropped_queue_full"] = static_cast<double>(queue_full);
    state.counters["dropped_at_source"] = static_cast<double>(at_source);
    state.counters["latency_p50_ms"] = status.latency_p50_ms;
    state.counters["latency_p99_ms"] = status.latency_p99_ms;
    state.counters["transitions_pending_max"] = static_cast<double>(pending_max);
    state.counters["sprites_per_s"] = status.sprites_stored / g_args.seconds;
  }
  fs::remove_all(work);
}

// Options come as --name=value (the bench command hands extras through in its own order).
int Run(const std::vector<std::string>& args) {
  std::vector<std::string> pass;
  for (const std::string& a : args) {
    const auto [key, value] = OptionNameValue(a);
    if (key == "--cameras") {
      g_args.cameras = std::stoi(value);
    } else if (key == "--size") {
      std::sscanf(value.c_str(), "%dx%d", &g_args.width, &g_args.height);
    } else if (key == "--fps") {
      g_args.fps = std::stod(value);
    } else if (key == "--seconds") {
      g_args.seconds = std::stod(value);
    } else if (key == "--preview-streams") {
      g_args.preview_streams = std::stoi(value);
    } else if (key == "--animation-spec") {
      g_args.animation_spec = value;
    } else {
      pass.push_back(a);
    }
  }
  benchmark::RegisterBenchmark(("station/baseline/decode_" + Tag()).c_str(), Decode)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark(("station/live_ffv1_replay_" + Tag()).c_str(), Live, false, 0, false)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark(("station/live_from_memory_" + Tag()).c_str(), Live, true, 0, false)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  if (g_args.preview_streams > 0) {
    benchmark::RegisterBenchmark(("station/live_from_memory_" + Tag() + "_with_" +
                                  std::to_string(g_args.preview_streams) + "_previews")
                                     .c_str(),
                                 Live, true, g_args.preview_streams, false)
        ->Iterations(1)
        ->Unit(benchmark::kSecond)
        ->UseRealTime();
  }
  if (!g_args.animation_spec.empty()) {
    benchmark::RegisterBenchmark(
        ("station/live_from_memory_" + Tag() + "_with_animation_jobs").c_str(), Live, true, 0, true)
        ->Iterations(1)
        ->Unit(benchmark::kSecond)
        ->UseRealTime();
  }
  const int rc = RunGoogleBenchmarks("station/", pass);
  std::printf("cameras need %.0f frames/s (%d x %.0f)\n", g_args.cameras * g_args.fps,
              g_args.cameras, g_args.fps);
  return rc;
}

const bool kRegistered =
    RegisterSuite({"station",
                   "the live station on paced replay: drops, latency, transitions lag (--cameras= "
                   "--size= --fps= --seconds= --preview-streams= --animation-spec=)",
                   &Run});

}  // namespace
}  // namespace ss::bench::station_bench
