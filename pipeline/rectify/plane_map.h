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

// A crop's colour (CV_8UC3) and matte (CV_8U, the same size) at `offset` in the image,
// resampled onto the plane of BuildPlaneMap: CV_8UC4 straight alpha of `size`.
cv::Mat ResampleBgra(const CameraModel& camera, const cv::Mat& bgr, const cv::Mat& alpha,
                     cv::Point offset, const Eigen::Vector3d& origin, const Eigen::Vector3d& du,
                     const Eigen::Vector3d& dv, cv::Size size);

// The contact shadow's ground patch: square, side 2 ceil(radius_m px_per_m) + 1, centred on
// the floor point `centre` (z = 0), its pixel (u, v) along the unit floor axes `right` and
// `away`; resampled from the crop `shadow` at `offset`, or zeros when there is none.
cv::Mat ShadowPatch(const CameraModel& camera, const cv::Mat* shadow, cv::Point offset,
                    const Eigen::Vector3d& centre, const Eigen::Vector3d& right,
                    const Eigen::Vector3d& away, double radius_m, double px_per_m);

}  // namespace ss
