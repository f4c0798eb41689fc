// Scenes from a spec over a synthetic bank: the optimizer meets the constraints, and the
// `animate` and `render` commands run end to end.
#include "animate/scene.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "animate/animate_run.h"
#include "animate/sequence_io.h"
#include "animate_test_bank.h"
#include "capture/recording/video_file.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

class SceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::WalkerBank::Write(dir_ / "walker.ssbank");
    testing::LookAtCamera(320, 240, 300, {0.5, -3, 2.5}, {0.5, 0.5, 0})
        .Write(dir_ / "virtual.cameramodel");
    cv::imwrite(dir_ / "floor.png", cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 140, 170)));
  }
  std::string WriteSpec(const std::string& body) {
    std::string path = dir_ / "scene.yaml";
    std::ofstream out(path);
    out << "camera: virtual.cameramodel\nbackground: floor.png\nbanks: [walker.ssbank]\n" << body;
    return path;
  }
  ScratchDir dir_;
};

TEST_F(SceneTest, APathFollowingSpriteReachesItsGoal) {
  const auto scene = Scene::Load(LoadAnimationSpec(WriteSpec(R"(frame_rate: 30
length: {min_frames: 30, max_frames: 200}
optimizer: {time_budget_s: 4, set_size: 100, threads: 1}
sprites:
  - name: walker
    start: [0, 0]
    constraints:
      - path: {points: [[0, 0], [1, 0], [1, 1]], direction_strength: 0.2, distance_strength: 20, unreached_strength: 5}
)")));
  AnimateRunOptions options;
  options.time_budget_s = 60;
  options.max_turns = 300;  // the same work on any machine (a budget never reached)
  const AnimateResult result = RunAnimation(*scene, options);
  ASSERT_EQ(result.tracks.size(), 1u);
  const Track& track = result.tracks[0];
  EXPECT_EQ(result.figures.paths_unfinished, 0);
  EXPECT_LT(result.figures.max_path_deviation_m, 0.15);
  // The path's end is reached: some step comes within 10 cm of (1, 1).
  double closest = 1e9;
  for (const Eigen::Vector2d& p : track.positions_m)
    closest = std::min(closest, (p - Eigen::Vector2d(1, 1)).norm());
  EXPECT_LT(closest, 0.1);
  EXPECT_TRUE(scene->problem().IsValid(result.tracks));
  EXPECT_LE(result.summary.final_cost.total, result.summary.initial_cost.total);
}

TEST_F(SceneTest, ASpriteStandsUpAtTheEndOfItsPathForTheTimeAsked) {
  const auto scene = Scene::Load(LoadAnimationSpec(WriteSpec(R"(frame_rate: 30
length: {min_frames: 60, max_frames: 200}
optimizer: {time_budget_s: 4, set_size: 100, threads: 1}
sprites:
  - name: walker
    start: [0, 0]
    constraints:
      - path: {points: [[0, 0], [0.8, 0]], distance_strength: 20, unreached_strength: 5}
      - frames: {tag: standing, after_path: walker, duration: 0.5, strength: 2}
)")));
  // The same work on any machine: 300 sprite turns (~2.3 s idle), a budget never reached.
  // (With a 4 s budget a loaded CI machine stopped it short: 3 steps off the tag.)
  AnimateRunOptions options;
  options.time_budget_s = 60;
  options.max_turns = 300;
  const AnimateResult result = RunAnimation(*scene, options);
  EXPECT_EQ(result.figures.paths_unfinished, 0);
  EXPECT_EQ(result.figures.frame_steps, 15);
  EXPECT_LE(result.figures.frame_steps_off, 2);
}

TEST_F(SceneTest, AnimateAndRenderCommandsEndToEnd) {
  const std::string spec = WriteSpec(R"(frame_rate: 30
length: 40
optimizer: {time_budget_s: 2, set_size: 60, threads: 1}
sprites:
  - name: a
    start: [0, 0]
    constraints:
      - location: {target: [1, 0], at: end, strength: 10}
  - name: b
    start: [1, 0.05]
    constraints:
      - location: {target: [0, 0], at: end, strength: 10}
collisions:
  - {sprites: [a, b], min_distance_m: 0.2, strength: 50}
)");
  const std::string seq = dir_ / "seq.json";
  const auto animate =
      testing::RunSpritestation("animate " + spec + " --out " + seq + " --json --time-budget 2");
  ASSERT_EQ(animate.exit_code, 0) << animate.output;
  EXPECT_NE(animate.output.find("\"final_cost\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "seq.cost.png"));
  const SequenceFile file = ReadSequenceFile(seq);
  ASSERT_EQ(file.sprites.size(), 2u);
  EXPECT_EQ(file.sprites[0].name, "a");
  EXPECT_EQ(file.sprites[0].frames.size(), 40u);
  EXPECT_EQ(file.sprites[0].positions_m[0], Eigen::Vector2d(0, 0));

  const auto render = testing::RunSpritestation("render " + seq + " --out " + (dir_ / "frames"));
  ASSERT_EQ(render.exit_code, 0) << render.output;
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "frames"))
    pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 40);
  const cv::Mat first = cv::imread(dir_ / "frames/frame_000000.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(first.type(), CV_8UC4);
  EXPECT_EQ(first.size(), cv::Size(320, 240));

  const auto video = testing::RunSpritestation("render " + seq + " --out " + (dir_ / "anim.mkv") +
                                               " --codec ffv1");
  ASSERT_EQ(video.exit_code, 0) << video.output;
  EXPECT_GT(fs::file_size(dir_ / "anim.mkv"), 1000u);
  EXPECT_EQ(ReadVideoFrames(dir_ / "anim.mkv").size(), 40u);
  const auto mp4 =
      testing::RunSpritestation("render " + seq + " --out " + (dir_ / "anim.mp4") + " --json");
  ASSERT_EQ(mp4.exit_code, 0) << mp4.output;
  EXPECT_EQ(ReadVideoFrames(dir_ / "anim.mp4").size(), 40u);

  const std::string bad =
      WriteSpec("frame_rate: 30\nlength: 40\nsprites:\n  - name: a\n    start: [0, zero]\n");
  const auto refused = testing::RunSpritestation("animate " + bad + " --out " + seq);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.output.find("scene.yaml:8: sprites[0].start[1]: expected a number"),
            std::string::npos)
      << refused.output;
}

}  // namespace
}  // namespace ss
