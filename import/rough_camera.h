#pragma once
// A camera model for footage without a calibration board: a pinhole camera at
// a given height over the floor, tilted down by a given angle, with a given
// horizontal field of view (no roll, no distortion). Rough, as the numbers a
// person can guess or measure are; docs/import.md says how to choose them.
// Ground frame as everywhere: z up, z = 0 the floor; the camera stands over the
// origin looking along +y.
#include <string>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss {

struct RoughCamera {
  double height_m = 0;  // camera centre above the floor
  double tilt_deg = 0;  // optical axis below the horizontal (90: straight down)
  double hfov_deg = 0;  // horizontal field of view, edge to edge

  // False with the flag at fault and what was expected in `why`.
  bool IsValid(std::string* why) const;
};

// The LENSMODEL_PINHOLE model of `camera` for width x height images. InputError
// (naming the flag) when the camera is invalid or sees no floor at all.
CameraModel RoughCameraModel(const RoughCamera& camera, int width, int height);

// The floor the camera sees: the ground under the image's pixels, out to
// `max_range_m` horizontal distance from the point below the camera. Traced
// along the image's bottom row and, per column, up to the farthest pixel whose
// ray meets the floor within range. InputError when too little is seen to make
// a simple polygon (say so with `--floor`).
GroundPolygon VisibleFloor(const CameraModel& model, double max_range_m);

}  // namespace ss
