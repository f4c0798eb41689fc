#pragma once
// The synthetic cameras' own projection, written out from mrcal's definitions of
// LENSMODEL_PINHOLE and LENSMODEL_OPENCV8 (OpenCV's rational model: intrinsics
// fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6). The renderer uses it per pixel so that
// it does not depend on libmrcal; tests check it against the CameraModel.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/geometry.h"

namespace ss::synth {

class Lens {
 public:
  Lens() = default;
  // InputError when the model is not PINHOLE/OPENCV8 or the intrinsics count is wrong.
  Lens(const std::string& lensmodel, const std::vector<double>& intrinsics);

  // Camera-frame point -> pixel; NaN when z <= 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const;
  // Normalized image coordinates (x/z, y/z) -> pixel, distortion applied.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  // Pixel -> unit ray in the camera frame (Newton iterations on Distort).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // Smallest derivative of the distorted radius r_d(r) over [0, r_max] (the
  // mapping is invertible while it stays positive).
  double MinRadialSlope(double r_max) const;

  double fx() const { return k_[0]; }
  double fy() const { return k_[1]; }
  double cx() const { return k_[2]; }
  double cy() const { return k_[3]; }

 private:
  bool distorted_ = false;
  double k_[12] = {1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
};

// One synthetic camera: its lens, imager size and pose against the ground.
struct SynthCamera {
  std::string name;                // "cam0"
  std::string lensmodel;           // "LENSMODEL_OPENCV8"
  std::vector<double> intrinsics;  // mrcal order
  int width = 0;
  int height = 0;
  Rigid3 cam_from_ground;
  Lens lens;
  double gain[3] = {1, 1, 1};  // per-channel sensor gains, B G R
  double vignetting = 0.2;     // relative fall-off at the image corner

  Eigen::Vector3d CentreInGround() const { return cam_from_ground.Inverse().translation; }
  Eigen::Vector2d ProjectGround(const Eigen::Vector3d& point_in_ground) const {
    return lens.Project(cam_from_ground * point_in_ground);
  }
  // Unit direction of the ray through `pixel`, in the ground frame.
  Eigen::Vector3d RayDirectionInGround(const Eigen::Vector2d& pixel) const {
    return cam_from_ground.rotation.transpose() * lens.Unproject(pixel);
  }
};

}  // namespace ss::synth
