#pragma once
// Synthetic board views with known truth for the calibration tests: a studio
// camera (synth/), boards rendered through its true lens at known poses, and
// the sensor's noise on top.
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "calib/board.h"
#include "core/camera_model.h"
#include "core/geometry.h"
#include "synth/board.h"
#include "synth/renderer.h"
#include "synth/scene.h"

namespace ss::testing {

inline calib::BoardSpec ToCalibBoard(const synth::BoardSpec& s) {
  calib::BoardSpec b;
  b.kind = s.kind == synth::BoardKind::kChessboard ? calib::BoardKind::kChessboard
                                                   : calib::BoardKind::kCharuco;
  b.squares_x = s.squares_x;
  b.squares_y = s.squares_y;
  b.square_m = s.square_m;
  b.marker_m = s.marker_m;
  if (!s.dictionary.empty()) b.dictionary = s.dictionary;
  return b;
}

// The synthetic camera's true model, posed on the ground.
inline CameraModel TrueModel(const synth::SynthCamera& cam) {
  return CameraModel(cam.lensmodel, cam.intrinsics, cam.width, cam.height, cam.cam_from_ground);
}

// Renders the camera's view of the boards, with sensor noise (`noise` 1 = typical).
inline cv::Mat RenderBoards(const synth::CameraRenderer& renderer,
                            const std::vector<synth::BoardInstance>& boards, double noise,
                            uint64_t frame) {
  synth::FrameScene scene;
  scene.boards = boards;
  synth::CameraImage image;
  renderer.Render(scene, &image);
  if (noise <= 0) return image.bgr.clone();
  const synth::Sensor sensor(1234, 0, noise);
  std::vector<uint8_t> bytes = sensor.Capture(image.bgr, PixelFormat::kBGR8, frame);
  return cv::Mat(image.bgr.rows, image.bgr.cols, CV_8UC3, bytes.data()).clone();
}

inline Eigen::Matrix3d Rot(double rx, double ry, double rz) {
  return (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// A board pose in front of the camera: its centre towards the normalized image
// point (u, v) in [-1, 1] at `depth_m`, tilted about the board's x and y axes.
// Pulled towards the image centre until the whole board (with margin) is in view.
inline Rigid3 CamFromBoardInView(const synth::SynthCamera& cam, const synth::BoardSpec& spec,
                                 double u, double v, double depth_m, double tilt_x, double tilt_y,
                                 double roll) {
  const Eigen::Matrix3d r = Rot(tilt_x, tilt_y, roll);
  const Eigen::Vector3d centre_in_board(spec.width_m() / 2, spec.height_m() / 2, 0);
  for (int attempt = 0; attempt < 40; ++attempt) {
    const double scale = std::pow(0.9, attempt);
    const Eigen::Vector2d pixel(cam.lens.cx() + u * scale * cam.width * 0.45,
                                cam.lens.cy() + v * scale * cam.height * 0.45);
    const Eigen::Vector3d ray = cam.lens.Unproject(pixel);
    const Eigen::Vector3d centre_in_cam = ray / ray.z() * depth_m;
    Rigid3 cam_from_board{r, centre_in_cam - r * centre_in_board};
    bool inside = true;
    const double m = spec.square_m * 0.8;
    for (double x : {-m, spec.width_m() + m}) {
      for (double y : {-m, spec.height_m() + m}) {
        const Eigen::Vector2d q = cam.lens.Project(cam_from_board * Eigen::Vector3d(x, y, 0));
        inside =
            inside && q.x() > 4 && q.y() > 4 && q.x() < cam.width - 5 && q.y() < cam.height - 5;
      }
    }
    if (inside) return cam_from_board;
  }
  return {r, Eigen::Vector3d(0, 0, depth_m * 1.5) - r * centre_in_board};
}

// A varied set of board poses for an intrinsic calibration (camera frame).
inline std::vector<Rigid3> CalibrationPoses(const synth::SynthCamera& cam,
                                            const synth::BoardSpec& spec, int count,
                                            double depth_m) {
  std::vector<Rigid3> poses;
  const double kDeg = M_PI / 180;
  for (int i = 0; i < count; ++i) {
    const double u = std::sin(i * 2.39996) * (0.3 + 0.7 * ((i * 7) % 11) / 10.0);
    const double v = std::cos(i * 2.39996) * (0.3 + 0.7 * ((i * 5) % 11) / 10.0);
    const double tx = ((i % 5) - 2) * 14 * kDeg, ty = (((i * 3) % 5) - 2) * 14 * kDeg;
    const double roll = ((i % 3) - 1) * 8 * kDeg;
    const double depth = depth_m * (0.85 + 0.3 * ((i * 3) % 7) / 6.0);
    poses.push_back(CamFromBoardInView(cam, spec, u, v, depth, tx, ty, roll));
  }
  return poses;
}

}  // namespace ss::testing
