#include "station/camera_runner.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <future>
#include <mutex>
#include <thread>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/camera_source.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/run/bounded_queue.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;

struct Captured {
  Frame frame;
  SteadyTime received;
  uint64_t drops_before = 0;  // frames dropped (queue full) just before this one
};

// The sources being closed (CloseSource's threads): the count, under `mutex`, and `done`,
// notified as each close ends (WaitForCameraCloses waits on it). Never destroyed: a close
// thread may still end while the process exits.
struct PendingCloses {
  std::mutex mutex;
  std::condition_variable done;
  int count = 0;
};
PendingCloses& Closes() {
  static auto* const closes = new PendingCloses;
  return *closes;
}

// `n` BGR images of width x height whose pages are already mapped (written once).
std::vector<cv::Mat> PrefaultedImages(int n, int width, int height) {
  std::vector<cv::Mat> images(static_cast<size_t>(std::max(1, n)));
  for (cv::Mat& m : images) m = cv::Mat(height, width, CV_8UC3, cv::Scalar::all(0));
  return images;
}

}  // namespace

bool WaitForCameraCloses(double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(std::max(0.0, timeout_s)));
  PendingCloses& closes = Closes();
  std::unique_lock lock(closes.mutex);
  return closes.done.wait_until(lock, deadline, [&] { return closes.count == 0; });
}

const char* CameraStateName(CameraState state) {
  switch (state) {
    case CameraState::kStarting:
      return "starting";
    case CameraState::kTraining:
      return "training";
    case CameraState::kLive:
      return "live";
    case CameraState::kOffline:
      return "offline";
    case CameraState::kFinished:
      return "finished";
    case CameraState::kError:
      return "error";
  }
  return "unknown";
}

struct CameraRunner::Impl {
  int index = 0;
  CameraRunnerOptions options;
  BatchSink sink;
  FrameTap tap;
  std::shared_ptr<spdlog::logger> log = Log("station.camera");

  std::unique_ptr<BoundedQueue<Captured>> queue;
  std::thread capture_thread, pipeline_thread;
  std::atomic<bool> stopping{false};

  // The open source; the pipeline thread may Stop() it when it stalls.
  mutable std::mutex source_mutex;
  std::shared_ptr<FrameSource> source;
  std::atomic<bool> stalled{false};
  std::condition_variable backoff_wake;

  // Status, under status_mutex.
  mutable std::mutex status_mutex;
  CameraStatus status;
  std::deque<SteadyTime> recent_frames;  // arrival times over the last ~2 s (fps)
  SteadyTime last_frame_time = Clock::now();
  uint64_t source_dropped_base = 0, source_errors_base = 0;  // of the sources closed before
  std::optional<SourceCamera> source_camera;
  SteadyTime last_reject_log{};

  // Bank camera switching: wanted by the station, applied by the pipeline thread.
  std::mutex target_mutex;
  std::condition_variable target_applied;
  int64_t wanted_camera_id = 0;
  int64_t applied_camera_id = 0;

  // Preview: a snapshot of the latest frame, its matte and candidates, taken every
  // preview_interval_s. Readers share it; the pipeline thread fills a spare one (reused
  // when no reader holds it, so no frame-sized allocation in the steady state) and swaps.
  mutable std::mutex preview_mutex;
  std::shared_ptr<const PreviewFrame> preview;
  std::shared_ptr<PreviewFrame> preview_spare;
  SteadyTime preview_time{};
  std::atomic<double> preview_interval_s{
      0};  // options.preview_interval_s, then as the station sets it
  // The exposure figures of the latest preview, measured at most once a second (on a reader's
  // thread).
  mutable std::mutex exposure_mutex;
  mutable ExposureFigures exposure;
  mutable SteadyTime exposure_time{};

  // What the keyer can do, which decides the state a camera (re)opens in: still learning the
  // empty enclosure (training), ready (live), none possible (live for preview and recording
  // without a model; error when making or training it failed). Under status_mutex.
  enum class KeyerPhase { kLearning, kReady, kNoModel, kFailed };
  KeyerPhase keyer_phase = KeyerPhase::kLearning;
  std::string keyer_message;

  // Applied at once to a camera that is open and learning (or, for a failure, not opened yet);
  // an offline camera takes it when it reopens.
  void SetKeyerPhase(KeyerPhase phase, const std::string& message) {
    bool apply = false;
    {
      std::lock_guard lock(status_mutex);
      keyer_phase = phase;
      keyer_message = message;
      apply = status.state == CameraState::kTraining ||
              (phase == KeyerPhase::kFailed && status.state == CameraState::kStarting);
    }
    if (apply) SetStateAfterOpen();
  }

  // The state of an open camera: from the keyer's phase (a reopened camera whose keyer has
  // learnt already is live at once, not training again).
  void SetStateAfterOpen() {
    KeyerPhase phase;
    std::string message;
    {
      std::lock_guard lock(status_mutex);
      phase = keyer_phase;
      message = keyer_message;
    }
    switch (phase) {
      case KeyerPhase::kLearning:
        SetState(CameraState::kTraining, "");
        break;
      case KeyerPhase::kReady:
        SetState(CameraState::kLive, "");
        break;
      case KeyerPhase::kNoModel:
        SetState(CameraState::kLive, message);
        break;
      case KeyerPhase::kFailed:
        SetState(CameraState::kError, message);
        break;
    }
  }

  void SetState(CameraState state, const std::string& message) {
    {
      std::lock_guard lock(status_mutex);
      if (status.state == state && status.message == message) return;
      if (state == CameraState::kOffline || state == CameraState::kError) {
        log->warn("{}: {}{}", options.camera.name, CameraStateName(state),
                  message.empty() ? "" : ": " + message);
      } else {
        log->info("{}: {}", options.camera.name, CameraStateName(state));
      }
      status.state = state;
      status.message = message;
    }
    if (queue) queue->Wake();  // the pipeline thread's stall deadline depends on the state
    if (options.state_changed) options.state_changed();
  }

  // Sleeps for the backoff delay unless stopping.
  void Backoff(double seconds) {
    std::unique_lock lock(source_mutex);
    backoff_wake.wait_for(lock, std::chrono::duration<double>(seconds),
                          [&] { return stopping.load(); });
  }

  // Closes the source on a thread of its own: a device that stopped answering can take
  // seconds to close (GigE Vision: 5 x 500 ms per unanswered register write), and neither
  // reopening it nor stopping the station should wait for that.
  void CloseSource() {
    std::shared_ptr<FrameSource> old;
    {
      std::lock_guard lock(source_mutex);
      old.swap(source);
    }
    if (!old) return;
    const SourceStats s = old->stats();
    {
      std::lock_guard lock(status_mutex);
      source_dropped_base += s.frames_dropped;
      source_errors_base += s.errors;
    }
    {
      std::lock_guard lock(Closes().mutex);
      ++Closes().count;
    }
    std::thread([old = std::move(old)]() mutable {
      old.reset();
      PendingCloses& closes = Closes();
      {
        std::lock_guard lock(closes.mutex);
        --closes.count;
      }
      closes.done.notify_all();
    }).detach();
  }

  void CaptureLoop() {
    double backoff = options.backoff_min_s;
    bool opened_once = false;
    uint64_t pending_drops = 0;
    while (!stopping) {
      std::shared_ptr<FrameSource> src;
      {
        std::lock_guard lock(source_mutex);
        src = source;
      }
      if (!src) {
        try {
          std::shared_ptr<FrameSource> opened = options.open_source
                                                    ? options.open_source(options.camera, index)
                                                    : OpenCameraSource(options.camera, index);
          {
            std::lock_guard lock(status_mutex);
            if (opened_once) ++status.reopens;
            const SourceCamera& sc = opened->cameras().at(0);
            status.width = sc.width;
            status.height = sc.height;
            status.pixel_format = PixelFormatName(sc.format);
            source_camera = sc;
            last_frame_time = Clock::now();
          }
          {
            std::lock_guard lock(source_mutex);
            source = opened;
          }
          opened_once = true;
          stalled = false;
          source_waits = opened->WaitsForReader();
          backoff = options.backoff_min_s;
          SetStateAfterOpen();
          continue;
        } catch (const std::exception& e) {
          SetState(CameraState::kOffline, e.what());
          Backoff(backoff);
          backoff = std::min(backoff * 2, options.backoff_max_s);
          continue;
        }
      }
      std::optional<Frame> frame;
      try {
        frame = src->Next();
      } catch (const std::exception& e) {
        SetState(CameraState::kOffline, e.what());
        CloseSource();
        continue;
      }
      if (!frame) {
        if (stopping) break;
        if (stalled) {
          char silent[64];
          std::snprintf(silent, sizeof silent, "no frame for %.1f s", options.offline_after_s);
          SetState(CameraState::kOffline, silent);
          CloseSource();
          Backoff(backoff);
          continue;
        }
        // The end of a finite source (a replay that does not loop).
        SetState(CameraState::kFinished, "the recording ended");
        break;
      }
      const SteadyTime now = Clock::now();
      {
        std::lock_guard lock(status_mutex);
        ++status.frames_captured;
        last_frame_time = now;
        recent_frames.push_back(now);
        while (!recent_frames.empty() && Seconds(now - recent_frames.front()) > 2.0)
          recent_frames.pop_front();
      }
      frame->camera = index;
      // A recording read as fast as it runs waits for the pipeline; a camera never does.
      Captured item{std::move(*frame), now, pending_drops};
      if (source_waits ? queue->Push(std::move(item)) : queue->TryPush(std::move(item))) {
        pending_drops = 0;
      } else {
        ++pending_drops;
        std::lock_guard lock(status_mutex);
        ++status.dropped_queue_full;
      }
    }
    queue->Close();
  }

  // Called by the pipeline thread while it waits: a source silent for too long is stopped.
  // When the camera counts as silent if no frame comes before: while it is open and streams
  // (not offline or finished, not already stopped as stalled); nullopt otherwise (then a
  // change of state wakes the pipeline thread to ask again).
  std::optional<SteadyTime> StallDeadline() const {
    if (stalled) return std::nullopt;
    std::lock_guard lock(status_mutex);
    // (A camera in error whose keyer failed still streams: it may stall too.)
    if (status.state == CameraState::kOffline || status.state == CameraState::kFinished)
      return std::nullopt;
    return last_frame_time + std::chrono::duration_cast<SteadyTime::duration>(
                                 std::chrono::duration<double>(options.offline_after_s));
  }

  void CheckStall() {
    bool stale = false;
    {
      std::lock_guard lock(status_mutex);
      stale = Seconds(Clock::now() - last_frame_time) >= options.offline_after_s &&
              status.state != CameraState::kOffline && status.state != CameraState::kFinished;
    }
    if (!stale) return;
    std::lock_guard lock(source_mutex);
    if (source && !stalled) {
      stalled = true;
      source->Stop();
    }
  }

  // Closes the open clips into `out` if the bank camera changed, and hands `out` to the writer.
  // The change is said applied only after that: a session that stops waits for its last clips to
  // be in the writer's queue (else its count grew after it said it had stopped).
  void ApplyTargetAndSink(CameraPipeline* pipeline, std::vector<ClipBatch>& out,
                          const std::deque<std::pair<int64_t, SteadyTime>>& arrivals) {
    std::unique_lock lock(target_mutex);
    const int64_t wanted = wanted_camera_id;
    const bool changed = wanted != applied_camera_id;
    lock.unlock();
    if (changed && pipeline != nullptr) pipeline->Retarget(wanted, &out);
    Sink(out, arrivals);
    if (!changed) return;
    lock.lock();
    applied_camera_id = wanted;
    target_applied.notify_all();
  }

  void Sink(std::vector<ClipBatch>& out,
            const std::deque<std::pair<int64_t, SteadyTime>>& arrivals) {
    for (ClipBatch& b : out) {
      if (b.clip.camera_id == 0) {
        std::lock_guard lock(status_mutex);
        ++status.batches_unstored;
        continue;
      }
      {
        std::lock_guard lock(status_mutex);
        for (const SpriteRecord& s : b.sprites) {
          if (s.mirrored) continue;
          ++status.sprites_to_bank;
          if (std::find(s.tags.begin(), s.tags.end(), kMergedTag) != s.tags.end())
            ++status.merged_to_bank;
        }
      }
      StationBatch sb;
      sb.camera = index;
      sb.received.reserve(b.sprites.size());
      for (const SpriteRecord& s : b.sprites) {
        // Arrivals are in sequence order; a sprite's frame is its sequence number.
        const auto it =
            std::lower_bound(arrivals.begin(), arrivals.end(), s.frame,
                             [](const auto& a, int64_t frame) { return a.first < frame; });
        sb.received.push_back(it != arrivals.end() && it->first == s.frame ? it->second
                                                                           : Clock::now());
      }
      sb.batch = std::move(b);
      sink(std::move(sb));
    }
    out.clear();
  }

  // True every preview_interval_s: only then is a frame kept for the preview.
  bool PreviewDue(SteadyTime now) const {
    std::lock_guard lock(preview_mutex);
    return preview_time == SteadyTime{} || Seconds(now - preview_time) >= preview_interval_s.load();
  }

  // `pipeline`: the frame went through it (its matte and candidates are shown); else only `bgr`.
  void UpdatePreview(const cv::Mat& bgr, const CameraPipeline* pipeline, const Frame& frame,
                     SteadyTime now) {
    std::shared_ptr<PreviewFrame> next;
    {
      std::lock_guard lock(preview_mutex);
      preview_time = now;
      if (preview_spare && preview_spare.use_count() == 1) next = std::move(preview_spare);
      preview_spare.reset();
    }
    if (!next) next = std::make_shared<PreviewFrame>();
    next->sequence = frame.sequence;
    next->timestamp_ns = frame.timestamp_ns;
    next->taken = now;
    bgr.copyTo(next->bgr);
    next->training = pipeline == nullptr;
    if (pipeline != nullptr) {
      pipeline->last_matte().alpha.copyTo(next->alpha);
      pipeline->last_matte().shadow.copyTo(next->shadow);
      next->candidates = PreviewCandidates(pipeline->last_verdicts());
    } else {
      next->alpha.release();
      next->shadow.release();
      next->candidates.clear();
    }
    std::lock_guard lock(preview_mutex);
    preview_spare = std::const_pointer_cast<PreviewFrame>(std::move(preview));
    preview = std::move(next);
  }

  // Once the keyer has learnt the enclosure (on its own thread): live, or in error if it failed.
  void PollTraining(std::future<void>& training, bool& pipeline_failed) {
    if (!training.valid() ||
        training.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      return;
    try {
      training.get();  // rethrows what Train threw
      SetKeyerPhase(KeyerPhase::kReady, "");
    } catch (const std::exception& e) {
      // Without a keyer no sprite can be made: the camera streams for preview and recording.
      SetKeyerPhase(KeyerPhase::kFailed,
                    std::string("learning the empty enclosure failed: ") + e.what());
      pipeline_failed = true;
    }
  }

  // Made before the camera opens (the floor mask takes a while), so the first frames find it ready.
  std::unique_ptr<CameraPipeline> pipeline;
  // The frames the keyer learns the empty enclosure from, allocated and touched before the camera
  // opens: first-touch page faults on ~6 MB a 1080p frame cost tens of ms on a VM, which at
  // 60 frames/s overflowed the queue while the set was collected.
  std::vector<cv::Mat> training_set;
  size_t training_collected = 0;
  std::pair<uint64_t, int64_t> training_first;  // the set's first frame: sequence, timestamp
  std::pair<uint64_t, int64_t> training_last;   // ... and the last one collected so far

  void PipelineLoop() {
    bool pipeline_failed = pipeline == nullptr;
    std::future<void> training;
    std::vector<ClipBatch> out;
    std::deque<std::pair<int64_t, SteadyTime>>
        arrivals;  // recent frames' sequence and arrival time
    cv::Mat bgr;
    while (true) {
      ApplyTargetAndSink(pipeline_failed ? nullptr : pipeline.get(), out, arrivals);
      // Until a frame comes, the capture ends, the station retargets or the camera's state
      // changes (each wakes the queue), or, while frames are due, until the camera has been
      // silent for offline_after_s.
      const std::optional<SteadyTime> stall_at = StallDeadline();
      std::optional<Captured> item = queue->PopUntil(stall_at.value_or(SteadyTime::max()));
      if (!item) {
        if (queue->closed() && queue->size() == 0) break;
        if (stall_at && Clock::now() >= *stall_at) CheckStall();
        continue;
      }
      const Frame& frame = item->frame;
      const bool preview = PreviewDue(item->received);
      bool usable = false;
      PollTraining(training, pipeline_failed);
      try {
        if (pipeline_failed || training.valid() || !pipeline->trained()) {
          // No keyer yet (or none possible): frames feed the preview and the training set only.
          // Learning runs beside this loop, which meanwhile keeps the queue empty.
          const bool collect = !pipeline_failed && !training.valid();
          if (collect) {
            // Straight into the next pre-faulted slot of the training set: no allocation here.
            if (training_set.empty())
              training_set =
                  PrefaultedImages(options.pipeline.TrainingFrames(), frame.width, frame.height);
            // A camera that reopened mid-collection numbers and times its frames from its own
            // start again: the frames before belong to another stream, so the set starts over
            // (else learnt_from's first frame came after its last).
            if (training_collected > 0 && (frame.sequence <= training_last.first ||
                                           frame.timestamp_ns <= training_last.second)) {
              training_collected = 0;
            }
            training_last = {frame.sequence, frame.timestamp_ns};
            cv::Mat& slot = training_set[training_collected];
            ToBgr(frame, slot);
            if (training_collected == 0) training_first = {frame.sequence, frame.timestamp_ns};
            ++training_collected;
            if (preview) UpdatePreview(slot, nullptr, frame, item->received);
            if (training_collected >= training_set.size()) {
              {
                std::lock_guard lock(status_mutex);
                status.learnt_from = {training_collected,
                                      static_cast<int64_t>(training_first.first),
                                      static_cast<int64_t>(frame.sequence), training_first.second,
                                      frame.timestamp_ns};
              }
              training = std::async(
                  std::launch::async,
                  [p = pipeline.get(), frames = std::move(training_set)] { p->Train(frames); });
              training_set.clear();
              training_collected = 0;
              // A source that waits for us (a recording) is held back while the keyer learns, so
              // no frame goes by unkeyed: the frames after the set are keyed, as ingest keys them.
              if (source_waits) {
                training.wait();
                PollTraining(training, pipeline_failed);
              }
            }
          } else if (preview) {
            ToBgr(frame, bgr);
            UpdatePreview(bgr, nullptr, frame, item->received);
          }
          if (!collect && !pipeline_failed) {
            std::lock_guard lock(status_mutex);
            ++status.frames_while_learning;
          }
        } else {
          arrivals.emplace_back(static_cast<int64_t>(frame.sequence), item->received);
          while (arrivals.size() > 1024) arrivals.pop_front();
          const uint64_t usable_before = pipeline->usable_sprites();
          pipeline->Process(frame, &out);
          usable = pipeline->usable_sprites() > usable_before;
          if (preview) {
            ToBgr(frame, bgr);  // the pipeline keys the camera's bytes as they are
            UpdatePreview(bgr, pipeline.get(), frame, item->received);
          }
          Sink(out, arrivals);
        }
      } catch (const std::exception& e) {
        // A frame the pipeline cannot take (corrupt, another size): counted and skipped (its
        // gap ends the open clips); the message names the camera and the frame.
        std::lock_guard lock(status_mutex);
        ++status.frames_rejected;
        status.message = e.what();
        if (Seconds(Clock::now() - last_reject_log) > 5.0) {
          last_reject_log = Clock::now();
          log->warn("{} (rejected frames so far: {})", e.what(), status.frames_rejected);
        }
      }
      {
        std::lock_guard lock(status_mutex);
        ++status.frames_processed;
        // Not while the keyer learns on its own thread: Train counts its frames into the stats
        // (a data race ThreadSanitizer found); they are read once the training is collected.
        if (pipeline && !training.valid()) status.pipeline = pipeline->stats();
      }
      if (tap) tap(index, frame, item->drops_before, usable);
    }
    if (training.valid()) training.wait();
    if (pipeline && !pipeline_failed && pipeline->trained()) {
      pipeline->Finish(&out);
      Sink(out, arrivals);
      std::lock_guard lock(status_mutex);
      status.pipeline = pipeline->stats();
    }
    std::lock_guard lock(target_mutex);
    applied_camera_id = wanted_camera_id;  // nothing more will be made
    pipeline_done = true;
    target_applied.notify_all();
  }

  std::atomic<bool> source_waits{false};  // the open source's WaitsForReader()
  bool pipeline_done = false;             // under target_mutex
};

bool CameraRunnerOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(pipeline.IsValid(&part), "pipeline.", part);
  for (const auto& [v, field] :
       {std::pair{offline_after_s, "offline_after_s"}, std::pair{backoff_min_s, "backoff_min_s"}}) {
    check(std::isfinite(v) && v > 0, field,
          "expected a positive number of seconds, got " + OptionProblems::Num(v));
  }
  check(std::isfinite(backoff_max_s) && !(backoff_max_s < backoff_min_s), "backoff_max_s",
        "expected at least backoff_min_s (" + OptionProblems::Num(backoff_min_s) + " s), got " +
            OptionProblems::Num(backoff_max_s));
  check.Within(preview_interval_s, AtLeast(0), "preview_interval_s", "a number of seconds >= 0");
  return check.ok();
}

CameraRunner::CameraRunner(int index, CameraRunnerOptions options, BatchSink sink, FrameTap tap)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.index = index;
  s.options = std::move(options);
  if (std::string why; !s.options.IsValid(&why)) {
    throw InputError("camera " + s.options.camera.name + " runner options", why);
  }
  s.preview_interval_s = s.options.preview_interval_s;
  s.sink = std::move(sink);
  s.tap = std::move(tap);
  s.queue = std::make_unique<BoundedQueue<Captured>>(
      static_cast<size_t>(std::max(1, s.options.pipeline.queue_frames)));
  s.status.name = s.options.camera.name;
  s.status.source = s.options.camera.source;
  s.status.has_model = s.options.model.has_value();
  s.status.has_floor = !s.options.floor.empty();
  s.status.queue_capacity = s.queue->capacity();
  if (s.options.model && s.options.floor.empty()) {
    s.SetKeyerPhase(Impl::KeyerPhase::kNoModel,
                    "no floor: calibrate (enclosure step); streams for preview and recording, "
                    "stores no sprites");
  } else if (s.options.model) {
    try {
      s.pipeline = std::make_unique<CameraPipeline>(s.options.camera.name, 0, *s.options.model,
                                                    s.options.floor, s.options.pipeline);
      s.training_set = PrefaultedImages(s.options.pipeline.TrainingFrames(),
                                        s.options.model->width(), s.options.model->height());
    } catch (const std::exception& e) {
      s.SetKeyerPhase(Impl::KeyerPhase::kFailed, e.what());
    }
  } else {
    s.SetKeyerPhase(Impl::KeyerPhase::kNoModel,
                    "no camera model: calibrate; streams for preview and recording, stores no "
                    "sprites");
  }
}

CameraRunner::~CameraRunner() { Stop(); }

void CameraRunner::Start() {
  Impl& s = *impl_;
  if (s.capture_thread.joinable()) return;
  s.capture_thread = std::thread([&s] {
    try {
      s.CaptureLoop();
    } catch (const std::exception& e) {
      s.SetState(CameraState::kError, e.what());
    }
    s.CloseSource();
    s.queue->Close();  // the pipeline thread drains what is left and ends
  });
  s.pipeline_thread = std::thread([&s] { s.PipelineLoop(); });
}

void CameraRunner::RequestStop() {
  Impl& s = *impl_;
  s.stopping = true;
  std::lock_guard lock(s.source_mutex);
  if (s.source) s.source->Stop();
  s.backoff_wake.notify_all();
}

void CameraRunner::Stop() {
  Impl& s = *impl_;
  RequestStop();
  if (s.capture_thread.joinable()) s.capture_thread.join();
  if (s.pipeline_thread.joinable()) s.pipeline_thread.join();
}

void CameraRunner::SetBankCamera(int64_t camera_id) {
  Impl& s = *impl_;
  std::unique_lock lock(s.target_mutex);
  s.wanted_camera_id = camera_id;
  if (!s.pipeline_thread.joinable()) {
    s.applied_camera_id = camera_id;  // not started: the pipeline starts with it
    return;
  }
  s.queue->Wake();  // a camera without frames applies it too
  s.target_applied.wait(lock, [&] { return s.pipeline_done || s.applied_camera_id == camera_id; });
}

CameraStatus CameraRunner::status() const {
  const Impl& s = *impl_;
  CameraStatus out = StatusWithoutExposure();
  // Measured outside status_mutex, which the pipeline thread takes every frame.
  std::lock_guard exposure_lock(s.exposure_mutex);
  if (s.exposure_time == SteadyTime{} || Seconds(Clock::now() - s.exposure_time) >= 1.0) {
    if (const auto frame = preview()) {
      s.exposure = MeasureExposure(*frame);
      s.exposure_time = Clock::now();
    }
  }
  out.exposure = s.exposure;
  return out;
}

CameraStatus CameraRunner::StatusWithoutExposure() const {
  const Impl& s = *impl_;
  std::lock_guard lock(s.status_mutex);
  CameraStatus out = s.status;
  const double span =
      s.recent_frames.size() >= 2 ? Seconds(s.recent_frames.back() - s.recent_frames.front()) : 0;
  out.fps = span > 0 ? (s.recent_frames.size() - 1) / span : 0;
  if (Seconds(Clock::now() - s.last_frame_time) > 2.0) out.fps = 0;
  out.dropped_at_source = s.source_dropped_base;
  out.source_errors = s.source_errors_base;
  {
    std::lock_guard source_lock(s.source_mutex);
    if (s.source) {
      const SourceStats ss = s.source->stats();
      out.dropped_at_source += ss.frames_dropped;
      out.source_errors += ss.errors;
      if (!ss.last_error.empty() && out.message.empty()) out.message = ss.last_error;
    }
  }
  out.queue_depth = s.queue->size();
  return out;
}

std::shared_ptr<const PreviewFrame> CameraRunner::preview() const {
  std::lock_guard lock(impl_->preview_mutex);
  return impl_->preview;
}

void CameraRunner::set_preview_interval(double seconds) { impl_->preview_interval_s = seconds; }

const std::string& CameraRunner::name() const { return impl_->options.camera.name; }
const std::optional<CameraModel>& CameraRunner::model() const { return impl_->options.model; }

std::optional<SourceCamera> CameraRunner::source_camera() const {
  std::lock_guard lock(impl_->status_mutex);
  return impl_->source_camera;
}

}  // namespace ss
