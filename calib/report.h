#pragma once
// What a calibration engineer needs to trust (or refuse) an intrinsic
// calibration: reprojection RMS and worst error, per-parameter uncertainty,
// mrcal's projection uncertainty at the working distance, how much of the
// image the board covered, the residual and coverage plots (PNG), and a verdict
// with reasons and what to do about them.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "calib/detect.h"
#include "calib/solve.h"

namespace ss::calib {

struct VerdictOptions {
  int min_views = 10;           // fewer accepted views: not enough to trust the model
  double max_rms_px = 0.5;      // RMS reprojection error above this: something is wrong
  double max_worst_px = 3.0;    // a single inlier corner off by more than this
  double min_coverage = 0.5;    // fraction of the image grid cells with observed corners
  double min_tilt_deg = 20.0;   // the most tilted view must be tilted at least this much
  int grid_x = 12, grid_y = 9;  // coverage cells
  // fx, fy, cx, cy each known to this percent of its value (1.96 sigma); 0: not checked.
  double max_stdev_percent = 0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct CameraReport {
  std::string camera;
  int width = 0, height = 0;
  int views_accepted = 0;
  std::vector<std::pair<std::string, std::string>> rejected;  // (view, reason)
  double rms_px = 0, worst_px = 0;
  int outliers = 0;
  std::vector<std::string> parameter_names;  // fx fy cx cy k1 ...
  std::vector<double> intrinsics, intrinsics_stdev;
  double coverage = 0;                     // fraction of grid cells with corners
  std::vector<std::string> empty_regions;  // "left edge", "top-right corner" ...
  double max_tilt_deg = 0;
  double working_distance_m = 0;          // median board distance
  double projection_stdev_centre_px = 0;  // mrcal projection uncertainty at the working distance
  double projection_stdev_worst_px = 0;   // ... worst over a grid across the image
  bool good = false;
  std::vector<std::string> reasons;                    // why not good, each with what to do
  std::string model_file, residual_png, coverage_png;  // written files ("" when none)
};

// Builds camera `camera`'s report from the solve and the detections (accepted and rejected).
CameraReport MakeCameraReport(const BoardSpec& board, const SolveSummary& solution, int camera,
                              const std::vector<BoardView>& views,
                              const VerdictOptions& options = {});

// A report for a camera that could not be solved at all (too few views...), with the reason.
CameraReport FailedCameraReport(const std::string& camera, const std::vector<BoardView>& views,
                                const std::string& reason);

// PNGs: residual vectors (magnified) over the image with a histogram; observed
// corners per cell as a heat map. WorkError naming the file when it cannot be written.
void WriteResidualPlot(const std::string& path, const SolveSummary& solution, int camera);
void WriteCoverageMap(const std::string& path, const SolveSummary& solution, int camera,
                      const VerdictOptions& options);
// mrcal's projection uncertainty (ProjectionStdev) across the image at `distance_m`, as a heat
// map with contours and a scale, the worst and the centre value written on it.
void WriteUncertaintyMap(const std::string& path, const SolveSummary& solution,
                         const BoardSpec& board, int camera, double distance_m);

// Image regions (thirds: "left edge", "top-right corner", "centre"...) whose
// cells of a coverage grid (corner counts, grid_y x grid_x, CV_32F) are all empty.
std::vector<std::string> EmptyRegions(const cv::Mat& counts);

nlohmann::json ToJson(const CameraReport& report);
std::string ToText(const CameraReport& report);  // a few human lines

}  // namespace ss::calib
