#pragma once
// A calibrated camera: mrcal lens model + intrinsics, imager size, and its pose
// against the ground (`cam_from_ground`, mrcal's rt_cam_ref with the ground as
// the reference frame). Read and written as mrcal `.cameramodel` files through
// libmrcal, so mrcal's own tools open what we write. Pixel coordinates follow
// mrcal (and OpenCV): (0, 0) is the centre of the top-left pixel.
// Every lens model libmrcal 2.2 projects works here: PINHOLE, STEREOGRAPHIC,
// LONLAT, LATLON, OPENCV4/5/8/12, CAHVOR, SPLINED_STEREOGRAPHIC_... (CAHVORE
// projects but cannot be unprojected: Unproject gives NaN).
#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/geometry.h"

namespace ss {

struct MrcalLens;  // the parsed mrcal_lensmodel_t (camera_model.cc), shared and immutable

class CameraModel {
 public:
  CameraModel() = default;
  // `lensmodel` is mrcal's name, e.g. "LENSMODEL_OPENCV8" or "LENSMODEL_PINHOLE".
  // Throws InputError when the name is unknown, the intrinsics count is wrong,
  // a value is not finite or the imager size is not positive.
  CameraModel(const std::string& lensmodel, std::vector<double> intrinsics, int width, int height,
              Rigid3 cam_from_ground);

  // Reads a .cameramodel file; InputError naming the file on any problem.
  static CameraModel Read(const std::string& path);
  // Parses .cameramodel text; `origin` names it in errors.
  static CameraModel Parse(const std::string& text, const std::string& origin);
  // The .cameramodel text. Numbers are written in their shortest exact form,
  // so Parse(ToText()) gives back identical doubles (mrcal's own C writer
  // prints 6 decimals, its Python writer 10 digits: both lose bits).
  std::string ToText() const;
  // Writes ToText() to a file atomically (temp file + rename); WorkError naming the file.
  void Write(const std::string& path) const;

  bool valid() const { return lens_ != nullptr; }  // false only when default-constructed
  const std::string& lensmodel() const { return lensmodel_; }  // mrcal's full configured name
  const std::vector<double>& intrinsics() const {
    return intrinsics_;
  }  // fx fy cx cy, then distortion
  int width() const { return width_; }
  int height() const { return height_; }
  const Rigid3& cam_from_ground() const { return cam_from_ground_; }
  // A new pose is written as itself: the extrinsics as read no longer apply.
  void set_cam_from_ground(const Rigid3& pose) {
    cam_from_ground_ = pose;
    rt_as_read_.reset();
  }
  // Camera centre in ground coordinates.
  Eigen::Vector3d CentreInGround() const;

  // Camera-frame point -> pixel (distortion applied). Points the lens cannot
  // see give NaN: z <= 0 for pinhole-like models (PINHOLE, OPENCV*, CAHVOR*).
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const;
  // Pixel -> unit ray direction in the camera frame (distortion removed); NaN
  // when mrcal cannot unproject it.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // Ground-frame point -> pixel.
  Eigen::Vector2d ProjectGround(const Eigen::Vector3d& point_in_ground) const;
  // The ray through a pixel, in the ground frame (unit direction).
  Ray RayInGround(const Eigen::Vector2d& pixel) const;

  // Batch forms of Project / Unproject: one libmrcal call for `n` points.
  void ProjectMany(const Eigen::Vector3d* points_in_cam, size_t n, Eigen::Vector2d* pixels) const;
  void UnprojectMany(const Eigen::Vector2d* pixels, size_t n, Eigen::Vector3d* rays_in_cam) const;

 private:
  std::string lensmodel_;
  std::vector<double> intrinsics_;
  int width_ = 0;
  int height_ = 0;
  Rigid3 cam_from_ground_;
  std::shared_ptr<const MrcalLens> lens_;
  // The extrinsics as the file had them: rt -> R -> rt moves r by ~1 ulp, so a model read
  // from a file writes these back (a pose read is a pose written, bit for bit).
  std::optional<std::array<double, 6>> rt_as_read_;
};

}  // namespace ss
