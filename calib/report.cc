#include "calib/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image_file.h"
#include "core/option_checks.h"

namespace ss::calib {
namespace {

std::vector<std::string> ParameterNames(const std::string& lensmodel, int count) {
  std::vector<std::string> names = {"fx", "fy", "cx", "cy"};
  if (lensmodel.rfind("LENSMODEL_OPENCV", 0) == 0) {
    for (const char* n : {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"})
      names.push_back(n);
  } else if (lensmodel.rfind("LENSMODEL_CAHVOR", 0) == 0) {
    for (const char* n : {"alpha", "beta", "r0", "r1", "r2", "e0", "e1", "e2", "linearity"})
      names.push_back(n);
  }
  for (int i = static_cast<int>(names.size()); i < count; ++i)
    names.push_back("d" + std::to_string(i - 4));
  names.resize(count);
  return names;
}

std::vector<const CornerResidual*> CameraCorners(const SolveSummary& s, int camera,
                                                 bool inliers_only) {
  std::vector<const CornerResidual*> out;
  for (const auto& c : s.corners) {
    if (c.camera == camera && (!inliers_only || !c.outlier)) out.push_back(&c);
  }
  return out;
}

cv::Mat CellCounts(const SolveSummary& s, int camera, const VerdictOptions& o) {
  const CameraModel& m = s.models[camera];
  cv::Mat counts(o.grid_y, o.grid_x, CV_32F, cv::Scalar(0));
  for (const auto* c : CameraCorners(s, camera, true)) {
    const int gx = static_cast<int>(c->observed.x() / m.width() * o.grid_x);
    const int gy = static_cast<int>(c->observed.y() / m.height() * o.grid_y);
    if (gx >= 0 && gy >= 0 && gx < o.grid_x && gy < o.grid_y) counts.at<float>(gy, gx) += 1;
  }
  return counts;
}

}  // namespace

std::vector<std::string> EmptyRegions(const cv::Mat& counts) {
  static const char* kNames[3][3] = {{"top-left corner", "top edge", "top-right corner"},
                                     {"left edge", "centre", "right edge"},
                                     {"bottom-left corner", "bottom edge", "bottom-right corner"}};
  std::vector<std::string> out;
  for (int ry = 0; ry < 3; ++ry) {
    for (int rx = 0; rx < 3; ++rx) {
      const cv::Range ys(ry * counts.rows / 3, (ry + 1) * counts.rows / 3);
      const cv::Range xs(rx * counts.cols / 3, (rx + 1) * counts.cols / 3);
      if (cv::sum(counts(ys, xs))[0] == 0) out.push_back(kNames[ry][rx]);
    }
  }
  return out;
}

bool VerdictOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(min_views, AtLeast(1), "min_views", "at least 1 view");
  check.Within(max_rms_px, Positive(), "max_rms_px", "a positive error in pixels");
  check.Within(max_worst_px, Positive(), "max_worst_px", "a positive error in pixels");
  check.Within(min_coverage, Between(0, 1), "min_coverage", "a fraction 0..1");
  check.Within(min_tilt_deg, FromUpTo(0, 90), "min_tilt_deg", "degrees within [0, 90)");
  check.Within(grid_x, AtLeast(1), "grid_x", "at least 1 cell");
  check.Within(grid_y, AtLeast(1), "grid_y", "at least 1 cell");
  check.Within(max_stdev_percent, AtLeast(0), "max_stdev_percent",
               "0 (not checked) or a percentage");
  return check.ok();
}

CameraReport MakeCameraReport(const BoardSpec& board, const SolveSummary& solution, int camera,
                              const std::vector<BoardView>& views, const VerdictOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("verdict options", why);
  (void)board;
  CameraReport r;
  const CameraModel& m = solution.models.at(camera);
  r.camera = "camera" + std::to_string(camera);
  r.width = m.width();
  r.height = m.height();
  for (const auto& v : views) {
    if (v.accepted) {
      ++r.views_accepted;
    } else {
      r.rejected.emplace_back(v.source, v.rejection);
    }
  }
  r.rms_px = solution.rms_px.at(camera);
  r.worst_px = solution.worst_px.at(camera);
  r.outliers = solution.outliers.at(camera);
  r.intrinsics = m.intrinsics();
  r.parameter_names = ParameterNames(m.lensmodel(), static_cast<int>(r.intrinsics.size()));
  r.intrinsics_stdev = solution.intrinsics_stdev.at(camera);
  const cv::Mat counts = CellCounts(solution, camera, options);
  r.coverage = cv::countNonZero(counts) / static_cast<double>(counts.total());
  r.empty_regions = EmptyRegions(counts);

  // Tilt and distance of every view of this camera.
  std::vector<double> distances;
  std::vector<bool> seen(solution.observation_frame.size(), false);
  for (const auto* c : CameraCorners(solution, camera, false)) seen[c->observation] = true;
  const Rigid3 cam_from_ref = m.cam_from_ground();
  const Eigen::Vector3d centre(board.squares_x * board.square_m / 2,
                               board.squares_y * board.square_m / 2, 0);
  for (size_t i = 0; i < seen.size(); ++i) {
    if (!seen[i]) continue;
    const Rigid3 cam_from_board =
        cam_from_ref * solution.ref_from_board[solution.observation_frame[i]];
    const double tilt =
        std::acos(std::min(1.0, std::abs(cam_from_board.rotation(2, 2)))) * 180 / M_PI;
    r.max_tilt_deg = std::max(r.max_tilt_deg, tilt);
    distances.push_back((cam_from_board * centre).norm());
  }
  if (!distances.empty()) {
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    r.working_distance_m = distances[distances.size() / 2];
    r.projection_stdev_centre_px =
        ProjectionStdev(solution, board, camera, {(m.width() - 1) / 2.0, (m.height() - 1) / 2.0},
                        r.working_distance_m);
    double worst = 0;
    for (int gy = 0; gy < 4; ++gy) {
      for (int gx = 0; gx < 5; ++gx) {
        const Eigen::Vector2d q((m.width() - 1) * (0.05 + 0.9 * gx / 4.0),
                                (m.height() - 1) * (0.05 + 0.9 * gy / 3.0));
        worst = std::max(worst, ProjectionStdev(solution, board, camera, q, r.working_distance_m));
      }
    }
    r.projection_stdev_worst_px = worst;
  }

  char buf[256];
  if (r.views_accepted < options.min_views) {
    std::snprintf(buf, sizeof buf, "too few views: %d accepted (need %d); capture more board views",
                  r.views_accepted, options.min_views);
    r.reasons.push_back(buf);
  }
  if (r.coverage < options.min_coverage || !r.empty_regions.empty()) {
    std::string where;
    for (const auto& e : r.empty_regions) where += (where.empty() ? "" : ", ") + e;
    std::snprintf(buf, sizeof buf, "poor coverage: corners in %.0f%% of the image (need %.0f%%)",
                  r.coverage * 100, options.min_coverage * 100);
    r.reasons.push_back(std::string(buf) + (where.empty() ? "" : "; cover the " + where));
  }
  if (!(r.rms_px <= options.max_rms_px)) {
    std::snprintf(
        buf, sizeof buf,
        "high residuals: RMS %.3f px (limit %.2f px); check the board spec, flatness and focus",
        r.rms_px, options.max_rms_px);
    r.reasons.push_back(buf);
  }
  if (!(r.worst_px <= options.max_worst_px)) {
    std::snprintf(buf, sizeof buf,
                  "worst corner off by %.2f px (limit %.1f px); see the residual plot", r.worst_px,
                  options.max_worst_px);
    r.reasons.push_back(buf);
  }
  if (r.max_tilt_deg < options.min_tilt_deg) {
    std::snprintf(buf, sizeof buf,
                  "views too frontal: most tilted view %.0f deg (need %.0f); tilt the board more",
                  r.max_tilt_deg, options.min_tilt_deg);
    r.reasons.push_back(buf);
  }
  if (options.max_stdev_percent > 0) {
    for (size_t i = 0; i < 4 && i < r.intrinsics.size() && i < r.intrinsics_stdev.size(); ++i) {
      const double percent = 1.96 * r.intrinsics_stdev[i] / std::abs(r.intrinsics[i]) * 100;
      if (!(percent <= options.max_stdev_percent)) {
        std::snprintf(buf, sizeof buf,
                      "%s known to %.2f%% only (1.96 sigma; need %.2f%%); capture more views, "
                      "tilted and nearer the edges",
                      i < r.parameter_names.size() ? r.parameter_names[i].c_str() : "?", percent,
                      options.max_stdev_percent);
        r.reasons.push_back(buf);
      }
    }
  }
  r.good = r.reasons.empty();
  return r;
}

CameraReport FailedCameraReport(const std::string& camera, const std::vector<BoardView>& views,
                                const std::string& reason) {
  CameraReport r;
  r.camera = camera;
  for (const auto& v : views) {
    if (v.accepted) {
      ++r.views_accepted;
    } else {
      r.rejected.emplace_back(v.source, v.rejection);
    }
    r.width = std::max(r.width, v.width);
    r.height = std::max(r.height, v.height);
  }
  r.rms_px = r.worst_px = NAN;
  r.good = false;
  r.reasons.push_back(reason);
  return r;
}

void WriteResidualPlot(const std::string& path, const SolveSummary& solution, int camera) {
  const CameraModel& m = solution.models.at(camera);
  const double scale = std::min(1.0, 1280.0 / m.width());
  const int w = static_cast<int>(m.width() * scale), h = static_cast<int>(m.height() * scale);
  const int hist_h = 140;
  cv::Mat canvas(h + hist_h, w, CV_8UC3, cv::Scalar(30, 30, 30));
  const auto all = CameraCorners(solution, camera, false);
  std::vector<double> mags;
  for (const auto* c : all) {
    if (!c->outlier) mags.push_back(c->residual.norm());
  }
  const double rms = solution.rms_px.at(camera);
  double p95 = 0;
  if (!mags.empty()) {
    std::vector<double> sorted = mags;
    std::sort(sorted.begin(), sorted.end());
    p95 = sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)];
  }
  const double gain = p95 > 0 ? 25.0 / p95 : 1.0;  // a 95th-percentile residual draws 25 px long
  for (const auto* c : all) {
    const cv::Point2d a(c->observed.x() * scale, c->observed.y() * scale);
    if (c->outlier) {
      cv::drawMarker(canvas, a, cv::Scalar(255, 0, 255), cv::MARKER_TILTED_CROSS, 8, 1);
      continue;
    }
    const double mag = c->residual.norm();
    const cv::Scalar colour = mag <= rms       ? cv::Scalar(80, 200, 80)
                              : mag <= 2 * rms ? cv::Scalar(0, 220, 255)
                                               : cv::Scalar(60, 60, 255);
    const cv::Point2d b = a + cv::Point2d(c->residual.x(), c->residual.y()) * gain * scale;
    cv::line(canvas, a, b, colour, 1, cv::LINE_AA);
    cv::circle(canvas, a, 1, colour, -1);
  }
  char text[200];
  std::snprintf(text, sizeof text,
                "residuals x%.0f   RMS %.3f px   worst %.3f px   outliers %d (magenta)", gain, rms,
                solution.worst_px.at(camera), solution.outliers.at(camera));
  cv::putText(canvas, text, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  // Histogram of |residual|, 40 bins up to 3x the 95th percentile.
  const int bins = 40;
  const double top = std::max(1e-3, 3 * p95);
  std::vector<int> hist(bins, 0);
  for (double v : mags) ++hist[std::min(bins - 1, static_cast<int>(v / top * bins))];
  const int peak = std::max(1, *std::max_element(hist.begin(), hist.end()));
  const int bw = std::max(1, (w - 20) / bins);
  for (int i = 0; i < bins; ++i) {
    const int bh = hist[i] * (hist_h - 40) / peak;
    cv::rectangle(canvas, cv::Rect(10 + i * bw, h + hist_h - 20 - bh, bw - 1, bh),
                  cv::Scalar(200, 200, 200), -1);
  }
  std::snprintf(text, sizeof text, "|residual| histogram, 0 .. %.2f px", top);
  cv::putText(canvas, text, {10, h + hist_h - 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WriteImageFile(path, canvas, "PNG");
}

void WriteCoverageMap(const std::string& path, const SolveSummary& solution, int camera,
                      const VerdictOptions& options) {
  const CameraModel& m = solution.models.at(camera);
  const double scale = std::min(1.0, 1280.0 / m.width());
  const int w = static_cast<int>(m.width() * scale), h = static_cast<int>(m.height() * scale);
  const cv::Mat counts = CellCounts(solution, camera, options);
  double peak = 1;
  cv::minMaxLoc(counts, nullptr, &peak);
  cv::Mat levels;
  counts.convertTo(levels, CV_8U, 255.0 / std::max(1.0, peak));
  cv::Mat coloured, canvas;
  cv::applyColorMap(levels, coloured, cv::COLORMAP_INFERNO);
  cv::resize(coloured, canvas, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
  for (const auto* c : CameraCorners(solution, camera, true)) {
    cv::circle(canvas, cv::Point2d(c->observed.x() * scale, c->observed.y() * scale), 1,
               cv::Scalar(255, 255, 255), -1);
  }
  for (int gx = 1; gx < options.grid_x; ++gx)
    cv::line(canvas, {gx * w / options.grid_x, 0}, {gx * w / options.grid_x, h},
             cv::Scalar(90, 90, 90));
  for (int gy = 1; gy < options.grid_y; ++gy)
    cv::line(canvas, {0, gy * h / options.grid_y}, {w, gy * h / options.grid_y},
             cv::Scalar(90, 90, 90));
  char text[160];
  std::snprintf(text, sizeof text, "coverage %.0f%% of %dx%d cells, up to %.0f corners per cell",
                100.0 * cv::countNonZero(counts) / counts.total(), options.grid_x, options.grid_y,
                peak);
  cv::putText(canvas, text, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  WriteImageFile(path, canvas, "PNG");
}

void WriteUncertaintyMap(const std::string& path, const SolveSummary& solution,
                         const BoardSpec& board, int camera, double distance_m) {
  const CameraModel& m = solution.models.at(camera);
  const double scale = std::min(1.0, 960.0 / m.width());
  const int w = static_cast<int>(m.width() * scale), h = static_cast<int>(m.height() * scale);
  // Sampled on a coarse grid (each sample is a small covariance product), then interpolated.
  constexpr int kX = 24, kY = 18;
  cv::Mat samples(kY, kX, CV_32F);
  double worst = 0;
  for (int gy = 0; gy < kY; ++gy) {
    for (int gx = 0; gx < kX; ++gx) {
      const Eigen::Vector2d q((m.width() - 1) * gx / (kX - 1.0),
                              (m.height() - 1) * gy / (kY - 1.0));
      const double s = ProjectionStdev(solution, board, camera, q, distance_m);
      samples.at<float>(gy, gx) = std::isfinite(s) ? static_cast<float>(s) : 0.f;
      if (std::isfinite(s)) worst = std::max(worst, s);
    }
  }
  const double centre = ProjectionStdev(
      solution, board, camera, {(m.width() - 1) / 2.0, (m.height() - 1) / 2.0}, distance_m);
  cv::Mat smooth, levels, canvas;
  cv::resize(samples, smooth, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
  // Colour scale 0 .. max(1 px, worst): a good calibration stays dark everywhere.
  const double top = std::max(1.0, worst);
  smooth.convertTo(levels, CV_8U, 255.0 / top);
  cv::applyColorMap(levels, canvas, cv::COLORMAP_VIRIDIS);
  // Contours at 0.1, 0.25, 0.5, 1, 2 px.
  for (const double c : {0.1, 0.25, 0.5, 1.0, 2.0}) {
    if (c > top) break;
    cv::Mat above = smooth > c;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(above, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(canvas, contours, -1, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    if (!contours.empty() && !contours.front().empty()) {
      char label[32];
      std::snprintf(label, sizeof label, "%.2g", c);
      cv::putText(canvas, label, contours.front()[contours.front().size() / 2],
                  cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    }
  }
  char text[200];
  std::snprintf(text, sizeof text,
                "projection uncertainty at %.2f m: centre %.3f px, worst %.3f px (1 sigma)",
                distance_m, centre, worst);
  cv::putText(canvas, text, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  // The scale bar.
  const int bar_w = std::min(200, w / 3), bar_x = w - bar_w - 10, bar_y = h - 24;
  for (int x = 0; x < bar_w; ++x) {
    const int level = 255 * x / std::max(1, bar_w - 1);  // 0..255 along the bar
    cv::Mat one(1, 1, CV_8U, cv::Scalar(level)), colour;
    cv::applyColorMap(one, colour, cv::COLORMAP_VIRIDIS);
    cv::line(canvas, {bar_x + x, bar_y}, {bar_x + x, bar_y + 10},
             cv::Scalar(colour.at<cv::Vec3b>(0, 0)));
  }
  std::snprintf(text, sizeof text, "0 .. %.2f px", top);
  cv::putText(canvas, text, {bar_x, bar_y - 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WriteImageFile(path, canvas, "PNG");
}

nlohmann::json ToJson(const CameraReport& r) {
  nlohmann::json j;
  j["camera"] = r.camera;
  j["imager"] = {r.width, r.height};
  j["verdict"] = r.good ? "good" : "rejected";
  j["reasons"] = r.reasons;
  j["views_accepted"] = r.views_accepted;
  j["views_rejected"] = nlohmann::json::array();
  for (const auto& [view, reason] : r.rejected)
    j["views_rejected"].push_back({{"view", view}, {"reason", reason}});
  auto num = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  j["rms_px"] = num(r.rms_px);
  j["worst_px"] = num(r.worst_px);
  j["outlier_corners"] = r.outliers;
  j["parameters"] = nlohmann::json::array();
  for (size_t i = 0; i < r.intrinsics.size(); ++i) {
    j["parameters"].push_back(
        {{"name", r.parameter_names[i]},
         {"value", r.intrinsics[i]},
         {"stdev", num(i < r.intrinsics_stdev.size() ? r.intrinsics_stdev[i] : NAN)}});
  }
  j["coverage"] = r.coverage;
  j["empty_regions"] = r.empty_regions;
  j["max_tilt_deg"] = r.max_tilt_deg;
  j["working_distance_m"] = r.working_distance_m;
  j["projection_stdev_px"] = {{"centre", num(r.projection_stdev_centre_px)},
                              {"worst", num(r.projection_stdev_worst_px)}};
  j["files"] = {
      {"model", r.model_file}, {"residuals", r.residual_png}, {"coverage", r.coverage_png}};
  return j;
}

std::string ToText(const CameraReport& r) {
  std::ostringstream o;
  char buf[256];
  o << r.camera << ": " << (r.good ? "GOOD" : "REJECTED") << "\n";
  std::snprintf(
      buf, sizeof buf,
      "  views %d accepted, %zu rejected; RMS %.3f px, worst %.3f px, %d outlier corners\n",
      r.views_accepted, r.rejected.size(), r.rms_px, r.worst_px, r.outliers);
  o << buf;
  if (!r.intrinsics.empty()) {
    o << "  ";
    for (size_t i = 0; i < r.intrinsics.size() && i < 4; ++i) {
      std::snprintf(buf, sizeof buf, "%s %.2f +- %.3f  ", r.parameter_names[i].c_str(),
                    r.intrinsics[i], i < r.intrinsics_stdev.size() ? r.intrinsics_stdev[i] : NAN);
      o << buf;
    }
    std::snprintf(
        buf, sizeof buf,
        "\n  coverage %.0f%%, most tilted view %.0f deg; projection uncertainty at %.2f m: %.3f px "
        "(centre), %.3f px (worst)\n",
        r.coverage * 100, r.max_tilt_deg, r.working_distance_m, r.projection_stdev_centre_px,
        r.projection_stdev_worst_px);
    o << buf;
  }
  for (const auto& reason : r.reasons) o << "  - " << reason << "\n";
  for (size_t i = 0; i < r.rejected.size() && i < 5; ++i) {
    o << "  view " << r.rejected[i].first << " rejected: " << r.rejected[i].second << "\n";
  }
  if (r.rejected.size() > 5)
    o << "  ... " << r.rejected.size() - 5 << " more rejected views in the JSON report\n";
  return o.str();
}

}  // namespace ss::calib
