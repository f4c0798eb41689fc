#pragma once
// What the station reports: `GET /api/status` (JSON) and `GET /metrics`
// (Prometheus text exposition format), both made from one StationStatus.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "station/camera_runner.h"

namespace ss {

struct SessionStatus {
  bool active = false;
  std::string name;
  int64_t bank_session_id = 0;
  std::string started;          // ISO 8601 UTC
  double seconds = 0;           // since it started
  uint64_t sprites_stored = 0;  // original sprites stored in it so far
  std::string recording_dir;    // "" when not recording
  // Counts the session changes (start, stop, rename) of every station the process ran (a replay
  // station follows the live one). A status taken before a change may reach a client after the
  // change's own answer; the client keeps the higher revision.
  uint64_t revision = 0;
};

enum class StationState { kStarting, kRunning, kStopping, kStopped };
const char* StationStateName(StationState state);  // "starting", "running", ...

// The storage's state: the disk guard's verdict (below storage.stop_recording_below_mib raw
// recording stops, below storage.stop_sprites_below_mib sprite storage stops too), or, with
// space above both, the bank's last append failed (a disk full or failing before the guard saw it).
enum class StorageState { kOk, kRecordingStopped, kSpritesStopped, kWritesFailing };
const char* StorageStateName(
    StorageState state);  // "ok", "recording_stopped", "sprites_stopped", "writes_failing"

struct StationStatus {
  StationState state = StationState::kStarting;
  double uptime_s = 0;
  SessionStatus session;
  std::vector<CameraStatus> cameras;
  // Bank
  std::string bank_path;
  int64_t bank_sprites = 0;       // rows in the bank (originals and mirrors)
  uint64_t sprites_stored = 0;    // originals stored since start
  double sprites_per_second = 0;  // over the last ~5 s
  uint64_t batches_stored = 0, batches_failed = 0,
           batches_refused = 0;  // refused: storage stopped (disk)
  // appends tried again after the bank stayed locked past its busy timeout
  uint64_t batches_retried = 0;
  // batches kept on disk because the bank could not take them (since start)
  uint64_t batches_spooled = 0;
  uint64_t spool_batches = 0;  // ... of them (and of earlier runs) still waiting in the spool
  int64_t spool_bytes = 0;
  size_t writer_queue = 0;
  double latency_p50_ms = 0,
         latency_p99_ms = 0;   // frame arrival -> sprite committed, last 10,000 sprites
  uint64_t latency_count = 0;  // sprites committed since start, and their latencies'
  double latency_sum_s = 0;    // sum (the Prometheus summary's _count and _sum)
  std::string bank_error;      // the last failed append
  // Transitions
  bool transitions_enabled = false, transitions_ready = false;
  int64_t transitions_pending = 0, transitions_stored = 0, transition_rounds_failed = 0;
  double transitions_last_round_ms = 0;
  std::string transitions_error;          // the worker's last failed round (or start-up)
  std::string transitions_startup_stage;  // "load" | "pairs" while the start-up build runs
  int64_t transitions_startup_done = 0, transitions_startup_total = 0;
  // Storage
  StorageState storage_state = StorageState::kOk;
  int64_t disk_free_mib = -1;  // the lower of the bank's and the recordings' file systems
  int64_t stop_recording_below_mib = 0, stop_sprites_below_mib = 0;  // the disk guard's thresholds
  std::string recording_mode;                                        // off | all | usable
  uint64_t frames_recorded = 0, frames_record_dropped = 0;
  std::string recording_error;
  std::string recording_stopped;  // why the disk guard stopped this session's recording
  // Control: its HTTP server (station/http_server.h)
  std::string control_url;
  uint64_t control_connections_open = 0;     // being served now
  uint64_t control_connections_refused = 0;  // over the per-client limit, since start
  // not received whole by the request deadline, since start
  uint64_t control_requests_timed_out = 0;
};

nlohmann::json StatusToJson(const StationStatus& status);
std::string StatusToPrometheus(const StationStatus& status);
nlohmann::json SessionToJson(const SessionStatus& session);

}  // namespace ss
