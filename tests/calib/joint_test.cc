// Issue 41: two synthetic cameras, a board moved in view of both, then lying on the floor. Each
// camera's pose relative to the other solved jointly (one mrcal problem) and one by one (each
// camera's own intrinsics and its own floor board), against the truth.
#include "calib/joint.h"

#include <cstdio>

#include <gtest/gtest.h>

#include "calib/detect.h"
#include "calib/ground.h"
#include "calib/solve.h"
#include "core/error.h"
#include "tests/calib/calib_fixtures.h"

namespace ss::calib {
namespace {

using ss::testing::RenderBoards;
using ss::testing::Rot;
using ss::testing::ToCalibBoard;

BoardView Fake(int n) {
  BoardView v;
  v.accepted = true;
  v.source = "view " + std::to_string(n);
  v.ids = {0, 1, 2, 3};
  v.pixels = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  return v;
}

TEST(SimultaneousObservations, PairsViewsWithinHalfAFrame) {
  // 30 fps: cam1 lags cam0 by 5 ms; cam0's view at 0.2 s has no partner; cam1 twice near 0.1 s.
  const std::vector<TimedView> views = {
      {0, 0.000, Fake(0)}, {1, 0.005, Fake(1)},  {0, 0.100, Fake(2)},
      {1, 0.104, Fake(3)}, {1, 0.1045, Fake(4)}, {0, 0.200, Fake(5)},
      {2, 0.301, Fake(6)}, {1, 0.300, Fake(7)},  {0, 0.2995, Fake(8)}};
  const std::vector<BoardObservation> obs = SimultaneousObservations(views, 0.5 / 30, 7);
  ASSERT_EQ(obs.size(), 7u);
  EXPECT_EQ(obs[0].frame, 7);
  EXPECT_EQ(obs[1].frame, 7);
  EXPECT_EQ(obs[2].source, "view 2");
  EXPECT_EQ(obs[3].source, "view 3");  // the nearer of cam1's two
  EXPECT_EQ(obs[3].frame, 8);
  for (size_t i = 4; i < 7; ++i) EXPECT_EQ(obs[i].frame, 9);
}

TEST(SimultaneousObservations, BoardsStillInBothMeetAcrossFrames) {
  // Each camera's wizard processes other frames of a board held still: cam0 saw it still from
  // 1.0 to 1.25 s, cam1 from 1.3 to 1.5 s; within half a frame (1/60 s) they do not meet, with
  // cam1's still span starting at 1.2 s they do.
  TimedView a{0, 1.25, Fake(0), 1.0}, b{1, 1.5, Fake(1), 1.3};
  EXPECT_TRUE(SimultaneousObservations({a, b}, 0.5 / 30).empty());
  b.start_s = 1.2;
  const std::vector<BoardObservation> obs = SimultaneousObservations({a, b}, 0.5 / 30);
  ASSERT_EQ(obs.size(), 2u);
  EXPECT_EQ(obs[0].frame, obs[1].frame);
}

TEST(PoseRigFrom, CarriesOnePoseThroughTheRig) {
  JointRig rig;
  const Rigid3 c1_from_c0{Rot(0.1, -0.2, 0.3), {0.5, 0.1, -0.2}};
  rig.solution.models = {
      CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, {}),
      CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, c1_from_c0)};
  const Rigid3 c1_from_ground{Rot(2.0, 0.1, 0.4), {0.1, 0.2, 1.5}};
  const std::vector<Rigid3> posed = PoseRigFrom(rig, 1, c1_from_ground);
  EXPECT_LT(TranslationMm(posed[1], c1_from_ground), 1e-9);
  EXPECT_LT(TranslationMm(c1_from_c0 * posed[0], c1_from_ground), 1e-9);
  EXPECT_LT(RotationDeg(c1_from_c0 * posed[0], c1_from_ground), 1e-9);
  const PairDisagreement d = CompareRelativePose(c1_from_c0, posed[0], posed[1]);
  EXPECT_LT(d.translation_mm, 1e-9);
  EXPECT_LT(d.floor_point_mm, 1e-9);
  EXPECT_THROW(PoseRigFrom(rig, 2, c1_from_ground), InputError);
}

// The enclosure studio of tests/calib/ground_test.cc (FloorScene): 2 cameras ~1.2 m high, the
// 0.7 m chessboard held face-up and tilted above the floor in `frames` places, then lying on it.
struct RigFootage {
  synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 21);
  std::vector<synth::SynthCamera> cams = synth::MakeCameras(studio, 2, 640, 480, 21);
  synth::BoardSpec spec = synth::ChessboardFor(true);
  synth::BoardTexture texture{spec};
  Rigid3 floor_board = FloorBoardPose(-0.33, 0.26, 4.0, 0.001);
  BoardSpec board = ToCalibBoard(spec);
  std::vector<std::vector<BoardView>> own;  // per camera: every accepted held view
  std::vector<TimedView> timed;             // the same, with the time of their frame
  std::vector<BoardView> floor;             // per camera: the floor board, 3 frames averaged

  explicit RigFootage(int frames) {
    std::vector<synth::CameraRenderer> renderers;
    for (const auto& cam : cams) renderers.emplace_back(cam, studio);
    own.resize(cams.size());
    const double kDeg = M_PI / 180;
    for (int f = 0; f < frames; ++f) {
      const double tx = ((f % 5) - 2) * 12 * kDeg, ty = (((f * 3) % 5) - 2) * 12 * kDeg;
      const Eigen::Matrix3d r = Rot(tx, ty, f * 25 * kDeg) * FloorBoardPose().rotation;
      const Eigen::Vector3d centre(0.12 * std::sin(f * 1.3), 0.08 * std::cos(f * 1.7),
                                   0.22 + 0.03 * (f % 4));
      const Rigid3 ground_from_board{
          r, centre - r * Eigen::Vector3d(spec.width_m() / 2, spec.height_m() / 2, 0)};
      for (size_t c = 0; c < cams.size(); ++c) {
        const cv::Mat image =
            RenderBoards(renderers[c], {{&texture, ground_from_board}}, 1.0, 200 + f);
        BoardView v = DetectBoard(board, image, {}, cams[c].name + " frame " + std::to_string(f));
        if (!v.accepted) continue;
        own[c].push_back(v);
        // 30 fps, the second camera's clock 4 ms behind.
        timed.push_back({static_cast<int>(c), f / 30.0 + 0.004 * static_cast<double>(c), v});
      }
    }
    for (size_t c = 0; c < cams.size(); ++c) {
      std::vector<BoardView> still;
      still.reserve(3);
      for (int f = 0; f < 3; ++f) {
        still.push_back(
            DetectBoard(board, RenderBoards(renderers[c], {{&texture, floor_board}}, 1.0, 100 + f),
                        {}, cams[c].name + " floor"));
      }
      floor.push_back(AverageStillViews(still));
    }
  }
};

struct Figures {
  double one_mm, one_deg, joint_mm, joint_deg, floor_mm;
};

Figures Measure(const RigFootage& r, const char* label) {
  const std::vector<SolveCamera> cameras = {{"cam0", 640, 480}, {"cam1", 640, 480}};
  const Rigid3 truth = r.cams[1].cam_from_ground * r.cams[0].cam_from_ground.Inverse();
  // One by one: each camera its own intrinsics from its own views, posed by its own floor board.
  std::vector<Rigid3> ground;
  for (size_t c = 0; c < 2; ++c) {
    std::vector<BoardObservation> obs;
    for (size_t i = 0; i < r.own[c].size(); ++i) {
      obs.push_back(
          {0, static_cast<int>(i), r.own[c][i].source, r.own[c][i].ids, r.own[c][i].pixels});
    }
    SolveOptions o;
    o.compute_covariance = false;
    CameraModel model = SolveBoards(r.board, {cameras[c]}, obs, o).models[0];
    model.set_cam_from_ground({});
    ground.push_back(SolveGroundPose(model, r.board, r.floor[c], r.floor_board, cameras[c].name)
                         .cam_from_ground);
  }
  const Rigid3 one = ground[1] * ground[0].Inverse();
  // Jointly: the instants both saw (no view of one camera alone here).
  const std::vector<BoardObservation> shared = SimultaneousObservations(r.timed, 0.5 / 30);
  const JointRig rig = SolveJointRig(r.board, cameras, {{}, {}}, shared, {});
  const Rigid3 joint = rig.solution.models[1].cam_from_ground();
  const PairDisagreement d = CompareRelativePose(joint, ground[0], ground[1]);
  const Figures f{TranslationMm(one, truth), RotationDeg(one, truth), TranslationMm(joint, truth),
                  RotationDeg(joint, truth), d.floor_point_mm};
  std::printf(
      "%s: %d shared instants, boards %.2f / %.2f m away; cam1 relative to cam0 against the "
      "truth: one by one %.2f mm %.3f deg, joint %.2f mm %.3f deg; joint against one by one "
      "%.2f mm %.3f deg, floor point %.2f mm; projection stdev %.3f / %.3f px (centre), "
      "%.3f / %.3f px (worst)\n",
      label, rig.shared_frames, rig.distance_m[0], rig.distance_m[1], f.one_mm, f.one_deg,
      f.joint_mm, f.joint_deg, d.translation_mm, d.rotation_deg, d.floor_point_mm, rig.stdev_px[0],
      rig.stdev_px[1], rig.stdev_worst[0], rig.stdev_worst[1]);
  return f;
}

// Issue 41's goal: 2 mm / 0.05 deg. Measured (bench/RESULTS.md, issue 41): 20 instants, joint
// 0.14 mm 0.027 deg, one by one 2.19 mm 0.052 deg; 10 instants, joint 1.50 mm 0.074 deg.
TEST(SolveJointRig, TwoCamerasAgainstTheTruth) {
  const RigFootage r(20);
  const Figures f = Measure(r, "20 instants");
  EXPECT_LT(f.joint_mm, 2.0);
  EXPECT_LT(f.joint_deg, 0.05);
  // one by one, same footage: within twice the goal (each ground pose carries its own error)
  EXPECT_LT(f.one_mm, 4.0);
  EXPECT_LT(f.one_deg, 0.1);
  EXPECT_LT(f.floor_mm, 3.0);
}

// The floor pose saved with a joint model is solved with the joint intrinsics: the console's
// posed camera had its wizard's pose, from its own intrinsics (here from 5 of its views), which
// the joint model saved beside it does not share. Solved again from the floor board's view, it
// reprojects that view at least as well (the pose that minimises it), and the floor it sees is
// where the true camera sees it (the pose alone is no measure: intrinsics and pose trade off).
TEST(PoseRigFromFloorView, PosesThePosedCameraWithTheJointIntrinsics) {
  const RigFootage r(12);
  const std::vector<SolveCamera> cameras = {{"cam0", 640, 480}, {"cam1", 640, 480}};
  std::vector<BoardObservation> obs;
  for (size_t i = 0; i < 5 && i < r.own[0].size(); ++i)
    obs.push_back(
        {0, static_cast<int>(i), r.own[0][i].source, r.own[0][i].ids, r.own[0][i].pixels});
  SolveOptions o;
  o.compute_covariance = false;
  CameraModel own = SolveBoards(r.board, {cameras[0]}, obs, o).models[0];
  own.set_cam_from_ground({});
  const Rigid3 own_pose =
      SolveGroundPose(own, r.board, r.floor[0], r.floor_board, "cam0").cam_from_ground;
  const JointRig rig =
      SolveJointRig(r.board, cameras, {{}, {}}, SimultaneousObservations(r.timed, 0.5 / 30), o);
  const Rigid3 before = PoseRigFrom(rig, 0, own_pose)[0];
  const std::vector<Rigid3> after =
      PoseRigFromFloorView(rig, 0, r.board, r.floor[0], r.floor_board, "cam0");
  // The floor view's reprojection with the joint model saved at each pose.
  auto rms = [&](const Rigid3& pose) {
    CameraModel m = rig.solution.models[0];
    m.set_cam_from_ground(pose);
    double sum = 0;
    for (size_t i = 0; i < r.floor[0].ids.size(); ++i) {
      const Eigen::Vector3d in_ground = r.floor_board * r.board.Corner(r.floor[0].ids[i]);
      sum += (m.ProjectGround(in_ground) - r.floor[0].pixels[i]).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(r.floor[0].ids.size()));
  };
  // What a sprite's place rests on: the floor as the saved model sees it, against the truth (a
  // grid over the floor's middle, 0.8 m x 0.6 m), in pixels.
  auto floor_px = [&](const Rigid3& pose) {
    CameraModel m = rig.solution.models[0];
    m.set_cam_from_ground(pose);
    double sum = 0;
    int n = 0;
    for (double x = -0.4; x <= 0.4001; x += 0.1) {
      for (double y = -0.3; y <= 0.3001; y += 0.1, ++n) {
        const Eigen::Vector3d p(x, y, 0);
        sum += (m.ProjectGround(p) - r.cams[0].ProjectGround(p)).squaredNorm();
      }
    }
    return std::sqrt(sum / n);
  };
  std::printf(
      "floor view with the joint model: own-intrinsics pose %.4f px, joint %.4f px; "
      "the floor against the truth: %.3f px, joint %.3f px; the pose against the truth: "
      "%.2f mm %.3f deg, joint %.2f mm %.3f deg\n",
      rms(before), rms(after[0]), floor_px(before), floor_px(after[0]),
      TranslationMm(before, r.cams[0].cam_from_ground),
      RotationDeg(before, r.cams[0].cam_from_ground),
      TranslationMm(after[0], r.cams[0].cam_from_ground),
      RotationDeg(after[0], r.cams[0].cam_from_ground));
  EXPECT_LE(rms(after[0]), rms(before) + 1e-6);
  EXPECT_LT(rms(after[0]), 0.2);
  // measured: 0.661 px with the wizard's pose, 0.034 px solved again
  EXPECT_LT(floor_px(after[0]), 0.2);
  EXPECT_LT(floor_px(after[0]), floor_px(before));
  EXPECT_LT(TranslationMm(after[0], r.cams[0].cam_from_ground), 5.0);
  EXPECT_LT(RotationDeg(after[0], r.cams[0].cam_from_ground), 0.2);
  // cam1 through the rig: the joint relative pose, unchanged
  EXPECT_LT(TranslationMm(after[1] * after[0].Inverse(), rig.solution.models[1].cam_from_ground()),
            1e-6);
  EXPECT_THROW(PoseRigFromFloorView(rig, 2, r.board, r.floor[0], r.floor_board), InputError);
}

}  // namespace
}  // namespace ss::calib
namespace ss::calib {
// The figures for other view counts: --gtest_also_run_disabled_tests.
TEST(SolveJointRigStudy, DISABLED_Frames) {
  for (int n : {10, 30}) {
    const RigFootage r(n);
    Measure(r, (std::to_string(n) + " instants").c_str());
  }
}
}  // namespace ss::calib
