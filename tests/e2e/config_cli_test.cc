// `spritestation config check` as a user runs it (the executable, so in tests/e2e).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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

// docs/station.replay.yaml, the config `scripts/demo.sh --station` runs, is valid as written, and
// with its files there (a copy of it beside a sample session, as in the repository: the paths
// are relative to the file) its cameras and session check out.
TEST(StationConfig, TheDemoStationConfigIsValid) {
  if (!Environment("SPRITESTATION_BIN"))
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  const std::string config = ss::testing::SourcePath("docs/station.replay.yaml");
  auto r = ss::testing::RunSpritestation("config check --no-file-checks " + config);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(": valid (2 cameras)"), std::string::npos) << r.output;

  ScratchDir dir;
  fs::create_directories(dir.path() / "docs");
  fs::copy_file(config, dir / "docs/station.replay.yaml");
  r = ss::testing::RunSpritestation("synth --out " + (dir / "recordings/sample") +
                                    " --kind animal --seconds 1 --fps 10 --size 160x120 "
                                    "--cameras 2 --subjects 1 --seed 7");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = ss::testing::RunSpritestation("config check " + (dir / "docs/station.replay.yaml"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(": valid (2 cameras)"), std::string::npos) << r.output;
}

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

// Issue 39: `config check` says what the daemon will do: a bank that is a device or a folder, a
// training set that cannot fit in memory, a 10 MiB name were "valid", and the daemon then
// refused to start or failed every frame. Refused now, each with its line, with exit code 2.
TEST(StationConfig, CheckRefusesWhatTheDaemonCannotRun) {
  if (!Environment("SPRITESTATION_BIN"))
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  ScratchDir dir;
  fs::create_directories(dir / "banks");
  const std::string config = dir / "station.yaml";
  const auto check = [&](const std::string& yaml) {
    std::ofstream(config) << yaml;
    return ss::testing::RunSpritestation("config check " + config);
  };
  auto r = check(kOneCamera + "storage:\n  bank: /dev/null\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":6: storage.bank: /dev/null: not a sprite bank (not a regular "
                                   "file)"),
            std::string::npos)
      << r.output;
  r = check(kOneCamera + "storage:\n  bank: banks\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":6: storage.bank: " + (dir / "banks") +
                          ": not a sprite bank (a folder)"),
            std::string::npos)
      << r.output;
  r = check(kOneCamera + "keying:\n  training_frames: 2000000000\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":6: keying.training_frames: expected at most 172 frames"),
            std::string::npos)
      << r.output;
  r = check("cameras:\n  - name: " + std::string(10 << 20, 'c') +
            "\n    source: v4l2\n    device: /dev/video0\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":2: cameras[0].name: expected a name of at most 64 characters, "
                                   "got 10485760"),
            std::string::npos)
      << r.output;
  EXPECT_LT(r.output.size(), 1000u);  // the name is not repeated (it made a 20 MB message)
  // no cameras key at all: a valid file for `ingest --config` (import writes one), which the
  // daemon refuses; check says so in the daemon's words
  r = check("storage:\n  bank: station.bank\n");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the daemon refuses it: cameras: the station needs at least one camera"),
            std::string::npos)
      << r.output;
  auto daemon = ss::testing::RunSpritestation("daemon --config " + config + " --duration 1");
  EXPECT_EQ(daemon.exit_code, 2) << daemon.output;
  EXPECT_NE(daemon.output.find(config + ": cameras: the station needs at least one camera"),
            std::string::npos)
      << daemon.output;
  r = check("cameras: []\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":1: cameras: expected at least one camera"), std::string::npos)
      << r.output;
  r = check(kOneCamera + "---\nversion: 1\n");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(config + ":5: a second YAML document (---) starts here"),
            std::string::npos)
      << r.output;
}

// Issue 38: a camera straight above its floor keys sprites and keeps none (an upright billboard
// from above is a sliver); `config check` names it, and keeps quiet for the oblique one.
TEST(StationConfig, CheckNamesACameraThatSeesItsFloorOnlyFromAbove) {
  if (!Environment("SPRITESTATION_BIN"))
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  ScratchDir dir;
  // 1 m above the ground's origin looking straight down (cam_from_ground: a half turn about x),
  // and one 1 m up and 1 m back looking 45 degrees down at the origin.
  const auto model = [&](const std::string& name, const std::string& extrinsics) {
    std::ofstream(dir / name) << "{\n 'lensmodel': 'LENSMODEL_PINHOLE',\n 'intrinsics': [500, 500, "
                                 "319.5, 239.5],\n 'extrinsics': ["
                              << extrinsics << "],\n 'imagersize': [640, 480]\n}\n";
  };
  model("top.cameramodel", "3.141592653589793, 0, 0, 0, 0, 1");
  model("side.cameramodel", "2.356194490192345, 0, 0, 0, 0, 1.4142135623730951");
  const std::string config = dir / "station.yaml";
  const std::string cameras_and_floor =
      "cameras:\n"
      "  - {name: top, source: v4l2, device: /dev/video0, model: top.cameramodel}\n"
      "  - {name: side, source: v4l2, device: /dev/video1, model: side.cameramodel}\n"
      "enclosure:\n  floor: [[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]\n";
  std::ofstream(config) << cameras_and_floor;
  // By default the top camera films from above (issue 38): it stores floor sprites, which no
  // view is too steep for.
  auto r = ss::testing::RunSpritestation("config check --json " + config);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"too_steep\": []"), std::string::npos) << r.output;
  // Kept upright, it keeps nothing. Its shallowest view, a corner of the floor:
  // atan(1 / hypot(0.1, 0.1)) = 81.9 degrees (the floor's pixels looked at every 8 px, a little
  // inside the corner: 82)
  std::ofstream(config) << cameras_and_floor << "pipeline:\n  floor_view_angle_deg: 90\n";
  r = ss::testing::RunSpritestation("config check " + config);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("too steep: top: sees all of its floor from 82 degrees or more above it, "
                          "steeper than pipeline.max_view_angle_deg 75"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("side:"), std::string::npos) << r.output;
  // allowed by the limit: quiet
  std::ofstream(config, std::ios::app) << "  max_view_angle_deg: 85\n";
  r = ss::testing::RunSpritestation("config check --json " + config);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"too_steep\": []"), std::string::npos) << r.output;
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

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `config keys --update` rewrites a stale copy of docs/config.md into the doc as committed, and
// says so; on the doc as committed it changes nothing. `--markdown` prints the tables it holds.
TEST(StationConfig, KeysCommandRewritesTheDocsKeyTables) {
  if (!Environment("SPRITESTATION_BIN"))
    GTEST_SKIP() << "SPRITESTATION_BIN not set (run through ctest)";
  const std::string committed = Slurp(ss::testing::SourcePath("docs/config.md"));
  ScratchDir dir;
  const std::string copy = dir / "config.md";
  std::string stale = committed;
  const size_t row = stale.find("| `queue_frames` |");
  ASSERT_NE(row, std::string::npos);
  stale.erase(row, stale.find('\n', row) + 1 - row);
  std::ofstream(copy) << stale;
  auto r = ss::testing::RunSpritestation("config keys --update " + copy);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(copy + ": key tables rewritten"), std::string::npos) << r.output;
  EXPECT_EQ(Slurp(copy), committed);
  r = ss::testing::RunSpritestation("config keys --update " + copy);
  EXPECT_NE(r.output.find(copy + ": the key tables are up to date"), std::string::npos) << r.output;

  r = ss::testing::RunSpritestation("config keys --markdown");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(committed.find(r.output.substr(0, r.output.find("<!-- end of generated table -->"))),
            std::string::npos)
      << "the first table printed is not the doc's";
  // A file without the markers: refused by name, left as it was.
  const std::string other = dir / "other.md";
  std::ofstream(other) << "# no tables\n";
  r = ss::testing::RunSpritestation("config keys --update " + other);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find(other + ": holds no key table \"top\""), std::string::npos) << r.output;
  EXPECT_EQ(Slurp(other), "# no tables\n");
}

}  // namespace
}  // namespace ss
