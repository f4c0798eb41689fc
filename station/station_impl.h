#pragma once
// Station::Impl (station.h): the station's state, shared by the files that hold its parts and
// used only inside station/:
//   station.cc             start, stop, status and reload
//   station_sessions.cc    sessions (start, stop, rename) and the frame taps: watcher, recorder
//   station_previews.cc    the previews' cache: each view encoded once for every viewer
//   station_status.cc      the status as JSON and as Prometheus text
//   bank_writer_thread.cc  the bank writer: batches into the bank, through the spool while it is
//                          away, and the stored counts
// and, in files of their own, the parts it holds: the camera runners, the recorder, the spool,
// the disk guard (disk_guard.h: asked before each write, it has no thread).
//
// Threads: the API's (an HTTP worker per request: Status, Preview, the session calls, Reload),
// one per camera (CameraRunner: its pipeline calls Store and Tap with none of its own locks
// held), the writer (WriterLoop: WriteBatch, DrainSpool, Stored) and the recorder's, one per
// camera. The transitions worker has its own thread and takes none of these locks.
//
// Lock order: a thread holding one of these takes only those after it, never one before.
//   control_mutex -> session_mutex -> bank_mutex, stats_mutex, config_mutex, recorder_mutex
//   control_mutex -> idle_mutex (StopSession waits for the writer under it: the writer never
//                    takes control_mutex)
//   PreviewCache::mutex -> CameraRunner's preview lock (an encode runs under the cache's lock)
// Every other lock is a leaf, held for a copy or a count and released before the next is taken
// (the writer's stats_mutex, then session_mutex, one after the other in Stored). watcher_mutex is
// held while the watcher runs: a watcher must not call the station. The disk guard's lock is a
// leaf too (it reads the settings under config_mutex before it takes its own).
// transitions_listeners' lock is held while the transitions listeners run on the worker's thread
// (with none of the worker's locks): a listener takes only its own locks.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "core/bank.h"
#include "core/elapsed.h"
#include "core/listeners.h"
#include "core/log.h"
#include "pipeline/run/bounded_queue.h"
#include "pipeline/transitions/worker.h"
#include "station/bank_spool.h"
#include "station/camera_runner.h"
#include "station/disk_guard.h"
#include "station/recorder.h"
#include "station/station.h"

namespace ss {

namespace station_detail {

using Clock = std::chrono::steady_clock;

// Preview snapshots a camera takes, idle and while a session stores; each view of a snapshot is
// encoded once, for every viewer, so these are also the most images a second a view costs.
constexpr double kPreviewIntervalS = 0.2, kPreviewIntervalSessionS = 0.5;

}  // namespace station_detail

// One camera's encoded previews, by (view, width): view 0 raw, 1 keyed, 2 the sprites view.
struct PreviewCache {
  struct Entry {
    // The snapshot it was made from, by when it was taken (holding the snapshot itself would
    // keep the runner from reusing its buffer).
    std::optional<SteadyTime> frame_taken;
    Station::PreviewImage image;
    std::string sprites_json;
  };
  std::mutex mutex;  // also makes concurrent callers wait for one encode instead of each doing it
  std::map<std::pair<int, int>, Entry> entries;
};

struct Station::Impl {
  StationOptions options;
  std::shared_ptr<spdlog::logger> log = Log("station");
  GroundPolygon floor;
  std::vector<std::optional<CameraModel>> models;
  SteadyTime started_at = station_detail::Clock::now();
  std::atomic<StationState> state{StationState::kStarting};

  std::mutex bank_mutex;  // BankWriter is one connection: one thread at a time
  std::unique_ptr<BankWriter> bank;
  std::unique_ptr<BankSpool> spool;  // the writer thread's
  std::unique_ptr<TransitionWorker> transitions;
  std::vector<std::unique_ptr<CameraRunner>> runners;

  BoundedQueue<StationBatch> batches{256};
  std::thread writer_thread;
  std::mutex idle_mutex;
  std::condition_variable idle_cv;
  uint64_t batches_in = 0, batches_done = 0;  // under idle_mutex

  // Under stats_mutex.
  mutable std::mutex stats_mutex;
  int64_t bank_sprites = 0;
  uint64_t sprites_stored = 0, batches_stored = 0, batches_failed = 0, batches_refused = 0;
  uint64_t batches_retried = 0;  // appends tried again after the bank stayed locked (BusyError)
  uint64_t batches_spooled = 0;  // kept on disk while the bank could not take them
  uint64_t spool_batches = 0;
  int64_t spool_bytes = 0;
  static constexpr int kBusyAttempts = 6;  // with SQLite's 10 s busy timeout: up to a minute
  std::deque<double> latencies_ms;         // last 10,000
  uint64_t latency_count = 0;              // every sprite's, since start
  double latency_sum_ms = 0;
  std::deque<std::pair<SteadyTime, uint64_t>>
      stored_log;  // (time, sprites_stored) samples for sprites/s
  std::string bank_error;
  bool last_append_failed = false;  // until an append succeeds again

  // The capture session, under session_mutex (held across start/stop).
  mutable std::mutex session_mutex;
  SessionStatus session;
  std::atomic<bool> session_active{false};  // session.active, read without the lock (previews)
  std::vector<std::unique_ptr<PreviewCache>> preview_caches;  // one per runner
  SteadyTime session_started{};
  std::unique_ptr<StationRecorder> recorder;
  mutable std::mutex recorder_mutex;  // guards `recorder` against the pipeline threads' taps
  std::mutex control_mutex;           // one session start / stop / rename at a time
  RecorderStats last_recording;

  // The cache entry of a camera's view, locked in `lock`; `frame` is set when the entry must be
  // made (again) from that snapshot, and `runner` to the camera's. nullptr before the camera's
  // first frame; NotFoundError for no such camera.
  PreviewCache::Entry* CachedPreview(const std::string& camera, int view, int width,
                                     std::unique_lock<std::mutex>* lock,
                                     std::shared_ptr<const PreviewFrame>* frame,
                                     const CameraRunner** runner) const;

  // The bank writer (bank_writer_thread.cc).
  void Store(StationBatch sb);
  void WriterLoop();

  // Clips one of whose batches failed or was refused (camera, track, first frame): their later
  // batches are not stored, so the bank never holds a complete clip with a hole (the clip's part
  // stored before the failure stays an incomplete clip, which readers do not see). Writer thread
  // only.
  std::set<std::tuple<int64_t, int64_t, int64_t>> broken_clips;
  static std::tuple<int64_t, int64_t, int64_t> ClipKey(const ClipRecord& clip) {
    return {clip.camera_id, clip.track_id, clip.first_frame};
  }
  // A batch of `clip` that is not stored (refused, failed, not spooled) or dropped as broken:
  // the clip's later batches are dropped too, until its last one (complete) ends it.
  void BreakClip(const ClipRecord& clip);

  void WriteBatch(StationBatch& sb);

  // Keeps a batch the bank could not take in the spool; if even that fails, the batch is lost
  // as a failed append is (counted, its clip's later batches not stored).
  void Spool(const ClipBatch& batch);

  // Appends the spooled batches, oldest first, until the spool is empty or the bank is still
  // away. A batch the bank refuses for what it holds is set aside in the spool's damaged/ folder.
  void DrainSpool();

  // Counts a batch the bank took (`received`: when each sprite's frame arrived, for the latency;
  // none for a batch from the spool) and hands its new sprites to the transitions worker.
  void Stored(const ClipBatch& batch, const AppendResult& result,
              const std::vector<SteadyTime>* received);

  // Waits until every batch handed to the writer so far is stored (or refused).
  void WaitWriterIdle();

  // The frame taps: the calibration wizard's watcher and the recorder (station.cc).
  std::mutex watcher_mutex;
  Station::FrameWatcher watcher;  // under watcher_mutex

  void Tap(int camera, const Frame& frame, uint64_t drops_before, bool usable);

  // Who follows the transitions worker's start-up (station.h AddTransitionsListener).
  Listeners transitions_listeners;  // its lock is held while they run
  void StopRecording(const std::string& why);

  mutable std::mutex config_mutex;  // guards options.config.storage / logging for Reload
  StorageConfig StorageSettings() const {
    std::lock_guard lock(config_mutex);
    return options.config.storage;
  }
  // Tells StationOptions::status_changed (station.h), if set.
  void Changed() const {
    if (options.status_changed) options.status_changed();
  }
  // Status() asks it too.
  mutable DiskGuard disk{[this] { return StorageSettings(); }, [this] { Changed(); }};
};

}  // namespace ss
