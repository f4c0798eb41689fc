// Transition work shared by several `spritestation transitions worker` processes on one
// PostgreSQL bank (issue 21): the table they make together equals a single-process build of
// the same bank exactly, also when one worker is killed in the middle of a unit, and with a cap
// on the transitions out of a sprite that the workers' rounds meet at once.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "tests/support/postgres_server.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::BackgroundCommand;
using testing::JsonInOutput;
using testing::PostgresServer;
using testing::QueryInt;
using testing::RunSpritestation;
using testing::ScratchDir;

void ExpectSameTransitions(const std::string& got_bank, const std::string& want_bank) {
  const auto got = Bank(got_bank).LoadTransitions();
  const auto want = Bank(want_bank).LoadTransitions();
  ASSERT_GT(want.size(), 0u) << "the session must have transitions for the test to mean anything";
  ASSERT_EQ(got.size(), want.size());
  size_t differ = 0;
  for (size_t k = 0; k < want.size(); ++k) {
    if (got[k].from_sprite != want[k].from_sprite || got[k].to_sprite != want[k].to_sprite ||
        got[k].d != want[k].d || got[k].cost != want[k].cost) {
      ++differ;
    }
  }
  EXPECT_EQ(differ, 0u) << "of " << want.size();
}

TEST(TransitionWorkers, TwoWorkersAndAKilledOneMakeTheSingleProcessTable) {
  PostgresServer server;
  ASSERT_TRUE(server.ok());
  ScratchDir dir;
  const auto synth = RunSpritestation(
      "synth --out " + dir / "session" +
      " --kind animal --seconds 8 --fps 30 --size 480x360 --cameras 2 --subjects 2 "
      "--seed 21");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string pg = server.CreateDatabase("studio");
  const auto ingest = RunSpritestation("--log-level warn ingest " + dir / "session" + " --bank " +
                                       pg + " --no-transitions --json");
  ASSERT_EQ(ingest.exit_code, 0) << ingest.output;
  // The single-process build, on a copy made before any worker ran.
  const std::string single = dir / "single.db";
  ASSERT_EQ(RunSpritestation("--log-level warn bank copy " + pg + " " + single).exit_code, 0);
  // A cap that bites (the session keeps more out of many sprites), so that the workers' prunes,
  // concurrent and out of order, must give exactly the single build's cheapest.
  const std::string cap = " --max-per-sprite 4";
  const auto build = RunSpritestation("--log-level warn transitions " + single + cap + " --json");
  ASSERT_EQ(build.exit_code, 0) << build.output;
  {
    std::map<int64_t, int> out;
    for (const TransitionRecord& t : Bank(single).LoadTransitions()) ++out[t.from_sprite];
    int at_cap = 0;
    for (const auto& [from, n] : out) {
      ASSERT_LE(n, 4) << "sprite " << from;
      at_cap += n == 4;
    }
    ASSERT_GT(at_cap, 20) << "the cap must bite for the test to mean anything";
  }
  const int64_t clips = QueryInt(pg, "SELECT count(*) FROM clips WHERE complete = 1");
  ASSERT_GE(clips, 4) << "several units are needed to share";

  // A worker that claims a unit and is killed before it stores anything: its lease (2 s) runs out.
  // Set for the child only, on gtest's one thread: no thread reads the environment meanwhile.
  setenv("SPRITESTATION_WORKER_TEST_PAUSE_S", "60", 1);  // NOLINT(concurrency-mt-unsafe)
  BackgroundCommand victim(
      "--log-level warn transitions worker --bank " + pg + cap + " --name victim --lease 2",
      dir / "victim.log");
  unsetenv("SPRITESTATION_WORKER_TEST_PAUSE_S");  // NOLINT(concurrency-mt-unsafe)
  int64_t claimed = 0;
  for (int i = 0; i < 300 && claimed == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    // The worker makes its work table when it starts.
    if (QueryInt(pg, "SELECT count(*) FROM pg_tables WHERE tablename = 'transition_work'") == 0)
      continue;
    claimed = QueryInt(pg, "SELECT count(*) FROM transition_work WHERE worker = 'victim'");
  }
  ASSERT_EQ(claimed, 1) << victim.output();
  victim.Signal(SIGKILL);
  victim.Wait(10);

  // Two workers at once do everything, the killed unit included.
  BackgroundCommand a("--log-level warn transitions worker --bank " + pg + cap +
                          " --name a --exit-when-idle --json",
                      dir / "a.log");
  BackgroundCommand b("--log-level warn transitions worker --bank " + pg + cap +
                          " --name b --exit-when-idle --json",
                      dir / "b.log");
  ASSERT_EQ(a.Wait(300), 0) << a.output();
  ASSERT_EQ(b.Wait(300), 0) << b.output();
  const nlohmann::json ja = JsonInOutput(a.output()), jb = JsonInOutput(b.output());
  EXPECT_EQ(ja["units"].get<int64_t>() + jb["units"].get<int64_t>(), clips)
      << a.output() << b.output();
  EXPECT_EQ(QueryInt(pg, "SELECT count(*) FROM transition_work WHERE done = 1"), clips);
  EXPECT_EQ(QueryInt(pg, "SELECT count(*) FROM transition_work WHERE attempts >= 2"),
            1);  // the killed one, redone

  const std::string shared = dir / "shared.db";
  ASSERT_EQ(RunSpritestation("--log-level warn bank copy " + pg + " " + shared).exit_code, 0);
  ExpectSameTransitions(shared, single);
}

}  // namespace
}  // namespace ss
