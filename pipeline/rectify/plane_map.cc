#include "pipeline/rectify/plane_map.h"

#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/grid_map.h"

namespace ss {
namespace {

// Coarse grid step (target pixels) at which points go through the full lens
// model; the dense remap is interpolated in between. Lens distortion varies
// slowly, so 8 px keeps the interpolation error far below a pixel.
constexpr int kGridStep = 8;

}  // namespace

void BuildPlaneMap(const CameraModel& camera, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& du, const Eigen::Vector3d& dv, cv::Size size,
                   cv::Point offset, cv::Mat& map) {
  const int gw = GridPoints(size.width, kGridStep);
  const int gh = GridPoints(size.height, kGridStep);
  std::vector<Eigen::Vector2f> grid(static_cast<size_t>(gw) * gh);
  for (int gy = 0; gy < gh; ++gy) {
    for (int gx = 0; gx < gw; ++gx) {
      const Eigen::Vector3d p = origin + (gx * kGridStep) * du + (gy * kGridStep) * dv;
      const Eigen::Vector2d px = camera.ProjectGround(p);
      grid[gy * gw + gx] = Eigen::Vector2f(static_cast<float>(px.x() - offset.x),
                                           static_cast<float>(px.y() - offset.y));
    }
  }
  InterpolateGridMap(grid, kGridStep, size, std::nullopt, map);
}

cv::Mat ResampleBgra(const CameraModel& camera, const cv::Mat& bgr, const cv::Mat& alpha,
                     cv::Point offset, const Eigen::Vector3d& origin, const Eigen::Vector3d& du,
                     const Eigen::Vector3d& dv, cv::Size size) {
  cv::Mat map;
  BuildPlaneMap(camera, origin, du, dv, size, offset, map);
  std::array<cv::Mat, 4> channels;
  cv::Mat colour;
  cv::remap(bgr, colour, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  cv::split(colour, channels.data());
  cv::remap(alpha, channels[3], map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(0));
  cv::Mat out;
  cv::merge(channels.data(), 4, out);
  return out;
}

cv::Mat ShadowPatch(const CameraModel& camera, const cv::Mat* shadow, cv::Point offset,
                    const Eigen::Vector3d& centre, const Eigen::Vector3d& right,
                    const Eigen::Vector3d& away, double radius_m, double px_per_m) {
  const int side = 2 * static_cast<int>(std::ceil(radius_m * px_per_m)) + 1;
  if (shadow == nullptr || shadow->empty()) return cv::Mat::zeros(side, side, CV_8U);
  const double half = (side - 1) / 2.0 / px_per_m;
  cv::Mat map, out;
  BuildPlaneMap(camera, centre - right * half - away * half, right / px_per_m, away / px_per_m,
                cv::Size(side, side), offset, map);
  cv::remap(*shadow, out, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

}  // namespace ss
