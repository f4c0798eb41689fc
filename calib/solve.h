#pragma once
// The board calibration solve, on mrcal's C library (mrcal_optimize): one or
// several stationary cameras observing a moving board. Camera 0 is the
// reference; board poses are shared between cameras that saw the board at the
// same instant (`frame`), which ties every camera's pose into one frame.
// Seeded with OpenCV (initCameraMatrix2D, solvePnP), solved in stages as
// mrcal-calibrate-cameras does (core only; everything but the board warp with
// outlier rejection; then the warp too), so both reach the same optimum. The covariance of the
// solution comes from mrcal's own residual function (mrcal_optimizer_callback) differentiated
// numerically.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/board.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

// One camera's accepted view of the board at one instant.
struct BoardObservation {
  int camera = 0;        // index into the cameras
  int frame = 0;         // instant; the same frame in two cameras = the same board pose
  std::string source;    // for messages: "cam0 frame 12", a file name
  std::vector<int> ids;  // inner-corner ids
  std::vector<Eigen::Vector2d> pixels;  // observed corners
};

struct SolveCamera {
  std::string name;
  int width = 0, height = 0;
};

struct SolveOptions {
  // any mrcal model with an fx fy cx cy core, splined included
  std::string lensmodel = "LENSMODEL_OPENCV8";
  bool optimize_board_warp = true;  // mrcal's board flex (calobject_warp)
  bool reject_outliers = true;      // mrcal's outlier rejection in the final stage
  bool compute_covariance = true;   // needed for parameter and projection uncertainty
  // Called between the solve's stages ("stage 2 of 3: ...", fraction of the work done): the
  // console shows it while a solve runs.
  std::function<void(const std::string& stage, double fraction)> progress;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h): a lens model mrcal does not
  // know, or one without the fx fy cx cy core the seed needs.
  bool IsValid(std::string* why) const;
};

// The residual of one observed corner after the solve.
struct CornerResidual {
  int camera = 0;
  int observation = 0;       // index into the observations
  int id = 0;                // corner id
  Eigen::Vector2d observed;  // pixel
  Eigen::Vector2d residual;  // projected - observed, pixels
  bool outlier = false;      // thrown out by mrcal
};

struct SolveSummary {
  std::vector<CameraModel> models;      // cam_from_ground holds cam_from_ref (camera 0 = identity)
  std::vector<Rigid3> ref_from_board;   // per frame (board frame of calib/board.h)
  std::vector<bool> frame_used;         // frames with at least one observation
  std::vector<int> observation_frame;   // per observation: index into ref_from_board
  double board_warp[2] = {0, 0};        // mrcal calobject_warp (x2, y2), metres
  std::vector<CornerResidual> corners;  // every observed corner
  std::vector<double> rms_px;    // per camera: sqrt(mean |residual|^2) over inliers (mrcal's RMS)
  std::vector<double> worst_px;  // per camera: largest inlier |residual|
  std::vector<int> outliers;     // per camera
  double mrcal_rms_px = 0;       // as mrcal_optimize reported it
  double pixel_sigma = 0;        // observation noise estimated from the residuals, per coordinate
  // Per camera: standard deviation of each intrinsic (mrcal order), from the covariance.
  std::vector<std::vector<double>> intrinsics_stdev;
  // The solved state and its covariance (internal layout; used by ProjectionStdev).
  std::vector<double> state;
  Eigen::MatrixXd covariance;
  int intrinsics_count = 0;
  std::string summary;  // one line
};

// Solves. InputError for options that are not valid (SolveOptions::IsValid), and (naming the
// camera or view) when a camera has no observation, a camera shares no board view with the others,
// or an observation has fewer than 4 corners; WorkError when mrcal fails.
SolveSummary SolveBoards(const BoardSpec& board, const std::vector<SolveCamera>& cameras,
                         const std::vector<BoardObservation>& observations,
                         const SolveOptions& options = {});

// mrcal's projection uncertainty (the "mean-frames" method of mrcal 2.x): the
// worst-direction standard deviation, in pixels, of the projection of the
// point seen at `pixel` at `distance_m` from camera `camera`. NaN without covariance.
double ProjectionStdev(const SolveSummary& solution, const BoardSpec& board, int camera,
                       const Eigen::Vector2d& pixel, double distance_m);

}  // namespace ss::calib
