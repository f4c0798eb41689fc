// The `spritestation animate` and `render` commands end to end: a scene spec over the
// synthetic walker bank (tests/animate/scene_fixture.h) animated into a sequence file,
// rendered to PNG frames and to video files, and a spec error named by file and line.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <opencv2/imgcodecs.hpp>

#include "animate/sequence_io.h"
#include "capture/recording/video_file.h"
#include "tests/animate/scene_fixture.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using testing::SceneTest;

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

// Issue 39: `animate` reads the spec's camera as `render` does (a YAML file was accepted as the
// camera), and a window past the animation's end is refused at once with its line (`from:
// 10000000` took 2.4 GB and 9 s, and exited 0).
TEST_F(SceneTest, AnimateRefusesABadCameraAndAWindowPastTheEnd) {
  const std::string seq = dir_ / "seq.json";
  const std::string past = WriteSpec(R"(frame_rate: 30
length: {min_frames: 60, max_frames: 120}
sprites:
  - name: a
    start: [0, 0]
    constraints:
      - location: {target: [1, 0], from: 10000000}
)");
  auto r = testing::RunSpritestation("animate " + past + " --out " + seq);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(past + ":10: sprites[0].constraints[0].location.from: past the "
                                 "animation's end: 10000000 s is step 300000000 at 30 fps, and "
                                 "its sequences are at most 120 frames"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(seq));

  const std::string spec = WriteSpec(
      "frame_rate: 30\nlength: 40\nsprites:\n"
      "  - name: a\n    start: [0, 0]\n");
  std::ofstream(dir_ / "virtual.cameramodel") << "cameras:\n  - name: cam0\n";  // a station config
  r = testing::RunSpritestation("animate " + spec + " --out " + seq);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(spec + ":1: camera: " + (dir_ / "virtual.cameramodel") + ": "),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(seq));

  // The command line's budget is bounded as the spec's is, before the camera is read.
  r = testing::RunSpritestation("animate " + spec + " --out " + seq + " --time-budget 1e300");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("time_budget_seconds: must be at most 86400 seconds (a day), got 1e+300"),
            std::string::npos)
      << r.output;
  r = testing::RunSpritestation("animate " + spec + " --out " + seq + " --max-turns 0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--max-turns"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ss
