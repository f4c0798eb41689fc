#include "animate/cost_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/image_file.h"

namespace ss {

cv::Mat PlotCostTraces(const std::vector<PlotSeries>& series, const std::string& title,
                       int width_px, int height_px) {
  cv::Mat image(height_px, width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 20, top = 40, bottom = 50;
  const cv::Rect area(left, top, width_px - left - right, height_px - top - bottom);
  double t_max = 1e-3, c_min = 1e300, c_max = -1e300;
  for (const PlotSeries& s : series) {
    for (const TracePoint& p : s.trace) {
      t_max = std::max(t_max, p.seconds);
      c_min = std::min(c_min, p.best_cost);
      c_max = std::max(c_max, p.best_cost);
    }
  }
  if (c_min > c_max) c_min = 0, c_max = 1;
  const bool log_axis = c_min > 0 && c_max / c_min > 50;
  auto y_value = [&](double c) { return log_axis ? std::log10(c) : c; };
  double y_lo = y_value(c_min), y_hi = y_value(c_max);
  if (y_hi - y_lo < 1e-12) y_lo -= 0.5, y_hi += 0.5;
  const double pad = 0.05 * (y_hi - y_lo);
  y_lo -= pad;
  y_hi += pad;
  if (!log_axis) y_lo = std::max(y_lo, std::min(0.0, c_min));
  auto to_px = [&](double t, double c) {
    const double x = area.x + area.width * (t / t_max);
    const double y = area.y + area.height * (1.0 - (y_value(c) - y_lo) / (y_hi - y_lo));
    return cv::Point(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
  };
  const cv::Scalar grey(200, 200, 200), black(0, 0, 0);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  char label[64];
  for (int k = 0; k <= 5; ++k) {  // grid and axis labels
    const double fy = y_lo + (y_hi - y_lo) * k / 5.0;
    const int py = area.y + static_cast<int>(area.height * (1.0 - k / 5.0));
    cv::line(image, {area.x, py}, {area.x + area.width, py}, grey, 1);
    std::snprintf(label, sizeof label, "%.3g", log_axis ? std::pow(10.0, fy) : fy);
    cv::putText(image, label, {5, py + 5}, font, 0.45, black, 1, cv::LINE_AA);
    const int px = area.x + static_cast<int>(area.width * k / 5.0);
    cv::line(image, {px, area.y}, {px, area.y + area.height}, grey, 1);
    std::snprintf(label, sizeof label, "%.3g", t_max * k / 5.0);
    cv::putText(image, label, {px - 15, area.y + area.height + 20}, font, 0.45, black, 1,
                cv::LINE_AA);
  }
  cv::rectangle(image, area, black, 1);
  cv::putText(image, "seconds", {area.x + area.width / 2 - 30, height_px - 8}, font, 0.5, black, 1,
              cv::LINE_AA);
  cv::putText(image, title + (log_axis ? "  (cost, log scale)" : "  (cost)"), {left, 25}, font,
              0.55, black, 1, cv::LINE_AA);
  int legend_y = area.y + 20;
  for (const PlotSeries& s : series) {
    if (s.trace.empty()) continue;
    // A step curve: the best cost holds until the next improvement.
    std::vector<cv::Point> points;
    for (size_t i = 0; i < s.trace.size(); ++i) {
      const TracePoint& p = s.trace[i];
      if (i > 0) points.push_back(to_px(p.seconds, s.trace[i - 1].best_cost));
      points.push_back(to_px(p.seconds, p.best_cost));
    }
    cv::polylines(image, points, false, s.colour, 2, cv::LINE_AA);
    cv::line(image, {area.x + area.width - 170, legend_y - 5},
             {area.x + area.width - 140, legend_y - 5}, s.colour, 2);
    std::snprintf(label, sizeof label, "%s %.4g", s.label.c_str(), s.trace.back().best_cost);
    cv::putText(image, label, {area.x + area.width - 135, legend_y}, font, 0.45, black, 1,
                cv::LINE_AA);
    legend_y += 20;
  }
  return image;
}

void WriteCostPlot(const std::string& path, const std::vector<PlotSeries>& series,
                   const std::string& title) {
  WriteImageFile(path, PlotCostTraces(series, title), "plot");
}

}  // namespace ss
