#include "pipeline/rectify/rectifier.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace ss {
namespace {

// A pinhole camera at height h looking down at the floor origin from distance d along -y.
CameraModel LookAtOrigin(double distance, double height) {
  const Eigen::Vector3d centre(0.0, -distance, height);
  const Eigen::Vector3d target(0.0, 0.0, 0.05);
  const Eigen::Vector3d z = (target - centre).normalized();                  // optical axis
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();  // image right
  const Eigen::Vector3d y = z.cross(x);                                      // image down
  Rigid3 cam_from_ground;
  cam_from_ground.rotation.row(0) = x;
  cam_from_ground.rotation.row(1) = y;
  cam_from_ground.rotation.row(2) = z;
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  return CameraModel("LENSMODEL_PINHOLE", {900, 900, 320, 240}, 640, 480, cam_from_ground);
}

struct Render {
  cv::Mat bgr, alpha, shadow;
  Eigen::Vector2d contact_px;
};

// Renders a flat red rectangle w x h metres standing on the floor at the
// origin, facing the camera, with a dark disc of shadow around its foot.
Render RenderCard(const CameraModel& cam, double w, double h) {
  Render r;
  r.bgr = cv::Mat(cam.height(), cam.width(), CV_8UC3, cv::Scalar(40, 200, 60));
  r.alpha = cv::Mat::zeros(cam.height(), cam.width(), CV_8U);
  r.shadow = cv::Mat::zeros(cam.height(), cam.width(), CV_8U);
  const Eigen::Vector3d c = cam.CentreInGround();
  const Eigen::Vector3d n = Eigen::Vector3d(c.x(), c.y(), 0).normalized();
  const Eigen::Vector3d right(-n.y(), n.x(), 0);
  double lowest_y = -1;
  double lowest_x_sum = 0;
  int lowest_count = 0;
  for (int y = 0; y < cam.height(); ++y) {
    for (int x = 0; x < cam.width(); ++x) {
      const Ray ray = cam.RayInGround(Eigen::Vector2d(x, y));
      const double s = (-ray.origin).dot(n) / ray.direction.dot(n);
      const Eigen::Vector3d p = ray.origin + s * ray.direction;
      if (s > 0 && std::abs(p.dot(right)) <= w / 2 && p.z() >= 0 && p.z() <= h) {
        r.bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(30, 30, 220);
        r.alpha.at<uint8_t>(y, x) = 255;
        if (y > lowest_y) {
          lowest_y = y;
          lowest_x_sum = 0;
          lowest_count = 0;
        }
        if (y == lowest_y) {
          lowest_x_sum += x;
          ++lowest_count;
        }
      } else if (auto g = IntersectGround(ray); g && g->head<2>().norm() < 0.05) {
        r.shadow.at<uint8_t>(y, x) = 200;
      }
    }
  }
  r.contact_px = Eigen::Vector2d(lowest_x_sum / lowest_count, lowest_y + 0.5);
  return r;
}

// The crop an extractor would hand over: the sprite and its shadow plus a few pixels.
struct Crop {
  cv::Mat bgr, alpha, shadow;
  cv::Point offset;
  SpriteView View(const Eigen::Vector2d& contact_px) const {
    return {&bgr, &alpha, &shadow, offset, contact_px};
  }
};
Crop CropOf(const Render& r) {
  cv::Rect box = cv::boundingRect((r.alpha > 0) | (r.shadow > 0));
  box = cv::Rect(box.x - 4, box.y - 4, box.width + 8, box.height + 8) &
        cv::Rect(0, 0, r.bgr.cols, r.bgr.rows);
  return {r.bgr(box), r.alpha(box), r.shadow(box), box.tl()};
}

cv::Rect AlphaBox(const cv::Mat& bgra) {
  cv::Mat alpha;
  cv::extractChannel(bgra, alpha, 3);
  return cv::boundingRect(alpha > 127);
}

TEST(Rectifier, BillboardHasTheSameMetricSizeNearAndFar) {
  const double w = 0.06, h = 0.04;
  const Rectifier rectifier;
  const double s = rectifier.options().px_per_m;
  for (double distance : {0.6, 1.4}) {
    const CameraModel cam = LookAtOrigin(distance, 0.8);
    const Render r = RenderCard(cam, w, h);
    const Crop crop = CropOf(r);
    const auto bb = rectifier.Rectify(cam, crop.View(r.contact_px));
    ASSERT_TRUE(bb.has_value()) << "distance " << distance;
    EXPECT_LT(bb->point_in_ground.head<2>().norm(), 0.003) << "distance " << distance;
    const cv::Rect box = AlphaBox(bb->bgra);
    EXPECT_NEAR(box.width, w * s, 3.0) << "distance " << distance;
    EXPECT_NEAR(box.height, h * s, 3.0) << "distance " << distance;
    // The card's foot sits on the anchor row, centred on the anchor column.
    EXPECT_NEAR(box.y + box.height, bb->anchor_px.y() + 1, 3.0);
    EXPECT_NEAR(box.x + box.width / 2.0, bb->anchor_px.x(), 2.0);
    // The card's colour survives.
    const cv::Vec4b centre = bb->bgra.at<cv::Vec4b>(box.y + box.height / 2, box.x + box.width / 2);
    EXPECT_GT(centre[2], 200);
    EXPECT_LT(centre[1], 60);
    // The shadow disc (radius 5 cm) lands centred in the ground patch.
    const cv::Rect sbox = cv::boundingRect(bb->shadow > 100);
    EXPECT_NEAR(sbox.x + sbox.width / 2.0, (bb->shadow.cols - 1) / 2.0, 4.0);
    EXPECT_NEAR(sbox.width, 0.10 * s, 6.0);
  }
}

TEST(Rectifier, MirrorFlipsContentAndVelocityAcrossTheView) {
  const CameraModel cam = LookAtOrigin(1.0, 0.8);
  Render r = RenderCard(cam, 0.06, 0.04);
  // Paint the card's left half (as the camera sees it) blue.
  const cv::Rect full = cv::boundingRect(r.alpha);
  r.bgr(cv::Rect(full.x, full.y, full.width / 2, full.height))
      .setTo(cv::Scalar(255, 0, 0), r.alpha(cv::Rect(full.x, full.y, full.width / 2, full.height)));
  const Crop crop = CropOf(r);
  const auto bb = Rectifier().Rectify(cam, crop.View(r.contact_px));
  ASSERT_TRUE(bb);
  const Billboard m = Rectifier::Mirror(*bb);
  const cv::Rect box = AlphaBox(bb->bgra);
  const int y = box.y + box.height / 2;
  EXPECT_GT(bb->bgra.at<cv::Vec4b>(y, box.x + 2)[0], 200);  // blue on the left
  EXPECT_GT(m.bgra.at<cv::Vec4b>(y, m.bgra.cols - 1 - (box.x + 2))[0],
            200);  // on the right in the mirror
  EXPECT_NEAR(m.anchor_px.x(), bb->bgra.cols - 1 - bb->anchor_px.x(), 1e-9);
  EXPECT_NE(m.bgra.data, bb->bgra.data);  // the original keeps its own pixels
  // Walking to the camera's right becomes walking to its left; toward the camera stays.
  const Eigen::Vector2d v = 0.3 * bb->right_in_ground + 0.1 * bb->toward_camera;
  const Eigen::Vector2d mv = Rectifier::MirrorVelocity(*bb, v);
  EXPECT_NEAR(mv.dot(bb->right_in_ground), -0.3, 1e-12);
  EXPECT_NEAR(mv.dot(bb->toward_camera), 0.1, 1e-12);
}

TEST(Rectifier, RayAboveTheHorizonGivesNothing) {
  const CameraModel cam = LookAtOrigin(1.0, 0.8);
  cv::Mat bgr(10, 10, CV_8UC3, cv::Scalar::all(0)), alpha(10, 10, CV_8U, cv::Scalar(255));
  const SpriteView view{&bgr, &alpha, nullptr, cv::Point(300, 0), Eigen::Vector2d(305, -2000)};
  Rectifier::Refusal why;
  EXPECT_FALSE(Rectifier().Rectify(cam, view, &why).has_value());
  EXPECT_FALSE(why.too_large) << "a ray that misses the floor is not a size problem";
}

// A subject too big for the bank's scale is refused as too large, with the size it would have.
TEST(Rectifier, ABillboardOverTheSizeLimitIsTooLargeNotAMissedFloor) {
  const CameraModel cam = LookAtOrigin(1.0, 0.8);
  const Render r = RenderCard(cam, 0.06, 0.04);
  const Crop crop = CropOf(r);
  RectifierOptions o;
  o.px_per_m = 20000;  // 6 cm at 20,000 px/m: 1,200 px wide, over the 512 px limit
  Rectifier::Refusal why;
  EXPECT_FALSE(Rectifier(o).Rectify(cam, crop.View(r.contact_px), &why).has_value());
  EXPECT_TRUE(why.too_large);
  EXPECT_GT(why.width_px, o.max_side_px);
  // The same card at the default scale is made, and says nothing.
  EXPECT_TRUE(Rectifier().Rectify(cam, crop.View(r.contact_px), &why).has_value());
  EXPECT_FALSE(why.too_large);
}

}  // namespace
}  // namespace ss
