// The demo's animation judged as a viewer sees it, from a bank our own pipeline made: a 30 s cut
// of the reference hamster (the same animal, seed 53, one camera, as scripts/reference-banks.sh
// renders) is rendered, ingested through the live pipeline, given its transitions and its
// clean plate; docs/examples/walk.yaml, the spec scripts/demo.sh runs, animates it unchanged
// but for the three paths. The hamster must cross the 0.6 m of floor without stutter or a
// visible jump (issue 33: the demo's walk covered 0.12 m and replayed four frames).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Replaces every occurrence of `from` in `text` by `to`; how many there were.
int ReplaceAll(std::string& text, const std::string& from, const std::string& to) {
  int n = 0;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
    ++n;
  }
  return n;
}

TEST(DemoWalk, TheHamsterCrossesTheFloorWithoutStutterOrAVisibleJump) {
  testing::ScratchDir dir;
  const std::string session = dir / "session";
  auto run = [](const std::string& args) {
    const testing::CommandResult r = testing::RunSpritestation("--log-level warn " + args);
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    return r.exit_code == 0;
  };
  ASSERT_TRUE(run("synth --out " + session +
                  " --kind animal --seconds 30 --fps 30 --size 640x480 --cameras 1 --subjects 1"
                  " --seed 53 --no-mattes"));
  ASSERT_TRUE(
      run("ingest " + session + " --bank " + (dir / "hamster.ssbank") + " --no-transitions"));
  ASSERT_TRUE(run("transitions " + (dir / "hamster.ssbank") + " --quiet"));
  ASSERT_TRUE(run("plate " + session + " --camera cam0 --out " + (dir / "floor.png")));
  fs::copy_file(session + "/cam0.cameramodel", dir / "virtual.cameramodel");

  std::string spec = ReadText(testing::SourcePath("docs/examples/walk.yaml"));
  ASSERT_EQ(ReplaceAll(spec, "../../recordings/reference/hamster-60s/", dir.path().string() + "/"),
            3)
      << spec;
  std::ofstream(dir / "walk.yaml") << spec;

  const testing::CommandResult animate =
      testing::RunSpritestation("--log-level off animate " + (dir / "walk.yaml") + " --out " +
                                (dir / "walk.json") + " --seed 1 --json 2>/dev/null");
  ASSERT_EQ(animate.exit_code, 0) << animate.output;
  const nlohmann::json judge = nlohmann::json::parse(animate.output).at("judge");
  SCOPED_TRACE(judge.dump(2));

  ASSERT_EQ(judge["paths"].size(), 1u);
  const nlohmann::json& path = judge["paths"][0];
  EXPECT_GE(path["swept_share"].get<double>(), 0.98) << "the walk stops short of its path";
  EXPECT_GE(path["finished_step"].get<int>(), 0) << "the walk never reaches the path's end";
  // The hamster wiggles about a straight line; 10 cm on this cut (the goal of 3 cm is unmet).
  EXPECT_LE(path["max_deviation_m"].get<double>(), 0.15);
  EXPECT_LE(path["median_deviation_m"].get<double>(), 0.06);
  EXPECT_GE(judge["lengths"][0]["frames"].get<int>(), 60);
  EXPECT_LE(judge["stutter"]["share"].get<double>(), 0.01);
  // Every transition no more visible than two ordinary frame steps (the p95 goal).
  if (judge["jumps"]["transitions"].get<int>() > 0) {
    EXPECT_LE(judge["jumps"]["max"].get<double>(), 2.0);
    EXPECT_LE(judge["jumps"]["median"].get<double>(), 1.0);
  }

  // What the demo does next: the render is a video a player reads, one frame per step.
  ASSERT_TRUE(run("render " + (dir / "walk.json") + " --out " + (dir / "walk.mkv")));
  const testing::CommandResult probe = testing::RunCommand(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames "
      "-of csv=p=0 " +
      (dir / "walk.mkv"));
  ASSERT_EQ(probe.exit_code, 0) << probe.output;
  EXPECT_EQ(std::stoi(probe.output), judge["lengths"][0]["frames"].get<int>());
}

}  // namespace
}  // namespace ss
