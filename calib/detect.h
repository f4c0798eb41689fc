#pragma once
// Board corner detection in one image: chessboards with OpenCV's sector-based
// detector (cv::findChessboardCornersSB, subpixel), ChArUco boards with the
// contrib aruco module (markers, then corners interpolated and refined; a
// partly visible board is fine). Every view is either accepted or rejected
// with a reason a person can act on (no board, blurred, too few corners,
// degenerate, too small).
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/board.h"

namespace ss::calib {

struct DetectOptions {
  // median 10-90% edge rise of the squares; blurrier views are rejected
  double max_edge_width_px = 4.0;
  int min_corners = 12;             // partial (ChArUco) views with fewer corners are rejected
  double min_area_fraction = 0.01;  // corners' convex hull must cover this much of the image
  bool check_sharpness = true;
  // chessboard: CALIB_CB_EXHAUSTIVE (harder views; a frame without a board costs ~2x)
  bool exhaustive = true;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// One image's detection.
struct BoardView {
  std::string source;         // "IMAGE.png" or "cam0 frame 12"
  int width = 0, height = 0;  // image size
  bool accepted = false;
  std::string rejection;                // why it was not accepted ("" when accepted)
  std::vector<int> ids;                 // inner-corner ids (BoardSpec::Corner), ascending
  std::vector<Eigen::Vector2d> pixels;  // the corners, same order as ids
  double edge_width_px = std::numeric_limits<double>::quiet_NaN();  // median edge rise (sharpness)
};

// Detects the board in an 8-bit grey or BGR image. Never throws for an image
// without a board: the view comes back rejected with the reason.
BoardView DetectBoard(const BoardSpec& board, const cv::Mat& image,
                      const DetectOptions& options = {}, const std::string& source = "");

// Median 10-90% rise, in pixels, across the square edges between neighbouring
// detected corners; NaN when no two neighbours were detected.
double MeasureEdgeWidth(const BoardSpec& board, const cv::Mat& grey, const std::vector<int>& ids,
                        const std::vector<Eigen::Vector2d>& pixels);

}  // namespace ss::calib
