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
  EXPECT_EQ(Bank(bank).GetMeta(SpriteChoice::kMetaKey).value_or(""), "false");

  // The single-process build leaves them out too, and finds the worker's table.
  BankUpdateOptions options;
  options.weights = Generous();
  const BankUpdateSummary s = UpdateBankTransitions(bank, options);
  EXPECT_EQ(s.left_out, 2 * static_cast<int64_t>(filler.merged.size()));
  EXPECT_EQ(s.transitions, static_cast<int64_t>(incremental.size()));
  EXPECT_EQ(s.store.added + s.store.changed + s.store.removed, 0);

  // Included, they have transitions; left out again, those go.
  options.sprites.include_merged = true;
  const BankUpdateSummary with = UpdateBankTransitions(bank, options);
  EXPECT_EQ(with.left_out, 0);
  EXPECT_GT(touches_merged(Bank(bank).LoadTransitions()), 0);
  EXPECT_EQ(Bank(bank).GetMeta(SpriteChoice::kMetaKey).value_or(""), "true");
  options.sprites.include_merged = false;
  const BankUpdateSummary without = UpdateBankTransitions(bank, options);
  EXPECT_GT(without.store.removed, 0);
  EXPECT_EQ(touches_merged(Bank(bank).LoadTransitions()), 0);
  // A worker starting on a table made with them drops their transitions at start.
  options.sprites.include_merged = true;
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
