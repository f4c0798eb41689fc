#include "import/rough_camera.h"

#include <cmath>
#include <optional>
#include <vector>

#include "core/error.h"

namespace ss {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace

bool RoughCamera::IsValid(std::string* why) const {
  if (!(height_m > 0 && height_m < 1000)) {
    *why = "--camera-height: expected metres above the floor, > 0, got " + std::to_string(height_m);
    return false;
  }
  if (!(tilt_deg > -90 && tilt_deg <= 90)) {
    *why = "--tilt: expected degrees below the horizontal, in (-90, 90], got " +
           std::to_string(tilt_deg);
    return false;
  }
  if (!(hfov_deg >= 1 && hfov_deg <= 170)) {
    *why = "--hfov: expected the horizontal field of view in degrees, 1 to 170, got " +
           std::to_string(hfov_deg);
    return false;
  }
  return true;
}

CameraModel RoughCameraModel(const RoughCamera& camera, int width, int height) {
  std::string why;
  if (!camera.IsValid(&why)) throw InputError(why);
  const double f = 0.5 * width / std::tan(0.5 * camera.hfov_deg * kDegToRad);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  // The bottom row must look below the horizon, or the camera sees no floor.
  const double lowest_ray_deg = camera.tilt_deg + std::atan((height - 1 - cy) / f) / kDegToRad;
  if (!(lowest_ray_deg > 0.5)) {
    throw InputError("--tilt", "a camera tilted " + std::to_string(camera.tilt_deg) +
                                   " degrees down with a " + std::to_string(camera.hfov_deg) +
                                   " degree field of view sees no floor; its image's " +
                                   "bottom row looks " + std::to_string(lowest_ray_deg) +
                                   " degrees down");
  }
  // Camera axes in the ground frame: x right, y down the image, z forward.
  const double t = camera.tilt_deg * kDegToRad;
  Eigen::Matrix3d ground_from_cam;
  ground_from_cam.col(0) = Eigen::Vector3d(1, 0, 0);
  ground_from_cam.col(1) = Eigen::Vector3d(0, -std::sin(t), -std::cos(t));
  ground_from_cam.col(2) = Eigen::Vector3d(0, std::cos(t), -std::sin(t));
  const Rigid3 ground_from_cam_pose{ground_from_cam, Eigen::Vector3d(0, 0, camera.height_m)};
  return CameraModel("LENSMODEL_PINHOLE", {f, f, cx, cy}, width, height,
                     ground_from_cam_pose.Inverse());
}

GroundPolygon VisibleFloor(const CameraModel& model, double max_range_m) {
  const Eigen::Vector3d centre = model.CentreInGround();
  const auto hit = [&](double x, double y) -> std::optional<Eigen::Vector2d> {
    const auto p = IntersectGround(model.RayInGround({x, y}));
    if (!p) return std::nullopt;
    const Eigen::Vector2d g = p->head<2>();
    if ((g - centre.head<2>()).norm() > max_range_m) return std::nullopt;
    return g;
  };
  const int w = model.width(), h = model.height();
  const int columns = 33;
  std::vector<Eigen::Vector2d> far, near;
  for (int i = 0; i < columns; ++i) {
    const double x = (w - 1) * static_cast<double>(i) / (columns - 1);
    const auto bottom = hit(x, h - 1);
    if (!bottom) continue;
    // The farthest row still on the floor within range: rows nearer the bottom
    // see nearer floor (a camera above the floor), so bisect.
    double lo = h - 1, hi = 0;
    if (!hit(x, 0)) {
      for (int k = 0; k < 40; ++k) {
        const double mid = 0.5 * (lo + hi);
        (hit(x, mid) ? lo : hi) = mid;
      }
    } else {
      lo = 0;
    }
    far.push_back(*hit(x, lo));
    near.push_back(*bottom);
  }
  std::vector<Eigen::Vector2d> vertices = far;
  vertices.insert(vertices.end(), near.rbegin(), near.rend());
  GroundPolygon polygon(std::move(vertices));
  if (!polygon.IsSimple()) {
    throw InputError("--floor", "the floor this camera sees within " + std::to_string(max_range_m) +
                                    " m is not a simple polygon; give the floor with --floor FILE");
  }
  return polygon;
}

}  // namespace ss
