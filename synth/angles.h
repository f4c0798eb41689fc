#pragma once
// Angles and rotations the synthetic subjects and cameras share: degrees, wrapping,
// the smoothstep easing of a move, and rotations about the ground axes.
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace ss::synth {

inline constexpr double kDeg = M_PI / 180.0;

// `a` wrapped into [-pi, pi].
inline double Wrap(double a) { return std::remainder(a, 2.0 * M_PI); }
// The fractional part of `x`, in [0, 1).
inline double Frac(double x) { return x - std::floor(x); }
// Smoothstep of `t` clamped to [0, 1]: 0 -> 0, 1 -> 1, flat at both ends.
inline double Smooth(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
inline Eigen::Matrix3d RotX(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
inline Eigen::Matrix3d RotY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
inline Eigen::Matrix3d RotZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace ss::synth
