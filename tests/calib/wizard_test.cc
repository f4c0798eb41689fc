#include "calib/wizard.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <opencv2/imgproc.hpp>

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

WizardOptions Options(const BoardSpec& board) {
  WizardOptions o;
  o.board = board;
  o.detect.exhaustive = false;
  return o;
}

// One enclosure-studio camera (seed, size) and the chessboard rendered through it.
struct BoardStudio {
  BoardStudio(uint64_t seed, int width, int height)
      : studio(synth::MakeStudio(synth::StudioKind::kEnclosure, seed)),
        cam(synth::MakeCameras(studio, 1, width, height, seed)[0]),
        renderer(cam, studio),
        spec(synth::ChessboardFor(false)),
        texture(spec) {}
  synth::Studio studio;
  synth::SynthCamera cam;
  synth::CameraRenderer renderer;
  synth::BoardSpec spec;
  synth::BoardTexture texture;
};

TEST(CalibrationWizard, NamesWhatIsMissingAndRefusesToSolveWithoutViews) {
  CalibrationWizard w("cam0", 320, 240, Options(ParseBoardSpec("chessboard:10x7:0.03")));
  const auto missing = w.MissingForIntrinsics();
  EXPECT_TRUE(AnyContains(missing, "cover the left edge"));
  EXPECT_TRUE(AnyContains(missing, "cover the top-right corner"));
  EXPECT_TRUE(AnyContains(missing, "tilt the board more"));
  EXPECT_TRUE(AnyContains(missing, "capture more views (0 of 10)"));
  // A grey frame: no board, and the wizard says so.
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  const WizardFrame f = w.Feed(grey, 0);
  EXPECT_FALSE(f.detected);
  EXPECT_FALSE(f.captured);
  EXPECT_TRUE(AnyContains(f.guidance, "show the board to the camera"));
  EXPECT_THROW(w.Feed(cv::Mat(100, 100, CV_8UC3, cv::Scalar(0)), 1), InputError);
  w.Finish();
  EXPECT_TRUE(w.done());
  EXPECT_FALSE(w.intrinsics_good());
  EXPECT_FALSE(w.intrinsics_model());
  ASSERT_FALSE(w.verdicts().empty());
  EXPECT_NE(w.verdicts()[0].find("no board"), std::string::npos) << w.verdicts()[0];
}

TEST(CalibrationWizard, CapturesAStillBoardOnceAndOnlyANewViewAgain) {
  const BoardStudio board_studio(7, 320, 240);
  const auto& [studio, cam, renderer, spec, texture] = board_studio;
  CalibrationWizard w("cam0", 320, 240, Options(ToCalibBoard(spec)));
  // (clang 14, the sanitizer build's, cannot capture structured bindings: a lambda takes members.)
  auto frame_of = [&board_studio](const Rigid3& cam_from_board, int n) {
    return RenderBoards(
        board_studio.renderer,
        {{&board_studio.texture, board_studio.cam.cam_from_ground.Inverse() * cam_from_board}}, 1.0,
        n);
  };
  const Rigid3 a = CamFromBoardInView(cam, spec, -0.4, -0.3, 0.5, 0.4, 0.1, 0.05);
  const Rigid3 b = CamFromBoardInView(cam, spec, 0.4, 0.3, 0.55, -0.3, 0.3, -0.1);
  int n = 0, captured = 0;
  // Pose a held for 4 frames: one capture; again: nothing new; pose b: a second capture.
  for (const Rigid3* pose : {&a, &a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const WizardFrame f = w.Feed(frame_of(*pose, n), n);
      ++n;
      EXPECT_TRUE(f.detected) << n;
      captured += f.captured;
      if (pose == &a && i == 0 && n == 1) {
        EXPECT_TRUE(AnyContains(f.guidance, "hold the board still"));
      }
    }
  }
  EXPECT_EQ(captured, 2);
  EXPECT_EQ(w.views(), 2);
  EXPECT_GT(w.coverage_fraction(), 0.1);
  EXPECT_GT(w.max_tilt_deg(), 15.0);
  // Two views: too few; the verdict says so and there is no model.
  w.Finish();
  EXPECT_FALSE(w.intrinsics_model());
  ASSERT_FALSE(w.verdicts().empty());
  EXPECT_NE(w.verdicts()[0].find("too few views"), std::string::npos) << w.verdicts()[0];
}

// The console solves apart from the camera's thread (issue 41: a solve there blinded the
// camera). A solve begun takes the views captured so far; the wizard goes on capturing and solves
// nothing by itself while it is out, and refuses the commands that would change the solved views.
// Its result is taken as Solve's would be, with the views captured meanwhile kept.
TEST(CalibrationWizard, ASolveBegunLeavesTheWizardCapturing) {
  const BoardStudio board_studio(7, 320, 240);
  WizardOptions o = Options(ToCalibBoard(board_studio.spec));
  o.max_views = 5;  // a 5th capture would solve by itself
  CalibrationWizard w("cam0", 320, 240, o);
  int n = 0;
  auto hold = [&](double x, double y, double distance, double rx, double ry, double rz) {
    const Rigid3 pose =
        CamFromBoardInView(board_studio.cam, board_studio.spec, x, y, distance, rx, ry, rz);
    const cv::Mat image = RenderBoards(
        board_studio.renderer,
        {{&board_studio.texture, board_studio.cam.cam_from_ground.Inverse() * pose}}, 1.0, n);
    bool captured = false;
    for (int i = 0; i < 4; ++i) captured = w.Feed(image, n++).captured || captured;
    return captured;
  };
  ASSERT_TRUE(hold(-0.4, -0.3, 0.5, 0.4, 0.1, 0.05));
  ASSERT_TRUE(hold(0.4, 0.3, 0.55, -0.3, 0.3, -0.1));
  ASSERT_TRUE(hold(0.4, -0.3, 0.5, 0.2, -0.35, 0.1));
  ASSERT_TRUE(hold(-0.4, 0.3, 0.6, -0.35, -0.2, 0.0));
  ASSERT_EQ(w.views(), 4);

  IntrinsicsSolve solve = w.BeginSolve();
  EXPECT_TRUE(w.solve_out());
  EXPECT_EQ(solve.views.size(), 4u);
  EXPECT_THROW(w.BeginSolve(), InputError);
  EXPECT_THROW(w.Solve(), InputError);
  EXPECT_THROW(w.DropLast(), InputError);
  EXPECT_THROW(w.Redo(WizardStep::kIntrinsics), InputError);
  // Two more places while it is out: captured, and the 5th does not solve by itself.
  EXPECT_TRUE(hold(0.0, 0.0, 0.45, 0.1, 0.4, 0.2));
  EXPECT_TRUE(hold(0.3, 0.0, 0.65, 0.45, 0.0, -0.2));
  EXPECT_EQ(w.views(), 6);
  EXPECT_FALSE(w.solution());

  solve.Run();  // where the caller likes: here, the same thread
  ASSERT_TRUE(solve.solution);
  ASSERT_TRUE(solve.report);
  w.EndSolve(std::move(solve));
  EXPECT_FALSE(w.solve_out());
  ASSERT_TRUE(w.solution());
  EXPECT_EQ(w.solution()->observation_frame.size(), 4u);
  EXPECT_EQ(w.views(), 6) << "the views captured during the solve stay";
  EXPECT_LT(w.solution()->rms_px[0], 0.5);
  // Four views are too few to trust: the wizard waits for more, then solves all of them.
  EXPECT_FALSE(w.intrinsics_good());
  EXPECT_TRUE(AnyContains(w.report()->reasons, "too few views")) << w.report()->reasons.size();
  w.Solve();
  EXPECT_EQ(w.solution()->observation_frame.size(), 6u);
}

// The board's still span for a capture is the frames' timestamps' when still_s is given: the
// time its frames cover, n / rate at a steady rate. 0.2 s is 2 frames at 5 fps (at least
// still_frames), 10 at 50 fps; a count of frames from a rate guessed (30 fps: 6 frames) held a
// 5 fps camera's board 1.2 s.
TEST(CalibrationWizard, TheStillSpanForACaptureIsMeasuredByTimestamps) {
  const BoardStudio board_studio(7, 320, 240);
  const Rigid3 a =
      CamFromBoardInView(board_studio.cam, board_studio.spec, -0.4, -0.3, 0.5, 0.4, 0.1, 0.05);
  const cv::Mat image = RenderBoards(
      board_studio.renderer,
      {{&board_studio.texture, board_studio.cam.cam_from_ground.Inverse() * a}}, 1.0, 0);
  WizardOptions o = Options(ToCalibBoard(board_studio.spec));
  o.still_frames = 2;
  o.still_s = 0.2;
  // The frame (from 0) at which a board held still at `fps` is first captured; -1: never.
  auto captured_at = [&](double fps) {
    CalibrationWizard w("cam0", 320, 240, o);
    for (int n = 0; n < 30; ++n) {
      if (w.Feed(image, n, n / fps).captured) return n;
    }
    return -1;
  };
  EXPECT_EQ(captured_at(5.0), 1);   // frames 0 and 1: 0.4 s
  EXPECT_EQ(captured_at(50.0), 9);  // frames 0-9: 0.2 s
  EXPECT_EQ(captured_at(30.0), 5);  // frames 0-5, as the count from the rate (0.2 x 30)
  // Without timestamps the count alone decides, as before.
  CalibrationWizard w("cam0", 320, 240, o);
  int at = -1;
  for (int n = 0; n < 30 && at < 0; ++n) {
    if (w.Feed(image, n).captured) at = n;
  }
  EXPECT_EQ(at, 1);
  // A still span below zero is refused by name.
  o.still_s = -1;
  EXPECT_THROW(CalibrationWizard("cam0", 320, 240, o), InputError);
}

// The enclosure step waits for the empty floor. A frame without the board is not enough: a
// person (here a dark block across the floor) hides part of it, and the floor found then is
// smaller than with the board lying on it, so the wizard keeps waiting.
TEST(CalibrationWizard, TheEnclosureWaitsForAFloorNothingHides) {
  const BoardStudio board_studio(5, 640, 480);
  const auto& [studio, cam, renderer, spec, texture] = board_studio;
  WizardOptions o = Options(ToCalibBoard(spec));
  o.ground_from_board = FloorBoardPose(-0.5 * spec.width_m(), 0.5 * spec.height_m(), 0.0, 0.001);
  CameraModel unposed = TrueModel(cam);
  unposed.set_cam_from_ground({});
  o.intrinsics = unposed;
  o.floor_still_frames = 3;
  CalibrationWizard w("cam0", 640, 480, o);
  int n = 0;
  for (int i = 0; i < 4; ++i, ++n)
    w.Feed(RenderBoards(renderer, {{&texture, o.ground_from_board}}, 1.0, n), n);
  ASSERT_TRUE(w.ground_good());
  ASSERT_EQ(w.step(), WizardStep::kEnclosure);
  for (int i = 0; i < 4; ++i, ++n) {
    cv::Mat hidden = RenderBoards(renderer, {}, 1.0, n);
    cv::rectangle(hidden, cv::Rect(160, 200, 320, 280), cv::Scalar(40, 40, 60), cv::FILLED);
    const WizardFrame f = w.Feed(hidden, n);
    EXPECT_FALSE(f.detected);
  }
  EXPECT_EQ(w.step(), WizardStep::kEnclosure);
  EXPECT_FALSE(w.enclosure_good());
  const auto& log = w.log();
  const bool rejected = std::any_of(
      log.begin(), log.end(), [](const auto& e) { return e["event"] == "enclosure_rejected"; });
  EXPECT_TRUE(rejected) << log.dump();
  // Nor does the operator's "detect the green floor" take the hidden floor: it says why.
  cv::Mat hidden = RenderBoards(renderer, {}, 1.0, n);
  cv::rectangle(hidden, cv::Rect(160, 200, 320, 280), cv::Scalar(40, 40, 60), cv::FILLED);
  try {
    w.DetectFloor(hidden);
    ADD_FAILURE() << "a floor hidden by a person was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("seen with the board lying on it"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(w.enclosure_good());
  for (int i = 0; i < 4 && !w.done(); ++i, ++n) w.Feed(RenderBoards(renderer, {}, 1.0, n), n);
  ASSERT_TRUE(w.enclosure_good()) << log.dump();
  // The true green floor is 1.2 m x 0.8 m; the near wall hides a strip of it from this camera.
  EXPECT_GT(w.floor()->Area(), 0.6);
  EXPECT_LT(w.floor()->Area(), 0.97);
  // Detected by the operator with the board lying on the floor, it is taken.
  w.DetectFloor(RenderBoards(renderer, {{&texture, o.ground_from_board}}, 1.0, n));
  EXPECT_GT(w.floor()->Area(), 0.6);
}

}  // namespace
}  // namespace ss::calib
