#pragma once
// Floor sprites (issue 38): a subject seen from above, laid on the floor. Seed 000's upright
// billboard is right for a camera that films from the side; from above it is seen nearly
// edge-on and holds a sliver (docs/pipeline.md, `view_too_steep`). From above the subject is
// instead resampled onto a horizontal plane at its body height, at the bank's metric scale,
// and turned so that it faces the image's top: every floor sprite faces the same way, so two
// are compared without turning either, a renderer turns one to any heading by laying it on the
// floor at that angle, and the horizontal flip that mirrors an upright billboard mirrors a
// floor sprite too (its left and right sides swap).
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

class FloorRectifier {
 public:
  // The upright rectifier's options (the bank's scale, the margin, the shadow patch, the size
  // limit) and its floor_height_m. InputError ("rectifier options") for options out of range.
  explicit FloorRectifier(RectifierOptions options = {});

  // A Billboard of kind kFloor: CV_8UC4 straight alpha, square with an odd side, the subject
  // seen from above on its body plane facing the image's top (its body axis vertical, its right
  // side to the image's right), the anchor its centre (the image's centre); the shadow patch in
  // the same axes and on the same body plane (so that the floor the body hides lines up with it).
  // heading_rad is the axis's direction, of either sign until ResolveHeadings picks one; elongation
  // how sure it is. nullopt when the subject's rays miss the body plane, its matte is empty, or the
  // sprite would exceed max_side_px (`why->too_large`, with the size it would have had). The anchor
  // is the centre of the matte on that plane, and `thickest_ahead_m` how far its thickest part lies
  // ahead (the clip batcher moves the place there); `view.contact_px` is not used.
  std::optional<Billboard> Rectify(const CameraModel& camera, const SpriteView& view,
                                   Rectifier::Refusal* why = nullptr) const;

  // A floor sprite turned half a turn: its heading plus pi, the same place (what
  // ResolveHeadings asks for when the axis's sign was the tail's).
  static Billboard TurnHalf(const Billboard& sprite);

  // Where a subject seen from above stands, before it is rectified: the ray through its
  // matte's centre (alpha crop at `offset`) meets the body plane at floor_height_m; the floor
  // point under that. What the tracker and the floor's tests read. nullopt when the matte is
  // empty or the ray misses the plane.
  std::optional<Eigen::Vector2d> Place(const CameraModel& camera, const cv::Mat& alpha,
                                       cv::Point offset) const;

  const RectifierOptions& options() const { return options_; }

 private:
  RectifierOptions options_;
};

// One frame of a clip, as ResolveHeadings reads it.
struct HeadingCue {
  double axis_rad = 0;                                 // the body axis (either sign)
  double elongation = 0;                               // Billboard::elongation
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // ground velocity, m/s
};

struct HeadingOptions {
  // Moving faster than this, the subject is taken to move forward (more sure up to twice it).
  // The pipeline's still speed: below it a centre's motion is mostly its outline changing.
  double moving_m_per_s = 0.05;
  // The cost of a frame moving backwards against that of the axis turning half a turn between
  // two frames: a stretch of apparent backward motion must last about 1 / this frames before
  // the signs turn. An animal rearing moves its centre back at up to 0.2 m/s for ~10 frames
  // (the synthetic hamster standing up, seen from above); walking, it moves forward for
  // hundreds.
  double backwards_weight = 0.1;
};

// For each frame of a clip, true when its axis points tail first (turn the sprite half a turn).
// The signs minimise, over the clip (a two-state Viterbi), the axis's turn between consecutive
// frames (weighted by how elongated both are) plus, where the subject moves, how far its
// heading lies from its direction of travel. `before`: the heading of the frame before the
// first, already decided (a clip handed out in batches), which the first frame turns from.
std::vector<bool> ResolveHeadings(const std::vector<HeadingCue>& clip,
                                  const HeadingOptions& options = {},
                                  std::optional<double> before = std::nullopt);

}  // namespace ss
