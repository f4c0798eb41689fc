#pragma once
// Which sprites are usable (seed 000 §2): entirely surrounded by floor in the
// image (touching no wall, no image border), standing inside the floor
// polygon, and not standing still for too long. Every discard has a reason.
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss {

enum class Discard {
  kNone = 0,
  kTooSmall,       // a noise blob below the minimum area
  kTouchesBorder,  // the sprite reaches the image border
  kNoGroundHit,    // the lowest point's ray misses the floor
  kLeavesFloor,    // the contact point lies outside the floor polygon (or within the wall margin)
  kTouchesWall,    // the silhouette overlaps something that is not floor (a wall)
  kStill,          // part of an extended period without motion
  kShortClip,      // its clip was too short to give transitions
  kTooLarge,       // its billboard at the bank's scale (pipeline.px_per_m) exceeds the size limit
  kNoise,  // keyed background, not a subject: scattered specks, thin lines, a soft haze (NoiseRule)
  kViewTooSteep,  // seen from too far above for an upright billboard (max_view_angle_deg)
  kCount,
};
const char* DiscardName(Discard reason);  // "too_small", "touches_border", ...

// Counts by reason; `kNone` counts kept sprites.
using DiscardCounts = std::array<uint64_t, static_cast<size_t>(Discard::kCount)>;

struct UsabilityOptions {
  int border_margin_px = 2;      // distance to keep from the image border
  int floor_margin_px = 3;       // floor pixels required around the silhouette
  double wall_margin_m = 0.005;  // contact point distance to keep from the polygon edge
  double wall_height_m = 0.0;    // walls occlude the floor behind them up to this height
  // A non-floor pixel under the silhouette is not counted (touches_wall) when it sees past the
  // floor (its ray meets the ground outside the floor polygon, or never) and passes more than this
  // high over the subject's contact point: background behind a tall subject's upper part, not
  // something in front of it (what stands on the floor in front of a subject hides its lowest part
  // first).
  double wall_check_height_m = 0.3;
  // The steepest view an upright billboard (seed 000) is kept from: the angle at the contact
  // point between the floor and the ray to the camera (0: the camera at floor level, 90:
  // straight above). From above, an upright billboard shows mostly the subject's top, stretched
  // up: a body D deep stands D tan(angle) tall on it, a sliver at 89 degrees (issue 38). The
  // reference sets are filmed at 43-60 (hamster) and 45-71 degrees (flies).
  double max_view_angle_deg = 75.0;
  // A camera whose median view of its floor (FloorMask::median_view_deg) is steeper than this
  // films from above: its subjects are laid on the floor as floor sprites
  // (pipeline/rectify/floor_rectifier.h), which max_view_angle_deg does not limit. 90: never.
  // Our oblique synthetic cameras see their floor at a median of 43-61 degrees, the overhead
  // ones at 73-80.
  double floor_view_angle_deg = 65.0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const UsabilityOptions&) const = default;
};

// The shape of a candidate's matte (its alpha crop at full resolution), for telling a subject from
// keyed background (issue 19). The matte is `alpha > 127` ("solid").
struct MatteShape {
  double area_px = 0;   // solid pixels
  double solidity = 0;  // solid pixels / their convex hull's area (1: convex; specks, rings: low)
  double thick_share = 0;  // of the solid pixels, those more than `thick_px` from the matte's edge
  double largest_share = 0;  // of the solid pixels, those in the largest 8-connected part
  double mean_alpha = 0;     // mean alpha / 255 over the pixels of alpha >= 16 (a soft haze: low)
};
// `thick_px`: distance to the matte's edge (L2) from which a pixel is interior.
MatteShape MeasureMatteShape(const cv::Mat& alpha_crop, double thick_px);

// When a candidate is noise (Discard::kNoise): a matte that fills too little of its convex hull
// (keyed background: specks, pieces of a sign, a line of tape, alone or joined to a person), or,
// when set, one with too little interior, too scattered or too soft. A threshold of 0 turns its
// test off. Defaults: measured on vtest.avi and the synthetic sessions (docs/pipeline.md).
struct NoiseOptions {
  double thick_px = 2.0;           // MatteShape::thick_px
  double min_solidity = 0.25;      // noise when solidity is below this
  double min_thick_share = 0.0;    // ... or thick_share
  double min_largest_share = 0.0;  // ... or largest_share
  double min_mean_alpha = 0.0;     // ... or mean_alpha
  // A subject whose previous frame was noise stays noise until its solidity reaches this
  // (keyed background flickers about the threshold; 0: no memory).
  double recover_solidity = 0.30;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const NoiseOptions&) const = default;
};
// The features those tests need, no more (the per-frame path): thick_share and largest_share,
// the costly ones, are measured only when their tests are on, and read 1 (pass) otherwise.
MatteShape MeasureMatteShape(const cv::Mat& alpha_crop, const NoiseOptions& tests);
// The shape tests alone, without a subject's history.
bool IsNoise(const MatteShape& shape, const NoiseOptions& options);

// Per subject: IsNoise, with the memory of NoiseOptions::recover_solidity.
class NoiseFilter {
 public:
  explicit NoiseFilter(NoiseOptions options) : options_(options) {}
  // Starts a frame: subjects not checked in the frame before are forgotten.
  void NextFrame();
  // True when the tracked subject's matte this frame is noise.
  bool IsNoise(int subject, const MatteShape& shape);
  const NoiseOptions& options() const { return options_; }

 private:
  NoiseOptions options_;
  std::unordered_map<int, bool> last_, current_;  // subject -> noise, the frame before and this one
};

// The pixels (255, CV_8U, the image size) whose ray meets the ground inside the floor and, with
// wall_height_m > 0, passes that height inside it too: FloorMask's mask before Restrict.
// `contains` decides a ground point: FloorMask gives it a GroundPolygonIndex (the edges near the
// point only); GroundPolygon::Contains (every edge, the way before issue 20) gives the same mask.
// Rows are computed in parallel (cv::parallel_for_): `contains` is called from several threads.
cv::Mat FloorPixels(const CameraModel& camera, double wall_height_m,
                    const std::function<bool(const Eigen::Vector2d&)>& contains);

// Per camera: the image of the floor, computed once.
class FloorMask {
 public:
  // Rays are unprojected exactly every this many pixels and interpolated between.
  static constexpr int kRayGridStepPx = 8;

  FloorMask(const CameraModel& camera, const GroundPolygon& floor, const UsabilityOptions& options);
  // Usability of one sprite from its alpha crop at `offset` and its contact point: the floor's
  // tests, then the view's (view_too_steep).
  Discard Check(const cv::Mat& alpha_crop, cv::Point offset,
                const Eigen::Vector2d& point_in_ground) const;
  const cv::Mat& mask() const { return mask_; }  // 255 where the camera sees floor
  // The shallowest view of the camera's floor (UsabilityOptions::max_view_angle_deg's angle), in
  // degrees, over the floor it sees (the geometric floor, every kRayGridStepPx); NaN when it sees
  // none. Above the limit, no sprite of the camera can be kept.
  double shallowest_view_deg() const { return shallowest_view_deg_; }
  // The median view of the floor it sees (the same grid: each part of the floor as much as it
  // fills of the image), degrees; NaN when it sees none. Steeper than max_view_angle_deg, the
  // camera films from above, and its subjects are laid on the floor (floor sprites, issue 38).
  double median_view_deg() const { return median_view_deg_; }
  // The camera films from above (median_view_deg steeper than floor_view_angle_deg): its sprites
  // are floor sprites, and Check does not apply max_view_angle_deg.
  bool FilmsFromAbove() const { return median_view_deg_ > options_.floor_view_angle_deg; }
  // For an upright camera whose shallowest view of its floor is steeper than
  // max_view_angle_deg: "sees all of its floor from 82 degrees or more above it, steeper than
  // pipeline.max_view_angle_deg 75", which import, config check and the pipeline put after the
  // camera's name (it keeps nothing); "" otherwise.
  std::string SteepViewText() const;
  // Keeps as floor only the pixels of the geometric floor where `seen` (CV_8U, the image size) is
  // non-zero: the keyer's green, so that a wall's outside or a cable in front of the floor is not
  // floor. A later call replaces the earlier restriction.
  void Restrict(const cv::Mat& seen);

 private:
  GroundPolygon floor_;
  GroundPolygonIndex floor_index_;  // floor_'s Contains for every pixel
  UsabilityOptions options_;
  Eigen::Vector3d centre_;             // the camera's centre on the ground frame
  std::vector<Eigen::Vector3f> rays_;  // ground-frame ray directions every kRayGridStepPx
  int ray_cols_ = 0, ray_rows_ = 0;
  // The floor's tests alone: touches_border, leaves_floor, touches_wall.
  Discard CheckFloor(const cv::Mat& alpha_crop, cv::Point offset,
                     const Eigen::Vector2d& point_in_ground) const;
  // The angle between the floor and the ray from a ground point to the camera, in degrees.
  double ViewAngleDeg(const Eigen::Vector2d& point_in_ground) const;
  // The pixel sees past the floor, over the contact point higher than wall_check_height_m.
  bool SeesBehind(int x, int y, const Eigen::Vector2d& point_in_ground) const;
  cv::Mat mask_;
  cv::Mat geometric_;           // the floor polygon seen over the walls, before Restrict
  cv::Mat not_floor_integral_;  // integral image of (mask_ == 0), for O(1) box tests
  double shallowest_view_deg_ = 0;
  double median_view_deg_ = 0;
};

// Per subject: drops frames once the subject has been still for longer than allowed. A frame is
// still when the subject moved less than min_speed over the last `window_s` (at least 2 mm, the
// keying jitter of a contact point); a still period is a run of still frames, counted from the
// start of the first one's window. Moving again ends it at once, however long it lasted.
class StillnessFilter {
 public:
  StillnessFilter(double min_speed_m_per_s, double max_still_s, double window_s = 0.5)
      : min_speed_(min_speed_m_per_s),
        max_still_ns_(static_cast<int64_t>(max_still_s * 1e9)),
        window_ns_(static_cast<int64_t>(window_s * 1e9)) {}
  // True when the subject's frame at `timestamp_ns` is part of a too-long still period.
  bool IsStill(int subject, int64_t timestamp_ns, const Eigen::Vector2d& point_in_ground);

 private:
  struct Sample {
    int64_t timestamp_ns;
    Eigen::Vector2d point;
  };
  struct State {
    std::deque<Sample> history;   // the last window, and the newest sample before it
    int64_t still_since_ns = -1;  // -1: moving
  };
  double min_speed_;
  int64_t max_still_ns_;
  int64_t window_ns_;
  std::unordered_map<int, State> subjects_;
};

}  // namespace ss
