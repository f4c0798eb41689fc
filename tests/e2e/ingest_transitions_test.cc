// End to end: `spritestation ingest` keeps the bank's transitions current (the
// TransitionWorker fed with each stored batch), and the table it leaves is the one a
// from-scratch `spritestation transitions BANK` builds.
#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::RunSpritestation;
using testing::ScratchDir;

std::vector<TransitionRecord> Table(const std::string& bank_path) {
  std::vector<TransitionRecord> t = Bank(bank_path).LoadTransitions();
  std::sort(t.begin(), t.end(), [](const TransitionRecord& a, const TransitionRecord& b) {
    return std::tie(a.from_sprite, a.to_sprite) < std::tie(b.from_sprite, b.to_sprite);
  });
  return t;
}

void ExpectSameTable(const std::vector<TransitionRecord>& a,
                     const std::vector<TransitionRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].from_sprite, b[k].from_sprite) << k;
    EXPECT_EQ(a[k].to_sprite, b[k].to_sprite) << k;
    EXPECT_NEAR(a[k].d, b[k].d, 1e-9) << k;
    EXPECT_NEAR(a[k].cost, b[k].cost, 1e-9) << k;
  }
}

// One synthetic session (one camera: two clips in two batches, ~120 sprites with mirrors).
class IngestTransitions : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    const auto r = RunSpritestation(
        "synth --out " + *dir_ / "session" +
        " --kind animal --seconds 6 --fps 30 --size 480x360 --cameras 1 --subjects 1 --seed 11");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static ScratchDir* dir_;
};
ScratchDir* IngestTransitions::dir_ = nullptr;

TEST_F(IngestTransitions, IngestKeepsTheTableEqualToAFromScratchBuild) {
  const ScratchDir& dir = *dir_;

  // Live: the worker runs during the ingest (the default).
  const std::string live = dir / "live.bank";
  const auto a = RunSpritestation("--log-level warn ingest " + dir / "session" + " --bank " + live +
                                  " --json");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const nlohmann::json ja = JsonInOutput(a.output);
  ASSERT_TRUE(ja.is_object()) << a.output;
  ASSERT_TRUE(ja["transitions"].get<bool>()) << a.output;
  EXPECT_EQ(ja["transitions_error"].get<std::string>(), "") << a.output;
  EXPECT_EQ(ja["transition_sprites"].get<int64_t>(), ja["rows_inserted"].get<int64_t>())
      << a.output;
  const auto live_table = Table(live);
  EXPECT_EQ(static_cast<int64_t>(live_table.size()), ja["transitions_stored"].get<int64_t>());
  ASSERT_GT(live_table.size(), 0u)
      << "the session must have transitions for this test to mean anything";
  ASSERT_GE(ja["batches"].get<int>(), 2)
      << "transitions across batches must be found incrementally";

  // Without the worker, then a from-scratch build of the whole bank.
  const std::string later = dir / "later.bank";
  const auto b = RunSpritestation("--log-level warn ingest " + dir / "session" + " --bank " +
                                  later + " --no-transitions --json");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_FALSE(JsonInOutput(b.output)["transitions"].get<bool>()) << b.output;
  EXPECT_TRUE(Table(later).empty());
  const auto build = RunSpritestation("--log-level warn transitions " + later + " --json");
  ASSERT_EQ(build.exit_code, 0) << build.output;
  ExpectSameTable(live_table, Table(later));

  // A from-scratch build over the live bank finds nothing to change.
  const auto again = RunSpritestation("--log-level warn transitions " + live + " --json");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const nlohmann::json j = JsonInOutput(again.output);
  EXPECT_EQ(j["transitions"].get<int64_t>(), static_cast<int64_t>(live_table.size()))
      << again.output;
  EXPECT_EQ(j["added"].get<int64_t>(), 0) << again.output;
  EXPECT_EQ(j["changed"].get<int64_t>(), 0) << again.output;
  EXPECT_EQ(j["removed"].get<int64_t>(), 0) << again.output;
  ExpectSameTable(live_table, Table(live));
}

TEST_F(IngestTransitions, WrongWeightsFileIsAnInputErrorBeforeTheBankIsTouched) {
  const ScratchDir& dir = *dir_;
  const auto r = RunSpritestation("ingest " + dir / "session" + " --bank " + dir / "x.bank" +
                                  " --transition-weights " + dir / "nowhere.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nowhere.json"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.bank"));
}

}  // namespace
}  // namespace ss
