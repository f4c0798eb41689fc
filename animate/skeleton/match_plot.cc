#include "animate/skeleton/match_plot.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image_file.h"
#include "core/option_checks.h"

namespace ss {
namespace {

// A round step (1, 2 or 5 times a power of ten) giving about `ticks` ticks over `range`.
int TickStep(int range, int ticks) {
  const double raw = std::max(1.0, static_cast<double>(range) / ticks);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw) return std::max(1, static_cast<int>(m * power));
  }
  return static_cast<int>(10 * power);
}

void DrawPanel(cv::Mat& canvas, const PlotPanel& panel, int source_count, const PlotOptions& o) {
  const int left = 60, right = 15, top = 30, bottom = 40;
  const cv::Rect area(left, top, canvas.cols - left - right, canvas.rows - top - bottom);
  const int targets = std::max<int>(1, static_cast<int>(panel.source_frames.size()));
  const int sources = std::max(1, source_count);
  auto px = [&](double t, double s) {
    const double x = area.x + (targets > 1 ? t / (targets - 1) : 0.5) * area.width;
    const double y = area.y + area.height - (sources > 1 ? s / (sources - 1) : 0.5) * area.height;
    return cv::Point(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
  };
  const cv::Scalar black(0, 0, 0), faint(225, 225, 225), grid(200, 200, 200);
  for (int c : o.clip_starts) cv::line(canvas, px(0, c), px(targets - 1, c), faint, 1);
  for (int m : o.target_movements) cv::line(canvas, px(m, 0), px(m, sources - 1), faint, 1);
  cv::rectangle(canvas, area, black, 1);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const int xstep = TickStep(targets, 8), ystep = TickStep(sources, 8);
  for (int t = 0; t < targets; t += xstep) {
    const cv::Point p = px(t, 0);
    cv::line(canvas, {p.x, area.y + area.height}, {p.x, area.y + area.height + 4}, black, 1);
    cv::putText(canvas, std::to_string(t), {p.x - 10, area.y + area.height + 17}, font, 0.38, black,
                1, cv::LINE_AA);
  }
  for (int s = 0; s < sources; s += ystep) {
    const cv::Point p = px(0, s);
    cv::line(canvas, {area.x - 4, p.y}, {area.x, p.y}, black, 1);
    cv::putText(canvas, std::to_string(s), {4, p.y + 4}, font, 0.38, black, 1, cv::LINE_AA);
  }
  cv::putText(canvas, "target frame", {area.x + area.width / 2 - 40, canvas.rows - 6}, font, 0.42,
              black, 1, cv::LINE_AA);
  cv::putText(canvas, panel.title, {area.x, 20}, font, 0.5, black, 1, cv::LINE_AA);
  const auto& f = panel.source_frames;
  for (size_t t = 1; t < f.size(); ++t)
    cv::line(canvas, px(t - 1, f[t - 1]), px(t, f[t]), grid, 1, cv::LINE_AA);
  for (size_t t = 0; t < f.size(); ++t) {
    cv::Scalar colour(200, 90, 20);  // blue: a move
    if (t > 0 && f[t] == f[t - 1])
      colour = cv::Scalar(30, 30, 220);  // red: a freeze
    else if (t > 0 && f[t] < f[t - 1] && f[t - 1] - f[t] <= o.stutter_window)
      colour = cv::Scalar(0, 140, 255);
    cv::circle(canvas, px(t, f[t]), 2, colour, cv::FILLED, cv::LINE_AA);
  }
}

}  // namespace

bool PlotOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(panel_size.width >= 120 && panel_size.height >= 100, "panel_size",
        "must be at least 120 x 100 pixels, got " + std::to_string(panel_size.width) + " x " +
            std::to_string(panel_size.height));
  check.Within(stutter_window, AtLeast(0), "stutter_window", "frames >= 0");
  return check.ok();
}

cv::Mat PlotMatch(const std::vector<PlotPanel>& panels, int source_count,
                  const PlotOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("plot options", why);
  if (panels.empty()) throw InputError("plot", "needs at least one panel");
  const cv::Size size = options.panel_size;
  cv::Mat canvas(size.height, size.width * static_cast<int>(panels.size()), CV_8UC3,
                 cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < panels.size(); ++i) {
    cv::Mat view = canvas(cv::Rect(static_cast<int>(i) * size.width, 0, size.width, size.height));
    DrawPanel(view, panels[i], source_count, options);
  }
  return canvas;
}

void WriteMatchPlot(const std::string& path, const std::vector<PlotPanel>& panels, int source_count,
                    const PlotOptions& options) {
  WriteImageFile(path, PlotMatch(panels, source_count, options), "plot");
}

}  // namespace ss
