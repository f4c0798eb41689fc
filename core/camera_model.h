#pragma once
// A calibrated camera: mrcal lens model + intrinsics, imager size, and its pose
// against the ground (`cam_from_ground`, mrcal's rt_cam_ref with the ground as
// the reference frame). Read and written as mrcal `.cameramodel` files through
// libmrcal, so mrcal's own tools open what we write.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/geometry.h"

namespace ss {

class CameraModel {
 public:
  CameraModel() = default;
  // `lensmodel` is mrcal's name, e.g. "LENSMODEL_OPENCV8" or "LENSMODEL_PINHOLE".
  // Throws InputError when the name is unknown or the intrinsics count is wrong.
  CameraModel(std::string lensmodel, std::vector<double> intrinsics, int width, int height,
              Rigid3 cam_from_ground);

  // Reads a .cameramodel file; InputError naming the file on any problem.
  static CameraModel Read(const std::string& path);
  // Parses .cameramodel text; `origin` names it in errors.
  static CameraModel Parse(const std::string& text, const std::string& origin);
  // Writes a .cameramodel file (WorkError naming the file when it cannot).
  void Write(const std::string& path) const;

  const std::string& lensmodel() const { return lensmodel_; }
  const std::vector<double>& intrinsics() const { return intrinsics_; }  // fx fy cx cy, then distortion
  int width() const { return width_; }
  int height() const { return height_; }
  const Rigid3& cam_from_ground() const { return cam_from_ground_; }
  void set_cam_from_ground(const Rigid3& pose) { cam_from_ground_ = pose; }
  // Camera centre in ground coordinates.
  Eigen::Vector3d CentreInGround() const;

  // Camera-frame point -> pixel (distortion applied). Points behind the camera give NaN.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const;
  // Pixel -> unit ray direction in the camera frame (distortion removed).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // Ground-frame point -> pixel.
  Eigen::Vector2d ProjectGround(const Eigen::Vector3d& point_in_ground) const;
  // The ray through a pixel, in the ground frame.
  Ray RayInGround(const Eigen::Vector2d& pixel) const;

 private:
  std::string lensmodel_;
  std::vector<double> intrinsics_;
  int width_ = 0;
  int height_ = 0;
  Rigid3 cam_from_ground_;
};

}  // namespace ss
