#include "pipeline/describe/sprite_description.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ss {

SpriteDescription DescribeBillboard(const cv::Mat& bgra) {
  if (bgra.type() != CV_8UC4) throw InputError("billboard", "expected 8-bit BGRA pixels");
  // One pass: alpha-weighted sums of colour and of the moments up to order 2.
  double w = 0, sb = 0, sg = 0, sr = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (int y = 0; y < bgra.rows; ++y) {
    const auto* p = bgra.ptr<cv::Vec4b>(y);
    double rw = 0, rb = 0, rg = 0, rr = 0, rx = 0, rxx = 0;
    for (int x = 0; x < bgra.cols; ++x) {
      const double a = p[x][3];
      if (a == 0) continue;
      rw += a;
      rb += a * p[x][0];
      rg += a * p[x][1];
      rr += a * p[x][2];
      rx += a * x;
      rxx += a * x * x;
    }
    w += rw;
    sb += rb;
    sg += rg;
    sr += rr;
    sx += rx;
    sxx += rxx;
    sy += rw * y;
    syy += rw * y * y;
    sxy += rx * y;
  }
  SpriteDescription d;
  if (w <= 0) return d;
  d.mean_b = sb / w;
  d.mean_g = sg / w;
  d.mean_r = sr / w;
  d.area_px = w / 255.0;
  const double mx = sx / w, my = sy / w;
  const double cxx = sxx / w - mx * mx, cyy = syy / w - my * my, cxy = sxy / w - mx * my;
  // Eigenvalues of the 2x2 covariance.
  const double half_trace = (cxx + cyy) / 2;
  const double root = std::sqrt(std::max(0.0, (cxx - cyy) * (cxx - cyy) / 4 + cxy * cxy));
  const double l_max = half_trace + root, l_min = std::max(0.0, half_trace - root);
  d.eccentricity = l_max > 0 ? std::sqrt(std::clamp(1.0 - l_min / l_max, 0.0, 1.0)) : 0.0;
  return d;
}

Eigen::Vector2d EstimateVelocity(const std::vector<int64_t>& timestamps_ns,
                                 const std::vector<Eigen::Vector2d>& points_in_ground, int i,
                                 int half_window) {
  const int n = static_cast<int>(points_in_ground.size());
  const int lo = std::max(0, i - half_window), hi = std::min(n - 1, i + half_window);
  if (hi <= lo) return Eigen::Vector2d::Zero();
  // Least squares p = a + v t over the window, times relative to frame i in seconds.
  double st = 0, stt = 0;
  Eigen::Vector2d sp = Eigen::Vector2d::Zero(), stp = Eigen::Vector2d::Zero();
  for (int k = lo; k <= hi; ++k) {
    const double t = static_cast<double>(timestamps_ns[k] - timestamps_ns[i]) * 1e-9;
    st += t;
    stt += t * t;
    sp += points_in_ground[k];
    stp += t * points_in_ground[k];
  }
  const double m = hi - lo + 1;
  const double denom = m * stt - st * st;
  return denom > 0 ? Eigen::Vector2d((m * stp - st * sp) / denom) : Eigen::Vector2d::Zero();
}

std::vector<Eigen::Vector2d> EstimateVelocities(
    const std::vector<int64_t>& timestamps_ns, const std::vector<Eigen::Vector2d>& points_in_ground,
    int half_window) {
  if (timestamps_ns.size() != points_in_ground.size()) {
    throw InputError("velocities", "as many timestamps as points are needed");
  }
  std::vector<Eigen::Vector2d> v(points_in_ground.size());
  for (size_t i = 0; i < v.size(); ++i) {
    v[i] = EstimateVelocity(timestamps_ns, points_in_ground, static_cast<int>(i), half_window);
  }
  return v;
}

}  // namespace ss
