// The articulated figure: its skeleton holds its proportions through every pose,
// the arm poses look like Y, M, C and A, the two builds perform the same
// timeline, and the 2-D joint truth lies on the rendered figure.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include <opencv2/imgcodecs.hpp>

#include "synth/directors.h"
#include "synth/figure.h"
#include "synth/studio_session.h"
#include "tests/support/test_support.h"
#include "tests/synth/synth_csv.h"

namespace ss::synth {
namespace {

namespace fs = std::filesystem;

enum {
  kHead,
  kNeck,
  kShoulderL,
  kElbowL,
  kWristL,
  kShoulderR,
  kElbowR,
  kWristR,
  kPelvis,
  kHipL,
  kKneeL,
  kAnkleL,
  kHipR,
  kKneeR,
  kAnkleR
};

std::vector<Eigen::Vector3d> Pose(const FigureBuild& b, ArmPose arms, double walking = 0,
                                  double phase = 0) {
  FigureState s;
  s.to = arms;
  s.blend = 1.0;
  s.walking = walking;
  s.gait_phase = phase;
  return FigureJoints(b, s);
}

TEST(Figure, LimbLengthsHoldInEveryPoseAndTheFeetStayDown) {
  for (int variant : {0, 1}) {
    const FigureBuild b = FigureBuildFor(variant);
    for (ArmPose arms : {ArmPose::kRest, ArmPose::kY, ArmPose::kM, ArmPose::kC, ArmPose::kA}) {
      for (double phase : {0.0, 0.3, 0.7}) {
        const auto j = Pose(b, arms, arms == ArmPose::kRest ? 1.0 : 0.0, phase);
        ASSERT_EQ(j.size(), FigureJointNames().size());
        EXPECT_NEAR((j[kElbowL] - j[kShoulderL]).norm(), b.upper_arm_m, 1e-9);
        EXPECT_NEAR((j[kWristR] - j[kElbowR]).norm(), b.forearm_m, 1e-9);
        EXPECT_NEAR((j[kKneeL] - j[kHipL]).norm(), (j[kAnkleL] - j[kKneeL]).norm(), 1e-9);
        EXPECT_NEAR(std::min(j[kAnkleL].z(), j[kAnkleR].z()), 0.08 * b.height_m / 1.75, 1e-9);
      }
    }
  }
}

TEST(Figure, ArmPosesSpellYMCA) {
  const FigureBuild b = FigureBuildFor(0);
  const auto rest = Pose(b, ArmPose::kRest), y = Pose(b, ArmPose::kY), m = Pose(b, ArmPose::kM),
             c = Pose(b, ArmPose::kC), a = Pose(b, ArmPose::kA);
  EXPECT_LT(rest[kWristL].z(), rest[kPelvis].z() + 0.1);  // hanging
  // Y: both hands high and wide apart.
  EXPECT_GT(y[kWristL].z(), y[kHead].z());
  EXPECT_GT((y[kWristL] - y[kWristR]).norm(), 1.0);
  // M: hands on the head.
  EXPECT_LT((m[kWristL] - m[kHead]).norm(), 0.2);
  EXPECT_LT((m[kWristR] - m[kHead]).norm(), 0.2);
  // C: both hands on the figure's left (ground y > 0 at heading 0).
  EXPECT_GT(c[kWristL].y(), 0.3);
  EXPECT_GT(c[kWristR].y(), 0.0);
  EXPECT_GT(c[kWristL].z(), c[kWristR].z() + 0.4);
  // A: hands together above the head.
  EXPECT_LT((a[kWristL] - a[kWristR]).norm(), 0.15);
  EXPECT_GT(a[kWristL].z(), a[kHead].z() + 0.15);
}

TEST(Figure, BothBuildsPerformTheSameTimeline) {
  const Studio studio = MakeStudio(StudioKind::kStage, 4);
  const auto cameras = MakeCameras(studio, 1, 160, 120, 4);
  DirectorOptions o;
  o.seed = 4;
  auto ref = MakeFigureDirector(studio, cameras, o);
  o.figure_variant = 1;
  auto other = MakeFigureDirector(studio, cameras, o);
  FrameSnapshot a, b;
  std::set<std::string> poses;
  for (int f = 0; f < 30 * 30; ++f) {
    ref->Frame(f / 30.0, &a);
    other->Frame(f / 30.0, &b);
    ASSERT_EQ(a.subjects[0].pose, b.subjects[0].pose) << "frame " << f;
    EXPECT_LT((a.subjects[0].position - b.subjects[0].position).norm(), 1e-9);
    EXPECT_FALSE(a.subjects[0].leaves_floor);
    poses.insert(a.subjects[0].pose);
  }
  for (const char* p : {"idle", "walk", "turn", "Y", "M", "C", "A"})
    EXPECT_TRUE(poses.count(p)) << p;
  EXPECT_GT(a.subjects[0].height_m, b.subjects[0].height_m + 0.1);
}

TEST(FigureSession, JointsProjectOntoTheRenderedFigure) {
  ss::testing::ScratchDir dir;
  SynthOptions o;
  o.out_dir = dir / "s";
  o.kind = SynthKind::kFigure;
  o.seconds = 6.0;
  o.fps = 2.0;
  o.width = 320;
  o.height = 240;
  o.cameras = 2;
  o.seed = 9;
  RenderStudioSession(o);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  const auto world = ss::testing::ReadCsv((truth / "joints.csv").string());
  EXPECT_EQ(world.size(), 12u * 15u);
  int checked = 0;
  for (const char* cam : {"cam0", "cam1"}) {
    const auto joints = ss::testing::ReadCsv((truth / cam / "joints.csv").string());
    ASSERT_EQ(joints.size(), 12u * 15u);
    for (const auto& row : joints) {
      const int f = std::stoi(row.at("frame"));
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.png", f);
      const cv::Mat alpha =
          cv::imread((truth / cam / "alpha_s0" / name).string(), cv::IMREAD_UNCHANGED);
      const double x = ss::testing::Num(row, "x"), y = ss::testing::Num(row, "y");
      const int xi = static_cast<int>(std::lround(x)), yi = static_cast<int>(std::lround(y));
      if (xi < 1 || yi < 1 || xi >= alpha.cols - 1 || yi >= alpha.rows - 1) continue;
      double best = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx)
          best = std::max(best, static_cast<double>(alpha.at<uint8_t>(yi + dy, xi + dx)));
      }
      EXPECT_GT(best, 0) << cam << " frame " << f << " " << row.at("name");
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
}

}  // namespace
}  // namespace ss::synth
