// The `spritestation transitions` commands on a bank of synthetic sprites
// (tests/pipeline/transitions_bank_fixtures.h): label from the session truth, train, build
// with the trained weights, and clear messages for wrong weights, an empty bank, no bank and
// labels naming unknown sprites.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/transition_jumps.h"
#include "pipeline/transitions/weights.h"
#include "tests/pipeline/transitions_bank_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::BankFiller;
using testing::Clips;
using testing::Sprites;
using testing::WriteTruth;

TEST(TransitionBank, CommandLine) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 7);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 40);
  WriteTruth(dir / "session", sprites);
  const std::string bank = dir / "bank.db";

  // label -> train -> build with the trained weights.
  auto r =
      testing::RunSpritestation("transitions label --from-truth " + (dir / "session") + " --bank " +
                                bank + " --out " + (dir / "labels.csv") + " --count 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = testing::RunSpritestation("transitions train " + (dir / "labels.csv") + " --bank " + bank +
                                " --out " + (dir / "w.json") + " --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stage 2 (all 6 features):   precision"), std::string::npos) << r.output;
  // The labels carry the truth's positive rate, so stage 2 is set for it and stage 1 refitted.
  double rate = 0;
  ReadLabelsCsv(dir / "labels.csv", &rate);
  EXPECT_GT(rate, 0.0);
  EXPECT_LT(rate, 0.5);
  EXPECT_NE(r.output.find("stage 2 then set for the positive rate"), std::string::npos) << r.output;
  // It fits the shipped classifier, the paper's six.
  EXPECT_EQ(LoadWeights(dir / "w.json").stage2_variant, Stage2Variant::kPaper);
  // --variant colour_cells fits that one (three thresholds, stage 1 the velocity ball).
  const auto cells = testing::RunSpritestation(
      "transitions train " + (dir / "labels.csv") + " --bank " + bank + " --out " +
      (dir / "cells.json") + " --threads 1 --variant colour_cells");
  ASSERT_EQ(cells.exit_code, 0) << cells.output;
  EXPECT_NE(cells.output.find("(colour_cells) fitted on the bank for the positive rate"),
            std::string::npos)
      << cells.output;
  EXPECT_EQ(LoadWeights(dir / "cells.json").stage2_variant, Stage2Variant::kColourCells);
  r = testing::RunSpritestation("transitions " + bank + " --weights " + (dir / "w.json") +
                                " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["sprites"], 600);
  EXPECT_EQ(j["transitions"].get<int64_t>(),
            static_cast<int64_t>(Bank(bank).LoadTransitions().size()));
  r = testing::RunSpritestation("transitions " + bank);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("finding transitions"), std::string::npos)
      << "progress lines: " << r.output;

  // Clear messages: wrong weights file, empty bank, no bank, labels naming unknown sprites.
  std::ofstream(dir / "bad.json")
      << R"({"format": "spritestation-transition-weights", "version": 7})";
  r = testing::RunSpritestation("transitions " + bank + " --weights " + (dir / "bad.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("version"), std::string::npos) << r.output;
  { BankWriter make(dir / "empty.db"); }
  r = testing::RunSpritestation("transitions " + (dir / "empty.db"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no sprites"), std::string::npos) << r.output;
  r = testing::RunSpritestation("transitions " + (dir / "none.db"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no such sprite bank"), std::string::npos) << r.output;
  std::ofstream(dir / "unknown.csv") << "sprite_i,sprite_j,accept\n1,999999,1\n";
  r = testing::RunSpritestation("transitions train " + (dir / "unknown.csv") + " --bank " + bank +
                                " --out " + (dir / "w2.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("999999"), std::string::npos) << r.output;
}

// The judge without a truth: `transitions --json` reports the visible jump of the kept
// transitions, as the meter measures it on the bank, and they are less visible than random pairs.
TEST(TransitionBank, JsonReportsTheVisibleJumpOfTheKeptTransitions) {
  testing::ScratchDir dir;
  const auto sprites = Sprites(300, 7);
  BankFiller filler(dir / "bank.db");
  for (const auto& c : Clips(sprites)) filler.Add(c, 40);
  const std::string bank_path = dir / "bank.db";
  // Every kept transition measured (the bank keeps ~2,400; by default 2,000 are sampled).
  auto r = testing::RunSpritestation("transitions " + bank_path +
                                     " --json --threads 1 --jump-sample 100000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  ASSERT_TRUE(j.contains("jumps")) << j.dump(2);
  const nlohmann::json& jumps = j["jumps"];
  const int64_t transitions = j["transitions"].get<int64_t>();
  ASSERT_GT(transitions, 0);
  EXPECT_EQ(jumps["transitions"].get<int64_t>(), transitions);
  EXPECT_EQ(jumps["sampled"].get<int64_t>(), transitions);
  EXPECT_EQ(jumps["measured"].get<int64_t>() + jumps["unmeasured"].get<int64_t>(),
            jumps["sampled"].get<int64_t>());
  int64_t by_kind = 0;
  for (const char* kind : {"within_clip", "joining_clips", "original_mirror"})
    by_kind += jumps["by_kind"][kind]["sampled"].get<int64_t>();
  EXPECT_EQ(by_kind, jumps["sampled"].get<int64_t>());
  EXPECT_NEAR(j["transitions_per_sprite"].get<double>(),
              static_cast<double>(transitions) / j["sprites"].get<double>(), 1e-9);

  // The same figures from the meter directly, over every kept transition.
  const Bank bank(bank_path);
  VisibleJumpMeter meter(bank);
  std::vector<double> kept;
  for (const TransitionRecord& t : bank.LoadTransitions()) {
    if (const auto jump = meter.Jump(t.from_sprite, t.to_sprite)) kept.push_back(*jump);
  }
  ASSERT_EQ(static_cast<int64_t>(kept.size()), jumps["measured"].get<int64_t>());
  EXPECT_NEAR(jumps["median"].get<double>(), *Quantile(kept, 0.5), 1e-9);
  EXPECT_NEAR(jumps["p95"].get<double>(), *Quantile(kept, 0.95), 1e-9);
  EXPECT_NEAR(jumps["median_step_px"].get<double>(), meter.MedianStep_px(), 1e-9);
  EXPECT_GT(meter.MedianStep_px(), 1.0);
  EXPECT_LE(jumps["median"].get<double>(), jumps["p95"].get<double>());
  // Sane: a kept transition is less visible than showing a random sprite instead.
  const std::vector<SpriteFeatures> features = bank.LoadFeatures();
  std::mt19937_64 rng(5);
  std::vector<double> random;
  for (int k = 0; k < 200; ++k) {
    const SpriteFeatures& from = features[rng() % features.size()];
    const SpriteFeatures& to = features[rng() % features.size()];
    if (const auto jump = meter.Jump(from.id, to.id)) random.push_back(*jump);
  }
  EXPECT_LT(jumps["median"].get<double>(), 0.5 * *Quantile(random, 0.5));
  // The natural successor of a sprite is no jump at all.
  EXPECT_EQ(meter.Jump(features[0].id, features[features[0].next].id), 0.0);

  // By default at most 2,000, spread over the table.
  r = testing::RunSpritestation("transitions " + bank_path + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output.substr(r.output.find('{')))["jumps"]["sampled"],
            std::min<int64_t>(transitions, 2000));
  r = testing::RunSpritestation("transitions " + bank_path + " --jump-sample 0 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(nlohmann::json::parse(r.output.substr(r.output.find('{'))).contains("jumps"));
  r = testing::RunSpritestation("transitions " + bank_path);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("visible jump of "), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ss
