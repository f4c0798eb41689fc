#pragma once
// The renderer of seed 000 §6: each sprite's billboard stands upright at its ground
// position facing the virtual camera, at the bank's metric scale (px_per_m, the scale the
// rectifier made it at; pipeline/rectify/rectifier.h), and is projected through the
// camera's full lens model. Sprites are depth sorted (far first) and composited with their
// alpha over the background, after every contact shadow has been laid on the floor.
// The bank's shadow layer is a ground patch at the same scale, centred on the contact
// point: its pixel (u, v) is the floor point p + right (u - (W-1)/2) / s + away (v - (H-1)/2) / s
// (right = the billboard's x axis, away = from the camera), as the rectifier samples it.
// A floor sprite (SpriteKind::kFloor, a subject filmed from above; docs/pipeline.md) lies on the
// floor instead, its top toward its heading, drawn after the shadows and before every upright
// one; its shadow patch shares its axes. It looks true only from above: a virtual camera that
// sees one from shallower than min_floor_view_deg is refused by name, as is one that sees an
// upright sprite from steeper than max_upright_view_deg.
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/bank_records.h"
#include "core/camera_model.h"

namespace ss {

// One sprite to draw; borrows the pixels for the call.
struct PlacedSprite {
  const SpritePixels* pixels = nullptr;  // billboard BGRA (straight alpha) + shadow layer
  Eigen::Vector2d anchor_px = Eigen::Vector2d::Zero();  // contact point on the billboard
  double px_per_m = 0;
  Eigen::Vector2d ground_m = Eigen::Vector2d::Zero();  // contact point on the floor
  SpriteKind kind = SpriteKind::kUpright;
  double heading_rad = 0;  // floor sprites: the ground direction its image's top faces
};

struct RenderOptions {
  bool shadows = true;
  double shadow_opacity = 1.0;  // darkening at a full (255) shadow pixel
  int grid_step_px = 8;         // the lens model is evaluated on this grid, interpolated between
  // A floor sprite seen from shallower than this (the angle between the floor and the ray to
  // the camera at its place) is refused: a subject filmed from above, laid flat, looks like a
  // decal from the side.
  double min_floor_view_deg = 60.0;
  // An upright sprite seen from steeper than this is refused: a billboard standing on the floor
  // is a sliver from straight above (the pipeline refuses to film one there, at
  // pipeline.max_view_angle_deg, the same 75 by default). 90: never.
  double max_upright_view_deg = 75.0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

class SpriteRenderer {
 public:
  // `background` BGR or BGRA of the camera's size, or empty for a transparent background.
  // InputError when the camera is invalid or the background's size differs from it.
  SpriteRenderer(CameraModel camera, const cv::Mat& background, RenderOptions options = {});

  // One frame, CV_8UC4 BGRA (straight alpha; opaque where the background is). InputError
  // ("floor sprite at (x, y)") for a floor sprite seen from shallower than min_floor_view_deg,
  // ("upright sprite at (x, y)") for an upright one seen from steeper than max_upright_view_deg.
  cv::Mat Render(const std::vector<PlacedSprite>& sprites) const;
  // The angle between the floor and the ray from a ground point to the camera, degrees.
  double ViewAngleDeg(const Eigen::Vector2d& ground_m) const;

  const CameraModel& camera() const { return camera_; }
  // Floor direction from a ground point toward the camera (unit); the billboard's normal.
  Eigen::Vector2d TowardCamera(const Eigen::Vector2d& ground_m) const;

 private:
  // Composites one planar layer into the premultiplied float canvas. `layer` is
  // premultiplied CV_32FC4; layer pixel (u, v) is origin + u*du + v*dv in the ground frame.
  void DrawPlane(const cv::Mat& layer, const Eigen::Vector3d& origin, const Eigen::Vector3d& du,
                 const Eigen::Vector3d& dv, cv::Mat* canvas) const;

  CameraModel camera_;
  cv::Mat background_;  // premultiplied CV_32FC4, or empty
  RenderOptions options_;
  Eigen::Vector3d centre_in_ground_;
};

}  // namespace ss
