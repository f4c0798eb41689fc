// The rough camera of `import` (import/rough_camera.h): where it looks, and the floor it sees.
#include "import/rough_camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace ss {
namespace {

TEST(RoughCamera, ItsOpticalAxisMeetsTheFloorWhereItsTiltSays) {
  const CameraModel m = RoughCameraModel({6.5, 22, 50}, 768, 576);
  EXPECT_EQ(m.lensmodel(), "LENSMODEL_PINHOLE");
  EXPECT_NEAR(m.CentreInGround().z(), 6.5, 1e-12);
  // fx from the field of view: half the width over tan(hfov / 2).
  EXPECT_NEAR(m.intrinsics()[0], 384 / std::tan(25 * M_PI / 180), 1e-9);
  // The image centre looks down 22 degrees along +y: it meets the floor 6.5 / tan(22 deg) ahead.
  const auto hit = IntersectGround(m.RayInGround({383.5, 287.5}));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->x(), 0, 1e-9);
  EXPECT_NEAR(hit->y(), 6.5 / std::tan(22 * M_PI / 180), 1e-9);
  // Right in the image is +x on the floor; lower in the image is nearer.
  EXPECT_GT(m.ProjectGround({1, hit->y(), 0}).x(), 383.5);
  EXPECT_GT(m.ProjectGround({0, hit->y() - 1, 0}).y(), 287.5);
}

TEST(RoughCamera, RefusesACameraThatSeesNoFloorNamingTheFlag) {
  EXPECT_THROW(RoughCameraModel({3, -40, 60}, 640, 480), InputError);
  try {
    RoughCameraModel({0, 20, 60}, 640, 480);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--camera-height"), std::string::npos) << e.what();
  }
  std::string why;
  EXPECT_FALSE((RoughCamera{3, 20, 200}).IsValid(&why));
  EXPECT_NE(why.find("--hfov"), std::string::npos);
}

TEST(VisibleFloor, HoldsWhatTheCameraSeesOutToTheRange) {
  const CameraModel m = RoughCameraModel({6.5, 22, 50}, 768, 576);
  const GroundPolygon floor = VisibleFloor(m, 30);
  ASSERT_TRUE(floor.IsSimple());
  const double ahead = 6.5 / std::tan(22 * M_PI / 180);  // 16.1 m, the image centre
  EXPECT_TRUE(floor.Contains({0, ahead}));
  EXPECT_FALSE(floor.Contains({0, 31}));       // beyond the range
  EXPECT_FALSE(floor.Contains({0, 5}));        // below the bottom row (it sees from ~11 m)
  EXPECT_FALSE(floor.Contains({-20, ahead}));  // outside the field of view
  for (const Eigen::Vector2d& v : floor.vertices()) {
    EXPECT_LE(v.norm(), 30 + 1e-6);
    // Every vertex is seen by a pixel inside the image.
    const Eigen::Vector2d px = m.ProjectGround({v.x(), v.y(), 0});
    EXPECT_GE(px.x(), -1e-6);
    EXPECT_LE(px.x(), 767 + 1e-6);
    EXPECT_GE(px.y(), -1e-6);
    EXPECT_LE(px.y(), 575 + 1e-6);
  }
}

}  // namespace
}  // namespace ss
