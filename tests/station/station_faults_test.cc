// The station in-process when the bank's disk fills up under it: appends
// fail (the process may not grow a file: RLIMIT_FSIZE, a full disk for this
// process alone), the storage state says so, nothing stored before is lost,
// and storage resumes when space comes back. And when another writer holds the
// bank's lock past SQLite's busy timeout: no batch is lost.
#include <signal.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <nlohmann/json.hpp>
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
