#include "pipeline/filter/usability.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }

}  // namespace

bool UsabilityOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(border_margin_px, AtLeast(0), "border_margin_px", "a number >= 0");
  check.Within(floor_margin_px, AtLeast(0), "floor_margin_px", "a number >= 0");
  for (const auto& [v, field] :
       {std::pair{wall_margin_m, "wall_margin_m"}, std::pair{wall_height_m, "wall_height_m"},
        std::pair{wall_check_height_m, "wall_check_height_m"}}) {
    check(NonNegative(v), field, "expected a number >= 0, got " + OptionProblems::Num(v));
  }
  check.Within(max_view_angle_deg, AboveUpTo(0, 90), "max_view_angle_deg",
               "an angle in degrees above 0 and at most 90 (90: no view is too steep)");
  check(
      std::isfinite(floor_view_angle_deg) && floor_view_angle_deg > 0 && floor_view_angle_deg <= 90,
      "floor_view_angle_deg",
      "expected an angle in degrees above 0 and at most 90 (90: no camera films from above), "
      "got " +
          OptionProblems::Num(floor_view_angle_deg));
  return check.ok();
}

bool NoiseOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(NonNegative(thick_px), "thick_px",
        "expected a number >= 0, got " + OptionProblems::Num(thick_px));
  for (const auto& [v, field] :
       {std::pair{recover_solidity, "recover_solidity"},
        std::pair{min_thick_share, "min_thick_share"}, std::pair{min_solidity, "min_solidity"},
        std::pair{min_largest_share, "min_largest_share"},
        std::pair{min_mean_alpha, "min_mean_alpha"}}) {
    check(std::isfinite(v) && v >= 0 && v <= 1, field,
          "expected a share from 0 to 1 (0 turns the test off), got " + OptionProblems::Num(v));
  }
  return check.ok();
}

const char* DiscardName(Discard reason) {
  switch (reason) {
    case Discard::kNone:
      return "kept";
    case Discard::kTooSmall:
      return "too_small";
    case Discard::kTouchesBorder:
      return "touches_border";
    case Discard::kNoGroundHit:
      return "no_ground_hit";
    case Discard::kLeavesFloor:
      return "leaves_floor";
    case Discard::kTouchesWall:
      return "touches_wall";
    case Discard::kStill:
      return "still";
    case Discard::kShortClip:
      return "short_clip";
    case Discard::kTooLarge:
      return "too_large";
    case Discard::kNoise:
      return "noise";
    case Discard::kViewTooSteep:
      return "view_too_steep";
    case Discard::kCount:
      break;
  }
  return "unknown";
}

namespace {

// Ground-frame ray directions through every pixel, unprojected exactly on a grid every `step`
// pixels and bilinearly interpolated between: the lens maps smoothly, and an exact iterative
// unprojection of each of a 1080p image's two million pixels took ~3 s a camera.
class PixelRays {
 public:
  PixelRays(const CameraModel& camera, int step) : camera_(camera), step_(step) {
    cols_ = (camera.width() - 1 + step - 1) / step + 1;
    rows_ = (camera.height() - 1 + step - 1) / step + 1;
    std::vector<Eigen::Vector2d> nodes;
    nodes.reserve(static_cast<size_t>(cols_) * rows_);
    for (int j = 0; j < rows_; ++j) {
      for (int i = 0; i < cols_; ++i) nodes.emplace_back(i * step, j * step);
    }
    rays_.resize(nodes.size());
    camera.UnprojectMany(nodes.data(), nodes.size(), rays_.data());
    const Eigen::Matrix3d ground_from_cam = camera.cam_from_ground().rotation.transpose();
    for (Eigen::Vector3d& r : rays_) r = ground_from_cam * r.normalized();
  }

  // The direction through pixel (x, y), in the ground frame.
  Eigen::Vector3d Direction(int x, int y) const {
    const int i = x / step_, j = y / step_;
    const double u = static_cast<double>(x - i * step_) / step_;
    const double v = static_cast<double>(y - j * step_) / step_;
    const int i1 = std::min(i + 1, cols_ - 1), j1 = std::min(j + 1, rows_ - 1);
    Eigen::Vector3d d = (1 - v) * ((1 - u) * Node(i, j) + u * Node(i1, j)) +
                        v * ((1 - u) * Node(i, j1) + u * Node(i1, j1));
    if (d.allFinite()) return d;
    return camera_.RayInGround(Eigen::Vector2d(x, y))
        .direction;  // a node outside the lens's valid region
  }

  int cols() const { return cols_; }
  int rows() const { return rows_; }

 private:
  const Eigen::Vector3d& Node(int i, int j) const {
    return rays_[static_cast<size_t>(j) * cols_ + i];
  }

  const CameraModel& camera_;
  int step_, cols_ = 0, rows_ = 0;
  std::vector<Eigen::Vector3d> rays_;
};

cv::Mat FloorPixels(const CameraModel& camera, const PixelRays& rays, double wall_height_m,
                    const std::function<bool(const Eigen::Vector2d&)>& contains) {
  cv::Mat mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8U);
  const Eigen::Vector3d centre = camera.CentreInGround();
  // Rows are independent: spread over the cores (a camera's pipeline waits for its mask).
  cv::parallel_for_(cv::Range(0, camera.height()), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      auto* row = mask.ptr<uint8_t>(y);
      for (int x = 0; x < camera.width(); ++x) {
        const auto g = IntersectGround(Ray{centre, rays.Direction(x, y)});
        if (!g || !contains(g->head<2>())) continue;
        // Seen over the walls: where the ray passes wall height it must be inside too.
        if (wall_height_m > 0 && centre.z() > wall_height_m) {
          const double s = (centre.z() - wall_height_m) / centre.z();
          const Eigen::Vector3d top = centre + s * (*g - centre);
          if (!contains(top.head<2>())) continue;
        }
        row[x] = 255;
      }
    }
  });
  return mask;
}

}  // namespace

cv::Mat FloorPixels(const CameraModel& camera, double wall_height_m,
                    const std::function<bool(const Eigen::Vector2d&)>& contains) {
  return FloorPixels(camera, PixelRays(camera, FloorMask::kRayGridStepPx), wall_height_m, contains);
}

FloorMask::FloorMask(const CameraModel& camera, const GroundPolygon& floor,
                     const UsabilityOptions& options)
    : floor_(floor), floor_index_(floor), options_(options) {
  const PixelRays rays(camera, kRayGridStepPx);
  centre_ = camera.CentreInGround();
  ray_cols_ = rays.cols();
  ray_rows_ = rays.rows();
  rays_.reserve(static_cast<size_t>(ray_cols_) * ray_rows_);
  for (int j = 0; j < ray_rows_; ++j) {
    for (int i = 0; i < ray_cols_; ++i) {
      rays_.push_back(rays.Direction(std::min(i * kRayGridStepPx, camera.width() - 1),
                                     std::min(j * kRayGridStepPx, camera.height() - 1))
                          .cast<float>());
    }
  }
  mask_ = FloorPixels(camera, rays, options_.wall_height_m,
                      [this](const Eigen::Vector2d& p) { return floor_index_.Contains(p); });
  cv::integral(mask_ == 0, not_floor_integral_, CV_32S);
  not_floor_integral_ /= 255;
  // The shallowest view: the floor pixel whose ray is nearest the horizontal; and the median.
  double lowest_sin = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sines;
  for (int j = 0; j < ray_rows_; ++j) {
    for (int i = 0; i < ray_cols_; ++i) {
      const int x = std::min(i * kRayGridStepPx, camera.width() - 1);
      const int y = std::min(j * kRayGridStepPx, camera.height() - 1);
      const Eigen::Vector3f& d = rays_[static_cast<size_t>(j) * ray_cols_ + i];
      if (mask_.at<uint8_t>(y, x) == 0 || !d.allFinite()) continue;
      const double s = -d.z() / d.norm();
      if (!(s >= lowest_sin)) lowest_sin = s;  // the first, then each lower one
      sines.push_back(s);
    }
  }
  shallowest_view_deg_ = std::asin(lowest_sin) * 180 / std::numbers::pi;
  median_view_deg_ = std::numeric_limits<double>::quiet_NaN();
  if (!sines.empty()) {
    const auto mid = sines.begin() + static_cast<std::ptrdiff_t>(sines.size() / 2);
    std::nth_element(sines.begin(), mid, sines.end());
    median_view_deg_ = std::asin(*mid) * 180 / std::numbers::pi;
  }
}

bool FloorMask::SeesBehind(int x, int y, const Eigen::Vector2d& point_in_ground) const {
  if (!(options_.wall_check_height_m > 0) || rays_.empty()) return false;
  const int i = std::min(x / kRayGridStepPx, ray_cols_ - 1),
            j = std::min(y / kRayGridStepPx, ray_rows_ - 1);
  const double u = static_cast<double>(x - i * kRayGridStepPx) / kRayGridStepPx;
  const double v = static_cast<double>(y - j * kRayGridStepPx) / kRayGridStepPx;
  const int i1 = std::min(i + 1, ray_cols_ - 1), j1 = std::min(j + 1, ray_rows_ - 1);
  const auto node = [&](int a, int b) {
    return rays_[static_cast<size_t>(b) * ray_cols_ + a].cast<double>();
  };
  const Eigen::Vector3d d = (1 - v) * ((1 - u) * node(i, j) + u * node(i1, j)) +
                            v * ((1 - u) * node(i, j1) + u * node(i1, j1));
  if (!d.allFinite()) return false;
  // Past the floor: the ray meets the ground outside the polygon, or never.
  if (d.z() < 0) {
    const Eigen::Vector3d g = centre_ + (-centre_.z() / d.z()) * d;
    if (floor_index_.Contains(g.head<2>())) return false;
  }
  // Its height where it passes the contact point's distance from the camera.
  const double reach = (point_in_ground - centre_.head<2>()).norm();
  const double along = d.head<2>().norm();
  if (along < 1e-9) return false;
  const double z = centre_.z() + d.z() * (reach / along);
  return z > options_.wall_check_height_m;
}

void FloorMask::Restrict(const cv::Mat& seen) {
  if (seen.type() != CV_8U || seen.size() != mask_.size()) {
    throw InputError("floor mask", "the restricting mask must be 8-bit and the image size");
  }
  if (geometric_.empty()) geometric_ = mask_.clone();
  geometric_.copyTo(mask_);
  mask_.setTo(0, seen == 0);
  cv::integral(mask_ == 0, not_floor_integral_, CV_32S);
  not_floor_integral_ /= 255;
}

std::string FloorMask::SteepViewText() const {
  if (FilmsFromAbove() || !(shallowest_view_deg_ > options_.max_view_angle_deg)) return "";
  return "sees all of its floor from " +
         std::to_string(static_cast<int>(std::floor(shallowest_view_deg_))) +
         " degrees or more above it, steeper than pipeline.max_view_angle_deg " +
         OptionProblems::Num(options_.max_view_angle_deg);
}

Discard FloorMask::Check(const cv::Mat& alpha_crop, cv::Point offset,
                         const Eigen::Vector2d& point_in_ground) const {
  const Discard floor = CheckFloor(alpha_crop, offset, point_in_ground);
  if (floor != Discard::kNone || FilmsFromAbove()) return floor;
  return ViewAngleDeg(point_in_ground) > options_.max_view_angle_deg ? Discard::kViewTooSteep
                                                                     : Discard::kNone;
}

double FloorMask::ViewAngleDeg(const Eigen::Vector2d& point_in_ground) const {
  return std::atan2(centre_.z(), (point_in_ground - centre_.head<2>()).norm()) * 180 /
         std::numbers::pi;
}

Discard FloorMask::CheckFloor(const cv::Mat& alpha_crop, cv::Point offset,
                              const Eigen::Vector2d& point_in_ground) const {
  const cv::Rect box(offset, alpha_crop.size());
  const int b = options_.border_margin_px;
  if (box.x < b || box.y < b || box.x + box.width > mask_.cols - b ||
      box.y + box.height > mask_.rows - b) {
    return Discard::kTouchesBorder;
  }
  if (!floor_.ContainsWithMargin(point_in_ground, options_.wall_margin_m))
    return Discard::kLeavesFloor;

  // Fast path: the whole crop grown by the margin is floor.
  const int m = options_.floor_margin_px;
  const cv::Rect grown = cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) &
                         cv::Rect(0, 0, mask_.cols, mask_.rows);
  const auto at = [&](int y, int x) { return not_floor_integral_.at<int>(y, x); };
  const int not_floor = at(grown.y + grown.height, grown.x + grown.width) -
                        at(grown.y, grown.x + grown.width) - at(grown.y + grown.height, grown.x) +
                        at(grown.y, grown.x);
  if (not_floor == 0) return Discard::kNone;

  // Slow path: the silhouette grown by the margin must not cover non-floor pixels.
  cv::Mat solid = alpha_crop > 127;
  cv::Mat padded;
  cv::copyMakeBorder(solid, padded, m, m, m, m, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::dilate(padded, padded,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * m + 1, 2 * m + 1)));
  for (int y = 0; y < padded.rows; ++y) {
    const int iy = box.y - m + y;
    if (iy < 0 || iy >= mask_.rows) continue;
    const auto* p = padded.ptr<uint8_t>(y);
    const auto* f = mask_.ptr<uint8_t>(iy);
    for (int x = 0; x < padded.cols; ++x) {
      const int ix = box.x - m + x;
      if (ix >= 0 && ix < mask_.cols && p[x] && !f[ix] && !SeesBehind(ix, iy, point_in_ground)) {
        return Discard::kTouchesWall;
      }
    }
  }
  return Discard::kNone;
}

namespace {

MatteShape Measure(const cv::Mat& alpha_crop, double thick_px, bool parts, bool interior) {
  MatteShape s;
  if (alpha_crop.empty()) return s;
  const cv::Mat solid = alpha_crop > 127;
  const int area = cv::countNonZero(solid);
  s.area_px = area;
  const cv::Mat present = alpha_crop >= 16;
  const int present_px = cv::countNonZero(present);
  if (present_px > 0) s.mean_alpha = cv::mean(alpha_crop, present)[0] / 255.0;
  if (area == 0) return s;

  std::vector<cv::Point> points;
  cv::findNonZero(solid, points);
  std::vector<cv::Point> hull;
  cv::convexHull(points, hull);
  // The hull through pixel centres misses half a pixel all round: count it back so a filled
  // rectangle is 1, not (w-1)(h-1)/(wh).
  const double hull_area = cv::contourArea(hull) + 0.5 * cv::arcLength(hull, true) + 1.0;
  s.solidity = std::min(1.0, area / hull_area);

  s.largest_share = 1.0;
  if (parts) {
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(solid, labels, stats, centroids, 8, CV_32S);
    int largest = 0;
    for (int i = 1; i < n; ++i) largest = std::max(largest, stats.at<int>(i, cv::CC_STAT_AREA));
    s.largest_share = static_cast<double>(largest) / area;
  }
  s.thick_share = 1.0;
  if (interior) {
    // Distance to the nearest non-solid pixel, the crop's outside counting as non-solid.
    cv::Mat padded, dist;
    cv::copyMakeBorder(solid, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::distanceTransform(padded, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    s.thick_share = static_cast<double>(cv::countNonZero(dist > thick_px)) / area;
  }
  return s;
}

}  // namespace

MatteShape MeasureMatteShape(const cv::Mat& alpha_crop, double thick_px) {
  return Measure(alpha_crop, thick_px, true, true);
}

MatteShape MeasureMatteShape(const cv::Mat& alpha_crop, const NoiseOptions& tests) {
  return Measure(alpha_crop, tests.thick_px, tests.min_largest_share > 0,
                 tests.min_thick_share > 0);
}

bool IsNoise(const MatteShape& shape, const NoiseOptions& o) {
  return shape.solidity < o.min_solidity || shape.thick_share < o.min_thick_share ||
         shape.largest_share < o.min_largest_share || shape.mean_alpha < o.min_mean_alpha;
}

void NoiseFilter::NextFrame() {
  last_.swap(current_);
  current_.clear();
}

bool NoiseFilter::IsNoise(int subject, const MatteShape& shape) {
  const auto before = last_.find(subject);
  const bool was_noise = before != last_.end() && before->second;
  const bool noise =
      ss::IsNoise(shape, options_) || (was_noise && shape.solidity < options_.recover_solidity);
  current_[subject] = noise;
  return noise;
}

bool StillnessFilter::IsStill(int subject, int64_t timestamp_ns, const Eigen::Vector2d& point) {
  State& s = subjects_[subject];
  // Lost for longer than the window (or time went backwards): start afresh.
  if (!s.history.empty() && (timestamp_ns - s.history.back().timestamp_ns > window_ns_ ||
                             timestamp_ns <= s.history.back().timestamp_ns)) {
    s.history.clear();
    s.still_since_ns = -1;
  }
  s.history.push_back({timestamp_ns, point});
  // Keep the newest sample at least a window old as the reference, nothing older.
  while (s.history.size() > 2 && s.history[1].timestamp_ns <= timestamp_ns - window_ns_)
    s.history.pop_front();
  const Sample& ref = s.history.front();
  if (timestamp_ns - ref.timestamp_ns < window_ns_) return false;  // too little history: moving
  const double dt = (timestamp_ns - ref.timestamp_ns) * 1e-9;
  if ((point - ref.point).norm() > std::max(0.002, min_speed_ * dt)) {
    s.still_since_ns = -1;
    return false;
  }
  if (s.still_since_ns < 0) s.still_since_ns = ref.timestamp_ns;
  return timestamp_ns - s.still_since_ns > max_still_ns_;
}

}  // namespace ss
