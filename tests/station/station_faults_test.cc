// The station in-process when the bank's disk fills up under it: appends
// fail (the process may not grow a file: RLIMIT_FSIZE, a full disk for this
// process alone), the storage state says so, nothing stored before is lost,
// and storage resumes when space comes back. When free space falls under the
// storage limits mid-session, recording stops first, then sprite storage. And
// when another writer holds the bank's lock past SQLite's busy timeout: no batch
// is lost.
#include <signal.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <nlohmann/json.hpp>
#include "capture/replay/replay_source.h"
#include "core/bank.h"
#include "core/bank_verify.h"
#include "station/station.h"
#include "station/station_status.h"
#include "synth/studio_session.h"
#include "tests/station/replay_station.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using Clock = std::chrono::steady_clock;
using testing::OneReplayCamera;
using testing::WaitFor;
namespace fs = std::filesystem;

// Restores the file-size limit however the test ends.
struct FileSizeLimit {
  rlimit saved{};
  FileSizeLimit() { getrlimit(RLIMIT_FSIZE, &saved); }
  ~FileSizeLimit() { setrlimit(RLIMIT_FSIZE, &saved); }
  void Set(rlim_t bytes) {
    rlimit l = saved;
    l.rlim_cur = bytes;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &l), 0);
  }
  void Lift() { setrlimit(RLIMIT_FSIZE, &saved); }
};

TEST(StationFaults, AFullDiskSaysWritesFailLosesNothingAndResumes) {
  signal(SIGXFSZ,
         SIG_IGN);  // a write past the limit fails with EFBIG instead of killing the process
  testing::ScratchDir dir;
  StationOptions options = OneReplayCamera(dir);
  options.config.logging.level = "warn";
  Station station(options);
  station.Start();
  station.StartSession("full disk");
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_stored >= 3; }, 30))
      << "no batch stored before the disk filled: " << StatusToJson(station.Status()).dump(2);
  EXPECT_EQ(station.Status().storage_state, StorageState::kOk);

  FileSizeLimit limit;
  limit.Set(4096);  // every file of this process is "full" past 4 KiB
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_failed >= 2; }, 30))
      << "no append failed on a full disk";
  const StationStatus failing = station.Status();
  EXPECT_EQ(failing.storage_state, StorageState::kWritesFailing);
  EXPECT_FALSE(failing.bank_error.empty());
  const uint64_t stored_before = failing.batches_stored;

  limit.Lift();  // space comes back
  ASSERT_TRUE(WaitFor(
      station, [&](const StationStatus& s) { return s.batches_stored > stored_before + 2; }, 30))
      << "storage did not resume: " << station.Status().bank_error;
  EXPECT_EQ(station.Status().storage_state, StorageState::kOk);
  station.StopSession();
  station.Stop();
  const BankVerifyReport verify = VerifyBank(options.config.storage.bank);
  std::string problems;
  for (const std::string& p : verify.problems) problems += p + "\n";
  EXPECT_TRUE(verify.ok()) << problems;
  EXPECT_GT(Bank(options.config.storage.bank).Counts().sprites_visible, 0);
}

// The disk filling up mid-session as the disk guard sees it: the limits raised over the free
// space by a reload, which the guard applies at once. Recording stops first (and what it wrote
// still replays), then sprite storage; sprites resume when the space comes back, the recording
// with the next session.
TEST(StationFaults, FreeSpaceUnderTheLimitsStopsRecordingThenSpritesAndTheyResume) {
  testing::ScratchDir dir;
  StationOptions options = OneReplayCamera(dir);
  options.config.logging.level = "warn";
  options.config.storage.recording = RecordingMode::kAll;
  options.config.storage.recording_codec = "mjpeg";
  Station station(options);
  station.Start();
  const SessionStatus session = station.StartSession("filling");
  ASSERT_FALSE(session.recording_dir.empty());
  ASSERT_TRUE(WaitFor(
      station,
      [](const StationStatus& s) { return s.frames_recorded >= 10 && s.batches_stored >= 2; }, 30))
      << StatusToJson(station.Status()).dump(2);

  constexpr int64_t kMoreThanAnyDisk = int64_t{1} << 40;  // MiB
  StationConfig full = options.config;
  full.storage.stop_recording_below_mib = kMoreThanAnyDisk;
  EXPECT_TRUE(station.Reload(full).empty());
  EXPECT_EQ(station.Status().storage_state, StorageState::kRecordingStopped);
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return !s.recording_stopped.empty(); }, 10));
  EXPECT_NE(station.Status().recording_stopped.find("storage.stop_recording_below_mib"),
            std::string::npos)
      << station.Status().recording_stopped;
  const uint64_t recorded = station.Status().frames_recorded;
  const uint64_t stored = station.Status().batches_stored;
  ASSERT_TRUE(WaitFor(
      station, [&](const StationStatus& s) { return s.batches_stored > stored + 2; }, 15))
      << "sprites were not stored while only recording was stopped";
  EXPECT_EQ(station.Status().frames_recorded, recorded);

  full.storage.stop_sprites_below_mib = kMoreThanAnyDisk;
  station.Reload(full);
  EXPECT_EQ(station.Status().storage_state, StorageState::kSpritesStopped);
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_refused >= 1; }, 15))
      << StatusToJson(station.Status()).dump(2);
  const uint64_t stored_full = station.Status().batches_stored;
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_refused >= 4; }, 15));
  EXPECT_EQ(station.Status().batches_stored, stored_full) << "a batch stored on a full disk";

  station.Reload(options.config);  // the space comes back
  EXPECT_EQ(station.Status().storage_state, StorageState::kOk);
  ASSERT_TRUE(WaitFor(
      station, [&](const StationStatus& s) { return s.batches_stored > stored_full + 2; }, 15))
      << "sprite storage did not resume";
  EXPECT_EQ(station.Status().frames_recorded, recorded);
  station.StopSession();
  station.Stop();

  // The recording was finalized: it replays every frame it wrote.
  ReplaySource replay(session.recording_dir);
  uint64_t frames = 0;
  while (replay.Next()) ++frames;
  EXPECT_EQ(frames, recorded);
  const BankVerifyReport verify = VerifyBank(options.config.storage.bank);
  std::string problems;
  for (const std::string& p : verify.problems) problems += p + "\n";
  EXPECT_TRUE(verify.ok()) << problems;
}

TEST(StationFaults, ABankLockedPastTheBusyTimeoutLosesNoBatch) {
  // Another writer (here a second connection; in the soak, the transitions worker's long
  // transactions on a loaded machine) holds the bank's write lock for 12 s, past SQLite's
  // 10 s busy timeout: the station tries its batches again and stores every one of them.
  testing::ScratchDir dir;
  StationOptions options = OneReplayCamera(dir);
  options.config.logging.level = "error";
  Station station(options);
  station.Start();
  station.StartSession("locked");
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_stored >= 3; }, 30))
      << "no batch stored: " << StatusToJson(station.Status()).dump(2);

  {
    sqlite3* other = nullptr;
    ASSERT_EQ(sqlite3_open(options.config.storage.bank.c_str(), &other), SQLITE_OK);
    // The station may be writing a batch just then: wait for its lock as it waits for ours.
    sqlite3_busy_timeout(other, 10000);
    ASSERT_EQ(sqlite3_exec(other, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr), SQLITE_OK);
    std::this_thread::sleep_for(std::chrono::seconds(12));
    ASSERT_EQ(sqlite3_exec(other, "COMMIT", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(other);
  }
  const uint64_t retried = station.Status().batches_retried;
  const uint64_t stored_then = station.Status().batches_stored;
  ASSERT_TRUE(WaitFor(
      station, [&](const StationStatus& s) { return s.batches_stored > stored_then + 2; }, 30))
      << "storage did not go on: " << station.Status().bank_error;
  station.StopSession();
  station.Stop();
  const StationStatus end = station.Status();
  EXPECT_GE(retried, 1u)
      << "the lock outlived the busy timeout, so an append had to be tried again";
  EXPECT_EQ(end.batches_failed, 0u) << end.bank_error;
  EXPECT_EQ(end.storage_state, StorageState::kOk);
  const BankVerifyReport verify = VerifyBank(options.config.storage.bank);
  EXPECT_TRUE(verify.ok());
  // Every sprite the station counted as stored is in the bank.
  const BankCounts counts = Bank(options.config.storage.bank).Counts();
  EXPECT_EQ(static_cast<uint64_t>(counts.sprites - counts.mirrors), end.sprites_stored);
}

}  // namespace
}  // namespace ss
