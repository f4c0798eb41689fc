// The bank's billboard scale (pipeline/run/bank_scale.h, docs/pipeline.md "The bank's scale").
#include "pipeline/run/bank_scale.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ss {
namespace {

// A pinhole camera at `centre` looking at `target`.
CameraModel LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double f,
                   int width, int height) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x;
  cam_from_ground.rotation.row(1) = z.cross(x);
  cam_from_ground.rotation.row(2) = z;
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  return CameraModel("LENSMODEL_PINHOLE", {f, f, (width - 1) / 2.0, (height - 1) / 2.0}, width,
                     height, cam_from_ground);
}

// The billboard height of an upright subject `h` metres tall at scale s (Rectifier::Rectify).
int BillboardHeight(double h, double s) { return static_cast<int>(std::ceil((h + 0.01) * s)) + 1; }

const GroundPolygon kEnclosure({{-0.6, -0.4}, {0.6, -0.4}, {0.6, 0.4}, {-0.6, 0.4}});
const GroundPolygon kStage({{-2, -1.5}, {2, -1.5}, {2, 1.5}, {-2, 1.5}});

TEST(BankScale, AnAnimalEnclosureGetsItsFinestCamerasResolution) {
  // Two 640x480 cameras 1.4 and 2 m from the floor's centre, looking down at it.
  const CameraModel near = LookAt({0, -0.9, 1.1}, {0, 0, 0}, 560, 640, 480);
  const CameraModel far = LookAt({1.3, 0, 1.5}, {0, 0, 0}, 560, 640, 480);
  BankScaleInputs in;
  in.models = {&near, &far};
  in.floor = kEnclosure;
  const BankScale s = ChooseBankScale(in);
  const double finest =
      std::max(SeenFloorPixelsPerMetre(near, kEnclosure), SeenFloorPixelsPerMetre(far, kEnclosure));
  EXPECT_GT(finest, 300);  // f / distance = 400, foreshortened along the view
  // Looking at the floor's centre, the typical resolution is near the centre's.
  EXPECT_NEAR(SeenFloorPixelsPerMetre(near, kEnclosure), FloorPixelsPerMetre(near, kEnclosure),
              0.1 * FloorPixelsPerMetre(near, kEnclosure));
  EXPECT_LE(s.px_per_m, finest);
  EXPECT_GT(s.px_per_m, 0.95 * finest);  // only rounded down to two digits
  EXPECT_EQ(s.px_per_m, std::floor(s.px_per_m / 10) * 10);
  EXPECT_NE(s.why.find("auto"), std::string::npos) << s.why;
}

TEST(BankScale, AWideViewOverALargeSquareGetsTheResolutionItsSubjectsAreSeenAt) {
  // A 768x576 camera 6.5 m up over a 30 m x 30 m square (vtest.avi's street scene, docs/import.md):
  // the square's centre is 17 m off, where a person is ~40 px tall, but most of the image sees
  // the square nearer than that, where people are seen at up to twice the resolution.
  const CameraModel cam = LookAt({0, 0, 6.5}, {0, 16, 0}, 820, 768, 576);
  const GroundPolygon square({{-15, 2}, {15, 2}, {15, 32}, {-15, 32}});
  const double centre = FloorPixelsPerMetre(cam, square);
  const double typical = SeenFloorPixelsPerMetre(cam, square);
  EXPECT_GT(typical, 1.3 * centre) << "centre " << centre << " px/m";
  BankScaleInputs in;
  in.models = {&cam};
  in.floor = square;
  const BankScale s = ChooseBankScale(in);
  EXPECT_LE(s.px_per_m, typical);
  EXPECT_GT(s.px_per_m, 0.9 * typical) << s.why;
  // The floor right below the image's bottom edge is seen finer still: the median is no maximum.
  const Eigen::Vector2d bottom(384, 560);
  const Eigen::Vector3d g = *IntersectGround(cam.RayInGround(bottom));
  const double near_px_per_m =
      (cam.ProjectGround(g + Eigen::Vector3d(0, 0.01, 0)) - cam.ProjectGround(g)).norm() / 0.01;
  EXPECT_LT(s.px_per_m, near_px_per_m);
}

TEST(BankScale, AHighResolutionStageIsCappedSoAnythingSeenWholeFits) {
  // A 1920x1080 camera 4.5 m in front of a 4 m x 3 m stage at 1.6 m: it sees ~400 px/m of floor,
  // so a standing person would be ~700 px tall at its own resolution, over the 512 px limit.
  const CameraModel cam = LookAt({0, -4.5, 1.6}, {0, 0, 0.8}, 1400, 1920, 1080);
  BankScaleInputs in;
  in.models = {&cam};
  in.floor = kStage;
  const BankScale s = ChooseBankScale(in);
  const double tallest = TallestVisibleM(cam, kStage);
  EXPECT_GT(tallest, 1.9) << "a person is seen whole somewhere on the stage";
  EXPECT_LT(s.px_per_m, FloorPixelsPerMetre(cam, kStage));
  EXPECT_LE(BillboardHeight(tallest, s.px_per_m), 512) << s.why;
  EXPECT_LE(BillboardHeight(1.8, s.px_per_m), 512);
  EXPECT_GT(BillboardHeight(tallest, s.px_per_m), 450) << "capped, not cut down further: " << s.why;
}

TEST(BankScale, ABankThatHoldsSpritesKeepsItsScale) {
  const CameraModel cam = LookAt({0, -0.9, 1.1}, {0, 0, 0}, 560, 640, 480);
  BankScaleInputs in;
  in.models = {&cam};
  in.floor = kEnclosure;
  in.bank_path = "/b/station.bank";
  in.bank_scales = {800};
  EXPECT_EQ(ChooseBankScale(in).px_per_m, 800);  // auto
  in.configured = 800;
  EXPECT_EQ(ChooseBankScale(in).px_per_m, 800);
  in.configured = 500;
  try {
    ChooseBankScale(in);
    FAIL() << "a configured scale other than the bank's is refused";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pipeline.px_per_m"), std::string::npos) << what;
    EXPECT_NE(what.find("500"), std::string::npos) << what;
    EXPECT_NE(what.find("800"), std::string::npos) << what;
    EXPECT_NE(what.find("/b/station.bank"), std::string::npos) << what;
  }
  in.configured = 0;
  in.bank_scales = {400, 800};
  EXPECT_THROW(ChooseBankScale(in), InputError);
}

TEST(BankScale, AConfiguredNumberOverridesForAnEmptyBank) {
  const CameraModel cam = LookAt({0, -0.9, 1.1}, {0, 0, 0}, 560, 640, 480);
  BankScaleInputs in;
  in.models = {&cam};
  in.floor = kEnclosure;
  in.configured = 500;
  EXPECT_EQ(ChooseBankScale(in).px_per_m, 500);
}

TEST(BankScale, AutoNeedsACameraThatSeesTheFloor) {
  const CameraModel away = LookAt({0, -0.9, 1.1}, {0, -3, 1.5}, 560, 640, 480);
  BankScaleInputs in;
  in.models = {&away};
  in.floor = kEnclosure;
  EXPECT_EQ(FloorPixelsPerMetre(away, kEnclosure), 0);
  EXPECT_THROW(ChooseBankScale(in), InputError);
}

}  // namespace
}  // namespace ss
