#pragma once
// The station's disk guard: the free space of the bank's and the recordings' file systems
// against the storage limits. Below storage.stop_recording_below_mib raw recording stops, below
// storage.stop_sprites_below_mib sprite storage stops too.
//
// It has no thread: free space has no event to wait for, so the guard is asked where the
// station writes, just before it writes (the bank writer before each batch, each camera's
// recording thread before each frame), and where it is shown (the status). It looks at the file
// systems at most once an interval and answers from that look in between; a start, a session's
// start and a reload look again at once. Any thread may ask; the guard's lock is a leaf (the
// settings are read, and the file systems looked at, without it).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "config/station_config.h"
#include "station/station_status.h"

namespace ss {

class DiskGuard {
 public:
  struct Reading {
    StorageState state = StorageState::kOk;  // never kWritesFailing (that is the bank's)
    int64_t free_mib = -1;                   // the lower of the two file systems; -1 unknown
  };

  // `settings` gives the storage section as it is now (a reload may change its limits);
  // `changed`, if set, is called after the state changes (on the thread that asked).
  explicit DiskGuard(std::function<StorageConfig()> settings, std::function<void()> changed = {},
                     double interval_s = 1.0);

  // The reading, looked at again when the last look is an interval old (or `fresh`). A change
  // of state is logged and told.
  Reading Check(bool fresh = false);

  // Why raw recording must stop now ("" when it may go on), for the recorder's threads.
  std::string RecordingRefusal();

 private:
  std::function<StorageConfig()> settings_;
  std::function<void()> changed_;
  double interval_s_;
  std::mutex mutex_;
  std::optional<std::chrono::steady_clock::time_point> looked_;  // under mutex_
  Reading last_;                                                 // under mutex_
};

}  // namespace ss
