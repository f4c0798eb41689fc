#pragma once
// The same corners our detector found, in the form mrcal-calibrate-cameras
// reads (its --corners-cache vnlog: "# filename x y level"), so mrcal's own
// tool can solve exactly the observations we solved and the two results can
// be compared (docs/calibration.md "Cross-check with mrcal").
#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/inputs.h"

namespace ss::calib {

// The file name a view gets in the vnlog: "CAMERA-frame000012.png" (mrcal
// takes the frame number from the digits that vary within one camera's glob;
// the same number in two cameras = the same instant). The image need not exist.
std::string MrcalViewName(const std::string& camera, int frame);

// One full grid (corners_x * corners_y rows, row-major = our corner ids) per
// accepted view; corners not seen (partial ChArUco views) are "- - -".
// Rejected views are left out. Level 0 = weight 1, as in our solve.
std::string MrcalCornersVnl(const BoardSpec& board, const std::vector<CameraViews>& cameras);

// The mrcal-calibrate-cameras command line that solves `vnl_path` into `out_dir`
// with `lensmodel` (one glob per camera, in the order given), creating `out_dir`.
std::string MrcalCalibrateCommand(const BoardSpec& board, const std::vector<CameraViews>& cameras,
                                  const std::string& vnl_path, const std::string& out_dir,
                                  const std::string& lensmodel, double focal_px);

}  // namespace ss::calib
