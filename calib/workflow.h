#pragma once
// The calibration jobs behind `spritestation calibrate ...`, kept out of apps/
// so tests can run them: intrinsics (one camera or a joint rig) with report,
// plots and verdict; the ground pose of every camera from a board on the floor.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calib/board.h"
#include "calib/ground.h"
#include "calib/inputs.h"
#include "calib/report.h"
#include "calib/solve.h"
#include "core/camera_model.h"

namespace ss::calib {

struct IntrinsicsJob {
  BoardSpec board;
  SolveOptions solve;
  VerdictOptions verdict;
  std::string out_dir;  // DIR/<camera>.cameramodel, .residuals.png, .coverage.png, intrinsics.json
  bool write_rejected = false;  // also write the models of cameras whose verdict is "rejected"
};

struct JobOutcome {
  nlohmann::json report;   // also written to the output folder
  std::string text;        // for a person
  bool all_good = false;   // every camera got a trusted result
  bool any_board = false;  // the board was found at all (false: probably the wrong spec)
};

// Solves every camera with enough accepted views (jointly when there are
// several), writes the files and the report. Cameras with too few views get a
// verdict and no model.
JobOutcome RunIntrinsics(const std::vector<CameraViews>& cameras, const IntrinsicsJob& job);

struct GroundJob {
  BoardSpec board;
  Rigid3 ground_from_board = FloorBoardPose();
  std::string out_dir;  // DIR/<camera>.cameramodel with cam_from_ground, ground.json
  int still_views = 5;  // accepted views averaged per camera
  bool rigid = false;   // models share one reference (joint solve): cameras without a floor view
                        // follow the others
};

// `models[i]` holds camera i's intrinsics (and, with `rigid`, its pose in the shared reference).
JobOutcome RunGround(const std::vector<CameraViews>& cameras,
                     const std::vector<CameraModel>& models, const GroundJob& job);

}  // namespace ss::calib
