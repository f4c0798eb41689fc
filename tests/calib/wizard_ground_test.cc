// The wizard's ground step (issue 41): a board is taken as lying on the floor only after the
// operator's word (when asked for), still for a span of the frames' timestamps, and only when
// its pose is plausible: surrounded by green floor, a camera above the floor looking down at
// it, the still frames agreeing. A board that is not on the floor is never taken and the
// wizard says why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "calib/wizard.h"
#include "core/error.h"
#include "tests/calib/calib_fixtures.h"
#include "tests/support/test_support.h"

namespace ss::calib {
namespace {

using ss::testing::AnyContains;
using ss::testing::CamFromBoardInView;
using ss::testing::RenderBoards;
using ss::testing::ToCalibBoard;
using ss::testing::TrueModel;

constexpr double kFps = 8;

double RotationBetweenDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / M_PI;
}

// One enclosure-studio camera at 640x480 (the floor board needs it) with its true intrinsics
// known, so the wizard starts at the ground step.
struct GroundStudio {
  explicit GroundStudio(uint64_t seed)
      : studio(synth::MakeStudio(synth::StudioKind::kEnclosure, seed)),
        cam(synth::MakeCameras(studio, 1, 640, 480, seed)[0]),
        renderer(cam, studio),
        spec(synth::ChessboardFor(false)),
        texture(spec),
        on_floor(FloorBoardPose(-0.5 * spec.width_m(), 0.5 * spec.height_m(), 0.0, 0.001)) {}
  WizardOptions Options() const {
    WizardOptions o;
    o.board = ToCalibBoard(spec);
    o.detect.exhaustive = false;
    o.ground_from_board = on_floor;
    CameraModel unposed = TrueModel(cam);
    unposed.set_cam_from_ground({});
    o.intrinsics = unposed;
    o.floor_still_s = 0.5;
    return o;
  }
  // The camera's view of the board at `ground_from_board`, without sensor noise; `grey`: the
  // same without colour (a board in a room without green floor).
  cv::Mat Scene(const Rigid3& ground_from_board, bool grey = false) const {
    cv::Mat image = RenderBoards(renderer, {{&texture, ground_from_board}}, 0.0, 0);
    if (grey) {
      cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
      cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
    }
    return image;
  }
  // A board held up before the camera: its centre at the normalized image point (u, v),
  // `depth_m` away, tilted about its axes.
  Rigid3 Held(double u, double v, double depth_m, double tilt_x, double tilt_y) const {
    return cam.cam_from_ground.Inverse() *
           CamFromBoardInView(cam, spec, u, v, depth_m, tilt_x, tilt_y, 0.1);
  }
  synth::Studio studio;
  synth::SynthCamera cam;
  synth::CameraRenderer renderer;
  synth::BoardSpec spec;
  synth::BoardTexture texture;
  Rigid3 on_floor;
};

// Frame `n` of a still scene: the sensor's noise of that frame on top.
cv::Mat Noisy(const cv::Mat& scene, int n) {
  const synth::Sensor sensor(1234, 0, 1.0);
  std::vector<uint8_t> bytes = sensor.Capture(scene, PixelFormat::kBGR8, static_cast<uint64_t>(n));
  return cv::Mat(scene.rows, scene.cols, CV_8UC3, bytes.data()).clone();
}

// Feeds `frames` frames of one still scene at kFps (timestamps from `*n`) while in the ground
// step; the last frame's guidance.
std::vector<std::string> FeedStill(CalibrationWizard& w, const cv::Mat& scene, int frames, int* n) {
  std::vector<std::string> guidance;
  for (int i = 0; i < frames && w.step() == WizardStep::kGround; ++i, ++*n) {
    const WizardFrame f = w.Feed(Noisy(scene, *n), *n, *n / kFps);
    EXPECT_TRUE(f.detected) << "frame " << *n;
    guidance = f.guidance;
  }
  return guidance;
}

std::string Describe(const GroundCheck& c) {
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "ring green %.3f, height %.3f m, axis down %.1f deg, spread %.2f mm %.3f deg",
                c.ring_green, c.height_m, c.axis_down_deg, c.spread_mm, c.spread_deg);
  return buf;
}

// The board lying on the green floor is taken, once still for floor_still_s by the timestamps,
// and the pose meets issue 6's numbers (2 mm / 0.1 deg) on several studio cameras.
TEST(WizardGround, ABoardLyingOnTheFloorIsTakenAndMeetsTheTruth) {
  for (const uint64_t seed : {5, 1, 3, 4}) {
    const GroundStudio s(seed);
    CalibrationWizard w("cam0", 640, 480, s.Options());
    ASSERT_EQ(w.step(), WizardStep::kGround);
    const cv::Mat image = s.Scene(s.on_floor);
    int n = 0;
    // 0.5 s at 8 fps: the 5th frame (t = 0.5 s after the first) ends the span, not the 4th.
    FeedStill(w, image, 4, &n);
    EXPECT_FALSE(w.ground_good()) << "seed " << seed << ": taken before 0.5 s";
    FeedStill(w, image, 1, &n);
    ASSERT_TRUE(w.ground_good()) << "seed " << seed << ": " << w.log().dump();
    ASSERT_TRUE(w.ground_check());
    const GroundCheck& c = *w.ground_check();
    EXPECT_TRUE(c.doubt.empty()) << c.doubt;
    EXPECT_EQ(c.frames, 5);
    EXPECT_NEAR(c.still_s, 0.5, 1e-9);
    const CameraModel posed = *w.posed_model();
    const double centre_mm = (posed.CentreInGround() - s.cam.CentreInGround()).norm() * 1000;
    const double angle_deg =
        RotationBetweenDeg(posed.cam_from_ground().rotation, s.cam.cam_from_ground.rotation);
    std::printf("seed %d floor board: %s; %.2f mm, %.3f deg from the truth\n",
                static_cast<int>(seed), Describe(c).c_str(), centre_mm, angle_deg);
    EXPECT_LT(centre_mm, 2.0) << "seed " << seed;
    EXPECT_LT(angle_deg, 0.1) << "seed " << seed;
  }
}

// With floor_needs_word (the console), a board lying still is not taken before the operator's
// word, however long it lies; after it, the still span starts again.
TEST(WizardGround, TheConsoleWaitsForTheOperatorsWord) {
  const GroundStudio s(5);
  WizardOptions o = s.Options();
  o.floor_needs_word = true;
  CalibrationWizard w("cam0", 640, 480, o);
  const cv::Mat image = s.Scene(s.on_floor);
  int n = 0;
  EXPECT_TRUE(w.waiting_for_word());
  const std::vector<std::string> guidance = FeedStill(w, image, 12, &n);  // 1.5 s
  EXPECT_TRUE(AnyContains(guidance, "then say so")) << ::testing::PrintToString(guidance);
  EXPECT_FALSE(w.ground_good());
  EXPECT_EQ(w.step(), WizardStep::kGround);
  w.BoardOnFloor();
  EXPECT_FALSE(w.waiting_for_word());
  FeedStill(w, image, 4, &n);
  EXPECT_FALSE(w.ground_good()) << "taken before the board was still 0.5 s after the word";
  FeedStill(w, image, 1, &n);
  EXPECT_TRUE(w.ground_good()) << w.log().dump();
  EXPECT_EQ(w.step(), WizardStep::kEnclosure);
  EXPECT_THROW(w.BoardOnFloor(), InputError);  // past the ground step
}

// The word holds floor_word_s by the timestamps: a board that lies still on the floor only after
// that is not taken, the guidance says why, and a new word takes it (issue 41: a word given while
// a camera could not see the floor board once took a board held up a loop later).
TEST(WizardGround, TheWordLapsesWhenNoBoardLiesStillInTime) {
  const GroundStudio s(5);
  WizardOptions o = s.Options();
  o.floor_needs_word = true;
  o.floor_word_s = 2.0;
  CalibrationWizard w("cam0", 640, 480, o);
  const cv::Mat a = s.Scene(s.Held(0.4, 0.5, 0.9, 20, 0)),
                b = s.Scene(s.Held(0.6, 0.5, 0.9, 0, 20));
  int n = 0;
  w.BoardOnFloor();
  // 2.5 s of a board waved about (never still): the word lapses after 2 s
  for (int i = 0; i < 20; ++i, ++n) w.Feed(Noisy(i % 2 ? a : b, n), n, n / kFps);
  EXPECT_TRUE(w.waiting_for_word());
  const std::vector<std::string> guidance = FeedStill(w, s.Scene(s.on_floor), 12, &n);  // 1.5 s
  EXPECT_FALSE(w.ground_good()) << "taken after the word lapsed";
  EXPECT_TRUE(AnyContains(guidance, "within 2 s of the word"))
      << ::testing::PrintToString(guidance);
  EXPECT_NE(w.log().dump().find("board_on_floor_lapsed"), std::string::npos);
  w.BoardOnFloor();
  FeedStill(w, s.Scene(s.on_floor), 5, &n);
  EXPECT_TRUE(w.ground_good()) << w.log().dump();
  // and the rule: the word must outlast the still span
  o.floor_word_s = 0.5;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("floor_word_s"), std::string::npos) << why;
}

// The still span is the timestamps', not the frames': frames 0.02 s apart (a fast camera) need
// 0.2 s of them, not floor_still_frames.
TEST(WizardGround, TheStillSpanIsMeasuredByTimestamps) {
  const GroundStudio s(5);
  WizardOptions o = s.Options();
  o.floor_still_s = 0.2;
  CalibrationWizard w("cam0", 640, 480, o);
  const cv::Mat image = s.Scene(s.on_floor);
  int taken = -1;
  for (int n = 0; n < 40 && taken < 0; ++n) {
    w.Feed(Noisy(image, n), n, n * 0.02);
    if (w.ground_good()) taken = n;
  }
  // 0.2 s after the first frame: frame 10 (11 with the rounding of 10 * 0.02), not the 3rd.
  EXPECT_GE(taken, 10);
  EXPECT_LE(taken, 11);
}

// A board not on the floor is never taken, however still, and the wizard says why: the same
// floor board in a room without green (the replayed hand-held recording of issue 41), and a
// board held up before the camera at several places and tilts. (A board held level with the
// floor 0.8 m before this camera, the green floor all round it behind, passes the checks: ring
// 0.73, the camera 0.64 m high. That is what the console's "board on floor" word is for.)
TEST(WizardGround, ABoardNotOnTheFloorIsNeverTaken) {
  const GroundStudio s(5);
  struct Case {
    const char* what;
    Rigid3 pose;
    bool grey;
  };
  const double deg = M_PI / 180;
  const std::vector<Case> cases = {
      {"on the floor, no green around", s.on_floor, true},
      {"held, no green around", s.Held(0.0, 0.0, 0.5, 20 * deg, -10 * deg), true},
      {"held facing the camera", s.Held(0.0, 0.0, 0.45, 0.0, 0.0), false},
      {"held tilted, left", s.Held(-0.4, 0.2, 0.6, 30 * deg, 20 * deg), false},
      {"held tilted, right", s.Held(0.4, -0.2, 0.55, -25 * deg, -30 * deg), false},
  };
  for (const Case& k : cases) {
    CalibrationWizard w("cam0", 640, 480, s.Options());
    int n = 0;
    // 1.5 s: two still spans of 0.5 s, each checked.
    const std::vector<std::string> guidance = FeedStill(w, s.Scene(k.pose, k.grey), 12, &n);
    ASSERT_TRUE(w.ground_check()) << k.what << ": never checked; " << w.log().dump();
    const GroundCheck& c = *w.ground_check();
    std::printf("%s: %s; %s\n", k.what, Describe(c).c_str(), c.doubt.c_str());
    EXPECT_FALSE(w.ground_good()) << k.what << ": " << Describe(c);
    EXPECT_EQ(w.step(), WizardStep::kGround) << k.what;
    EXPECT_FALSE(c.doubt.empty()) << k.what;
    EXPECT_TRUE(AnyContains(guidance, "doubtful"))
        << k.what << ": " << ::testing::PrintToString(guidance);
    if (k.grey) {
      EXPECT_NE(c.doubt.find("not surrounded by green floor"), std::string::npos) << c.doubt;
    }
    w.Finish();
    ASSERT_EQ(w.verdicts().size(), 1u) << k.what;
    EXPECT_NE(w.verdicts()[0].find("doubtful"), std::string::npos) << w.verdicts()[0];
    EXPECT_FALSE(w.posed_model()) << k.what;
  }
}

// Once done (posed, the floor set), the console's wizard goes on finding the board: the joint
// solve of a rig takes the places a board is held still before this camera and another from
// every step, so a camera posed early is not left out of later ones (issue 41). The command
// line's stops looking.
TEST(WizardGround, DoneGoesOnFindingTheBoardOnlyWhenAsked) {
  const GroundStudio s(5);
  const cv::Mat held = s.Scene(s.Held(0.0, 0.0, 0.6, 0.2, -0.1));
  for (const bool keep : {false, true}) {
    WizardOptions o = s.Options();
    o.detect_when_done = keep;
    CalibrationWizard w("cam0", 640, 480, o);
    int n = 0;
    FeedStill(w, s.Scene(s.on_floor), 5, &n);
    ASSERT_TRUE(w.ground_good()) << w.log().dump();
    w.SetFloorFromPixels({{100, 300}, {540, 300}, {600, 470}, {40, 470}});
    ASSERT_EQ(w.step(), WizardStep::kDone);
    WizardFrame f;
    for (int i = 0; i < 3; ++i, ++n) f = w.Feed(Noisy(held, n), n, n / kFps);
    EXPECT_EQ(f.step, WizardStep::kDone);
    EXPECT_EQ(f.detected, keep) << "detect_when_done " << keep;
    EXPECT_EQ(f.still, keep) << "detect_when_done " << keep;
    if (keep) EXPECT_TRUE(w.last_view().accepted);
    EXPECT_TRUE(w.ground_good()) << "the pose is kept";
  }
}

}  // namespace
}  // namespace ss::calib
