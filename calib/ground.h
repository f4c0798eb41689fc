#pragma once
// The ground plane from a board lying flat on the floor: the board's pose in
// each camera (intrinsics known) gives cam_from_ground = cam_from_board *
// board_from_ground, with the ground frame z up, z = 0 the floor, metres.
// The pose is seeded with OpenCV (IPPE on undistorted rays) and refined in
// pixels by mrcal_optimize with the intrinsics held fixed.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/board.h"
#include "calib/detect.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

// A board lying face-up on the floor: the checkered area's top-left corner at
// ground (x_m, y_m), its x axis turned by yaw_deg from ground x, its printed
// surface thickness_m above the floor. Ground y = -board y, ground z = -board z.
Rigid3 FloorBoardPose(double x_m = 0, double y_m = 0, double yaw_deg = 0, double thickness_m = 0);

// The mean of views of a board that did not move (same ids in all), which
// lowers the corner noise; InputError when the views disagree by more than
// `max_motion_px` (the board moved) or none was accepted.
BoardView AverageStillViews(const std::vector<BoardView>& views, double max_motion_px = 1.0);

struct GroundResult {
  std::string camera;
  Rigid3 cam_from_ground;
  Eigen::Vector3d centre_in_ground = Eigen::Vector3d::Zero();  // camera position, metres
  double height_m = 0;                                         // camera height above the floor
  double optical_axis_down_deg = 0;  // angle of the optical axis below the horizon
  double rms_px = 0, worst_px = 0;   // the floor board's reprojection
  int corners = 0;
};

// Solves one camera's pose against the ground. InputError when the view has
// fewer than 4 corners; WorkError when the pose cannot be found.
GroundResult SolveGroundPose(const CameraModel& model, const BoardSpec& board,
                             const BoardView& view, const Rigid3& ground_from_board,
                             const std::string& camera = "camera");

// Corners seen by camera a, carried through the board plane into camera b,
// against b's own detections of the same corners.
struct CrossCheck {
  std::string from, to;
  int points = 0;
  double rms_px = 0, worst_px = 0;
};
CrossCheck CrossReprojection(const CameraModel& a, const BoardView& view_a, const CameraModel& b,
                             const BoardView& view_b, const Rigid3& ground_from_board);

}  // namespace ss::calib
