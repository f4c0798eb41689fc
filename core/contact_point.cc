#include "core/contact_point.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

constexpr int kHalf = 127;  // alpha > kHalf is more subject than background

bool RowHasSubject(const uint8_t* a, int n) {
  uint8_t m = 0;
  for (int i = 0; i < n; ++i) m = std::max(m, a[i]);
  return m > kHalf;
}

}  // namespace

bool ContactPointOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  // Checked on every call of ContactPoint: the reasons are written only when needed.
  check(
      std::isfinite(band_fraction) && band_fraction >= 0 && band_fraction <= 1, "band_fraction",
      [&] { return "expected a fraction from 0 to 1, got " + OptionProblems::Num(band_fraction); });
  // The band's height divides the ramp: it must not be 0.
  check(std::isfinite(min_band_px) && min_band_px > 0, "min_band_px", [&] {
    return "expected a positive number of pixels, got " + OptionProblems::Num(min_band_px);
  });
  return check.ok();
}

bool ContactPoint(const cv::Mat& alpha, cv::Point2d* point, const ContactPointOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("contact point options", why);
  if (alpha.type() != CV_8U) throw InputError("contact point", "alpha must be 8-bit, one channel");
  const int w = alpha.cols;
  int top = 0, bottom = alpha.rows - 1;
  while (top < alpha.rows && !RowHasSubject(alpha.ptr<uint8_t>(top), w)) ++top;
  if (top == alpha.rows) return false;
  while (bottom > top && !RowHasSubject(alpha.ptr<uint8_t>(bottom), w)) --bottom;

  // y: where alpha falls through 1/2 below the lowest row, averaged over that row's subject pixels.
  double y_low = bottom;
  {
    const uint8_t* a = alpha.ptr<uint8_t>(bottom);
    const uint8_t* below = bottom + 1 < alpha.rows ? alpha.ptr<uint8_t>(bottom + 1) : nullptr;
    double st = 0;
    int n = 0;
    for (int x = 0; x < w; ++x) {
      if (a[x] <= kHalf) continue;
      const double a1 = below ? below[x] : 0.0;
      st += (a[x] - 127.5) / (a[x] - a1);
      ++n;
    }
    y_low += st / n;
  }

  // x: the alpha-weighted centre of the bottom band, weights ramping from 1 at
  // the lowest point to 0 at the band's top (soft rows below the lowest point count fully).
  const double band = std::max(options.min_band_px, options.band_fraction * (y_low - top));
  const int first = std::max(0, static_cast<int>(y_low - band));
  const int last = std::min(alpha.rows - 1, bottom + 1);
  double sum_w = 0, sum_wx = 0;
  for (int y = first; y <= last; ++y) {
    const double ramp = std::clamp((band - (y_low - y)) / band, 0.0, 1.0);
    if (ramp <= 0) continue;
    const uint8_t* a = alpha.ptr<uint8_t>(y);
    uint64_t s = 0, sx = 0;
    for (int x = 0; x < w; ++x) {
      s += a[x];
      sx += static_cast<uint64_t>(a[x]) * static_cast<uint64_t>(x);
    }
    sum_w += ramp * static_cast<double>(s);
    sum_wx += ramp * static_cast<double>(sx);
  }
  *point = {sum_wx / sum_w, y_low};
  return true;
}

}  // namespace ss
