// Transition workers sharing a PostgreSQL bank agree on the classifier and the table's choice
// (issue 39): the first to start decides them, and a worker with other settings refuses to start,
// on an empty table too, where both used to proceed and make a table of neither.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>

#include "core/error.h"
#include "pipeline/transitions/unit_worker.h"
#include "tests/support/postgres_server.h"

namespace ss {
namespace {

using testing::PostgresServer;

UnitWorkerOptions Options(const std::string& name) {
  UnitWorkerOptions o;
  o.name = name;
  return o;
}

// What constructing a worker says: "" when it starts.
std::string Refusal(const std::string& bank, const UnitWorkerOptions& options) {
  try {
    UnitWorker worker(bank, options);
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

TEST(UnitWorkerSettings, TheFirstWorkersSettingsHoldOnAnEmptyTable) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  const std::string bank = server.CreateDatabase("empty");
  const UnitWorker first(bank, Options("first"));

  UnitWorkerOptions other = Options("other weights");
  other.weights.stage2_bias += 1.0;
  const std::string weights = Refusal(bank, other);
  EXPECT_NE(weights.find("its transitions are made with other weights"), std::string::npos)
      << weights;
  EXPECT_NE(weights.find("spritestation transitions BANK"), std::string::npos) << weights;

  UnitWorkerOptions merged = Options("merged");
  merged.table.include_merged = true;
  const std::string choice = Refusal(bank, merged);
  EXPECT_NE(choice.find("transitions.include_merged false, this worker has true"),
            std::string::npos)
      << choice;

  UnitWorkerOptions capped = Options("capped");
  capped.table.max_per_sprite = 7;
  const std::string cap = Refusal(bank, capped);
  EXPECT_NE(cap.find("transitions.max_per_sprite 100, this worker has 7"), std::string::npos)
      << cap;

  EXPECT_EQ(Refusal(bank, Options("alike")), "");  // the same settings join
}

// Two workers with other weights started at the same moment, on a fresh empty bank each round:
// exactly one starts.
TEST(UnitWorkerSettings, OfTwoStartingAtOnceWithOtherWeightsOneStarts) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  for (int round = 0; round < 8; ++round) {
    const std::string bank = server.CreateDatabase("race" + std::to_string(round));
    UnitWorkerOptions a = Options("a"), b = Options("b");
    b.weights.stage2_bias += 1.0;
    std::atomic<int> ready{0};
    std::string refused[2];
    auto start = [&](int i, const UnitWorkerOptions& o) {
      ++ready;
      while (ready < 2) std::this_thread::yield();
      refused[i] = Refusal(bank, o);
    };
    std::thread ta(start, 0, a), tb(start, 1, b);
    ta.join();
    tb.join();
    EXPECT_EQ(refused[0].empty() + refused[1].empty(), 1)
        << "round " << round << ": '" << refused[0] << "' / '" << refused[1] << "'";
  }
}

}  // namespace
}  // namespace ss
