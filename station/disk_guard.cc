// The station's disk guard (station_impl.h): a monitor thread checks the free space of the
// bank's and the recordings' file systems every second; below storage.stop_recording_below_mib
// raw recording stops, below storage.stop_sprites_below_mib sprite storage stops too.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>

#include "core/sql_postgres.h"
#include "station/station_impl.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

// Free MiB on the file system holding `path` (or its nearest existing parent).
int64_t FreeMib(fs::path path) {
  std::error_code ec;
  while (!path.empty() && !fs::exists(path, ec)) path = path.parent_path();
  if (path.empty()) path = ".";
  const fs::space_info info = fs::space(path, ec);
  if (ec) return -1;
  return static_cast<int64_t>(info.available / (1024 * 1024));
}

}  // namespace

void Station::Impl::MonitorLoop() {
  std::unique_lock lock(monitor_mutex);
  while (!monitor_stop) {
    lock.unlock();
    CheckDisk();
    lock.lock();
    monitor_wake.wait_for(lock, std::chrono::seconds(1), [&] { return monitor_stop; });
  }
}

void Station::Impl::CheckDisk() {
  const StorageConfig storage = StorageSettings();
  // A PostgreSQL bank's disk is its server's (a full one fails appends: writes_failing).
  int64_t free_mib =
      sql::IsPostgresAddress(storage.bank) ? -1 : FreeMib(fs::path(storage.bank).parent_path());
  if (storage.recording != RecordingMode::kOff) {
    const int64_t rec = FreeMib(storage.recording_dir);
    if (rec >= 0 && (free_mib < 0 || rec < free_mib)) free_mib = rec;
  }
  StorageState next = StorageState::kOk;
  if (free_mib >= 0 && free_mib < storage.stop_sprites_below_mib) {
    next = StorageState::kSpritesStopped;
  } else if (free_mib >= 0 && free_mib < storage.stop_recording_below_mib) {
    next = StorageState::kRecordingStopped;
  }
  StorageState previous;
  {
    std::lock_guard lock(stats_mutex);
    previous = storage_state;
    storage_state = next;
    disk_free_mib = free_mib;
  }
  if (next != StorageState::kOk) {
    bool recording = false;
    {
      std::lock_guard lock(recorder_mutex);
      recording = recorder != nullptr;
    }
    if (recording)
      StopRecording("free disk space " + std::to_string(free_mib) +
                    " MiB is below storage.stop_recording_below_mib");
  }
  if (next != previous) {
    if (next == StorageState::kOk) {
      log->info("disk: {} MiB free, storage back to normal", free_mib);
    } else {
      log->warn("disk: {} MiB free: {}", free_mib,
                next == StorageState::kSpritesStopped
                    ? "sprite storage stopped (storage.stop_sprites_below_mib)"
                    : "raw recording stopped (storage.stop_recording_below_mib)");
    }
  }
}

}  // namespace ss
