#include "calib/enclosure.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "synth/renderer.h"
#include "synth/scene.h"
#include "tests/calib/calib_fixtures.h"

namespace ss::calib {
namespace {

using ss::testing::TrueModel;

TEST(FloorPolygon, FromGroundPointsIsCheckedAndNamed) {
  const GroundPolygon p =
      FloorPolygonFromPoints(ParsePointList("-0.6,-0.4 0.6,-0.4 0.6,0.4;-0.6,0.4", "--points"));
  EXPECT_NEAR(p.Area(), 0.96, 1e-12);
  EXPECT_THROW(FloorPolygonFromPoints(ParsePointList("0,0 1,1 1,0 0,1", "--points")),
               InputError);  // crosses itself
  EXPECT_THROW(FloorPolygonFromPoints(ParsePointList("0,0 1,1", "--points")), InputError);
  try {
    ParsePointList("0,0 1;1", "--points");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--points"), std::string::npos);
  }
}

TEST(FloorPolygon, FromPixelsLandsOnTheTrueFloorCorners) {
  const synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 5);
  const synth::SynthCamera cam = synth::MakeCameras(studio, 1, 640, 480, 5)[0];
  const CameraModel model = TrueModel(cam);
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& v : studio.floor.vertices())
    pixels.push_back(cam.ProjectGround({v.x(), v.y(), 0}));
  const GroundPolygon p = FloorPolygonFromPixels(model, pixels);
  ASSERT_EQ(p.vertices().size(), studio.floor.vertices().size());
  for (size_t i = 0; i < pixels.size(); ++i)
    EXPECT_LT((p.vertices()[i] - studio.floor.vertices()[i]).norm(), 1e-6);
  // A pixel above the horizon does not look at the floor.
  EXPECT_THROW(FloorPolygonFromPixels(model, {{320, -5000}, {0, 0}, {10, 10}}), InputError);
}

TEST(FloorPolygon, LargestGreenFloorRegionMatchesTheStudioFloor) {
  const synth::Studio studio = synth::MakeStudio(synth::StudioKind::kEnclosure, 9);
  const synth::SynthCamera cam = synth::MakeCameras(studio, 1, 640, 480, 9)[0];
  const synth::CameraRenderer renderer(cam, studio);
  const GroundPolygon found = FindGreenFloor(TrueModel(cam), renderer.clean_plate());
  EXPECT_TRUE(found.IsSimple());
  // The found polygon is floor (its vertices within 3 cm of it) and covers most
  // of it: the near wall hides a strip of floor from a single camera.
  EXPECT_GT(found.Area(), 0.75 * studio.floor.Area());
  EXPECT_LT(found.Area(), 1.02 * studio.floor.Area());
  int inside = 0;
  for (const auto& v : found.vertices()) inside += studio.floor.SignedDistance(v) > -0.03 ? 1 : 0;
  EXPECT_GE(inside, static_cast<int>(found.vertices().size()) * 9 / 10);
  // The wrong image size is refused.
  cv::Mat small(10, 10, CV_8UC3, cv::Scalar(0, 255, 0));
  EXPECT_THROW(FindGreenFloor(TrueModel(cam), small), InputError);
}

}  // namespace
}  // namespace ss::calib
