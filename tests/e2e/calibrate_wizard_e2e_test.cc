// End to end: `spritestation calibrate wizard` headless on recorded synthetic
// calibration sessions (frames through the replay FrameSource, as a configured
// camera gives them), against the sessions' true camera models.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/camera_model.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::RunSpritestation;
using testing::ScratchDir;

const std::string kWizardBoard = "chessboard:10x7:0.03";
// 320x240 at 8 fps: the director holds each board pose for 0.32 s (2-3 frames);
// the chessboard segment is frames 0-71 (9 s, 12 poses).
constexpr int kWizardChessFrames = 72, kChessPoses = 12;

class WizardEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    auto r = RunSpritestation(
        "--log-level warn synth --out " + *dir_ / "held" +
        " --kind calibration --seconds 20 --fps 8 --size 320x240 --cameras 1 --seed 1");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // The floor board needs 640x480 to be found; a short session reaches the floor at frame 16.
    r = RunSpritestation(
        "--log-level warn synth --out " + *dir_ / "floor" +
        " --kind calibration --seconds 3 --fps 8 --size 640x480 --cameras 1 --seed 5");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static ScratchDir* dir_;
};
ScratchDir* WizardEndToEnd::dir_ = nullptr;

int Count(const nlohmann::json& log, const std::string& event) {
  return static_cast<int>(
      std::count_if(log.begin(), log.end(), [&](const auto& e) { return e["event"] == event; }));
}

TEST_F(WizardEndToEnd, IntrinsicsFromStillViewsMeetTheNumbers) {
  const std::string session = *dir_ / "held";
  const std::string out = *dir_ / "intrinsics";
  // The chessboard segment only: the intrinsics step ends, the ground step is left waiting.
  const auto r = RunSpritestation("--log-level warn calibrate wizard --session " + session +
                                  " --board " + kWizardBoard + " --min-coverage 0.4 --count " +
                                  std::to_string(kWizardChessFrames) + " --out " + out + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const nlohmann::json j = JsonInOutput(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  ASSERT_TRUE(j.contains("intrinsics")) << r.output;
  EXPECT_EQ(j["intrinsics"]["verdict"], "good") << r.output;
  // A bounded number of captures: at most one per still pose, and it stopped once the criteria were
  // met.
  const int captures = Count(j["log"], "capture");
  EXPECT_GE(captures, 10);
  EXPECT_LE(captures, kChessPoses);
  EXPECT_EQ(j["views_captured"].get<int>(), captures);
  EXPECT_EQ(Count(j["log"], "solve"), 1);
  // It said what was missing on the way, and what the next step wants.
  const std::string log = j["log"].dump();
  EXPECT_NE(log.find("hold the board still"), std::string::npos);
  EXPECT_NE(log.find("cover the "), std::string::npos);
  EXPECT_NE(log.find("lay the board flat on the floor"), std::string::npos);
  ASSERT_EQ(j["verdicts"].size(), 1u) << j["verdicts"].dump();
  EXPECT_NE(j["verdicts"][0].get<std::string>().find("ground:"), std::string::npos);

  const CameraModel truth = CameraModel::Read(session + "/truth/cam0.cameramodel");
  const CameraModel solved = CameraModel::Read(out + "/cam0.cameramodel");
  EXPECT_NEAR(solved.intrinsics()[0], truth.intrinsics()[0], 0.002 * truth.intrinsics()[0]);
  EXPECT_NEAR(solved.intrinsics()[1], truth.intrinsics()[1], 0.002 * truth.intrinsics()[1]);
  EXPECT_NEAR(solved.intrinsics()[2], truth.intrinsics()[2], 1.0);
  EXPECT_NEAR(solved.intrinsics()[3], truth.intrinsics()[3], 1.0);
  EXPECT_LT(j["intrinsics"]["rms_px"].get<double>(), 0.3);
  EXPECT_TRUE(std::filesystem::exists(out + "/cam0.coverage.png"));
  EXPECT_TRUE(std::filesystem::exists(out + "/wizard.json"));
}

TEST_F(WizardEndToEnd, TooFewViewsEndWithAVerdictAndNoModel) {
  const std::string out = *dir_ / "few";
  const auto r = RunSpritestation("--log-level warn calibrate wizard --session " + *dir_ / "held" +
                                  " --board " + kWizardBoard + " --count 24 --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("too few views"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no model written"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out + "/cam0.cameramodel"));
}

TEST_F(WizardEndToEnd, AWrongBoardSpecIsNamed) {
  const auto r =
      RunSpritestation("--log-level warn calibrate wizard --session " + *dir_ / "held" +
                       " --board chessboard:12x9:0.03 --count 16 --out " + *dir_ / "wrong");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no board"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(*dir_ / "wrong/cam0.cameramodel"));
}

TEST_F(WizardEndToEnd, GroundAndEnclosureWithKnownIntrinsics) {
  const std::string session = *dir_ / "floor";
  const std::string out = *dir_ / "ground";
  const CameraModel truth = CameraModel::Read(session + "/truth/cam0.cameramodel");
  // The chessboard lies on the floor with its frame at (-W/2, H/2, 1 mm), face up.
  const auto r = RunSpritestation("--log-level warn calibrate wizard --session " + session +
                                  " --board " + kWizardBoard + " --intrinsics " + session +
                                  "/truth/cam0.cameramodel --board-pose -0.15 0.105 0 "
                                  "--board-thickness 0.001 --floor-still-seconds 0.5 --out " +
                                  out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = JsonInOutput(r.output);
  ASSERT_TRUE(j.is_object()) << r.output;
  EXPECT_EQ(j["verdict"], "good");
  const CameraModel posed = CameraModel::Read(out + "/cam0.cameramodel");
  EXPECT_EQ(posed.intrinsics(), truth.intrinsics());
  // The enclosure's 0.3 m board at ~1.5 m: issue 6's 2 mm / 0.1 deg (measured 1.33 mm, 0.051 deg).
  EXPECT_LT((posed.CentreInGround() - truth.CentreInGround()).norm(), 0.002);
  const double angle = Eigen::AngleAxisd(posed.cam_from_ground().rotation *
                                         truth.cam_from_ground().rotation.transpose())
                           .angle() *
                       180 / M_PI;
  EXPECT_LT(angle, 0.1);
  // The green floor (1.2 m x 0.8 m) seen past the boards lying on it; the near wall hides a strip.
  ASSERT_TRUE(j.contains("enclosure")) << r.output;
  const double area = j["enclosure"]["area_m2"].get<double>();
  EXPECT_GT(area, 0.6);
  EXPECT_LT(area, 0.97);
  for (const auto& v : j["enclosure"]["vertices"]) {
    EXPECT_LT(std::abs(v[0].get<double>()), 0.63) << v.dump();
    EXPECT_LT(std::abs(v[1].get<double>()), 0.43) << v.dump();
  }
  EXPECT_TRUE(std::filesystem::exists(out + "/enclosure.yaml"));
  // The written model (read through libmrcal above) round-trips exactly: written
  // again and read back, every number is the same to the bit.
  posed.Write(out + "/again.cameramodel");
  const CameraModel again = CameraModel::Read(out + "/again.cameramodel");
  EXPECT_EQ(again.intrinsics(), posed.intrinsics());
  EXPECT_EQ(again.cam_from_ground().rotation, posed.cam_from_ground().rotation);
  EXPECT_EQ(again.cam_from_ground().translation, posed.cam_from_ground().translation);
  EXPECT_EQ(again.ToText(), posed.ToText());
}

}  // namespace
}  // namespace ss
