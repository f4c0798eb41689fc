// `spritestation judge` end to end: sequences `animate` made over the walker bank
// (tests/animate/scene_fixture.h) judged with and without their spec, the same figures as the
// ones `animate` printed, and bad input refused with exit code 2.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "animate/sequence_io.h"
#include "core/posix.h"
#include "tests/animate/scene_fixture.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::SceneTest;

TEST_F(SceneTest, JudgeCommandReportsWhatAnimateReported) {
  const std::string spec = WriteSpec(R"(frame_rate: 30
length: 30
optimizer: {time_budget_s: 1, set_size: 40, threads: 1, seed: 3}
sprites:
  - name: a
    start: [0, 0]
    constraints:
      - path: {points: [[0, 0], [1, 0]]}
)");
  // Animated from the spec's folder with relative names: the file names its bank absolute,
  // so the judge finds it from anywhere.
  const std::string seq = dir_ / "seq.json";
  const auto animate = testing::RunCommand(
      "cd " + dir_.path().string() + " && " +
      Environment("SPRITESTATION_BIN").value_or("spritestation") +
      " --log-level off animate scene.yaml --out seq.json --json --time-budget 1");
  ASSERT_EQ(animate.exit_code, 0) << animate.output;
  const nlohmann::json from_animate = nlohmann::json::parse(animate.output)["judge"];
  ASSERT_TRUE(from_animate.is_object()) << animate.output;

  const auto judge =
      testing::RunSpritestation("--log-level off judge " + seq + " --spec " + spec + " --json");
  ASSERT_EQ(judge.exit_code, 0) << judge.output;
  const nlohmann::json j = nlohmann::json::parse(judge.output);
  ASSERT_EQ(j["paths"].size(), 1u);
  const double swept = j["paths"][0]["swept_share"];
  EXPECT_GE(swept, 0.0);
  EXPECT_LE(swept, 1.0);
  EXPECT_EQ(j["paths"][0]["swept_share"], from_animate["paths"][0]["swept_share"]);
  EXPECT_EQ(j["stutter"], from_animate["stutter"]);
  EXPECT_EQ(j["jumps"]["transitions"], from_animate["jumps"]["transitions"]);
  EXPECT_EQ(j["lengths"][0]["frames"], 30);
  EXPECT_EQ(ReadSequenceFile(seq).summary["judge"]["stutter"], j["stutter"]);

  // Without the spec: no constraints, the same stutter; the human report says so.
  const auto plain = testing::RunSpritestation("--log-level off judge " + seq);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("stutter"), std::string::npos) << plain.output;
  EXPECT_NE(plain.output.find("no spec given"), std::string::npos) << plain.output;

  const auto missing = testing::RunSpritestation("judge " + (dir_ / "none.json"));
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  const auto banks = testing::RunSpritestation("judge " + seq + " --bank a.ssbank --bank b.ssbank");
  EXPECT_EQ(banks.exit_code, 2) << banks.output;
  EXPECT_NE(banks.output.find("--bank"), std::string::npos) << banks.output;
}

}  // namespace
}  // namespace ss
