#pragma once
// The enclosure's usable floor: a polygon in ground coordinates (metres), from
// points given in ground coordinates, from points picked in a calibrated
// camera's image (rays meet the floor), or found as the largest green floor
// region in a camera's view of the empty enclosure. The result goes into the
// station config's `enclosure.floor` (config/station_config.h; ReplaceEnclosureFloor in
// config/station_save.h edits it), which the pipeline reads.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

// A simple polygon from ground points; InputError naming `field` when it has
// fewer than 3 points, crosses itself or has no area.
GroundPolygon FloorPolygonFromPoints(const std::vector<Eigen::Vector2d>& points_in_ground,
                                     const std::string& field = "--points");

// The floor points seen at these pixels of a posed camera (cam_from_ground set).
GroundPolygon FloorPolygonFromPixels(const CameraModel& model,
                                     const std::vector<Eigen::Vector2d>& pixels,
                                     const std::string& field = "--pixels");

struct GreenFloorOptions {
  double min_green_excess = 30;  // G - max(R, B), 8-bit levels, for a pixel to count as green
  bool split_walls = true;   // green walls are darker than the lit floor: keep the brighter green
  double simplify_m = 0.01;  // polygon simplification tolerance on the floor
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The pixels of `bgr` (8-bit BGR) that pass the green floor test (255, else 0): green
// enough, and with split_walls the brighter of the floor's and the walls' greens.
cv::Mat GreenFloorMask(const cv::Mat& bgr, const GreenFloorOptions& options = {});

// The largest connected green floor region in `bgr`, carried onto the floor.
// InputError when the image holds no green region or its size does not match the model.
GroundPolygon FindGreenFloor(const CameraModel& model, const cv::Mat& bgr,
                             const GreenFloorOptions& options = {});

// Parses "x,y x,y ..." (or ';'-separated) into points; InputError naming `field`.
std::vector<Eigen::Vector2d> ParsePointList(const std::string& text, const std::string& field);

// The config's enclosure section for this floor (YAML, docs/config.md).
std::string EnclosureYaml(const GroundPolygon& floor, double wall_height_m);

}  // namespace ss::calib
