#include "calib/enclosure.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss::calib {
namespace {

GroundPolygon Checked(std::vector<Eigen::Vector2d> points, const std::string& field) {
  if (points.size() < 3) throw InputError(field, "a floor polygon needs at least 3 points");
  if (points.size() > GroundPolygon::kMaxVertices) {
    throw InputError(field, std::to_string(points.size()) +
                                " points; a floor polygon has at most " +
                                std::to_string(GroundPolygon::kMaxVertices));
  }
  GroundPolygon polygon(std::move(points));
  if (!polygon.IsSimple()) {
    throw InputError(field,
                     "the floor polygon crosses itself, repeats a point or has no area; give its "
                     "corners in order");
  }
  return polygon;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

}  // namespace

GroundPolygon FloorPolygonFromPoints(const std::vector<Eigen::Vector2d>& points_in_ground,
                                     const std::string& field) {
  for (const auto& p : points_in_ground) {
    if (!p.allFinite()) throw InputError(field, "a point is not a finite number");
  }
  return Checked(points_in_ground, field);
}

GroundPolygon FloorPolygonFromPixels(const CameraModel& model,
                                     const std::vector<Eigen::Vector2d>& pixels,
                                     const std::string& field) {
  std::vector<Eigen::Vector2d> points;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const auto hit = IntersectGround(model.RayInGround(pixels[i]));
    if (!hit) {
      throw InputError(field, "pixel " + std::to_string(i) + " (" + Number(pixels[i].x()) + ", " +
                                  Number(pixels[i].y()) + ") does not look at the floor");
    }
    points.push_back(hit->head<2>());
  }
  return Checked(points, field);
}

bool GreenFloorOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(min_green_excess, Between(0, 255), "min_green_excess", "8-bit levels 0..255");
  check.Within(simplify_m, AtLeast(0), "simplify_m", "a distance in metres >= 0");
  return check.ok();
}

cv::Mat GreenFloorMask(const cv::Mat& bgr, const GreenFloorOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("green floor options", why);
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw InputError("image", "expected an 8-bit colour image");
  cv::Mat mask(bgr.size(), CV_8U, cv::Scalar(0));
  std::vector<uint8_t> green_levels;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
      if (p[1] - std::max(p[0], p[2]) > options.min_green_excess) {
        mask.at<uint8_t>(y, x) = 255;
        green_levels.push_back(p[1]);
      }
    }
  }
  if (options.split_walls && green_levels.size() >= 2) {
    // Lit from above, the floor is brighter than the green walls: Otsu on the green level.
    cv::Mat levels(1, static_cast<int>(green_levels.size()), CV_8U, green_levels.data()), unused;
    const double t = cv::threshold(levels, unused, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    double lo = 0, hi = 0;
    int nlo = 0, nhi = 0;
    for (uint8_t g : green_levels) (g > t ? (hi += g, ++nhi) : (lo += g, ++nlo));
    if (nlo > 0 && nhi > 0 && hi / nhi - lo / nlo > 20) {
      for (int y = 0; y < bgr.rows; ++y) {
        for (int x = 0; x < bgr.cols; ++x) {
          if (mask.at<uint8_t>(y, x) && bgr.at<cv::Vec3b>(y, x)[1] <= t) mask.at<uint8_t>(y, x) = 0;
        }
      }
    }
  }
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  return mask;
}

GroundPolygon FindGreenFloor(const CameraModel& model, const cv::Mat& bgr,
                             const GreenFloorOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("green floor options", why);
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw InputError("image", "expected an 8-bit colour image");
  if (bgr.cols != model.width() || bgr.rows != model.height()) {
    throw InputError("image", "the image is " + std::to_string(bgr.cols) + "x" +
                                  std::to_string(bgr.rows) + " but the camera model's imager is " +
                                  std::to_string(model.width()) + "x" +
                                  std::to_string(model.height()));
  }
  cv::Mat mask = GreenFloorMask(bgr, options);
  if (cv::countNonZero(mask) < 100) throw InputError("image", "no green floor region in view");
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int best = -1;
  for (int i = 1; i < n; ++i) {
    if (best < 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
      best = i;
  }
  if (best < 0) throw InputError("image", "no green floor region in view");
  cv::Mat region = labels == best;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(region, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) throw InputError("image", "no green floor region in view");
  size_t largest = 0;
  for (size_t i = 1; i < contours.size(); ++i) {
    if (cv::contourArea(contours[i]) > cv::contourArea(contours[largest])) largest = i;
  }
  std::vector<cv::Point2f> on_floor_mm;
  for (const cv::Point& p : contours[largest]) {
    const auto hit = IntersectGround(model.RayInGround(Eigen::Vector2d(p.x, p.y)));
    if (hit)
      on_floor_mm.emplace_back(static_cast<float>(hit->x() * 1000),
                               static_cast<float>(hit->y() * 1000));
  }
  if (on_floor_mm.size() < 3)
    throw InputError("image", "the green region does not lie on the floor");
  std::vector<cv::Point2f> simple;
  cv::approxPolyDP(on_floor_mm, simple, options.simplify_m * 1000, true);
  std::vector<Eigen::Vector2d> vertices;
  vertices.reserve(simple.size());
  for (const auto& p : simple) vertices.emplace_back(p.x / 1000.0, p.y / 1000.0);
  GroundPolygon polygon(vertices);
  if (!polygon.IsSimple())
    throw WorkError("image", "the green floor's outline does not give a simple polygon");
  // Counter-clockwise, like the studio's own floor.
  double twice_area = 0;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const auto& a = vertices[i];
    const auto& b = vertices[(i + 1) % vertices.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  if (twice_area < 0)
    polygon = GroundPolygon(std::vector<Eigen::Vector2d>(vertices.rbegin(), vertices.rend()));
  return polygon;
}

std::vector<Eigen::Vector2d> ParsePointList(const std::string& text, const std::string& field) {
  std::string s = text;
  for (char& c : s) c = (c == ';') ? ' ' : c;
  std::istringstream in(s);
  std::string token;
  std::vector<Eigen::Vector2d> points;
  while (in >> token) {
    double x = 0, y = 0;
    char comma = 0, extra = 0;
    if (std::sscanf(token.c_str(), "%lf%c%lf%c", &x, &comma, &y, &extra) != 3 || comma != ',') {
      throw InputError(field, "expected points as \"x,y x,y ...\", got \"" + token + "\"");
    }
    points.emplace_back(x, y);
  }
  return points;
}

std::string EnclosureYaml(const GroundPolygon& floor, double wall_height_m) {
  std::ostringstream o;
  o << "enclosure:\n  floor:\n";
  for (const auto& v : floor.vertices())
    o << "    - [" << Number(v.x()) << ", " << Number(v.y()) << "]\n";
  o << "  wall_height_m: " << Number(wall_height_m) << "\n";
  return o.str();
}

}  // namespace ss::calib
