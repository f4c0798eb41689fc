// The `spritestation transitions` commands on a bank of synthetic sprites
// (tests/pipeline/transitions_bank_fixtures.h): label from the session truth, train, build
// with the trained weights, and clear messages for wrong weights, an empty bank, no bank and
// labels naming unknown sprites.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "pipeline/transitions/training.h"
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

}  // namespace
}  // namespace ss
