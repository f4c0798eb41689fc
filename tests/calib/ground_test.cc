#include "calib/ground.h"

#include <gtest/gtest.h>

#include "calib/detect.h"
#include "calib/solve.h"
#include "core/error.h"
#include "tests/calib/calib_fixtures.h"

namespace ss::calib {
namespace {

using ss::testing::TrueModel;

using ss::testing::RenderBoards;
using ss::testing::Rot;
using ss::testing::ToCalibBoard;

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / M_PI;
}

struct FloorScene {
  synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 21);
  std::vector<synth::SynthCamera> cams = synth::MakeCameras(studio, 2, 640, 480, 21);
  // 0.7 m x 0.49 m, fits the 1.2 m x 0.8 m floor
  synth::BoardSpec spec = synth::ChessboardFor(true);
  synth::BoardTexture texture{spec};
  // 1 mm thick: off the floor for the renderer
  Rigid3 ground_from_board = FloorBoardPose(-0.33, 0.26, 4.0, 0.001);
};

TEST(FloorBoardPose, IsFaceUpOnTheFloor) {
  const Rigid3 g = FloorBoardPose(0.1, 0.2, 30, 0.004);
  EXPECT_NEAR(g.rotation.determinant(), 1.0, 1e-12);
  EXPECT_NEAR((g.rotation.col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 0.0,
              1e-12);  // board z points down
  EXPECT_NEAR((g * Eigen::Vector3d(0, 0, 0) - Eigen::Vector3d(0.1, 0.2, 0.004)).norm(), 0.0, 1e-12);
}

TEST(SolveGroundPose, RecoversEachCameraAndAgreesAcrossCameras) {
  FloorScene s;
  const BoardSpec board = ToCalibBoard(s.spec);
  std::vector<BoardView> views;
  std::vector<CameraModel> models;
  for (size_t c = 0; c < s.cams.size(); ++c) {
    const synth::CameraRenderer renderer(s.cams[c], s.studio);
    // Three noisy frames of the still board, averaged.
    std::vector<BoardView> still;
    for (int f = 0; f < 3; ++f) {
      const cv::Mat image =
          RenderBoards(renderer, {{&s.texture, s.ground_from_board}}, 1.0, 100 + f);
      still.push_back(DetectBoard(board, image, {}, s.cams[c].name));
      ASSERT_TRUE(still.back().accepted) << still.back().rejection;
    }
    const BoardView view = AverageStillViews(still);
    Eigen::Vector2d mean_err = Eigen::Vector2d::Zero();
    double worst_err = 0;
    for (size_t i = 0; i < view.ids.size(); ++i) {
      const Eigen::Vector2d e =
          view.pixels[i] - s.cams[c].ProjectGround(s.ground_from_board * board.Corner(view.ids[i]));
      mean_err += e / static_cast<double>(view.ids.size());
      worst_err = std::max(worst_err, e.norm());
    }
    RecordProperty("detect_worst_px_" + s.cams[c].name, std::to_string(worst_err));
    EXPECT_LT(worst_err, 0.3) << "mean " << mean_err.transpose();
    CameraModel unposed = TrueModel(s.cams[c]);
    unposed.set_cam_from_ground({});
    const GroundResult g =
        SolveGroundPose(unposed, board, view, s.ground_from_board, s.cams[c].name);
    const Eigen::Vector3d truth = s.cams[c].CentreInGround();
    RecordProperty("centre_mm_" + s.cams[c].name,
                   std::to_string((g.centre_in_ground - truth).norm() * 1000));
    RecordProperty(
        "angle_deg_" + s.cams[c].name,
        std::to_string(AngleDeg(g.cam_from_ground.rotation, s.cams[c].cam_from_ground.rotation)));
    // Issue 6 asks for 2 mm and 0.1 deg: measured 1.3 / 0.35 mm and 0.048 / 0.015 deg
    // (2-5 mm and 0.12-0.17 deg before the corners were refined with cornerSubPix).
    EXPECT_LT((g.centre_in_ground - truth).norm(), 0.002) << s.cams[c].name;
    EXPECT_NEAR(g.height_m, truth.z(), 0.002);
    EXPECT_LT(AngleDeg(g.cam_from_ground.rotation, s.cams[c].cam_from_ground.rotation), 0.1);
    EXPECT_LT(g.rms_px, 0.3);
    CameraModel posed = unposed;
    posed.set_cam_from_ground(g.cam_from_ground);
    models.push_back(posed);
    views.push_back(view);
  }
  const CrossCheck x =
      CrossReprojection(models[0], views[0], models[1], views[1], s.ground_from_board);
  EXPECT_GT(x.points, 20);
  EXPECT_LT(x.worst_px, 1.0);
}

// The enclosure's small chessboard (0.3 m, squares ~9 px at ~1.5 m) lying on
// the floor, as in a synthetic calibration session. Its corners once carried
// a fixed per-corner bias that averaging still views cannot remove: corners
// from findChessboardCornersSB alone (~0.1 px, rows spread apart) and a 4 x 4
// supersampled board edge (coverage in quarter steps) put the pose 10 mm /
// 0.39 deg (then 2.7 mm / 0.12 deg) from the truth. Issue 6: 2 mm / 0.1 deg.
TEST(SolveGroundPose, SmallFloorBoardMeetsTheIssueNumbers) {
  const synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 5);
  const std::vector<synth::SynthCamera> cams = synth::MakeCameras(studio, 1, 640, 480, 5);
  const synth::BoardSpec spec = synth::ChessboardFor(false);
  const synth::BoardTexture texture{spec};
  const Rigid3 ground_from_board =
      FloorBoardPose(-0.5 * spec.width_m(), 0.5 * spec.height_m(), 0.0, 0.001);
  const BoardSpec board = ToCalibBoard(spec);
  const synth::CameraRenderer renderer(cams[0], studio);
  std::vector<BoardView> still;
  for (int f = 0; f < 3; ++f) {
    const cv::Mat image = RenderBoards(renderer, {{&texture, ground_from_board}}, 1.0, 200 + f);
    still.push_back(DetectBoard(board, image, {}, cams[0].name));
    ASSERT_TRUE(still.back().accepted) << still.back().rejection;
  }
  const BoardView view = AverageStillViews(still);
  ASSERT_EQ(static_cast<int>(view.ids.size()), board.corner_count());
  Eigen::Vector2d mean_err = Eigen::Vector2d::Zero();
  double sum2 = 0;
  for (size_t i = 0; i < view.ids.size(); ++i) {
    const Eigen::Vector2d e =
        view.pixels[i] - cams[0].ProjectGround(ground_from_board * board.Corner(view.ids[i]));
    mean_err += e / static_cast<double>(view.ids.size());
    sum2 += e.squaredNorm();
  }
  const double rms = std::sqrt(sum2 / static_cast<double>(view.ids.size()));
  EXPECT_LT(mean_err.norm(), 0.03) << mean_err.transpose();  // was 0.07 px with SB corners alone
  EXPECT_LT(rms, 0.12);                                      // was 0.16 px
  CameraModel unposed = TrueModel(cams[0]);
  unposed.set_cam_from_ground({});
  const GroundResult g = SolveGroundPose(unposed, board, view, ground_from_board, cams[0].name);
  const double centre_mm = (g.centre_in_ground - cams[0].CentreInGround()).norm() * 1000;
  const double angle_deg = AngleDeg(g.cam_from_ground.rotation, cams[0].cam_from_ground.rotation);
  RecordProperty("corner_rms_px", std::to_string(rms));
  RecordProperty("centre_mm", std::to_string(centre_mm));
  RecordProperty("angle_deg", std::to_string(angle_deg));
  EXPECT_LT(centre_mm, 2.0) << "corner rms " << rms << " px, mean " << mean_err.transpose();
  EXPECT_LT(angle_deg, 0.1);
}

TEST(AverageStillViews, RefusesAMovingBoard) {
  BoardView a, b;
  a.accepted = b.accepted = true;
  a.ids = b.ids = {0, 1, 2, 3};
  a.pixels = {{0, 0}, {10, 0}, {0, 10}, {10, 10}};
  b.pixels = {{5, 0}, {15, 0}, {5, 10}, {15, 10}};
  EXPECT_THROW(AverageStillViews({a, b}), InputError);
  EXPECT_THROW(AverageStillViews({}), InputError);
  const BoardView m = AverageStillViews({a, a});
  EXPECT_EQ(m.ids.size(), 4u);
}

// Two cameras calibrated together from board views they share: the relative
// pose from the joint solve against the truth.
TEST(SolveBoards, JointSolveGivesBothCamerasInOneFrame) {
  FloorScene s;
  const BoardSpec board = ToCalibBoard(s.spec);
  std::vector<BoardObservation> obs;
  std::vector<synth::CameraRenderer> renderers;
  for (const auto& cam : s.cams) renderers.emplace_back(cam, s.studio);
  const double kDeg = M_PI / 180;
  for (int f = 0; f < 10; ++f) {
    // The board held face-up above the floor, tilted and turned.
    const double tx = ((f % 5) - 2) * 12 * kDeg, ty = (((f * 3) % 5) - 2) * 12 * kDeg;
    const Eigen::Matrix3d r = Rot(tx, ty, f * 25 * kDeg) * FloorBoardPose().rotation;
    const Eigen::Vector3d centre(0.12 * std::sin(f * 1.3), 0.08 * std::cos(f * 1.7),
                                 0.22 + 0.03 * (f % 4));
    const Rigid3 ground_from_board{
        r, centre - r * Eigen::Vector3d(s.spec.width_m() / 2, s.spec.height_m() / 2, 0)};
    for (size_t c = 0; c < s.cams.size(); ++c) {
      const cv::Mat image =
          RenderBoards(renderers[c], {{&s.texture, ground_from_board}}, 1.0, 200 + f);
      const BoardView v =
          DetectBoard(board, image, {}, s.cams[c].name + " frame " + std::to_string(f));
      if (v.accepted) obs.push_back({static_cast<int>(c), f, v.source, v.ids, v.pixels});
    }
  }
  ASSERT_GE(obs.size(), 14u);
  SolveOptions options;
  options.compute_covariance = false;
  const SolveSummary sol =
      SolveBoards(board, {{"cam0", 640, 480}, {"cam1", 640, 480}}, obs, options);
  const Rigid3 truth = s.cams[1].cam_from_ground * s.cams[0].cam_from_ground.Inverse();
  const Rigid3 got = sol.models[1].cam_from_ground();  // cam1_from_cam0
  // Measured: 5.3 mm and 0.23 deg (both lenses solved too, from boards ~1.3 m away).
  EXPECT_LT((got.Inverse().translation - truth.Inverse().translation).norm(), 0.01);
  EXPECT_LT(AngleDeg(got.rotation, truth.rotation), 0.4);
  EXPECT_LT(sol.rms_px[0], 0.3);
  EXPECT_LT(sol.rms_px[1], 0.3);
}

}  // namespace
}  // namespace ss::calib
