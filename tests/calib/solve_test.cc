#include "calib/solve.h"

#include <gtest/gtest.h>

#include "calib/detect.h"
#include "calib/report.h"
#include "core/error.h"
#include "tests/calib/calib_fixtures.h"
#include "tests/support/test_support.h"

namespace ss::calib {
namespace {

using ss::testing::CalibrationPoses;
using ss::testing::RenderBoards;
using ss::testing::ToCalibBoard;

struct Rig {
  synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 11);
  std::vector<synth::SynthCamera> cams;
  synth::BoardSpec spec = synth::ChessboardFor(false);
  synth::BoardTexture texture{spec};
  explicit Rig(int count) : cams(synth::MakeCameras(studio, count, 640, 480, 11)) {}
};

// Renders and detects `count` views of camera 0; returns views and observations.
void Views(const Rig& rig, int count, std::vector<BoardView>* views,
           std::vector<BoardObservation>* obs) {
  const synth::CameraRenderer renderer(rig.cams[0], rig.studio);
  const auto poses = CalibrationPoses(rig.cams[0], rig.spec, count, 0.5);
  for (int i = 0; i < count; ++i) {
    const Rigid3 ground_from_board = rig.cams[0].cam_from_ground.Inverse() * poses[i];
    const cv::Mat image = RenderBoards(renderer, {{&rig.texture, ground_from_board}}, 1.0, i);
    BoardView v = DetectBoard(ToCalibBoard(rig.spec), image, {}, "view" + std::to_string(i));
    if (v.accepted) obs->push_back({0, i, v.source, v.ids, v.pixels});
    views->push_back(std::move(v));
  }
}

TEST(SolveBoards, RecoversTheTrueIntrinsicsWithMrcal) {
  Rig rig(1);
  std::vector<BoardView> views;
  std::vector<BoardObservation> obs;
  Views(rig, 16, &views, &obs);
  ASSERT_GE(obs.size(), 14u);
  const BoardSpec board = ToCalibBoard(rig.spec);
  const SolveSummary s = SolveBoards(board, {{"cam0", 640, 480}}, obs);
  const auto& truth = rig.cams[0].intrinsics;
  const auto& got = s.models[0].intrinsics();
  EXPECT_EQ(s.models[0].lensmodel(), "LENSMODEL_OPENCV8");
  EXPECT_NEAR(got[0], truth[0], 0.002 * truth[0]);
  EXPECT_NEAR(got[1], truth[1], 0.002 * truth[1]);
  EXPECT_NEAR(got[2], truth[2], 1.0);
  EXPECT_NEAR(got[3], truth[3], 1.0);
  EXPECT_LT(s.rms_px[0], 0.3);
  // Projection through the solved lens agrees with the truth where the views covered the image.
  for (double u : {0.2, 0.5, 0.8}) {
    for (double v : {0.2, 0.5, 0.8}) {
      const Eigen::Vector2d q(639 * u, 479 * v);
      const Eigen::Vector3d ray = rig.cams[0].lens.Unproject(q);
      EXPECT_LT((s.models[0].Project(ray) - q).norm(), 1.0) << u << "," << v;
    }
  }
  // The uncertainty is finite and small, and the truth lies within a few sigma of it.
  ASSERT_EQ(s.intrinsics_stdev[0].size(), 12u);
  EXPECT_GT(s.intrinsics_stdev[0][0], 0.0);
  EXPECT_LT(std::abs(got[0] - truth[0]), 6 * s.intrinsics_stdev[0][0] + 0.05);
  const double centre = ProjectionStdev(s, board, 0, {320, 240}, 0.5);
  EXPECT_GT(centre, 0.0);
  EXPECT_LT(centre, 0.5);

  // The report: a good verdict, and both plots written.
  const CameraReport r = MakeCameraReport(board, s, 0, views);
  EXPECT_GT(r.coverage, 0.3);
  EXPECT_GT(r.max_tilt_deg, 20.0);
  ss::testing::ScratchDir dir;
  WriteResidualPlot(dir / "res.png", s, 0);
  WriteCoverageMap(dir / "cov.png", s, 0, {});
  EXPECT_TRUE(std::filesystem::file_size(dir / "res.png") > 1000);
  EXPECT_TRUE(std::filesystem::file_size(dir / "cov.png") > 1000);
  // The model round-trips through libmrcal's text exactly.
  s.models[0].Write(dir / "cam0.cameramodel");
  const CameraModel back = CameraModel::Read(dir / "cam0.cameramodel");
  EXPECT_EQ(back.intrinsics(), s.models[0].intrinsics());
}

TEST(SolveBoards, TooFewViewsGiveAVerdictNotATrustedModel) {
  Rig rig(1);
  std::vector<BoardView> views;
  std::vector<BoardObservation> obs;
  Views(rig, 4, &views, &obs);
  ASSERT_GE(obs.size(), 3u);
  const BoardSpec board = ToCalibBoard(rig.spec);
  const SolveSummary s = SolveBoards(board, {{"cam0", 640, 480}}, obs);
  const CameraReport r = MakeCameraReport(board, s, 0, views);
  EXPECT_FALSE(r.good);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_NE(r.reasons[0].find("too few views"), std::string::npos) << r.reasons[0];
}

TEST(SolveBoards, FrontalViewsOnlyGiveAVerdictNotATrustedModel) {
  // Degenerate for intrinsics: the board always square to the camera.
  Rig rig(1);
  const synth::CameraRenderer renderer(rig.cams[0], rig.studio);
  const BoardSpec board = ToCalibBoard(rig.spec);
  std::vector<BoardView> views;
  std::vector<BoardObservation> obs;
  const double places[][2] = {{-0.5, -0.4}, {0.5, -0.4}, {-0.5, 0.4}, {0.5, 0.4},
                              {0, 0},       {0, -0.5},   {0, 0.5},    {-0.6, 0}};
  int i = 0;
  for (const auto& p : places) {
    const Rigid3 cam_from_board =
        ss::testing::CamFromBoardInView(rig.cams[0], rig.spec, p[0], p[1], 0.5, 0, 0, 0.05 * i);
    const cv::Mat image = RenderBoards(
        renderer, {{&rig.texture, rig.cams[0].cam_from_ground.Inverse() * cam_from_board}}, 1.0, i);
    BoardView v = DetectBoard(board, image, {}, "frontal" + std::to_string(i));
    if (v.accepted) obs.push_back({0, i, v.source, v.ids, v.pixels});
    views.push_back(std::move(v));
    ++i;
  }
  ASSERT_GE(obs.size(), 6u);
  SolveOptions fast;
  fast.compute_covariance = false;
  const SolveSummary s = SolveBoards(board, {{"cam0", 640, 480}}, obs, fast);
  VerdictOptions verdict;
  verdict.min_views = 6;
  verdict.min_coverage = 0.2;
  const CameraReport r = MakeCameraReport(board, s, 0, views, verdict);
  EXPECT_FALSE(r.good);
  EXPECT_LT(r.max_tilt_deg, 10.0);
  bool named = false;
  for (const auto& reason : r.reasons)
    named = named || reason.find("tilt the board more") != std::string::npos;
  EXPECT_TRUE(named) << ::testing::PrintToString(r.reasons);
}

TEST(SolveBoards, BadInputIsNamed) {
  const BoardSpec board = ParseBoardSpec("chessboard:10x7:0.03");
  EXPECT_THROW(SolveBoards(board, {{"cam0", 640, 480}}, {}), InputError);
  BoardObservation tiny{0, 0, "v", {0, 1}, {{1, 1}, {2, 2}}};
  EXPECT_THROW(SolveBoards(board, {{"cam0", 640, 480}}, {tiny}), InputError);
  SolveOptions bad;
  bad.lensmodel = "LENSMODEL_NOPE";
  EXPECT_THROW(SolveBoards(board, {{"cam0", 640, 480}}, {}, bad), InputError);
}

}  // namespace
}  // namespace ss::calib
