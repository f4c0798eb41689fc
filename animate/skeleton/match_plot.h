#pragma once
// A plot like seed 003's Figures 2 and 3: the source frame chosen (vertical) for each
// target frame (horizontal), one panel per path side by side (e.g. without and with
// penalties, after refinement). Repeats (freezes) are drawn red, backward steps
// (stutters) orange, other choices blue.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

struct PlotPanel {
  std::string title;
  std::vector<int> source_frames;  // s_t
};

struct PlotOptions {
  cv::Size panel_size{640, 480};      // pixels per panel
  int stutter_window = 8;             // a backward step of up to this many frames is a stutter
  std::vector<int> clip_starts;       // drawn as faint horizontal lines
  std::vector<int> target_movements;  // drawn as faint vertical lines
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The panels side by side, BGR. `source_count` sets the vertical range. InputError for options
// that are not valid ("plot options") and for no panel.
cv::Mat PlotMatch(const std::vector<PlotPanel>& panels, int source_count,
                  const PlotOptions& options = {});

// PlotMatch written as PNG; throws WorkError when the file cannot be written.
void WriteMatchPlot(const std::string& path, const std::vector<PlotPanel>& panels, int source_count,
                    const PlotOptions& options = {});

}  // namespace ss
