#include "synth/lens.h"

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/error.h"

namespace ss::synth {

Lens::Lens(const std::string& lensmodel, const std::vector<double>& intrinsics) {
  if (lensmodel == "LENSMODEL_PINHOLE") {
    if (intrinsics.size() != 4)
      throw InputError("lensmodel", "LENSMODEL_PINHOLE needs 4 intrinsics");
    distorted_ = false;
  } else if (lensmodel == "LENSMODEL_OPENCV8") {
    if (intrinsics.size() != 12)
      throw InputError("lensmodel", "LENSMODEL_OPENCV8 needs 12 intrinsics");
    distorted_ = true;
  } else {
    throw InputError(
        "lensmodel",
        "the synthetic studio renders LENSMODEL_PINHOLE or LENSMODEL_OPENCV8, not " + lensmodel);
  }
  for (size_t i = 0; i < intrinsics.size(); ++i) k_[i] = intrinsics[i];
}

Eigen::Vector2d Lens::Distort(const Eigen::Vector2d& n) const {
  const double x = n.x(), y = n.y();
  if (!distorted_) return {k_[0] * x + k_[2], k_[1] * y + k_[3]};
  const double k1 = k_[4], k2 = k_[5], p1 = k_[6], p2 = k_[7], k3 = k_[8], k4 = k_[9], k5 = k_[10],
               k6 = k_[11];
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial = (1.0 + k1 * r2 + k2 * r4 + k3 * r6) / (1.0 + k4 * r2 + k5 * r4 + k6 * r6);
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  return {k_[0] * xd + k_[2], k_[1] * yd + k_[3]};
}

Eigen::Vector2d Lens::Project(const Eigen::Vector3d& p) const {
  if (!(p.z() > 0.0)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  return Distort({p.x() / p.z(), p.y() / p.z()});
}

Eigen::Vector3d Lens::Unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d& target = pixel;
  Eigen::Vector2d n((pixel.x() - k_[2]) / k_[0], (pixel.y() - k_[3]) / k_[1]);
  if (distorted_) {
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector2d f = Distort(n) - target;
      if (f.squaredNorm() < 1e-24) break;
      const double h = 1e-7;
      Eigen::Matrix2d j;
      j.col(0) =
          (Distort(n + Eigen::Vector2d(h, 0)) - Distort(n - Eigen::Vector2d(h, 0))) / (2 * h);
      j.col(1) =
          (Distort(n + Eigen::Vector2d(0, h)) - Distort(n - Eigen::Vector2d(0, h))) / (2 * h);
      n -= j.inverse() * f;
    }
  }
  return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized();
}

double Lens::MinRadialSlope(double r_max) const {
  if (!distorted_) return 1.0;
  double min_slope = std::numeric_limits<double>::infinity();
  double prev = 0.0;
  const int steps = 400;
  for (int i = 1; i <= steps; ++i) {
    const double r = r_max * i / steps;
    const Eigen::Vector2d d = Distort({r, 0.0});
    const double rd = (d.x() - k_[2]) / k_[0];
    min_slope = std::min(min_slope, (rd - prev) / (r_max / steps));
    prev = rd;
  }
  return min_slope;
}

}  // namespace ss::synth
