#include "station/station.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "capture/camera_source.h"
#include "core/bank.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "pipeline/run/bank_scale.h"
#include "pipeline/run/bounded_queue.h"
#include "pipeline/run/ingest.h"
#include "pipeline/transitions/worker.h"
#include "station/bank_spool.h"
#include "station/recorder.h"
#include "station/station_impl.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using station_detail::Clock;
using station_detail::Seconds;

// SIGTERM must finish within 5 s: from the start of Stop, the transition worker may drain this
// long.
constexpr double kTransitionDrainS = 3.0;

// Preview snapshots a camera takes, idle and while a session stores; each view of a snapshot is
// encoded once, for every viewer, so these are also the most images a second a view costs.
constexpr double kPreviewIntervalS = 0.2, kPreviewIntervalSessionS = 0.5;

std::string UtcNow(const char* format = "%Y-%m-%dT%H:%M:%SZ") {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[64];
  std::strftime(text, sizeof text, format, &tm);
  return text;
}

// A session name: what a studio user types, kept usable as a folder name.
std::string CheckSessionName(const std::string& name) {
  if (name.empty() || name.size() > 100)
    throw InputError("name", "a session name needs 1 to 100 characters");
  for (const char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
          c == ' ')) {
      throw InputError(
          "name", "\"" + name + "\": only letters, digits, space, '-', '_' and '.' are allowed");
    }
  }
  if (name == "." || name == "..")
    throw InputError("name", "\"" + name + "\" is not a session name");
  return name;
}

void ApplyLogging(const LoggingConfig& logging) {
  SetLogLevel(logging.level);
  for (const auto& [component, level] : logging.components)
    Log(component)->set_level(spdlog::level::from_str(level));
}

}  // namespace

PreviewCache::Entry* Station::Impl::CachedPreview(const std::string& camera, int view, int width,
                                                  std::unique_lock<std::mutex>* lock,
                                                  std::shared_ptr<const PreviewFrame>* frame,
                                                  const CameraRunner** runner) const {
  for (size_t k = 0; k < runners.size(); ++k) {
    if (runners[k]->name() != camera) continue;
    PreviewCache& cache = *preview_caches[k];
    *lock = std::unique_lock(cache.mutex);
    *runner = runners[k].get();
    *frame = runners[k]->preview();
    if (!*frame) return nullptr;
    PreviewCache::Entry& entry = cache.entries[{view, width}];
    if (entry.frame_taken == (*frame)->taken) {
      *frame = nullptr;  // made from this snapshot already
    } else {
      entry.frame_taken = (*frame)->taken;
    }
    return &entry;
  }
  throw NotFoundError("camera", "no camera named \"" + camera + "\"");
}

void Station::Impl::Tap(int camera, const Frame& frame, uint64_t drops_before, bool usable) {
  {
    std::lock_guard lock(watcher_mutex);
    if (watcher) watcher(camera, frame);
  }
  std::lock_guard lock(recorder_mutex);
  if (!recorder) return;
  const std::optional<SourceCamera> source = runners[static_cast<size_t>(camera)]->source_camera();
  if (!source) return;
  const std::optional<CameraModel>& model = models[static_cast<size_t>(camera)];
  recorder->Offer(camera, *source, model ? &*model : nullptr, frame, drops_before, usable);
}

void Station::Impl::StopRecording(const std::string& why) {
  std::unique_ptr<StationRecorder> done;
  {
    std::lock_guard lock(recorder_mutex);
    done.swap(recorder);
  }
  if (!done) return;
  done->Close();
  std::lock_guard lock(recorder_mutex);
  last_recording = done->stats();
  log->info("recording {} closed ({} frames, {} dropped){}", last_recording.dir,
            last_recording.frames_written, last_recording.frames_dropped,
            why.empty() ? "" : ": " + why);
}

Station::Station(StationOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = std::move(options);
  const StationConfig& config = s.options.config;
  if (config.cameras.empty()) throw InputError("cameras", "the station needs at least one camera");
  if (config.enclosure.floor.empty()) {
    // A replay station may take the floor from its session, as ingest does.
    const CameraConfig* replay = nullptr;
    for (const CameraConfig& c : config.cameras) {
      if (c.source == "replay") replay = &c;
    }
    if (replay == nullptr)
      throw InputError("enclosure.floor", "the station needs the floor polygon");
    s.floor = FloorForSession(replay->session, config.enclosure.floor);
  } else {
    s.floor = config.enclosure.floor;
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
  if (!scale_inputs.models.empty()) {
    const BankScale scale = ChooseAndKeepBankScale(*s.bank, scale_inputs);
    pipeline.rectify.px_per_m = scale.px_per_m;
    s.log->info("billboard scale {} px/m: {}", scale.px_per_m, scale.why);
  }
  if (s.options.transitions) {
    s.transitions = std::make_unique<TransitionWorker>(
        config.storage.bank, s.options.weights ? *s.options.weights : DefaultWeights(), 1,
        SpriteChoice{.include_merged = config.transitions.include_merged});
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
    o.training_frames = std::max(
        1, (config.pipeline.keying ? *config.pipeline.keying : KeyingConfig{}).training_frames);
    o.queue_frames = config.pipeline.queue_frames;
    o.offline_after_s = s.options.offline_after_s;
    o.preview_interval_s = kPreviewIntervalS;
    o.open_source = s.options.open_source;
    s.runners.push_back(std::make_unique<CameraRunner>(
        static_cast<int>(i), std::move(o), [&s](StationBatch b) { s.Store(std::move(b)); },
        [&s](int camera, const Frame& f, uint64_t drops, bool usable) {
          s.Tap(camera, f, drops, usable);
        }));
    s.preview_caches.push_back(std::make_unique<PreviewCache>());
  }
  s.CheckDisk();  // before any session: a full disk refuses from the first frame
  for (auto& r : s.runners) r->Start();
  s.monitor_thread = std::thread([&s] { s.MonitorLoop(); });
  s.state = StationState::kRunning;
  s.log->info("station running: {} camera(s), bank {}", s.runners.size(), config.storage.bank);
}

void Station::Stop() {
  Impl& s = *impl_;
  if (s.state == StationState::kStopped || (!s.writer_thread.joinable() && s.runners.empty())) {
    s.state = StationState::kStopped;
    return;
  }
  s.state = StationState::kStopping;
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
  {
    std::lock_guard lock(s.monitor_mutex);
    s.monitor_stop = true;
    s.monitor_wake.notify_all();
  }
  if (s.monitor_thread.joinable()) s.monitor_thread.join();
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
  s.log->info("station stopped: {} sprites stored", s.sprites_stored);
}

SessionStatus Station::StartSession(const std::string& requested_name) {
  Impl& s = *impl_;
  const std::string name = CheckSessionName(requested_name);
  std::lock_guard control(s.control_mutex);
  std::unique_lock lock(s.session_mutex);
  if (s.state != StationState::kRunning)
    throw ConflictError("session", "the station is not running");
  if (s.session.active)
    throw ConflictError("session", "session \"" + s.session.name + "\" is running; stop it first");
  const std::string created = UtcNow();
  SessionRecord record;
  record.uid = name + "@" + created;
  record.name = name;
  record.created = created;
  record.source = "station";
  std::vector<int64_t> camera_ids(s.runners.size(), 0);
  {
    std::lock_guard bank_lock(s.bank_mutex);
    const int64_t session_id = s.bank->AddSession(record);
    s.session = SessionStatus{};
    s.session.bank_session_id = session_id;
    for (size_t i = 0; i < s.runners.size(); ++i) {
      if (!s.models[i]) continue;
      CameraRecord camera;
      camera.name = s.runners[i]->name();
      camera.cameramodel = s.models[i]->ToText();
      camera.width = s.models[i]->width();
      camera.height = s.models[i]->height();
      camera_ids[i] = s.bank->AddCamera(session_id, camera);
    }
  }
  s.session.active = true;
  s.session_active = true;
  s.session.name = name;
  s.session.started = created;
  s.session_started = Clock::now();
  const StorageConfig storage = s.StorageSettings();
  StorageState storage_state;
  {
    std::lock_guard stats_lock(s.stats_mutex);
    storage_state = s.storage_state;
  }
  if (storage.recording != RecordingMode::kOff && storage_state == StorageState::kOk) {
    const fs::path dir = fs::path(storage.recording_dir) / (name + "-" + UtcNow("%Y%m%dT%H%M%SZ"));
    RecordingOptions recording;
    recording.codec = storage.recording_codec;
    try {
      auto recorder = std::make_unique<StationRecorder>(dir.string(), name, recording,
                                                        storage.recording == RecordingMode::kUsable,
                                                        static_cast<int>(s.runners.size()));
      std::lock_guard rec_lock(s.recorder_mutex);
      s.recorder = std::move(recorder);
      s.session.recording_dir = dir.string();
    } catch (const std::exception& e) {
      s.log->error("recording: {}", e.what());
      std::lock_guard rec_lock(s.recorder_mutex);
      s.last_recording.error = e.what();
    }
  }
  SessionStatus out = s.session;
  lock.unlock();  // the writer updates the session's counts meanwhile
  for (size_t i = 0; i < s.runners.size(); ++i) s.runners[i]->SetBankCamera(camera_ids[i]);
  // Previews back off while a session stores: fewer snapshots for the pipeline threads to copy.
  for (auto& r : s.runners) r->set_preview_interval(kPreviewIntervalSessionS);
  s.log->info("session \"{}\" started (bank session {})", name, out.bank_session_id);
  return out;
}

SessionStatus Station::StopSession() {
  Impl& s = *impl_;
  std::lock_guard control(s.control_mutex);
  {
    std::lock_guard lock(s.session_mutex);
    if (!s.session.active) throw ConflictError("session", "no session is running");
  }
  // Every open clip closes into the writer queue under the session's cameras; then
  // the writer stores them all before the session is reported stopped.
  for (auto& r : s.runners) r->SetBankCamera(0);
  s.WaitWriterIdle();
  s.StopRecording("the session stopped");
  std::lock_guard lock(s.session_mutex);
  s.session.active = false;
  s.session_active = false;
  for (auto& r : s.runners) r->set_preview_interval(kPreviewIntervalS);
  s.session.seconds = Seconds(Clock::now() - s.session_started);
  s.log->info("session \"{}\" stopped: {} sprites stored", s.session.name,
              s.session.sprites_stored);
  return s.session;
}

SessionStatus Station::RenameSession(const std::string& requested_name) {
  Impl& s = *impl_;
  const std::string name = CheckSessionName(requested_name);
  std::lock_guard control(s.control_mutex);
  std::lock_guard lock(s.session_mutex);
  if (!s.session.active) throw ConflictError("session", "no session is running");
  {
    std::lock_guard bank_lock(s.bank_mutex);
    s.bank->RenameSession(s.session.bank_session_id, name);
  }
  s.log->info("session \"{}\" renamed \"{}\"", s.session.name, name);
  s.session.name = name;
  return s.session;
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
    out.storage_state = s.storage_state;
    if (out.storage_state == StorageState::kOk && s.last_append_failed)
      out.storage_state = StorageState::kWritesFailing;
    out.disk_free_mib = s.disk_free_mib;
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
  }
  return out;
}

std::optional<Station::PreviewImage> Station::Preview(const std::string& camera, PreviewView view,
                                                      int max_width) const {
  const int width = std::clamp(max_width, 16, 4096);
  std::unique_lock<std::mutex> lock;
  std::shared_ptr<const PreviewFrame> frame;
  const CameraRunner* runner = nullptr;
  PreviewCache::Entry* entry = impl_->CachedPreview(camera, view == PreviewView::kKeyed ? 1 : 0,
                                                    width, &lock, &frame, &runner);
  if (entry == nullptr) return std::nullopt;
  if (frame) {
    entry->image = {EncodeJpeg(RenderPreview(*frame, view, width)), frame->sequence,
                    frame->timestamp_ns, frame->bgr.cols, frame->bgr.rows};
  }
  return entry->image;
}

std::optional<std::string> Station::SpritesView(const std::string& camera, int max_width) const {
  const int width = std::clamp(max_width, 16, 4096);
  std::unique_lock<std::mutex> lock;
  std::shared_ptr<const PreviewFrame> frame;
  const CameraRunner* runner = nullptr;
  PreviewCache::Entry* entry = impl_->CachedPreview(camera, 2, width, &lock, &frame, &runner);
  if (entry == nullptr) return std::nullopt;
  if (frame) {
    const cv::Mat image = RenderPreview(*frame, PreviewView::kRaw, width);
    const double scale = frame->bgr.cols > 0 ? double(image.cols) / frame->bgr.cols : 1.0;
    const bool storing = SessionActive() && runner->model().has_value();
    entry->sprites_json =
        SpritesViewJson(*frame, storing, "data:image/jpeg;base64," + Base64(EncodeJpeg(image)),
                        scale)
            .dump();
  }
  return entry->sprites_json;
}

const std::string& Station::bank_path() const { return impl_->options.config.storage.bank; }

bool Station::SessionActive() const { return impl_->session_active.load(); }

void Station::SetFrameWatcher(FrameWatcher watcher) {
  std::lock_guard lock(impl_->watcher_mutex);
  impl_->watcher = std::move(watcher);
}

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
  s.log->info("config reloaded (logging, storage limits and recording mode applied){}",
              needs_restart.empty() ? "" : "; some sections need a restart");
  for (const std::string& line : needs_restart) s.log->warn("{}", line);
  return needs_restart;
}

}  // namespace ss
