// `spritestation config check` as a user runs it (the executable, so in tests/e2e).
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

const std::string kExample = fs::path(ss::testing::SourcePath("docs/station.example.yaml"));
const std::string kOneCamera = "cameras:\n  - name: cam0\n    source: v4l2\n    device: /dev/video0\n";

// `spritestation config check`: exit codes and messages of the real executable.
TEST(StationConfig, CheckCommand) {
  if (std::getenv("SPRITESTATION_BIN") == nullptr)
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  ScratchDir dir;
  auto r = ss::testing::RunSpritestation("config check --no-file-checks " + kExample);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(kExample + ": valid (3 cameras)"), std::string::npos) << r.output;

  const std::string bad = dir / "bad.yaml";
  std::ofstream(bad) << kOneCamera << "    fps: fast\n";
  r = ss::testing::RunSpritestation("config check " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(bad + ":5: cameras[0].fps: expected a positive number, got \"fast\""),
            std::string::npos)
      << r.output;

  r = ss::testing::RunSpritestation("config check --json " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("\"status\": \"invalid\""), std::string::npos) << r.output;

  r = ss::testing::RunSpritestation("config check " + (dir / "missing.yaml"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir / "missing.yaml"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ss
