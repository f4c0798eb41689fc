#include "calib/detect.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "calib/board.h"
#include "core/error.h"
#include "tests/calib/calib_fixtures.h"

namespace ss::calib {
namespace {

using ss::testing::CamFromBoardInView;
using ss::testing::RenderBoards;
using ss::testing::ToCalibBoard;

struct Scene {
  synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 7);
  synth::SynthCamera cam = synth::MakeCameras(studio, 1, 640, 480, 7)[0];
  synth::CameraRenderer renderer{cam, studio};
};

// Detected corners against the true projections; returns the largest error (px).
double WorstCornerError(const Scene& s, const synth::BoardSpec& spec, const Rigid3& cam_from_board,
                        const BoardView& view) {
  const BoardSpec board = ToCalibBoard(spec);
  double worst = 0;
  for (size_t i = 0; i < view.ids.size(); ++i) {
    const Eigen::Vector2d truth = s.cam.lens.Project(cam_from_board * board.Corner(view.ids[i]));
    worst = std::max(worst, (truth - view.pixels[i]).norm());
  }
  return worst;
}

TEST(BoardSpecParse, AcceptsBothKindsAndNamesErrors) {
  const BoardSpec c = ParseBoardSpec("chessboard:10x7:0.03");
  EXPECT_EQ(c.kind, BoardKind::kChessboard);
  EXPECT_EQ(c.corners_x(), 9);
  EXPECT_EQ(c.corners_y(), 6);
  EXPECT_DOUBLE_EQ(c.square_m, 0.03);
  const BoardSpec a = ParseBoardSpec("charuco:8x6:0.04:0.03:DICT_5X5_100");
  EXPECT_EQ(a.kind, BoardKind::kCharuco);
  EXPECT_EQ(a.dictionary, "DICT_5X5_100");
  EXPECT_EQ(ParseBoardSpec(a.ToString()).ToString(), a.ToString());
  EXPECT_THROW(ParseBoardSpec("chessboard:10:0.03"), InputError);
  EXPECT_THROW(ParseBoardSpec("circles:10x7:0.03"), InputError);
  EXPECT_THROW(ParseBoardSpec("charuco:8x6:0.04:0.05"), InputError);
  EXPECT_THROW(ParseBoardSpec("charuco:8x6:0.04:0.03:DICT_9X9"), InputError);
  try {
    ParseBoardSpec("chessboard:10x7:-1", "--board");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--board"), std::string::npos);
  }
}

TEST(DetectBoard, ChessboardCornersAreSubpixelAndInBoardOrder) {
  Scene s;
  const synth::BoardSpec spec = synth::ChessboardFor(false);
  const synth::BoardTexture texture(spec);
  // Rolled by ~180 degrees and tilted: the detector's own ordering must be normalized.
  for (double roll : {0.1, 3.0}) {
    const Rigid3 cam_from_board = CamFromBoardInView(s.cam, spec, 0.2, -0.1, 0.55, 0.3, -0.2, roll);
    const Rigid3 ground_from_board = s.cam.cam_from_ground.Inverse() * cam_from_board;
    const cv::Mat image = RenderBoards(s.renderer, {{&texture, ground_from_board}}, 1.0, 1);
    const BoardView view = DetectBoard(ToCalibBoard(spec), image, {}, "roll");
    ASSERT_TRUE(view.accepted) << view.rejection;
    EXPECT_EQ(view.ids.size(), 54u);
    EXPECT_LT(WorstCornerError(s, spec, cam_from_board, view), 0.25);
    EXPECT_LT(view.edge_width_px, 3.0);
  }
}

TEST(DetectBoard, CharucoToleratesAPartlyVisibleBoard) {
  Scene s;
  const synth::BoardSpec spec = synth::CharucoFor(false);
  const synth::BoardTexture texture(spec);
  Rigid3 cam_from_board = CamFromBoardInView(s.cam, spec, 0, 0, 0.5, 0.2, 0.25, 0.1);
  // Push the board half out of the left edge of the image.
  cam_from_board.translation.x() -= 0.2;
  const Rigid3 ground_from_board = s.cam.cam_from_ground.Inverse() * cam_from_board;
  const cv::Mat image = RenderBoards(s.renderer, {{&texture, ground_from_board}}, 1.0, 2);
  const BoardView view = DetectBoard(ToCalibBoard(spec), image, {}, "partial");
  ASSERT_TRUE(view.accepted) << view.rejection;
  EXPECT_GT(view.ids.size(), 12u);
  EXPECT_LT(view.ids.size(), static_cast<size_t>(ToCalibBoard(spec).corner_count()));
  EXPECT_LT(WorstCornerError(s, spec, cam_from_board, view), 0.35);
}

TEST(DetectBoard, RejectsWithReasons) {
  Scene s;
  const synth::BoardSpec spec = synth::ChessboardFor(false);
  const synth::BoardTexture texture(spec);
  const BoardSpec board = ToCalibBoard(spec);
  // No board at all.
  const BoardView empty = DetectBoard(board, s.renderer.clean_plate(), {}, "plate");
  EXPECT_FALSE(empty.accepted);
  EXPECT_NE(empty.rejection.find("no chessboard"), std::string::npos) << empty.rejection;
  // Blurred board.
  const Rigid3 cam_from_board = CamFromBoardInView(s.cam, spec, 0, 0, 0.45, 0.1, 0.1, 0);
  const Rigid3 ground_from_board = s.cam.cam_from_ground.Inverse() * cam_from_board;
  cv::Mat sharp = RenderBoards(s.renderer, {{&texture, ground_from_board}}, 0.0, 3), blurred;
  cv::GaussianBlur(sharp, blurred, cv::Size(0, 0), 3.0);
  const BoardView blur = DetectBoard(board, blurred, {}, "blurred");
  EXPECT_FALSE(blur.accepted);
  EXPECT_NE(blur.rejection.find("blurred"), std::string::npos) << blur.rejection;
  // A spec that does not match the board in view.
  const BoardView wrong =
      DetectBoard(ParseBoardSpec("chessboard:8x6:0.03"), sharp, {}, "wrong spec");
  EXPECT_FALSE(wrong.accepted);
  // Too small in the image.
  DetectOptions strict;
  strict.min_area_fraction = 0.9;
  const BoardView small = DetectBoard(board, sharp, strict, "small");
  EXPECT_FALSE(small.accepted);
  EXPECT_NE(small.rejection.find("degenerate"), std::string::npos) << small.rejection;
}

}  // namespace
}  // namespace ss::calib
