#pragma once
// Perspective correction (seed 000 §2.1). The ray through the sprite's contact
// point (its lowest point, core/contact_point.h) meets the floor at its ground
// position; the sprite is resampled onto a vertical billboard standing there
// and facing the camera, at a fixed metric
// scale (px_per_m) shared by the whole bank, so near and far sprites look
// alike. The contact shadow is resampled onto a horizontal ground patch around
// the same point, so rendering can lay it on the virtual floor.
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/bank_records.h"
#include "core/camera_model.h"

namespace ss {

struct RectifierOptions {
  double px_per_m = 800.0;  // billboard and shadow-patch scale, px per metre (1.25 mm per pixel)
  double margin_m = 0.01;   // billboard border around the sprite's extent, metres
  double shadow_radius_m = 0.08;  // half-size of the square ground patch for the shadow, metres
  // largest billboard side, px (>= 3): refuses absurd billboards (a sprite far above the floor)
  int max_side_px = 512;
  // Floor sprites (floor_rectifier.h): the plane a subject seen from above is laid on, metres
  // above the floor, where its outline lies (the widest part of its body). A wrong height moves
  // its place by the error x tan(off-nadir angle): 1 cm at 20 degrees off the vertical, 3.6 mm.
  double floor_height_m = 0.03;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const RectifierOptions&) const = default;
};

// What the camera saw, cropped: pixels of the crop at (offset) in the full image.
struct SpriteView {
  const cv::Mat* bgr = nullptr;     // CV_8UC3 crop
  const cv::Mat* alpha = nullptr;   // CV_8U crop, same size
  const cv::Mat* shadow = nullptr;  // CV_8U crop, same size; may be null
  cv::Point offset;                 // crop's top-left in the full image
  Eigen::Vector2d contact_px;       // contact point (core/contact_point.h), full-image pixels
};

// An upright billboard (this file) or a floor sprite (floor_rectifier.h): SpriteKind says which.
struct Billboard {
  SpriteKind kind = SpriteKind::kUpright;
  cv::Mat bgra;    // CV_8UC4 straight alpha, billboard pixels
  cv::Mat shadow;  // CV_8U ground patch centred on the contact point, axes right and -toward
  // Upright: the contact point on the billboard (bottom centre). Floor: the subject's centre
  // (the image's centre).
  Eigen::Vector2d anchor_px;
  Eigen::Vector3d point_in_ground;  // the anchor's point on the floor (z = 0)
  Eigen::Vector2d right_in_ground;  // unit billboard x axis on the floor
  // Upright: unit floor direction from the sprite to the camera. Floor: the direction the
  // subject faces, the image's up (heading_rad's direction).
  Eigen::Vector2d toward_camera;
  double px_per_m = 0;
  // Floor sprites: the ground direction the subject faces, atan2(y, x), and how sure its axis
  // is, 1 - minor / major of the matte's second moments (0 round, towards 1 long and thin).
  double heading_rad = 0;
  double elongation = 0;
  // Floor sprites: how far the body's thickest part (where an animal rests its weight) lies
  // ahead of the outline's centre, along the heading, metres. The clip batcher moves the place
  // there by this, smoothed over the clip (one frame's estimate jitters; the outline's centre
  // does not, but the head pulls it ahead).
  double thickest_ahead_m = 0;
};

class Rectifier {
 public:
  // InputError ("rectifier options") for options out of range.
  explicit Rectifier(RectifierOptions options = {});
  // Why Rectify made no billboard.
  struct Refusal {
    bool too_large = false;  // else: the contact point's ray misses the floor, or degenerate
    int width_px = 0, height_px = 0;  // the billboard it would have made (too_large)
  };
  // nullopt when the contact point's ray misses the floor, the billboard is degenerate, or it
  // would exceed max_side_px at px_per_m; `why` (when given) says which.
  std::optional<Billboard> Rectify(const CameraModel& camera, const SpriteView& view,
                                   Refusal* why = nullptr) const;
  // The horizontally mirrored billboard (seed 000 §2): the image flipped about
  // its vertical axis and the anchor with it; place and axes unchanged. A floor sprite's
  // vertical axis is its body axis: its left and right sides swap.
  static Billboard Mirror(const Billboard& billboard);
  // A ground velocity seen in the mirror: its component along `right` flips.
  static Eigen::Vector2d MirrorVelocity(const Billboard& billboard,
                                        const Eigen::Vector2d& velocity);

  const RectifierOptions& options() const { return options_; }

 private:
  RectifierOptions options_;
};

}  // namespace ss
