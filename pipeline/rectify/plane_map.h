#pragma once
// The remap that resamples a camera image onto a plane in the ground frame: what the upright
// billboard (rectifier.h), its ground shadow patch and the floor sprite (floor_rectifier.h)
// each lay their pixels on.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera_model.h"

namespace ss {

// Fills `map` (CV_32FC2 of `size`, for cv::remap) from a `size` target to image pixels minus
// `offset`, where target pixel (u, v) is the ground-frame point `origin + u * du + v * dv`. The
// lens model runs on a coarse grid and is interpolated between (core/grid_map.h).
void BuildPlaneMap(const CameraModel& camera, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& du, const Eigen::Vector3d& dv, cv::Size size,
                   cv::Point offset, cv::Mat& map);

}  // namespace ss
