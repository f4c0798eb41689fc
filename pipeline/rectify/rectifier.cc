#include "pipeline/rectify/rectifier.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/rectify/plane_map.h"

namespace ss {
namespace {

// Where the ray through `pixel` meets the vertical plane through `point` with normal `n`
// (horizontal).
std::optional<Eigen::Vector3d> IntersectVerticalPlane(const CameraModel& camera,
                                                      const Eigen::Vector2d& pixel,
                                                      const Eigen::Vector3d& point,
                                                      const Eigen::Vector3d& n) {
  const Ray ray = camera.RayInGround(pixel);
  const double denom = ray.direction.dot(n);
  if (std::abs(denom) < 1e-12) return std::nullopt;
  const double s = (point - ray.origin).dot(n) / denom;
  if (s <= 0) return std::nullopt;
  return ray.origin + s * ray.direction;
}

}  // namespace

bool RectifierOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(px_per_m, Positive(), "px_per_m", "a positive number of pixels per metre");
  for (const auto& [v, field] :
       {std::pair{margin_m, "margin_m"}, std::pair{shadow_radius_m, "shadow_radius_m"},
        std::pair{floor_height_m, "floor_height_m"}}) {
    check(std::isfinite(v) && v >= 0, field,
          "expected a number of metres >= 0, got " + OptionProblems::Num(v));
  }
  // A billboard is at least 3 px on each side.
  check.Within(max_side_px, AtLeast(3), "max_side_px", "at least 3 pixels");
  return check.ok();
}

Rectifier::Rectifier(RectifierOptions options) : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("rectifier options", why);
}

std::optional<Billboard> Rectifier::Rectify(const CameraModel& camera, const SpriteView& view,
                                            Refusal* why) const {
  if (why != nullptr) *why = {};
  if (view.bgr == nullptr || view.alpha == nullptr || view.bgr->empty() ||
      view.bgr->size() != view.alpha->size()) {
    return std::nullopt;
  }
  const auto contact = IntersectGround(camera.RayInGround(view.contact_px));
  if (!contact) return std::nullopt;

  const Eigen::Vector3d centre = camera.CentreInGround();
  Eigen::Vector2d toward(centre.x() - contact->x(), centre.y() - contact->y());
  if (toward.norm() < 1e-9) return std::nullopt;  // camera straight above: no vertical billboard
  toward.normalize();
  // Seen from the camera, x runs to the right: right = view_direction x up.
  const Eigen::Vector2d right(-toward.y(), toward.x());
  const Eigen::Vector3d n(toward.x(), toward.y(), 0.0);
  const Eigen::Vector3d right3(right.x(), right.y(), 0.0);
  const Eigen::Vector3d up(0, 0, 1);

  // The billboard's extent: the corners and edge midpoints of the sprite's own box (alpha > 0) on
  // the plane. Not the crop's: the crop also holds the contact shadow, which goes to the ground
  // patch, and a long shadow would make the billboard needlessly wide (or too big to keep).
  const cv::Rect solid = cv::boundingRect(*view.alpha);
  if (solid.empty()) return std::nullopt;
  const double x0 = view.offset.x + solid.x, y0 = view.offset.y + solid.y;
  const double x1 = x0 + solid.width, y1 = y0 + solid.height;
  double min_r = 0, max_r = 0, max_h = 0;
  bool any = false;
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0), Eigen::Vector2d(x0, y1),
        Eigen::Vector2d(x1, y1), Eigen::Vector2d((x0 + x1) / 2, y0),
        Eigen::Vector2d(x0, (y0 + y1) / 2), Eigen::Vector2d(x1, (y0 + y1) / 2)}) {
    const auto hit = IntersectVerticalPlane(camera, px, *contact, n);
    if (!hit) continue;
    const Eigen::Vector3d d = *hit - *contact;
    min_r = any ? std::min(min_r, d.dot(right3)) : d.dot(right3);
    max_r = any ? std::max(max_r, d.dot(right3)) : d.dot(right3);
    max_h = std::max(max_h, d.z());
    any = true;
  }
  if (!any || max_h <= 0) return std::nullopt;

  const double s = options_.px_per_m;
  const double half_w = std::max(-min_r, max_r) + options_.margin_m;
  const int width = 2 * static_cast<int>(std::ceil(half_w * s)) + 1;
  const int height = static_cast<int>(std::ceil((max_h + options_.margin_m) * s)) + 1;
  if (width > options_.max_side_px || height > options_.max_side_px || width < 3 || height < 3) {
    if (why != nullptr && (width > options_.max_side_px || height > options_.max_side_px)) {
      *why = {true, width, height};
    }
    Log("pipeline.rectify")
        ->trace("billboard {}x{} px refused (max {}): crop {}x{}+{}+{}, contact ({:.1f}, {:.1f})",
                width, height, options_.max_side_px, view.bgr->cols, view.bgr->rows, view.offset.x,
                view.offset.y, view.contact_px.x(), view.contact_px.y());
    return std::nullopt;
  }

  Billboard out;
  out.px_per_m = s;
  out.point_in_ground = *contact;
  out.right_in_ground = right;
  out.toward_camera = toward;
  out.anchor_px = Eigen::Vector2d((width - 1) / 2.0, height - 1.0);

  // Billboard pixel (u, v) is the point contact + right*(u - a_u)/s + up*(a_v - v)/s.
  const Eigen::Vector3d origin =
      *contact - right3 * (out.anchor_px.x() / s) + up * (out.anchor_px.y() / s);
  out.bgra = ResampleBgra(camera, *view.bgr, *view.alpha, view.offset, origin, right3 / s, -up / s,
                          cv::Size(width, height));
  // The shadow patch: ground axes `right` (u) and `-toward` (v, away from the camera).
  out.shadow =
      ShadowPatch(camera, view.shadow, view.offset, *contact, right3,
                  Eigen::Vector3d(-toward.x(), -toward.y(), 0.0), options_.shadow_radius_m, s);
  return out;
}

// The billboard keeps its place and axes; only its content is mirrored.
Billboard Rectifier::Mirror(const Billboard& b) {
  Billboard m = b;
  // cv::Mat copies share pixels: give the mirror its own buffers before flipping into them.
  m.bgra = cv::Mat();
  m.shadow = cv::Mat();
  cv::flip(b.bgra, m.bgra, 1);
  if (!b.shadow.empty()) cv::flip(b.shadow, m.shadow, 1);
  m.anchor_px.x() = (b.bgra.cols - 1) - b.anchor_px.x();
  return m;
}

Eigen::Vector2d Rectifier::MirrorVelocity(const Billboard& b, const Eigen::Vector2d& v) {
  return v - 2.0 * v.dot(b.right_in_ground) * b.right_in_ground;
}

}  // namespace ss
