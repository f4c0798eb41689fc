// The station storing into a PostgreSQL bank whose server goes away for 10 s: the batches
// wait in the spool on disk, the bank takes them in order when the server is back, and no
// sprite is lost (issue 21). And the spool's own format, and a spool an earlier run left.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/bank.h"
#include "core/bank_verify.h"
#include "station/bank_spool.h"
#include "station/station.h"
#include "station/station_status.h"
#include "tests/station/replay_station.h"
#include "tests/support/bank_fixtures.h"
#include "tests/support/postgres_server.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using namespace ss::testing;  // NOLINT: PostgresServer, ScratchDir, the station and bank fixtures

TEST(StationPostgres, TenSecondsWithoutTheDatabaseLoseNoSprite) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  StationOptions options = OneReplayCamera(dir);
  options.config.logging.level = "error";
  options.config.storage.bank = server.CreateDatabase("studio");
  options.config.storage.spool_dir = dir / "spool";
  Station station(options);
  station.Start();
  station.StartSession("outage");
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.batches_stored >= 3; }, 60))
      << "no batch stored before the outage";

  server.Stop();
  const auto stopped = std::chrono::steady_clock::now();
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.spool_batches >= 2; }, 30))
      << "batches were not spooled while the database was away";
  const StationStatus during = station.Status();
  EXPECT_EQ(during.storage_state, StorageState::kWritesFailing);
  EXPECT_NE(during.bank_error.find("studio"), std::string::npos) << during.bank_error;
  std::this_thread::sleep_until(stopped + std::chrono::seconds(10));
  ASSERT_TRUE(server.Start()) << server.log();

  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.spool_batches == 0; }, 60))
      << "the spool was not drained";
  const uint64_t spooled = station.Status().batches_spooled;
  ASSERT_TRUE(WaitFor(
      station, [](const StationStatus& s) { return s.storage_state == StorageState::kOk; }, 30));
  station.StopSession();
  station.Stop();
  const StationStatus end = station.Status();
  EXPECT_GE(spooled, 2u);
  EXPECT_EQ(end.batches_failed, 0u);
  EXPECT_EQ(end.spool_batches, 0u);

  // Every sprite the station counted as stored is in the bank, in complete clips without a hole.
  const Bank bank(options.config.storage.bank);
  const BankCounts counts = bank.Counts();
  EXPECT_EQ(static_cast<uint64_t>(counts.sprites - counts.mirrors), end.sprites_stored);
  const BankVerifyReport report = VerifyBank(options.config.storage.bank);
  EXPECT_TRUE(report.ok()) << (report.ok() ? "" : report.problems.front());
}

TEST(BankSpool, KeepsBatchesInOrderAcrossARestartAndWithinItsLimit) {
  ScratchDir dir;
  const ClipBatch a{Clip(3, 1, 10, false), MakeBatch(10, 12, 1)};
  const ClipBatch b{Clip(3, 1, 10, true), MakeBatch(13, 13, 1)};
  {
    BankSpool spool(dir / "spool", 1 << 20);
    EXPECT_TRUE(spool.Push(a));
    EXPECT_TRUE(spool.Push(b));
    EXPECT_EQ(spool.batches(), 2u);
  }
  BankSpool spool(dir / "spool", 1 << 20);  // what an earlier run left
  ASSERT_EQ(spool.batches(), 2u);
  const std::optional<ClipBatch> first = spool.Front();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->clip.first_frame, 10);
  EXPECT_FALSE(first->clip.complete);
  ASSERT_EQ(first->sprites.size(), a.sprites.size());
  for (size_t i = 0; i < a.sprites.size(); ++i) {
    EXPECT_EQ(first->sprites[i].frame, a.sprites[i].frame);
    EXPECT_EQ(first->sprites[i].mirrored, a.sprites[i].mirrored);
    EXPECT_EQ(first->sprites[i].ground_x_m, a.sprites[i].ground_x_m);
    EXPECT_EQ(first->sprites[i].px_per_m, a.sprites[i].px_per_m);
    EXPECT_EQ(first->sprites[i].tags, a.sprites[i].tags);
    if (!a.sprites[i].mirrored) {
      EXPECT_TRUE(SameMat(first->sprites[i].pixels.bgra, a.sprites[i].pixels.bgra));
    }
  }
  spool.PopFront();
  EXPECT_TRUE(spool.Front()->clip.complete);
  // A batch past the limit is refused with nothing written.
  BankSpool small(dir / "small", 100);
  EXPECT_FALSE(small.Push(a));
  EXPECT_TRUE(small.empty());
  // A damaged file is set aside, not read as a batch and not lost.
  {
    BankSpool damaged(dir / "damaged", 1 << 20);
    ASSERT_TRUE(damaged.Push(a));
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir / "damaged")) {
    if (entry.is_regular_file()) std::filesystem::resize_file(entry.path(), 20);
  }
  BankSpool damaged(dir / "damaged", 1 << 20);
  EXPECT_FALSE(damaged.Front());
  EXPECT_TRUE(damaged.empty());
  EXPECT_FALSE(std::filesystem::is_empty(dir / "damaged/damaged"));
}

}  // namespace
}  // namespace ss
