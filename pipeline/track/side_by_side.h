#pragma once
// Two subjects side by side in one blob, from the sprite's looks (issue 19). MergeDetector
// counts subjects from tracks that meet, so a pair that enters the view together, one blob from
// its first frame, is never counted two by it. Such a pair shows, in the frames where a gap
// parts them, as a billboard matte of two parts, left and right: a column (the "neck") holding
// almost none of the matte, a good share of the matte on each side, each side nearly as tall as
// the whole; and the whole wider than one subject of this camera usually is. The width keeps a
// subject whose matte broke into two tall strips (a coat the colour of the floor) for one.
// In the frames where the two overlap there is no gap, but the blob is still wide: a clip once
// seen split counts two in every frame it is wide (CameraPipeline, ClipBatcher::MarkMerged).
#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

struct SideBySideOptions {
  // The matte's width over the camera's median width of one subject, at least; 0 turns the rule
  // off (the config's pipeline.merged_min_width_ratio).
  double min_width_ratio = 1.5;
  double max_neck_share = 0.1;   // the neck column's matte, of the fullest column's, at most
  double min_part_share = 0.25;  // of the matte's area on each side of the neck, at least
  double min_part_height = 0.6;  // each side's height, of the whole matte's, at least
  int median_window = 200;       // widths of single subjects the median is taken over
  int min_widths = 20;           // single subjects seen before the rule speaks
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const SideBySideOptions&) const = default;
};

// One billboard's matte (alpha > 1/2), measured.
struct MatteLook {
  double width_m = 0;  // the columns holding the middle 90 % of the matte (stray streaks aside)
  bool split = false;  // two parts side by side, as the options ask (the width not yet judged)
};

// `alpha`: the billboard's alpha, its last channel (CV_8UC1 or the BGRA); `px_per_m`: its scale.
MatteLook MeasureMatteLook(const cv::Mat& alpha, double px_per_m, const SideBySideOptions& options);

// One camera's judge: keeps the median width of the sprites counted one subject.
class SideBySide {
 public:
  explicit SideBySide(SideBySideOptions options = {});
  // Whether a matte `width_m` wide is wider than one subject: min_width_ratio times the median
  // width of one (never before min_widths sprites, nor with the rule off).
  bool IsWide(double width_m) const { return width_m >= min_wide_m(); }
  // The narrowest width IsWide takes (infinite while it takes none).
  double min_wide_m() const;
  // A sprite counted one subject: its width joins the median.
  void AddOne(double width_m);
  // The median width of one subject so far; 0 before min_widths sprites.
  double median_width_m() const { return median_m_; }
  const SideBySideOptions& options() const { return options_; }

 private:
  SideBySideOptions options_;
  std::vector<double> widths_;   // a ring of the last median_window widths
  std::vector<double> scratch_;  // for the median
  size_t next_ = 0;
  double median_m_ = 0;
};

}  // namespace ss
