#include "pipeline/filter/usability.h"

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace ss {
namespace {

// A pinhole camera 1 m above the floor origin looking straight down... tilted a little,
// so that the 0.6 x 0.4 m floor fills the middle of a 640x480 image.
CameraModel CameraLookingDown() {
  Rigid3 cam_from_ground;
  cam_from_ground.rotation << 1, 0, 0, 0, -1, 0, 0, 0,
      -1;  // x right, y down the image = -y ground, z down
  cam_from_ground.translation = Eigen::Vector3d(0, 0, 1.0);
  return CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, cam_from_ground);
}

GroundPolygon FloorUnderIt() {
  return GroundPolygon({{-0.3, -0.2}, {0.3, -0.2}, {0.3, 0.2}, {-0.3, 0.2}});
}

TEST(FloorMask, MarksExactlyThePixelsThatSeeTheFloor) {
  const CameraModel cam = CameraLookingDown();
  const FloorMask floor(cam, FloorUnderIt(), {});
  // 0.6 m at 1 m and f = 500 is 300 px wide, 200 px high, centred.
  const cv::Rect box = cv::boundingRect(floor.mask());
  EXPECT_NEAR(box.width, 300, 2);
  EXPECT_NEAR(box.height, 200, 2);
  EXPECT_NEAR(box.x, 170, 2);
  EXPECT_NEAR(box.y, 140, 2);
}

// A wide-angle, strongly distorted camera 1.6 m up, tilted 35 degrees down, looking at a
// floor with 0.5 m walls: the interpolated rays must mark the same pixels as exact unprojection.
TEST(FloorMask, InterpolatedRaysMatchExactUnprojection) {
  const double tilt = 35.0 * M_PI / 180.0;
  Rigid3 cam_from_ground;
  // Camera looking along ground +y, tilted down: x right, y down, z forward.
  cam_from_ground.rotation << 1, 0, 0,      //
      0, -std::sin(tilt), -std::cos(tilt),  //
      0, std::cos(tilt), -std::sin(tilt);
  const Eigen::Vector3d centre(0.1, -1.2, 1.6);
  cam_from_ground.translation = -cam_from_ground.rotation * centre;
  const CameraModel cam("LENSMODEL_OPENCV8",
                        {420, 425, 322, 236, -0.28, 0.09, 0.001, -0.002, -0.012, 0, 0, 0}, 640, 480,
                        cam_from_ground);
  const GroundPolygon floor({{-2.0, -0.2}, {2.1, -0.3}, {2.2, 3.9}, {-1.9, 4.0}});
  UsabilityOptions options;
  options.wall_height_m = 0.5;
  const FloorMask mask(cam, floor, options);

  // Ground truth: every pixel's own ray.
  cv::Mat exact = cv::Mat::zeros(cam.height(), cam.width(), CV_8U);
  for (int y = 0; y < cam.height(); ++y) {
    for (int x = 0; x < cam.width(); ++x) {
      const Ray ray = cam.RayInGround(Eigen::Vector2d(x, y));
      const auto g = IntersectGround(ray);
      if (!g || !floor.Contains(g->head<2>())) continue;
      const double s = (centre.z() - options.wall_height_m) / centre.z();
      if (!floor.Contains((centre + s * (*g - centre)).head<2>())) continue;
      exact.at<uint8_t>(y, x) = 255;
    }
  }
  const int floor_pixels = cv::countNonZero(exact);
  ASSERT_GT(floor_pixels, 640 * 480 / 4);  // the floor fills a good part of the image
  cv::Mat differ;
  cv::compare(mask.mask(), exact, differ, cv::CMP_NE);
  // Any pixel that differs lies on the exact mask's edge (within one pixel of the other class).
  cv::Mat grown, shrunk, edge;
  cv::dilate(exact, grown, cv::Mat());
  cv::erode(exact, shrunk, cv::Mat());
  cv::compare(grown, shrunk, edge, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differ & ~edge), 0);
  EXPECT_LE(cv::countNonZero(differ), floor_pixels / 1000)
      << "of " << floor_pixels << " floor pixels";
}

// Issue 20: the mask tested every pixel against every edge (~13 s a 640x480 camera at 10,000
// vertices); it now tests the edges near each pixel's ground point (GroundPolygonIndex). The mask
// must be the one the old way gives, pixel for pixel: on a strongly distorted tilted camera and a
// straight-down one, over a star (zigzag edges), a comb (teeth spanning the floor) and a polygon
// on the pixels' ground grid, with and without walls.
TEST(FloorMask, TheIndexedMaskIsTheMaskOfEveryEdge) {
  const double tilt = 35.0 * M_PI / 180.0;
  Rigid3 cam_from_ground;
  cam_from_ground.rotation << 1, 0, 0,      //
      0, -std::sin(tilt), -std::cos(tilt),  //
      0, std::cos(tilt), -std::sin(tilt);
  const Eigen::Vector3d centre(0.1, -1.2, 1.6);
  cam_from_ground.translation = -cam_from_ground.rotation * centre;
  const CameraModel tilted("LENSMODEL_OPENCV8",
                           {420, 425, 322, 236, -0.28, 0.09, 0.001, -0.002, -0.012, 0, 0, 0}, 640,
                           480, cam_from_ground);
  const CameraModel down = CameraLookingDown();

  std::mt19937 rng(20);
  std::vector<std::pair<std::string, GroundPolygon>> floors;
  std::vector<Eigen::Vector2d> star;
  for (int i = 0; i < 120; ++i) {  // radii 1.5-2.2 m around (0, 1.8): zigzag edges
    const double angle = 2 * M_PI * (i + std::uniform_real_distribution<double>(0, 0.9)(rng)) / 120;
    const double r = std::uniform_real_distribution<double>(1.5, 2.2)(rng);
    star.push_back({r * std::cos(angle), 1.8 + r * std::sin(angle)});
  }
  floors.emplace_back("star", GroundPolygon(star));
  std::vector<Eigen::Vector2d> comb = {{-2.0, -0.2}, {2.0, -0.2}};
  for (int k = 29; k >= 0; --k) {  // 30 teeth 4 cm wide, 4 m long, gaps of 4 cm
    const double x0 = -2.0 + 0.08 * k;
    comb.push_back({x0 + 0.04, 3.9});
    comb.push_back({x0, 3.9});
    if (k > 0) {
      comb.push_back({x0, 0.0});
      comb.push_back({x0 - 0.04, 0.0});
    }
  }
  floors.emplace_back("comb", GroundPolygon(comb));
  // Straight down at 1 m, f = 500: pixel x sees ground x = (x - 320) / 500, multiples of 1/500 m:
  // a polygon on that grid puts ground points on (or within rounding of) its vertices and edges.
  floors.emplace_back(
      "grid-aligned",
      GroundPolygon({{-0.3, -0.2}, {0.3, -0.2}, {0.3, 0.2}, {0.0, 0.0}, {-0.3, 0.2}}));

  for (const auto& named : floors) {
    const std::string& name = named.first;
    const GroundPolygon& floor = named.second;  // (not a structured binding: a lambda takes it)
    for (const double wall_height_m : {0.0, 0.5}) {
      for (const CameraModel* cam : {&tilted, &down}) {
        // (The old way is slow: each floor on one camera, the grid on the straight-down one.)
        if ((cam == &down) != (name == "grid-aligned")) continue;
        UsabilityOptions options;
        options.wall_height_m = wall_height_m;
        const FloorMask mask(*cam, floor, options);
        const cv::Mat every_edge = FloorPixels(
            *cam, wall_height_m, [&](const Eigen::Vector2d& p) { return floor.Contains(p); });
        cv::Mat differ;
        cv::compare(mask.mask(), every_edge, differ, cv::CMP_NE);
        EXPECT_EQ(cv::countNonZero(differ), 0) << name << ", walls " << wall_height_m << ", camera "
                                               << (cam == &down ? "down" : "tilted");
        EXPECT_GT(cv::countNonZero(every_edge), 1000) << name;  // the floor is in view
      }
    }
  }
}

// The floor's own tests, seen from straight above with the view's test off (90 keeps every view).
TEST(FloorMask, ChecksBorderFloorAndWalls) {
  const CameraModel cam = CameraLookingDown();
  UsabilityOptions every_view;
  every_view.max_view_angle_deg = 90;
  const FloorMask floor(cam, FloorUnderIt(), every_view);
  const cv::Mat blob(20, 20, CV_8U, cv::Scalar(255));
  EXPECT_EQ(floor.Check(blob, {310, 230}, {0.0, 0.0}), Discard::kNone);
  EXPECT_EQ(floor.Check(blob, {0, 230}, {0.0, 0.0}), Discard::kTouchesBorder);
  EXPECT_EQ(floor.Check(blob, {310, 230}, {0.35, 0.0}), Discard::kLeavesFloor);
  // Silhouette over the floor's edge in the image: touches the wall.
  EXPECT_EQ(floor.Check(blob, {460, 230}, {0.29, 0.0}), Discard::kTouchesWall);
  // A crop whose corner is off the floor but whose silhouette (a thin line) is on it: kept.
  cv::Mat line = cv::Mat::zeros(20, 20, CV_8U);
  line.col(0).setTo(255);
  EXPECT_EQ(floor.Check(line, {450, 230}, {0.25, 0.0}), Discard::kNone);
}

// A person on a 4 m x 4.5 m stage, seen from 4 m in front at 1.6 m: above its lowest 0.3 m it is
// seen against what lies past the floor (the back wall), which is background, not a wall in front.
TEST(FloorMask, ATallSubjectSeenAgainstTheBackgroundIsNotTouchingAWall) {
  const Eigen::Vector3d centre(0, -4, 1.6), target(0, 0, 0.8);
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x;
  cam_from_ground.rotation.row(1) = z.cross(x);
  cam_from_ground.rotation.row(2) = z;
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  const CameraModel cam("LENSMODEL_PINHOLE", {700, 700, 319.5, 239.5}, 640, 480, cam_from_ground);
  const GroundPolygon stage({{-2, -1.5}, {2, -1.5}, {2, 3}, {-2, 3}});
  // A 1.75 m tall, 40 px wide silhouette standing at `at`.
  const auto person = [&](const Eigen::Vector2d& at, cv::Point* offset) {
    const Eigen::Vector2d foot = cam.ProjectGround({at.x(), at.y(), 0.0});
    const Eigen::Vector2d head = cam.ProjectGround({at.x(), at.y(), 1.75});
    *offset = cv::Point(static_cast<int>(foot.x()) - 20, static_cast<int>(head.y()));
    return cv::Mat(static_cast<int>(foot.y() - head.y()), 40, CV_8U, cv::Scalar(255));
  };
  cv::Point offset;
  const cv::Mat middle = person({0.0, 0.5}, &offset);
  EXPECT_EQ(FloorMask(cam, stage, {}).Check(middle, offset, {0.0, 0.5}), Discard::kNone);
  UsabilityOptions every_pixel;  // the check before: any non-floor pixel under the silhouette
  every_pixel.wall_check_height_m = 0;
  EXPECT_EQ(FloorMask(cam, stage, every_pixel).Check(middle, offset, {0.0, 0.5}),
            Discard::kTouchesWall);
  // Against the back wall its legs are seen past the floor too: that is touching the wall.
  const cv::Mat back = person({0.0, 2.95}, &offset);
  EXPECT_EQ(FloorMask(cam, stage, {}).Check(back, offset, {0.0, 2.95}), Discard::kTouchesWall);
}

// A camera 0.6 m up and 0.6 m behind the floor's near edge, tilted `tilt_deg` below the horizontal.
CameraModel TiltedCamera(double height_m, double back_m, double tilt_deg) {
  const double tilt = tilt_deg * std::numbers::pi / 180;
  Rigid3 cam_from_ground;
  cam_from_ground.rotation << 1, 0, 0,      //
      0, -std::sin(tilt), -std::cos(tilt),  //
      0, std::cos(tilt), -std::sin(tilt);
  const Eigen::Vector3d centre(0, -back_m, height_m);
  cam_from_ground.translation = -cam_from_ground.rotation * centre;
  return CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, cam_from_ground);
}

// Issue 38: from straight above an upright billboard is a sliver. The angle at the contact point
// between the floor and the ray to the camera decides, against max_view_angle_deg.
TEST(FloorMask, ASpriteSeenFromTooFarAboveIsRefused) {
  const cv::Mat blob(20, 20, CV_8U, cv::Scalar(255));
  // Straight above: 90 degrees at the origin, atan(1 / 0.25) = 76 at x = 0.25 m. Such a camera
  // films from above and stores floor sprites, which no view is too steep for; kept upright
  // (floor_view_angle_deg 90), its steep views are refused.
  const FloorMask from_above(CameraLookingDown(), FloorUnderIt(), {});
  EXPECT_TRUE(from_above.FilmsFromAbove());
  EXPECT_GT(from_above.median_view_deg(), 75.0);
  EXPECT_EQ(from_above.Check(blob, {310, 230}, {0.0, 0.0}), Discard::kNone);
  EXPECT_EQ(from_above.SteepViewText(), "");
  UsabilityOptions upright;
  upright.floor_view_angle_deg = 90;
  const FloorMask above(CameraLookingDown(), FloorUnderIt(), upright);
  EXPECT_FALSE(above.FilmsFromAbove());
  EXPECT_EQ(above.Check(blob, {310, 230}, {0.0, 0.0}), Discard::kViewTooSteep);
  EXPECT_EQ(above.Check(blob, {430, 230}, {0.25, 0.0}), Discard::kViewTooSteep);
  UsabilityOptions steeper = upright;
  steeper.max_view_angle_deg = 80;
  EXPECT_EQ(
      FloorMask(CameraLookingDown(), FloorUnderIt(), steeper).Check(blob, {430, 230}, {0.25, 0.0}),
      Discard::kNone);
  // The floor's tests come first: off the floor is leaves_floor, however steep.
  EXPECT_EQ(above.Check(blob, {310, 230}, {0.35, 0.0}), Discard::kLeavesFloor);
  // Its shallowest view of the floor is at a corner: atan(1 / hypot(0.3, 0.2)) = 70.1 degrees
  // (measured every 8 px, up to 1.6 cm inside the corner here: 70.9).
  EXPECT_NEAR(above.shallowest_view_deg(), 70.1, 1.0);

  // From 1 m up and 1.5 m behind the floor, looking 35 degrees down, every view is oblique:
  // at the floor's centre atan(1 / 1.5) = 33.7 degrees.
  const FloorMask oblique(TiltedCamera(1.0, 1.5, 35), FloorUnderIt(), {});
  const Eigen::Vector2d centre_px = TiltedCamera(1.0, 1.5, 35).ProjectGround({0, 0, 0});
  const cv::Point at(static_cast<int>(centre_px.x()) - 10, static_cast<int>(centre_px.y()) - 19);
  EXPECT_EQ(oblique.Check(blob, at, {0.0, 0.0}), Discard::kNone);
  // Seen from the far corners down to 1 / hypot(0.3, 1.7) = 30.0 degrees.
  EXPECT_NEAR(oblique.shallowest_view_deg(), 30.0, 1.0);
  EXPECT_FALSE(oblique.FilmsFromAbove());
  EXPECT_NEAR(oblique.median_view_deg(), 33.7, 3.0);
}

TEST(StillnessFilter, DropsOnlyTheTooLongStillPart) {
  StillnessFilter still(0.02, 1.0);
  const int64_t frame_ns = 33'333'333;
  int dropped = 0;
  for (int f = 0; f < 90; ++f) {  // 3 s standing still
    dropped += still.IsStill(1, f * frame_ns, Eigen::Vector2d(0.1, 0.1)) ? 1 : 0;
  }
  EXPECT_NEAR(dropped, 60, 1);  // everything after the first second
  // Walking again: kept at once.
  EXPECT_FALSE(still.IsStill(1, 90 * frame_ns, Eigen::Vector2d(0.2, 0.1)));
  // Walking steadily at 0.1 m/s is never still.
  for (int f = 0; f < 90; ++f) {
    EXPECT_FALSE(still.IsStill(2, f * frame_ns, Eigen::Vector2d(0.1 * f / 30.0, 0)));
  }
}

// Matte shapes (issue 19): hand-made mattes of what a subject and keyed background look like.
cv::Mat Blank(int w, int h) { return cv::Mat::zeros(h, w, CV_8U); }
// Every test off but the ones set.
NoiseOptions Off() {
  NoiseOptions o;
  o.min_solidity = 0;
  o.recover_solidity = 0;
  return o;
}
NoiseOptions Only(double NoiseOptions::*test, double threshold) {
  NoiseOptions o = Off();
  o.*test = threshold;
  return o;
}

TEST(MatteShape, ASolidFigureIsThickSolidAndWhole) {
  cv::Mat a = Blank(60, 120);
  cv::ellipse(a, {30, 60}, {14, 50}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  const MatteShape s = MeasureMatteShape(a, 2.0);
  EXPECT_NEAR(s.area_px, CV_PI * 14.5 * 50.5,
              0.03 * CV_PI * 14.5 * 50.5);  // drawn with its outline
  EXPECT_GT(s.solidity, 0.95);
  EXPECT_GT(s.thick_share, 0.8);
  EXPECT_DOUBLE_EQ(s.largest_share, 1.0);
  EXPECT_DOUBLE_EQ(s.mean_alpha, 1.0);
  cv::Mat rect = Blank(30, 40);
  rect(cv::Rect(5, 5, 20, 30)).setTo(255);
  EXPECT_NEAR(MeasureMatteShape(rect, 2.0).solidity, 1.0, 1e-9);  // the hull counts whole pixels
  NoiseOptions all;
  all.min_thick_share = 0.3;
  all.min_largest_share = 0.6;
  all.min_mean_alpha = 0.5;
  EXPECT_FALSE(IsNoise(s, all));
}

TEST(MatteShape, ScatteredSpecksHaveNoInteriorAndNoLargePart) {
  cv::Mat a = Blank(80, 80);
  for (int y = 4; y < 76; y += 9) {
    for (int x = 4 + (y % 2) * 3; x < 76; x += 8) a(cv::Rect(x, y, 3, 2)).setTo(255);
  }
  const MatteShape s = MeasureMatteShape(a, 2.0);
  EXPECT_EQ(s.thick_share, 0.0);
  EXPECT_LT(s.largest_share, 0.05);
  EXPECT_LT(s.solidity, 0.2);
  EXPECT_TRUE(IsNoise(s, Only(&NoiseOptions::min_thick_share, 0.3)));
  EXPECT_TRUE(IsNoise(s, Only(&NoiseOptions::min_largest_share, 0.5)));
  EXPECT_TRUE(IsNoise(s, NoiseOptions{}));  // the defaults: by solidity
}

TEST(MatteShape, AThinLineHasNoInterior) {
  cv::Mat a = Blank(100, 60);
  cv::line(a, {5, 50}, {95, 10}, cv::Scalar(255), 2);
  const MatteShape s = MeasureMatteShape(a, 2.0);
  EXPECT_GT(s.area_px, 150);
  EXPECT_EQ(s.thick_share, 0.0);
  EXPECT_DOUBLE_EQ(s.largest_share, 1.0);  // whole and fairly convex: only its thinness tells
  EXPECT_TRUE(IsNoise(s, Only(&NoiseOptions::min_thick_share, 0.3)));
  // A thick bar of the same length is not noise by thickness.
  cv::Mat bar = Blank(100, 60);
  cv::line(bar, {5, 50}, {95, 10}, cv::Scalar(255), 12);
  EXPECT_GT(MeasureMatteShape(bar, 2.0).thick_share, 0.4);
}

TEST(MatteShape, ARingIsWholeButNotSolid) {
  cv::Mat a = Blank(100, 100);
  cv::circle(a, {50, 50}, 40, cv::Scalar(255), 2);
  const MatteShape s = MeasureMatteShape(a, 2.0);
  EXPECT_DOUBLE_EQ(s.largest_share, 1.0);
  EXPECT_LT(s.solidity, 0.25);
  EXPECT_LT(s.thick_share, 0.1);
  EXPECT_TRUE(IsNoise(s, Only(&NoiseOptions::min_solidity, 0.5)));
  EXPECT_TRUE(IsNoise(s, NoiseOptions{}));
}

TEST(MatteShape, ASoftHazeIsLowInAlpha) {
  cv::Mat a = Blank(60, 60);
  a(cv::Rect(10, 10, 40, 40)).setTo(60);
  a(cv::Rect(25, 25, 6, 6)).setTo(200);
  const MatteShape s = MeasureMatteShape(a, 2.0);
  EXPECT_EQ(s.area_px, 36);
  EXPECT_LT(s.mean_alpha, 0.3);
  EXPECT_TRUE(IsNoise(s, Only(&NoiseOptions::min_mean_alpha, 0.5)));
  EXPECT_FALSE(IsNoise(s, Off()));  // every test off
  EXPECT_EQ(MeasureMatteShape(Blank(10, 10), 2.0).area_px, 0);
  EXPECT_STREQ(DiscardName(Discard::kNoise), "noise");
}

// Keyed background flickers about the threshold: once noise, a subject stays noise until its
// matte is clearly solid again; a subject that was never noise is judged by the threshold alone.
TEST(NoiseFilter, ASubjectStaysNoiseUntilItsMatteRecovers) {
  NoiseFilter f(NoiseOptions{});  // 0.25 to become noise, 0.30 to stop
  const auto shape = [](double solidity) {
    MatteShape s;
    s.solidity = solidity;
    return s;
  };
  f.NextFrame();
  EXPECT_TRUE(f.IsNoise(1, shape(0.20)));
  EXPECT_FALSE(f.IsNoise(2, shape(0.27)));
  f.NextFrame();
  EXPECT_TRUE(f.IsNoise(1, shape(0.27)));   // was noise: 0.27 is not enough
  EXPECT_FALSE(f.IsNoise(2, shape(0.27)));  // was not
  f.NextFrame();
  EXPECT_FALSE(f.IsNoise(1, shape(0.31)));  // recovered
  f.NextFrame();
  EXPECT_FALSE(f.IsNoise(1, shape(0.27)));
  EXPECT_TRUE(f.IsNoise(3, shape(0.10)));
  f.NextFrame();
  f.NextFrame();  // subject 3 unseen for a frame: forgotten
  EXPECT_FALSE(f.IsNoise(3, shape(0.27)));
}

}  // namespace
}  // namespace ss
