#include "pipeline/rectify/floor_rectifier.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "pipeline/rectify/plane_map.h"

namespace ss {
namespace {

// Alpha (of 255) that counts as the subject for the sprite's extent.
constexpr int kSolidAlpha = 16;

// Where `ray` meets the horizontal plane z = height in front of its origin.
std::optional<Eigen::Vector3d> IntersectHeight(const Ray& ray, double height) {
  if (std::abs(ray.direction.z()) < 1e-12) return std::nullopt;
  const double s = (height - ray.origin.z()) / ray.direction.z();
  if (!(s > 0) || !std::isfinite(s)) return std::nullopt;
  return ray.origin + s * ray.direction;
}

// The angle in (-pi, pi].
double Wrap(double a) { return std::remainder(a, 2 * M_PI); }

// The centre of the body's thickest part, in the plane image's pixels: the solid matte's points
// weighted by their distance to its edge to the 4th power (the torso; the outline's plain centre
// is pulled ahead by the head: 8-9 mm on the synthetic hamster, against 0.5-0.7 mm so). nullopt
// for an empty matte.
std::optional<cv::Point2d> ThickestCentre(const cv::Mat& plane_alpha) {
  cv::Mat inside;
  cv::distanceTransform(plane_alpha > kSolidAlpha, inside, cv::DIST_L2, cv::DIST_MASK_5);
  double sum = 0, sum_u = 0, sum_v = 0;
  for (int y = 0; y < inside.rows; ++y) {
    const float* row = inside.ptr<float>(y);
    for (int x = 0; x < inside.cols; ++x) {
      const double d2 = static_cast<double>(row[x]) * row[x];
      const double w = d2 * d2;
      sum += w;
      sum_u += w * x;
      sum_v += w * y;
    }
  }
  if (!(sum > 0)) return std::nullopt;
  return cv::Point2d(sum_u / sum, sum_v / sum);
}

}  // namespace

FloorRectifier::FloorRectifier(RectifierOptions options) : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("rectifier options", why);
}

std::optional<Eigen::Vector2d> FloorRectifier::Place(const CameraModel& camera,
                                                     const cv::Mat& alpha, cv::Point offset) const {
  const cv::Moments m = cv::moments(alpha);
  if (!(m.m00 > 0)) return std::nullopt;
  const Eigen::Vector2d centre_px(offset.x + m.m10 / m.m00, offset.y + m.m01 / m.m00);
  const auto hit = IntersectHeight(camera.RayInGround(centre_px), options_.floor_height_m);
  if (!hit) return std::nullopt;
  return hit->head<2>();
}

std::optional<Billboard> FloorRectifier::Rectify(const CameraModel& camera, const SpriteView& view,
                                                 Rectifier::Refusal* why) const {
  if (why != nullptr) *why = {};
  if (view.bgr == nullptr || view.alpha == nullptr || view.bgr->empty() ||
      view.bgr->size() != view.alpha->size()) {
    return std::nullopt;
  }
  const double s = options_.px_per_m, h = options_.floor_height_m;

  // A first look: the matte's centre on the body plane (Place), and its extent there.
  const cv::Rect solid = cv::boundingRect(*view.alpha > kSolidAlpha);
  const auto place = Place(camera, *view.alpha, view.offset);
  if (solid.empty() || !place) return std::nullopt;
  const Eigen::Vector3d first(place->x(), place->y(), h);
  double reach = 0;
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(solid.x, solid.y), Eigen::Vector2d(solid.br().x, solid.y),
        Eigen::Vector2d(solid.x, solid.br().y), Eigen::Vector2d(solid.br().x, solid.br().y)}) {
    const auto hit =
        IntersectHeight(camera.RayInGround(px + Eigen::Vector2d(view.offset.x, view.offset.y)), h);
    if (!hit) return std::nullopt;
    reach = std::max(reach, (*hit - first).head<2>().norm());
  }
  const auto too_large = [&](int side) {
    if (side <= options_.max_side_px) return false;
    if (why != nullptr) *why = {true, side, side};
    return true;
  };
  int side = 2 * static_cast<int>(std::ceil((reach + options_.margin_m) * s)) + 1;
  if (too_large(side)) return std::nullopt;

  // The matte on the body plane, the ground's axes (u along +x, v along -y): its centre and
  // second moments there are free of the lens's perspective.
  const Eigen::Vector3d du(1 / s, 0, 0), dv(0, -1 / s, 0);
  double a = (side - 1) / 2.0;
  cv::Mat map, plane_alpha;
  BuildPlaneMap(camera, first - a * du - a * dv, du, dv, cv::Size(side, side), view.offset, map);
  cv::remap(*view.alpha, plane_alpha, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(0));
  const cv::Moments pm = cv::moments(plane_alpha);
  if (pm.m00 <= 0) return std::nullopt;
  const double cu = pm.m10 / pm.m00, cv_ = pm.m01 / pm.m00;
  const Eigen::Vector3d centre = first + (cu - a) * du + (cv_ - a) * dv;
  // The major axis in the plane image's axes, then on the ground (v runs along -y).
  const double mu20 = pm.mu20 / pm.m00, mu02 = pm.mu02 / pm.m00, mu11 = pm.mu11 / pm.m00;
  const double axis_image = 0.5 * std::atan2(2 * mu11, mu20 - mu02);
  const double spread = std::sqrt(4 * mu11 * mu11 + (mu20 - mu02) * (mu20 - mu02));
  const double major = (mu20 + mu02 + spread) / 2, minor = (mu20 + mu02 - spread) / 2;
  double far = 0;  // the farthest solid pixel from the centre, plane pixels
  for (int y = 0; y < plane_alpha.rows; ++y) {
    const uint8_t* row = plane_alpha.ptr<uint8_t>(y);
    for (int x = 0; x < plane_alpha.cols; ++x) {
      if (row[x] > kSolidAlpha) far = std::max(far, std::hypot(x - cu, y - cv_));
    }
  }

  Billboard out;
  out.kind = SpriteKind::kFloor;
  out.px_per_m = s;
  out.heading_rad = Wrap(-axis_image);
  out.elongation = major > 0 ? 1 - std::sqrt(std::max(0.0, minor) / major) : 0;
  if (const auto thick = ThickestCentre(plane_alpha)) {
    // Along the axis in the plane image is along the heading on the ground (v runs along -y).
    out.thickest_ahead_m =
        ((thick->x - cu) * std::cos(axis_image) + (thick->y - cv_) * std::sin(axis_image)) / s;
  }
  out.point_in_ground = Eigen::Vector3d(centre.x(), centre.y(), 0);
  side = 2 * static_cast<int>(std::ceil(far + options_.margin_m * s)) + 1;
  if (too_large(side)) return std::nullopt;
  a = (side - 1) / 2.0;
  out.anchor_px = Eigen::Vector2d(a, a);

  // The sprite: its top ahead along the axis, +x to the subject's right (seen from above, the
  // ground turned so that the axis points up).
  out.toward_camera = Eigen::Vector2d(std::cos(out.heading_rad), std::sin(out.heading_rad));
  out.right_in_ground = Eigen::Vector2d(out.toward_camera.y(), -out.toward_camera.x());
  const Eigen::Vector3d right(out.right_in_ground.x(), out.right_in_ground.y(), 0);
  const Eigen::Vector3d back(-out.toward_camera.x(), -out.toward_camera.y(), 0);
  out.bgra =
      ResampleBgra(camera, *view.bgr, *view.alpha, view.offset, centre - (a / s) * (right + back),
                   right / s, back / s, cv::Size(side, side));
  // The shadow, in the same axes, on the same body plane as the image: the keyer leaves no
  // shadow where the body hides the floor, and that hole must lie under the body when the two are
  // laid on the floor together. Taken on the floor itself, the hole stood off the body by the
  // camera's parallax (h / height of the distance from under the camera: 9 px, a white crescent
  // beside a real mouse 0.2 m off the centre of an overhead view).
  out.shadow = ShadowPatch(camera, view.shadow, view.offset, centre, right, back,
                           options_.shadow_radius_m, s);
  return out;
}

Billboard FloorRectifier::TurnHalf(const Billboard& sprite) {
  Billboard t = sprite;
  t.bgra = cv::Mat();
  t.shadow = cv::Mat();
  cv::rotate(sprite.bgra, t.bgra, cv::ROTATE_180);
  if (!sprite.shadow.empty()) cv::rotate(sprite.shadow, t.shadow, cv::ROTATE_180);
  t.heading_rad = Wrap(sprite.heading_rad + M_PI);
  t.thickest_ahead_m = -sprite.thickest_ahead_m;
  t.toward_camera = -sprite.toward_camera;
  t.right_in_ground = -sprite.right_in_ground;
  return t;
}

std::vector<bool> ResolveHeadings(const std::vector<HeadingCue>& clip,
                                  const HeadingOptions& options, std::optional<double> before) {
  const size_t n = clip.size();
  std::vector<bool> flip(n, false);
  if (n == 0) return flip;
  const auto heading = [&](size_t t, int state) { return clip[t].axis_rad + state * M_PI; };
  // Where the subject moves, the cost of a heading away from its direction of travel.
  const auto unary = [&](size_t t, int state) {
    const double speed = clip[t].velocity.norm();
    if (!(speed > options.moving_m_per_s)) return 0.0;
    const double sure = std::min(1.0, speed / (2 * options.moving_m_per_s));
    const double travel = std::atan2(clip[t].velocity.y(), clip[t].velocity.x());
    return options.backwards_weight * sure * (1 - std::cos(heading(t, state) - travel)) / 2;
  };
  // A turn from one heading to the next, in half turns, counted as much as the axes are sure.
  const auto turn = [](double elongation, double from, double to) {
    return std::clamp(elongation / 0.2, 0.05, 1.0) * std::abs(Wrap(to - from)) / M_PI;
  };
  const auto pair = [&](size_t t, int from, int to) {
    return turn(std::min(clip[t - 1].elongation, clip[t].elongation), heading(t - 1, from),
                heading(t, to));
  };
  std::vector<std::array<int, 2>> back(n, {0, 0});
  std::array<double, 2> cost = {unary(0, 0), unary(0, 1)};
  for (int state = 0; before && state < 2; ++state) {
    cost[state] += turn(clip[0].elongation, *before, heading(0, state));
  }
  for (size_t t = 1; t < n; ++t) {
    std::array<double, 2> next{};
    for (int to = 0; to < 2; ++to) {
      const double via0 = cost[0] + pair(t, 0, to), via1 = cost[1] + pair(t, 1, to);
      back[t][to] = via1 < via0 ? 1 : 0;
      next[to] = std::min(via0, via1) + unary(t, to);
    }
    cost = next;
  }
  int state = cost[1] < cost[0] ? 1 : 0;
  for (size_t t = n; t-- > 0;) {
    flip[t] = state == 1;
    state = back[t][state];
  }
  return flip;
}

}  // namespace ss
