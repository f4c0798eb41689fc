#include "station/disk_guard.h"

#include <filesystem>
#include <utility>

#include "core/log.h"
#include "core/sql_postgres.h"

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

DiskGuard::Reading Look(const StorageConfig& storage) {
  DiskGuard::Reading r;
  // A PostgreSQL bank's disk is its server's (a full one fails appends: writes_failing).
  r.free_mib =
      sql::IsPostgresAddress(storage.bank) ? -1 : FreeMib(fs::path(storage.bank).parent_path());
  if (storage.recording != RecordingMode::kOff) {
    const int64_t rec = FreeMib(storage.recording_dir);
    if (rec >= 0 && (r.free_mib < 0 || rec < r.free_mib)) r.free_mib = rec;
  }
  if (r.free_mib < 0) return r;
  if (r.free_mib < storage.stop_sprites_below_mib) {
    r.state = StorageState::kSpritesStopped;
  } else if (r.free_mib < storage.stop_recording_below_mib) {
    r.state = StorageState::kRecordingStopped;
  }
  return r;
}

}  // namespace

DiskGuard::DiskGuard(std::function<StorageConfig()> settings, std::function<void()> changed,
                     double interval_s)
    : settings_(std::move(settings)), changed_(std::move(changed)), interval_s_(interval_s) {}

DiskGuard::Reading DiskGuard::Check(bool fresh) {
  using Clock = std::chrono::steady_clock;
  {
    std::lock_guard lock(mutex_);
    if (!fresh && looked_ &&
        std::chrono::duration<double>(Clock::now() - *looked_).count() < interval_s_)
      return last_;
  }
  const Reading now = Look(settings_());
  StorageState previous;
  {
    std::lock_guard lock(mutex_);
    previous = looked_ ? last_.state : StorageState::kOk;
    last_ = now;
    looked_ = Clock::now();
  }
  if (now.state != previous) {
    auto log = Log("station");
    if (now.state == StorageState::kOk) {
      log->info("disk: {} MiB free, storage back to normal", now.free_mib);
    } else {
      log->warn("disk: {} MiB free: {}", now.free_mib,
                now.state == StorageState::kSpritesStopped
                    ? "sprite storage stopped (storage.stop_sprites_below_mib)"
                    : "raw recording stopped (storage.stop_recording_below_mib)");
    }
    if (changed_) changed_();
  }
  return now;
}

std::string DiskGuard::RecordingRefusal() {
  const Reading r = Check();
  if (r.state != StorageState::kRecordingStopped && r.state != StorageState::kSpritesStopped)
    return "";
  return "free disk space " + std::to_string(r.free_mib) + " MiB is below " +
         (r.state == StorageState::kSpritesStopped ? "storage.stop_sprites_below_mib"
                                                   : "storage.stop_recording_below_mib");
}

}  // namespace ss
