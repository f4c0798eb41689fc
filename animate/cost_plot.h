#pragma once
// The cost-versus-time plot of an optimization run (PNG through OpenCV): the current cost
// and the best cost so far over seconds, a log axis when the costs span a wide range.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "animate/summary.h"

namespace ss {

struct PlotSeries {
  std::string label;
  std::vector<TracePoint> trace;
  cv::Scalar colour;  // BGR
};

// A BGR chart of the series' best cost over time.
cv::Mat PlotCostTraces(const std::vector<PlotSeries>& series, const std::string& title,
                       int width_px = 900, int height_px = 540);
// Writes the chart as PNG; WorkError naming the file.
void WriteCostPlot(const std::string& path, const std::vector<PlotSeries>& series,
                   const std::string& title);

}  // namespace ss
