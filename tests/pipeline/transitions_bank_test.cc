// Transitions of a real sprite bank: the bank build equals the in-memory build, the
// incremental worker equals a from-scratch build, labels from truth. The command line and
// its error messages are tested in tests/e2e/transitions_cli_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include "core/bank.h"
#include "core/error.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/worker.h"
#include "tests/pipeline/transitions_bank_fixtures.h"
#include "tests/pipeline/transitions_test_util.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::BankFiller;
using testing::Clips;
using testing::Sprites;
using testing::WriteTruth;

// Generous weights for the synthetic set so that many pairs and transitions exist.
TransitionWeights Generous() {
  return testing::UnitWeights({0.03, 30, 0.0006, 0.04, 0.12, 12}, 4.0, 3.0);
}

std::vector<TransitionRecord> Sorted(std::vector<TransitionRecord> t) {
  std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) {
    return std::tie(a.from_sprite, a.to_sprite) < std::tie(b.from_sprite, b.to_sprite);
  });
  return t;
}

TEST(TransitionBank, BankBuildEqualsInMemoryBuild) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 3);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 25);

  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(s.sprites, 600);

  TransitionBuilder memory(Generous(), SyntheticSpriteOptions{}.px_per_m);
  memory.BuildFromScratch(AsSpriteInputs(sprites));
  std::vector<TransitionRecord> want;
  for (const Transition& t : memory.Transitions()) {
    want.push_back({filler.bank_id.at(t.from), filler.bank_id.at(t.to), t.distance, t.cost});
  }
  ASSERT_GT(want.size(), 100u);
  const auto got = Bank(dir / "bank.db").LoadTransitions();
  ASSERT_EQ(got.size(), want.size());
  const auto sorted = Sorted(want);
  for (size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].from_sprite, sorted[k].from_sprite);
    EXPECT_EQ(got[k].to_sprite, sorted[k].to_sprite);
    EXPECT_NEAR(got[k].d, sorted[k].d, 1e-9);  // area_px / px_per_m^2 may round in the last bit
    EXPECT_NEAR(got[k].cost, sorted[k].cost, 1e-9);
  }
  EXPECT_EQ(s.store.added, static_cast<int64_t>(want.size()));

  // Running it again finds nothing to write; other weights replace the table.
  const BankUpdateSummary again = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(again.store.added + again.store.changed + again.store.removed, 0);
  EXPECT_EQ(again.store.unchanged, static_cast<int64_t>(want.size()));
  options.weights = testing::UnitWeights({0.03, 30, 0.0006, 0.04, 0.12, 12}, 2.0, 1.5);
  const BankUpdateSummary other = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_TRUE(other.store.replaced_all);
  EXPECT_LT(other.transitions, static_cast<int64_t>(want.size()));
  EXPECT_EQ(Bank(dir / "bank.db").LoadTransitions().size(), static_cast<size_t>(other.transitions));
}

TEST(TransitionBank, WorkerEqualsFromScratch) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(400, 4);
  const auto clips = Clips(sprites);
  ASSERT_GT(clips.size(), 6u);
  BankFiller filler(dir / "bank.db");
  // A third of the clips are in the bank before the worker starts.
  const size_t before = clips.size() / 3;
  for (size_t k = 0; k < before; ++k) filler.Add(clips[k], 50);
  {
    TransitionWorker worker(dir / "bank.db", Generous());
    for (size_t k = before; k < clips.size(); ++k) {
      filler.Add(clips[k], 7, [&](const std::vector<int64_t>& ids) { worker.Submit(ids); });
    }
    worker.WaitIdle();
    const TransitionWorkerStats st = worker.stats();
    EXPECT_TRUE(st.ready);
    EXPECT_EQ(st.failed_rounds, 0) << st.last_error;
    EXPECT_EQ(st.sprites, 800);
    EXPECT_EQ(st.queued, 0);
  }
  const auto incremental = Bank(dir / "bank.db").LoadTransitions();
  ASSERT_GT(incremental.size(), 100u);
  // A from-scratch build of the whole bank finds exactly the same table.
  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(s.transitions, static_cast<int64_t>(incremental.size()));
  EXPECT_EQ(s.store.added, 0);
  EXPECT_EQ(s.store.changed, 0);
  EXPECT_EQ(s.store.removed, 0);
  EXPECT_FALSE(s.store.replaced_all);
}

// The K cheapest of `table` (sorted by (from, to)) out of each sprite, by cost and then `to`.
std::vector<TransitionRecord> Cheapest(const std::vector<TransitionRecord>& table, size_t keep) {
  std::map<int64_t, std::vector<TransitionRecord>> out;
  for (const TransitionRecord& t : table) out[t.from_sprite].push_back(t);
  std::vector<TransitionRecord> kept;
  for (auto& [from, list] : out) {
    std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) {
      return std::tie(a.cost, a.to_sprite) < std::tie(b.cost, b.to_sprite);
    });
    list.resize(std::min(list.size(), keep));
    kept.insert(kept.end(), list.begin(), list.end());
  }
  return Sorted(kept);
}

void ExpectSamePairs(const std::vector<TransitionRecord>& got,
                     const std::vector<TransitionRecord>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  size_t differ = 0;
  for (size_t k = 0; k < got.size(); ++k) {
    differ += got[k].from_sprite != want[k].from_sprite || got[k].to_sprite != want[k].to_sprite ||
              got[k].cost != want[k].cost;
  }
  EXPECT_EQ(differ, 0u) << what << ": of " << want.size();
}

// At most K transitions out of a sprite, its cheapest: the batch build and the incremental worker
// (whose rounds arrive in another order and prune what they push out) keep the same ones.
TEST(TransitionBank, TheCapKeepsTheCheapestOnEveryPath) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(400, 4);
  const auto clips = Clips(sprites);
  constexpr int kCap = 3;
  // Filled as the worker's bank is below, so that both give their sprites the same ids.
  const size_t before = clips.size() / 3;
  BankFiller all(dir / "all.db");
  for (size_t k = 0; k < clips.size(); ++k) all.Add(clips[k], k < before ? 50 : 7);
  BankUpdateOptions options;
  options.weights = Generous();
  options.table.max_per_sprite = 0;
  UpdateBankTransitions(dir / "all.db", options);
  const auto uncapped = Bank(dir / "all.db").LoadTransitions();
  const auto want = Cheapest(uncapped, kCap);
  ASSERT_LT(want.size() * 2, uncapped.size()) << "the cap must bite for the test to mean anything";
  EXPECT_EQ(Bank(dir / "all.db").GetMeta(TableChoice::kCapMetaKey).value_or(""), "0");

  // The batch build with the cap, over the uncapped table: what goes is removed.
  options.table.max_per_sprite = kCap;
  const BankUpdateSummary capped = UpdateBankTransitions(dir / "all.db", options);
  EXPECT_EQ(capped.transitions, static_cast<int64_t>(want.size()));
  EXPECT_EQ(capped.store.removed, static_cast<int64_t>(uncapped.size() - want.size()));
  ExpectSamePairs(Bank(dir / "all.db").LoadTransitions(), want, "batch");
  EXPECT_EQ(Bank(dir / "all.db").GetMeta(TableChoice::kCapMetaKey).value_or(""), "3");
  const TableChoice recorded = TableChoice::RecordedIn(Bank(dir / "all.db"));
  EXPECT_EQ(recorded.max_per_sprite, kCap);  // what a retrain rebuilds it with
  EXPECT_FALSE(recorded.include_merged);

  // The worker: a third of the clips before it starts, the rest in rounds of 7 frames.
  BankFiller filler(dir / "bank.db");
  for (size_t k = 0; k < before; ++k) filler.Add(clips[k], 50);
  {
    TransitionWorker worker(dir / "bank.db", Generous(), 1, TableChoice{.max_per_sprite = kCap});
    for (size_t k = before; k < clips.size(); ++k) {
      filler.Add(clips[k], 7, [&](const std::vector<int64_t>& ids) { worker.Submit(ids); });
    }
    worker.WaitIdle();
    EXPECT_EQ(worker.stats().failed_rounds, 0) << worker.stats().last_error;
  }
  ASSERT_EQ(filler.bank_id, all.bank_id);
  ExpectSamePairs(Bank(dir / "bank.db").LoadTransitions(), want, "worker");
  const BankUpdateSummary again = UpdateBankTransitions(dir / "bank.db", options);
  EXPECT_EQ(again.store.added + again.store.changed + again.store.removed, 0);
}

// Sprites tagged merged (two subjects in one blob) take part in no transition, on the worker
// path (start-up and rounds) and in a single-process build alike, unless included.
TEST(TransitionBank, MergedSpritesTakePartOnlyWhenIncluded) {
  testing::ScratchDir dir;
  const std::string bank = dir / "bank.db";
  const auto sprites = Sprites(400, 5);
  const auto clips = Clips(sprites);
  ASSERT_GT(clips.size(), 6u);
  BankFiller filler(bank);
  // In every clip, 3 frames a third of the way in (the clip's segment is cut there).
  for (const auto& c : clips) {
    const size_t at = c.originals.size() / 3;
    for (size_t k = at; k < at + 3 && k < c.originals.size(); ++k)
      filler.merged.insert(c.originals[k]->id);
  }
  const auto touches_merged = [&](const std::vector<TransitionRecord>& table) {
    const std::vector<int64_t> tagged = Bank(bank).SpritesTagged(kMergedTag);
    const std::set<int64_t> m(tagged.begin(), tagged.end());
    int64_t n = 0;
    for (const TransitionRecord& t : table) n += m.count(t.from_sprite) || m.count(t.to_sprite);
    return n;
  };
  const size_t before = clips.size() / 3;
  for (size_t k = 0; k < before; ++k) filler.Add(clips[k], 50);
  {
    TransitionWorker worker(bank, Generous());
    for (size_t k = before; k < clips.size(); ++k)
      filler.Add(clips[k], 7, [&](const std::vector<int64_t>& ids) { worker.Submit(ids); });
    worker.WaitIdle();
    EXPECT_EQ(worker.stats().failed_rounds, 0) << worker.stats().last_error;
    EXPECT_EQ(worker.stats().sprites, 800 - 2 * static_cast<int64_t>(filler.merged.size()));
  }
  EXPECT_EQ(Bank(bank).SpritesTagged(kMergedTag).size(), 2 * filler.merged.size());
  const auto incremental = Bank(bank).LoadTransitions();
  ASSERT_GT(incremental.size(), 100u);
  EXPECT_EQ(touches_merged(incremental), 0);
  EXPECT_EQ(Bank(bank).GetMeta(TableChoice::kMetaKey).value_or(""), "false");

  // The single-process build leaves them out too, and finds the worker's table.
  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(bank, options);
  EXPECT_EQ(s.left_out, 2 * static_cast<int64_t>(filler.merged.size()));
  EXPECT_EQ(s.transitions, static_cast<int64_t>(incremental.size()));
  EXPECT_EQ(s.store.added + s.store.changed + s.store.removed, 0);

  // Included, they have transitions; left out again, those go.
  options.table.include_merged = true;
  const BankUpdateSummary with = UpdateBankTransitions(bank, options);
  EXPECT_EQ(with.left_out, 0);
  EXPECT_GT(touches_merged(Bank(bank).LoadTransitions()), 0);
  EXPECT_EQ(Bank(bank).GetMeta(TableChoice::kMetaKey).value_or(""), "true");
  options.table.include_merged = false;
  const BankUpdateSummary without = UpdateBankTransitions(bank, options);
  EXPECT_GT(without.store.removed, 0);
  EXPECT_EQ(touches_merged(Bank(bank).LoadTransitions()), 0);
  // A worker starting on a table made with them drops their transitions at start.
  options.table.include_merged = true;
  UpdateBankTransitions(bank, options);
  {
    TransitionWorker worker(bank, Generous());
    worker.WaitIdle();
  }
  EXPECT_EQ(touches_merged(Bank(bank).LoadTransitions()), 0);
}

TEST(TransitionBank, EmptyBankOneClipAndMissingBank) {
  testing::ScratchDir dir;
  { BankWriter make(dir / "empty.db"); }
  BankUpdateOptions options;
  options.weights = Generous();
  try {
    UpdateBankTransitions(dir / "empty.db", options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no sprites"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("empty.db"), std::string::npos) << e.what();
  }
  EXPECT_THROW(UpdateBankTransitions(dir / "missing.db", options), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "missing.db")) << "a missing bank must not be created";

  const auto sprites = Sprites(60, 5);
  BankFiller filler(dir / "one.db");
  filler.Add(Clips(sprites)[0], 100);
  const BankUpdateSummary s = UpdateBankTransitions(dir / "one.db", options);
  EXPECT_EQ(s.clips, 1);
  ASSERT_FALSE(s.notes.empty());
  EXPECT_NE(s.notes[0].find("one clip"), std::string::npos);

  // The worker on an empty bank starts empty and learns the bank's scale from its first sprites.
  TransitionWorker worker(dir / "empty.db", Generous());
  worker.WaitIdle();
  EXPECT_TRUE(worker.stats().ready);
  EXPECT_EQ(worker.stats().failed_rounds, 0) << worker.stats().last_error;
  TransitionWorker missing(dir / "missing2.db", Generous());
  missing.WaitIdle();
  EXPECT_EQ(missing.stats().failed_rounds, 1);
  EXPECT_NE(missing.stats().last_error.find("missing2.db"), std::string::npos)
      << missing.stats().last_error;
}

TEST(TransitionBank, LabelsFromSessionTruth) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 6);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 40);
  WriteTruth(dir / "session", sprites);
  const TruthLabelSummary s =
      LabelBankFromTruth(dir / "session", dir / "bank.db", 200, TruthLabelOptions{}, 1);
  EXPECT_EQ(s.sprites_matched, 300);
  EXPECT_EQ(s.mirrored_skipped, 300);
  ASSERT_EQ(s.labels.size(), 200u);
  std::map<int64_t, const SyntheticSprite*> by_bank_id;
  for (const auto& sp : sprites) by_bank_id[filler.bank_id.at(sp.id)] = &sp;
  TruthLabelOptions phase_only;  // the session truth has no key points: heading and phase decide
  for (const Label& l : s.labels) {
    SpriteTruth a = by_bank_id.at(l.sprite_i)->truth, b = by_bank_id.at(l.sprite_j)->truth;
    a.keypoints_m.clear();
    b.keypoints_m.clear();
    EXPECT_EQ(l.accept, TruthAccepts(a, b, phase_only));
    EXPECT_FALSE(by_bank_id.at(l.sprite_i)->id > 300) << "mirrors are left out";
  }
  EXPECT_THROW(LabelBankFromTruth(dir / "nosession", dir / "bank.db", 200, TruthLabelOptions{}, 1),
               InputError);
}

}  // namespace
}  // namespace ss
