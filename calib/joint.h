#pragma once
// The joint solve of a rig (issue 41): every camera that saw the board at the same instant in
// one mrcal problem (calib/solve.h SolveBoards: the intrinsics of all and the cameras' poses
// relative to camera 0), and how it compares with the cameras solved one by one (each its own
// intrinsics, each posed by its own floor board: their relative pose is the two ground poses').
#include <limits>
#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/detect.h"
#include "calib/solve.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

// One camera's view of the board and when it was taken (seconds, any clock the cameras share).
struct TimedView {
  int camera = 0;
  double time_s = 0;
  BoardView view;
  // The board stood still in this camera from start_s to time_s (the same pose all along); NaN:
  // the instant time_s alone.
  double start_s = std::numeric_limits<double>::quiet_NaN();
};

// The instants two or more cameras saw the board: each camera's view whose span (start_s to
// time_s) comes within `max_gap_s` (half a frame interval) of another camera's view's span. Two
// cameras that process different frames of a board held still still meet. A camera's views that
// match none are left out, and a camera gives at most one view to an instant (the nearest in
// time); a view goes to one instant. The observations of one instant share a frame, numbered
// from `first_frame` up.
std::vector<BoardObservation> SimultaneousObservations(const std::vector<TimedView>& views,
                                                       double max_gap_s, int first_frame = 0);

struct JointRig {
  SolveSummary solution;            // models[i].cam_from_ground() = cam_i_from_cam_0
  int shared_frames = 0;            // instants seen by two or more cameras
  std::vector<int> views;           // per camera: observations used
  std::vector<double> distance_m;   // per camera: median board distance
  std::vector<double> stdev_px;     // per camera: projection stdev at the image centre, distance_m
  std::vector<double> stdev_worst;  // per camera: the worst of the centre and 4 corners
  // Per camera: fx's and fy's 1.96-sigma uncertainty, the worse, in % (as VerdictOptions'
  // max_stdev_percent reads it); NaN without the covariance.
  std::vector<double> focal_stdev_percent;
};

// One SolveBoards problem: each camera's own views (`own[i]`: camera i alone, each a frame of its
// own) and the simultaneous ones (SimultaneousObservations). InputError (from SolveBoards) when a
// camera shares no instant with the others.
JointRig SolveJointRig(const BoardSpec& board, const std::vector<SolveCamera>& cameras,
                       const std::vector<std::vector<BoardView>>& own,
                       const std::vector<BoardObservation>& simultaneous,
                       const SolveOptions& options);

// Every camera posed on the floor from one: camera `posed`'s cam_from_ground (its floor board)
// carried through the joint relative poses (cam_i_from_ground = cam_i_from_0 * cam_posed_from_0^-1
// * cam_posed_from_ground), as GroundJob::rigid does.
std::vector<Rigid3> PoseRigFrom(const JointRig& rig, int posed, const Rigid3& cam_from_ground);

// As PoseRigFrom, from camera `posed`'s view of the board lying on the floor (`floor_view`, the
// board's frame at `ground_from_board`), its pose solved again with the joint model's intrinsics:
// the pose its wizard solved with the camera's own intrinsics does not agree with the joint
// intrinsics saved beside it. InputError / WorkError as SolveGroundPose.
std::vector<Rigid3> PoseRigFromFloorView(const JointRig& rig, int posed, const BoardSpec& board,
                                         const BoardView& floor_view,
                                         const Rigid3& ground_from_board,
                                         const std::string& camera = "camera");

// Where two cameras disagree: b's pose relative to a from the joint solve against the same from
// the two ground poses (one by one), and a floor point both see (the middle of where their
// optical axes meet the floor) placed in b by each.
struct PairDisagreement {
  int a = 0, b = 1;
  double translation_mm = 0, rotation_deg = 0;  // b_from_a, joint against one by one
  double floor_point_mm = 0;
  Eigen::Vector3d floor_point = Eigen::Vector3d::Zero();  // in ground metres (a's ground)
};
PairDisagreement CompareRelativePose(const Rigid3& b_from_a_joint, const Rigid3& a_from_ground,
                                     const Rigid3& b_from_ground);

// The distance (mm) and angle (degrees) between two poses of the same thing.
double TranslationMm(const Rigid3& x, const Rigid3& y);
double RotationDeg(const Rigid3& x, const Rigid3& y);

}  // namespace ss::calib
