#pragma once
// Floor sprites (issue 38): a subject seen from above, laid on the floor. Seed 000's upright
// billboard is right for a camera that films from the side; from above it is seen nearly
// edge-on and holds a sliver (docs/pipeline.md, `view_too_steep`). From above the subject is
// instead resampled onto a horizontal plane at its body height, at the bank's metric scale,
// and turned so that its body axis runs along the image's +x: every floor sprite faces the same
// way, so two are compared without turning either, and a renderer turns one to any heading by
// laying it on the floor at that angle.
//
// The body axis comes from the matte's second moments on that plane, which leave its sign
// open (head or tail): ResolveHeadings picks the signs of a whole clip at once, from how the
// axis turns between frames and which way the subject moves.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera_model.h"
#include "pipeline/rectify/rectifier.h"

namespace ss {

struct FloorRectifierOptions {
  double px_per_m = 800.0;  // the bank's scale, px per metre (as RectifierOptions)
  double margin_m = 0.01;   // border around the subject, metres
  // The plane the subject is laid on, metres above the floor: where its outline seen from
  // above lies (the widest part of the body). A subject's centre seen through the lens is
  // found on this plane, so a wrong height moves the ground position by height error x
  // tan(off-nadir angle): 1 cm off at 20 degrees off the vertical is 3.6 mm.
  double body_height_m = 0.03;
  double shadow_radius_m = 0.08;  // half-size of the square ground patch for the shadow
  int max_side_px = 512;          // largest side, px (>= 3)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct FloorSprite {
  // CV_8UC4 straight alpha, square with an odd side: the subject seen from above on its body
  // plane, its body axis along +x (image right), its left side up. The centre pixel is the
  // subject's centre.
  cv::Mat bgra;
  // CV_8U contact shadow on the floor (z = 0), the same axes and centre as `bgra`, side
  // 2 * shadow_radius * px_per_m + 1.
  cv::Mat shadow;
  Eigen::Vector2d anchor_px;        // the centre pixel, ((side - 1) / 2, (side - 1) / 2)
  Eigen::Vector3d point_in_ground;  // the floor point under the subject's centre (z = 0)
  double heading_rad = 0;           // the ground direction of the image's +x, atan2(y, x)
  // How sure the axis is: 1 - minor / major of the matte's second moments on the body plane
  // (0 round, towards 1 long and thin).
  double elongation = 0;
  double px_per_m = 0;
};

class FloorRectifier {
 public:
  // InputError ("floor rectifier options") for options out of range.
  explicit FloorRectifier(FloorRectifierOptions options = {});

  // nullopt when the subject's rays miss the body plane, its matte is empty, or the sprite
  // would exceed max_side_px (`why->too_large`, with the size it would have had).
  // `view.contact_px` is not used: from above, the centre of the matte is the subject's place.
  std::optional<FloorSprite> Rectify(const CameraModel& camera, const SpriteView& view,
                                     Rectifier::Refusal* why = nullptr) const;

  // The sprite turned half a turn: its heading plus pi, the same place (what ResolveHeadings
  // asks for when the axis's sign was the tail's).
  static FloorSprite TurnHalf(const FloorSprite& sprite);
  // The mirrored floor sprite (seed 000 §2): flipped across its body axis (left and right
  // sides swapped), the same place and heading.
  static FloorSprite Mirror(const FloorSprite& sprite);

  const FloorRectifierOptions& options() const { return options_; }

 private:
  FloorRectifierOptions options_;
};

// One frame of a clip, as ResolveHeadings reads it.
struct HeadingCue {
  double axis_rad = 0;                                 // the body axis (either sign)
  double elongation = 0;                               // FloorSprite::elongation
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // ground velocity, m/s
};

struct HeadingOptions {
  // Moving faster than this, the subject is taken to move forward (more sure up to twice it).
  double moving_m_per_s = 0.03;
  // The cost of moving backwards against that of the axis turning half a turn between frames.
  double backwards_weight = 0.5;
};

// For each frame of a clip, true when its axis points tail first (turn the sprite half a turn).
// The signs minimise, over the clip (a two-state Viterbi), the axis's turn between consecutive
// frames (weighted by how elongated both are) plus, where the subject moves, how far its
// heading lies from its direction of travel.
std::vector<bool> ResolveHeadings(const std::vector<HeadingCue>& clip,
                                  const HeadingOptions& options = {});

}  // namespace ss
