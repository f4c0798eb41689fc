#include "pipeline/track/side_by_side.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

bool SideBySideOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  const auto share = [&](double v, const char* field) {
    check(std::isfinite(v) && v >= 0 && v <= 1, field,
          "expected a share from 0 to 1, got " + OptionProblems::Num(v));
  };
  check(std::isfinite(min_width_ratio) && (min_width_ratio == 0 || min_width_ratio >= 1),
        "min_width_ratio",
        "expected 0 (off) or a ratio of at least 1, got " + OptionProblems::Num(min_width_ratio));
  share(max_neck_share, "max_neck_share");
  share(min_part_share, "min_part_share");
  share(min_part_height, "min_part_height");
  check(min_part_share <= 0.5, "min_part_share",
        "both sides cannot hold more than half, got " + OptionProblems::Num(min_part_share));
  check.Within(median_window, AtLeast(1), "median_window", "at least 1 width");
  check(min_widths >= 1 && min_widths <= median_window, "min_widths",
        "expected 1 to median_window (" + std::to_string(median_window) + ") widths, got " +
            std::to_string(min_widths));
  return check.ok();
}

MatteLook MeasureMatteLook(const cv::Mat& alpha, double px_per_m,
                           const SideBySideOptions& options) {
  MatteLook look;
  const int cols = alpha.cols, channels = alpha.channels();
  // Per column: its matte pixels and the rows they span.
  std::vector<int> count(cols, 0), top(cols, alpha.rows), bottom(cols, -1);
  for (int y = 0; y < alpha.rows; ++y) {
    const uint8_t* a = alpha.ptr<uint8_t>(y) + (channels - 1);
    for (int x = 0; x < cols; ++x) {
      if (a[x * channels] <= 127) continue;
      ++count[x];
      top[x] = std::min(top[x], y);
      bottom[x] = y;
    }
  }
  double total = 0;
  int fullest = 0, first_row = alpha.rows, last_row = -1;
  for (int x = 0; x < cols; ++x) {
    total += count[x];
    fullest = std::max(fullest, count[x]);
    if (count[x] > 0) {
      first_row = std::min(first_row, top[x]);
      last_row = std::max(last_row, bottom[x]);
    }
  }
  if (total <= 0 || px_per_m <= 0) return look;
  // The width: from the column where 5 % of the matte lies left to where 95 % does.
  int from = -1, to = -1;
  double left = 0;
  for (int x = 0; x < cols; ++x) {
    left += count[x];
    if (from < 0 && left >= 0.05 * total) from = x;
    if (to < 0 && left >= 0.95 * total) to = x;
  }
  look.width_m = (to - from + 1) / px_per_m;
  // The neck: of the columns with min_part_share of the matte on each side, the emptiest.
  int neck = -1;
  left = 0;
  for (int x = 0; x < cols; ++x) {
    const double before = left;
    left += count[x];
    if (std::min(before, total - left) < options.min_part_share * total) continue;
    if (neck < 0 || count[x] < count[neck]) neck = x;
  }
  if (neck < 0 || count[neck] > options.max_neck_share * fullest) return look;
  // Each side nearly as tall as the whole.
  const auto height = [&](int x0, int x1) {
    int t = alpha.rows, b = -1;
    for (int x = x0; x < x1; ++x) {
      if (count[x] == 0) continue;
      t = std::min(t, top[x]);
      b = std::max(b, bottom[x]);
    }
    return b < t ? 0 : b - t + 1;
  };
  const double whole = last_row - first_row + 1;
  look.split = height(0, neck) >= options.min_part_height * whole &&
               height(neck + 1, cols) >= options.min_part_height * whole;
  return look;
}

SideBySide::SideBySide(SideBySideOptions options) : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("side-by-side options", why);
  widths_.reserve(static_cast<size_t>(options_.median_window));
}

double SideBySide::min_wide_m() const {
  if (options_.min_width_ratio <= 0 || median_m_ <= 0)
    return std::numeric_limits<double>::infinity();
  return options_.min_width_ratio * median_m_;
}

void SideBySide::AddOne(double width_m) {
  if (!(width_m > 0)) return;
  if (widths_.size() < static_cast<size_t>(options_.median_window)) {
    widths_.push_back(width_m);
  } else {
    widths_[next_] = width_m;
    next_ = (next_ + 1) % widths_.size();
  }
  if (widths_.size() < static_cast<size_t>(options_.min_widths)) return;
  scratch_ = widths_;
  const auto mid = scratch_.begin() + static_cast<std::ptrdiff_t>(scratch_.size() / 2);
  std::nth_element(scratch_.begin(), mid, scratch_.end());
  median_m_ = *mid;
}

}  // namespace ss
