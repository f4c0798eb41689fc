// `spritestation synth` as a user runs it (the executable, so in tests/e2e).
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

TEST(SynthCommand, RendersAndRejectsBadOptions) {
  ScratchDir dir;
  auto ok = ss::testing::RunSpritestation(
      "synth --out " + (dir / "s") +
      " --seconds 0.5 --fps 10 --size 128x96 --cameras 1 --seed 3 --json");
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const auto start = ok.output.find('{');
  ASSERT_NE(start, std::string::npos) << ok.output;
  const auto report = nlohmann::json::parse(ok.output.substr(start));
  EXPECT_EQ(report["frames"], 5);
  EXPECT_TRUE(fs::exists(fs::path(dir / "s") / "truth" / "truth.json"));
  auto bad = ss::testing::RunSpritestation("synth --out " + (dir / "t") + " --size 12x");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--size"), std::string::npos) << bad.output;
  auto again = ss::testing::RunSpritestation("synth --out " + (dir / "s") + " --seconds 0.2");
  EXPECT_NE(again.exit_code, 0) << again.output;  // the folder is taken
}

}  // namespace
}  // namespace ss
