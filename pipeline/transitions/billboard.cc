#include "pipeline/transitions/billboard.h"

#include <cmath>
#include <string>

#include "core/error.h"

namespace ss {

void ValidateBillboard(const RgbaBillboard& b) {
  if (b.width <= 0 || b.height <= 0) {
    throw InputError("billboard", "size " + std::to_string(b.width) + "x" +
                                      std::to_string(b.height) + " is empty");
  }
  if (b.rgba.size() != static_cast<size_t>(b.width) * b.height * 4) {
    throw InputError("billboard", "holds " + std::to_string(b.rgba.size()) + " bytes, expected " +
                                      std::to_string(static_cast<size_t>(b.width) * b.height * 4) +
                                      " for RGBA " + std::to_string(b.width) + "x" +
                                      std::to_string(b.height));
  }
  const bool inside = std::isfinite(b.anchor_x_px) && std::isfinite(b.anchor_y_px) &&
                      b.anchor_x_px >= -0.5 && b.anchor_x_px <= b.width - 0.5 &&
                      b.anchor_y_px >= -0.5 && b.anchor_y_px <= b.height - 0.5;
  if (!inside) {
    throw InputError("billboard", "anchor (" + std::to_string(b.anchor_x_px) + ", " +
                                      std::to_string(b.anchor_y_px) +
                                      ") lies outside the billboard");
  }
}

CheapFeatures DescribeBillboard(const RgbaBillboard& b, double px_per_m) {
  ValidateBillboard(b);
  if (!(px_per_m > 0)) throw InputError("px_per_m", "must be positive");
  // Alpha-weighted sums, in pixel units; alpha in 0..1.
  double sum_a = 0, sum_x = 0, sum_y = 0, sum_xx = 0, sum_yy = 0, sum_xy = 0;
  double sum_c[3] = {0, 0, 0};
  for (int y = 0; y < b.height; ++y) {
    for (int x = 0; x < b.width; ++x) {
      const uint8_t* p = b.Pixel(x, y);
      if (p[3] == 0) continue;
      const double a = p[3] / 255.0;
      sum_a += a;
      sum_x += a * x;
      sum_y += a * y;
      sum_xx += a * x * x;
      sum_yy += a * y * y;
      sum_xy += a * x * y;
      for (int c = 0; c < 3; ++c) sum_c[c] += a * p[c];
    }
  }
  CheapFeatures f;
  if (sum_a <= 0) return f;  // fully transparent: colour, area and eccentricity 0
  for (int c = 0; c < 3; ++c) f.colour[c] = sum_c[c] / sum_a;
  f.area_m2 = sum_a / (px_per_m * px_per_m);
  const double mx = sum_x / sum_a, my = sum_y / sum_a;
  const double cxx = sum_xx / sum_a - mx * mx;
  const double cyy = sum_yy / sum_a - my * my;
  const double cxy = sum_xy / sum_a - mx * my;
  // Eigenvalues of the 2x2 covariance.
  const double half_trace = 0.5 * (cxx + cyy);
  const double root = std::sqrt(std::max(0.0, 0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy));
  const double l1 = half_trace + root, l2 = std::max(0.0, half_trace - root);
  f.eccentricity = l1 > 0 ? std::sqrt(std::max(0.0, 1.0 - l2 / l1)) : 0.0;
  return f;
}

RgbaBillboard MirrorBillboard(const RgbaBillboard& b) {
  ValidateBillboard(b);
  RgbaBillboard m = b;
  m.anchor_x_px = (b.width - 1) - b.anchor_x_px;
  for (int y = 0; y < b.height; ++y) {
    for (int x = 0; x < b.width; ++x) {
      const uint8_t* src = b.Pixel(b.width - 1 - x, y);
      uint8_t* dst = m.rgba.data() + (static_cast<size_t>(y) * b.width + x) * 4;
      for (int c = 0; c < 4; ++c) dst[c] = src[c];
    }
  }
  return m;
}

}  // namespace ss
