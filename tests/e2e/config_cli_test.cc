// `spritestation config check` as a user runs it (the executable, so in tests/e2e).
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/posix.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

const std::string kExample = fs::path(ss::testing::SourcePath("docs/station.example.yaml"));
const std::string kOneCamera =
    "cameras:\n  - name: cam0\n    source: v4l2\n    device: /dev/video0\n";

// `spritestation config check`: exit codes and messages of the real executable.
TEST(StationConfig, CheckCommand) {
  if (!Environment("SPRITESTATION_BIN"))
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

// Issue 20: a config or a spec over 16 MiB is bad input (exit 2), refused before it is parsed.
TEST(StationConfig, OversizedFilesAreRefusedWithExitCode2) {
  if (!Environment("SPRITESTATION_BIN"))
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  ScratchDir dir;
  const std::string config = dir / "big.yaml", spec = dir / "big-spec.yaml";
  for (const std::string& path : {config, spec}) {
    std::ofstream(path) << kOneCamera;
    fs::resize_file(path, 250'000'000);  // sparse
  }
  auto r = ss::testing::RunSpritestation("config check " + config);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find(config +
                    ": 238.4 MiB (250000000 bytes): larger than the 16 MiB a config file may be"),
      std::string::npos)
      << r.output;
  r = ss::testing::RunSpritestation("animate " + spec + " --out " + (dir / "out.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find(
          spec + ": 238.4 MiB (250000000 bytes): larger than the 16 MiB an animation spec may be"),
      std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace ss
