// The station: start and stop, its status, reloading the config. Sessions and the recorder
// taps are in station_sessions.cc, previews in station_previews.cc, the bank writer in
// bank_writer_thread.cc, the disk guard in disk_guard.cc (shared state: station_impl.h).
#include "station/station.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <thread>

#include <opencv2/core/utility.hpp>

#include "capture/camera_source.h"
#include "capture/replay/replay_source.h"
#include "core/bank.h"
#include "core/bank_verify.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/sql_postgres.h"
#include "pipeline/filter/usability.h"
#include "pipeline/run/bank_scale.h"
#include "pipeline/run/bounded_queue.h"
#include "pipeline/run/ingest.h"
#include "pipeline/transitions/worker.h"
#include "station/bank_spool.h"
#include "station/recorder.h"
#include "station/station_impl.h"

namespace ss {
namespace {

using station_detail::Clock;
using station_detail::kPreviewIntervalS;
namespace fs = std::filesystem;

// SIGTERM must finish within 5 s: from the start of Stop, the transition worker may drain this
// long.
constexpr double kTransitionDrainS = 3.0;

void ApplyLogging(const LoggingConfig& logging) {
  SetLogLevel(logging.level);
  for (const auto& [component, level] : logging.components)
    Log(component)->set_level(spdlog::level::from_str(level));
}

}  // namespace

GroundPolygon StationFloor(const StationConfig& config) {
  if (!config.enclosure.floor.empty()) return config.enclosure.floor;
  for (const CameraConfig& c : config.cameras) {
    const auto* replay = c.backend.Find<ReplayCameraKeys>();
    if (replay == nullptr) continue;
    try {
      return FloorForSession(replay->session, GroundPolygon());
    } catch (const InputError&) {
      // that session has none: the next replay's, or none
    }
  }
  return {};
}

std::vector<std::string> CalibrationGaps(const StationConfig& config) {
  std::vector<std::string> gaps;
  for (const CameraConfig& c : config.cameras) {
    std::optional<CameraModel> model;
    try {
      model = ModelForCamera(c);
    } catch (const std::exception& e) {
      gaps.push_back(c.name + ": no camera model (" + e.what() + ")");
      continue;
    }
    if (!model) gaps.push_back(c.name + ": no camera model");
  }
  if (StationFloor(config).empty()) gaps.push_back("enclosure.floor: no floor polygon");
  return gaps;
}

std::vector<std::string> SteepViews(const StationConfig& config) {
  std::vector<std::string> steep;
  const GroundPolygon floor = StationFloor(config);
  if (floor.empty()) return steep;
  for (const CameraConfig& c : config.cameras) {
    std::optional<CameraModel> model;
    try {
      model = ModelForCamera(c);
    } catch (const std::exception&) {
      continue;  // a gap, named by CalibrationGaps
    }
    if (!model) continue;
    const std::string text = FloorMask(*model, floor, config.pipeline.usability).SteepViewText();
    if (!text.empty())
      steep.push_back(c.name + ": " + text + ": every sprite would be view_too_steep");
  }
  return steep;
}

bool StationOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  if (weights) check.Nested(weights->IsValid(&part), "weights.", part);
  check.Within(offline_after_s, Positive(), "offline_after_s", "a positive number of seconds");
  return check.ok();
}

void CheckStationConfig(const StationConfig& config) {
  if (config.cameras.empty()) {
    throw InputError("cameras",
                     "the station needs at least one camera (only `ingest --config` may leave "
                     "them out: it takes the session's)");
  }
}

Station::Station(StationOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = std::move(options);
  if (std::string why; !s.options.IsValid(&why)) throw InputError("station options", why);
  const StationConfig& config = s.options.config;
  CheckStationConfig(config);
  s.floor = StationFloor(config);
  // Without a floor the station still runs, so that the calibration wizard can find it: every
  // camera streams for preview and recording and stores no sprite until it is calibrated.
  if (s.floor.empty()) {
    s.log->warn(
        "enclosure.floor: no floor polygon: every camera streams for preview and recording but "
        "stores no sprites (find the floor: the console's calibration page, enclosure step)");
  }
  for (size_t i = 0; i < config.cameras.size(); ++i) {
    const CameraConfig& c = config.cameras[i];
    s.models.push_back(ModelForCamera(c));
    if (!s.models.back()) {
      s.log->warn(
          "{}: no camera model: it streams for preview and recording but stores no sprites "
          "(calibrate it: spritestation calibrate)",
          c.name);
    }
  }
  ApplyLogging(config.logging);
}

Station::~Station() { Stop(); }

void Station::Start() {
  Impl& s = *impl_;
  const StationConfig& config = s.options.config;
  if (!sql::IsPostgresAddress(config.storage.bank)) {
    // A first run's bank folder (docs/station.replay.yaml names recordings/demo-output/): made,
    // as the recordings' folder is.
    const fs::path folder = fs::path(config.storage.bank).parent_path();
    std::error_code ec;
    if (!folder.empty()) fs::create_directories(folder, ec);
    if (ec) {
      throw InputError("storage.bank",
                       "cannot make the bank's folder " + folder.string() + ": " + ec.message());
    }
  }
  RefuseDamagedBank(config.storage.bank);
  s.bank = std::make_unique<BankWriter>(config.storage.bank);
  s.bank_sprites = s.bank->Counts().sprites;
  {
    std::string spool_dir = config.storage.spool_dir;
    if (spool_dir.empty())
      spool_dir = s.bank->is_postgres() ? "spool" : config.storage.bank + ".spool";
    s.spool = std::make_unique<BankSpool>(spool_dir, config.storage.spool_max_mib * 1024 * 1024);
    s.spool_batches = s.spool->batches();
    s.spool_bytes = s.spool->bytes();
  }
  CameraPipelineOptions pipeline = config.pipeline;
  // The bank's one billboard scale, shared by every camera (pipeline/run/bank_scale.h).
  BankScaleInputs scale_inputs;
  scale_inputs.configured = config.pipeline.rectify.px_per_m;
  scale_inputs.bank_path = config.storage.bank;
  for (const std::optional<CameraModel>& m : s.models) {
    if (m) scale_inputs.models.push_back(&*m);
  }
  scale_inputs.floor = s.floor;
  scale_inputs.max_side_px = pipeline.rectify.max_side_px;
  scale_inputs.margin_m = pipeline.rectify.margin_m;
  if (!scale_inputs.models.empty() && !s.floor.empty()) {
    const BankScale scale = ChooseAndKeepBankScale(*s.bank, scale_inputs);
    pipeline.rectify.px_per_m = scale.px_per_m;
    s.log->info("billboard scale {} px/m: {}", scale.px_per_m, scale.why);
  }
  if (s.options.transitions) {
    s.transitions = std::make_unique<TransitionWorker>(
        config.storage.bank, s.options.weights ? *s.options.weights : DefaultWeights(), 1,
        TableChoice{.include_merged = config.transitions.include_merged,
                    .max_per_sprite = config.transitions.max_per_sprite},
        [&s] {
          s.transitions_listeners.Notify("transitions");
          s.Changed();
        });
  }
  s.writer_thread = std::thread([&s] { s.WriterLoop(); });

  if (config.pipeline.workers > 0) cv::setNumThreads(config.pipeline.workers);  // process-wide
  for (size_t i = 0; i < config.cameras.size(); ++i) {
    const CameraConfig& c = config.cameras[i];
    // Live batches are small (1/30 s of frames): a sprite reaches the bank as soon as its
    // clip is min_clip_frames long and its velocity window is complete.
    const double fps = c.fps > 0 ? c.fps : 30.0;
    CameraPipelineOptions camera_pipeline = pipeline;
    camera_pipeline.batch.batch_frames = std::max(1, static_cast<int>(fps / 30.0));
    CameraRunnerOptions o;
    o.camera = c;
    o.model = s.models[i];
    o.floor = s.floor;
    o.pipeline = camera_pipeline;
    o.offline_after_s = s.options.offline_after_s;
    o.preview_interval_s = kPreviewIntervalS;
    o.open_source = s.options.open_source;
    o.state_changed = [&s] { s.Changed(); };
    s.runners.push_back(std::make_unique<CameraRunner>(
        static_cast<int>(i), std::move(o), [&s](StationBatch b) { s.Store(std::move(b)); },
        [&s](int camera, const Frame& f, uint64_t drops, bool usable) {
          s.Tap(camera, f, drops, usable);
        }));
    s.preview_caches.push_back(std::make_unique<PreviewCache>());
  }
  s.disk.Check(true);  // before any session: a full disk refuses from the first frame
  for (auto& r : s.runners) r->Start();
  s.state = StationState::kRunning;
  s.Changed();
  s.log->info("station running: {} camera(s), bank {}", s.runners.size(), config.storage.bank);
}

void Station::Stop() {
  Impl& s = *impl_;
  if (s.state == StationState::kStopped || (!s.writer_thread.joinable() && s.runners.empty())) {
    s.state = StationState::kStopped;
    return;
  }
  s.state = StationState::kStopping;
  s.Changed();
  const auto stop_start = Clock::now();
  bool active = false;
  {
    std::lock_guard lock(s.session_mutex);
    active = s.session.active;
  }
  if (active) {
    try {
      StopSession();
    } catch (const std::exception& e) {
      s.log->error("stopping the session: {}", e.what());
    }
  }
  for (auto& r : s.runners) r->RequestStop();
  for (auto& r : s.runners) r->Stop();
  s.batches.Close();
  if (s.writer_thread.joinable()) s.writer_thread.join();
  s.StopRecording("the station stopped");
  if (s.transitions) {
    // The transitions of the last sprites get what is left of the stop's few seconds; what
    // remains is not lost: the worker brings complete clips up to date when it next starts.
    const double left_s =
        kTransitionDrainS - std::chrono::duration<double>(Clock::now() - stop_start).count();
    s.transitions->WaitIdleFor(left_s);
    if (const int64_t deferred = s.transitions->Stop(); deferred > 0) {
      s.log->warn(
          "{} new sprites' transitions left for the next start (it brings complete clips up to "
          "date)",
          deferred);
    }
  }
  s.transitions.reset();
  {
    std::lock_guard lock(s.bank_mutex);
    s.bank.reset();  // the last connection closes: the bank is whole on disk
  }
  s.state = StationState::kStopped;
  s.Changed();
  s.log->info("station stopped: {} sprites stored", s.sprites_stored);
}

StationStatus Station::Status() const {
  const Impl& s = *impl_;
  StationStatus out;
  out.state = s.state.load();
  out.uptime_s = Seconds(Clock::now() - s.started_at);
  {
    std::lock_guard lock(s.session_mutex);
    out.session = s.session;
    if (out.session.active) out.session.seconds = Seconds(Clock::now() - s.session_started);
  }
  for (const auto& r : s.runners) out.cameras.push_back(r->status());
  out.bank_path = s.options.config.storage.bank;
  const DiskGuard::Reading disk = s.disk.Check();
  {
    std::lock_guard lock(s.stats_mutex);
    out.bank_sprites = s.bank_sprites;
    out.sprites_stored = s.sprites_stored;
    out.batches_stored = s.batches_stored;
    out.batches_failed = s.batches_failed;
    out.batches_retried = s.batches_retried;
    out.batches_spooled = s.batches_spooled;
    out.spool_batches = s.spool_batches;
    out.spool_bytes = s.spool_bytes;
    out.batches_refused = s.batches_refused;
    out.bank_error = s.bank_error;
    out.storage_state = disk.state;
    if (out.storage_state == StorageState::kOk && s.last_append_failed)
      out.storage_state = StorageState::kWritesFailing;
    out.disk_free_mib = disk.free_mib;
    if (s.stored_log.size() >= 2) {
      const double span = Seconds(s.stored_log.back().first - s.stored_log.front().first);
      const double recent = Seconds(Clock::now() - s.stored_log.back().first);
      if (span > 0 && recent < 5.0) {
        out.sprites_per_second = (s.stored_log.back().second - s.stored_log.front().second) / span;
      }
    }
    out.latency_count = s.latency_count;
    out.latency_sum_s = s.latency_sum_ms / 1e3;
    if (!s.latencies_ms.empty()) {
      std::vector<double> v(s.latencies_ms.begin(), s.latencies_ms.end());
      const auto at = [&v](size_t k) {
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
        return v[k];
      };
      out.latency_p50_ms = at(v.size() / 2);
      out.latency_p99_ms = at(std::min(v.size() - 1, v.size() * 99 / 100));
    }
  }
  out.writer_queue = s.batches.size();
  out.transitions_enabled = s.transitions != nullptr;
  if (s.transitions) {
    const TransitionWorkerStats t = s.transitions->stats();
    out.transitions_ready = t.ready;
    out.transitions_pending = t.queued;
    out.transitions_stored = t.transitions_stored;
    out.transition_rounds_failed = t.failed_rounds;
    out.transitions_last_round_ms = t.last_round_ms;
    out.transitions_error = t.last_error;
    out.transitions_startup_stage = t.startup_stage;
    out.transitions_startup_done = t.startup_done;
    out.transitions_startup_total = t.startup_total;
  }
  const StorageConfig storage = s.StorageSettings();
  out.recording_mode = ToText(storage.recording);
  out.stop_recording_below_mib = storage.stop_recording_below_mib;
  out.stop_sprites_below_mib = storage.stop_sprites_below_mib;
  {
    std::lock_guard lock(s.recorder_mutex);
    const RecorderStats r = s.recorder ? s.recorder->stats() : s.last_recording;
    out.frames_recorded = r.frames_written;
    out.frames_record_dropped = r.frames_dropped;
    if (!r.error.empty()) out.recording_error = r.error;
    out.recording_stopped = r.stopped;
  }
  return out;
}

const std::string& Station::bank_path() const { return impl_->options.config.storage.bank; }

bool Station::SessionActive() const { return impl_->session_active.load(); }

void Station::SetFrameWatcher(FrameWatcher watcher) {
  std::lock_guard lock(impl_->watcher_mutex);
  impl_->watcher = std::move(watcher);
}

int Station::AddTransitionsListener(std::function<void()> listener) {
  return impl_->transitions_listeners.Add(std::move(listener));
}

void Station::RemoveTransitionsListener(int id) { impl_->transitions_listeners.Remove(id); }

std::vector<std::string> Station::Reload(const StationConfig& config) {
  Impl& s = *impl_;
  std::vector<std::string> needs_restart;
  const StationConfig& old = s.options.config;
  if (config.cameras != old.cameras)
    needs_restart.push_back("cameras: changed; restart the daemon to apply");
  // The pipeline's options hold the keying section and enclosure.wall_height_m too: each
  // section is named for what it sets.
  const auto pipeline_section = [](const StationConfig& c) {
    CameraPipelineOptions p = c.pipeline;
    p.keying.reset();
    p.usability.wall_height_m = 0;
    return p;
  };
  if (config.pipeline.keying != old.pipeline.keying)
    needs_restart.push_back("keying: changed; restart the daemon to apply");
  if (config.enclosure != old.enclosure ||
      config.pipeline.usability.wall_height_m != old.pipeline.usability.wall_height_m)
    needs_restart.push_back("enclosure: changed; restart the daemon to apply");
  if (pipeline_section(config) != pipeline_section(old))
    needs_restart.push_back("pipeline: changed; restart the daemon to apply");
  if (config.control != old.control)
    needs_restart.push_back("control: changed; restart the daemon to apply");
  if (config.storage.bank != old.storage.bank)
    needs_restart.push_back("storage.bank: changed; restart the daemon to apply");
  {
    std::lock_guard lock(s.config_mutex);
    const std::string bank = s.options.config.storage.bank;
    s.options.config.storage = config.storage;
    s.options.config.storage.bank = bank;
    s.options.config.logging = config.logging;
  }
  ApplyLogging(config.logging);
  s.disk.Check(true);  // the new limits apply at once
  s.log->info("config reloaded (logging, storage limits and recording mode applied){}",
              needs_restart.empty() ? "" : "; some sections need a restart");
  for (const std::string& line : needs_restart) s.log->warn("{}", line);
  return needs_restart;
}

}  // namespace ss
