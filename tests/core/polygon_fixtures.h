#pragma once
// Polygons for the floor polygon's tests and benchmark: the simplicity check as it was before
// the sweep (core/geometry.cc until issue 20: every pair of edges compared, O(n^2), in plain
// floating point), kept as the reference the sweep must agree with (tests/core/geometry_test.cc)
// and as the baseline of `spritestation bench geometry`; and large simple shapes.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

namespace ss::testing {

// A comb: a bar 1 high along y = 0, `teeth` teeth 1 wide and `height` high above it, gaps of 1.
// 4 * teeth vertices, simple; half its edges cross a vertical line at once.
inline std::vector<Eigen::Vector2d> Comb(size_t teeth, double height = 10) {
  const double width = 2.0 * static_cast<double>(teeth) - 1;
  std::vector<Eigen::Vector2d> v = {{0, 0}, {width, 0}};
  for (size_t k = teeth; k-- > 0;) {
    const double x0 = 2.0 * static_cast<double>(k);
    v.push_back({x0 + 1, 1 + height});
    v.push_back({x0, 1 + height});
    if (k > 0) {
      v.push_back({x0, 1});
      v.push_back({x0 - 1, 1});
    }
  }
  return v;
}

// A star around the origin: vertices at increasing angles, radii from `r_min` to 1: simple.
inline std::vector<Eigen::Vector2d> Star(size_t n, std::mt19937& rng, double r_min = 0.2) {
  std::uniform_real_distribution<double> radius(r_min, 1.0), jitter(0.0, 0.9);
  std::vector<Eigen::Vector2d> v;
  for (size_t i = 0; i < n; ++i) {
    const double angle = 2 * M_PI * (static_cast<double>(i) + jitter(rng)) / static_cast<double>(n);
    const double r = radius(rng);
    v.push_back({r * std::cos(angle), r * std::sin(angle)});
  }
  return v;
}

namespace reference {

inline int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                       const Eigen::Vector2d& c) {
  const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  return (cross > 0) - (cross < 0);
}

inline bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      const Eigen::Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

inline bool SegmentsMeet(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const int o1 = Orientation(a, b, c), o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a), o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

inline double Area(const std::vector<Eigen::Vector2d>& v) {
  double twice = 0;
  const size_t n = v.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) twice += v[j].x() * v[i].y() - v[i].x() * v[j].y();
  return std::abs(twice) / 2.0;
}

}  // namespace reference

// GroundPolygon::IsSimple before issue 20, verbatim.
inline bool BruteForceIsSimple(const std::vector<Eigen::Vector2d>& vertices_) {
  using reference::Orientation;
  using reference::SegmentsMeet;
  const size_t n = vertices_.size();
  if (n < 3) return false;
  for (const auto& v : vertices_) {
    if (!v.allFinite()) return false;
  }
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = vertices_[i];
    const Eigen::Vector2d& b = vertices_[(i + 1) % n];
    if (a == b) return false;  // a repeated vertex makes a zero-length edge
    for (size_t j = i + 1; j < n; ++j) {
      const Eigen::Vector2d& c = vertices_[j];
      const Eigen::Vector2d& d = vertices_[(j + 1) % n];
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Neighbours share one vertex; they must not fold back onto each other.
        const Eigen::Vector2d& shared = j == i + 1 ? b : a;
        const Eigen::Vector2d& p = j == i + 1 ? a : b;  // far end of edge i
        const Eigen::Vector2d& q = j == i + 1 ? d : c;  // far end of edge j
        if (Orientation(p, shared, q) == 0 && (p - shared).dot(q - shared) > 0) return false;
        continue;
      }
      if (SegmentsMeet(a, b, c, d)) return false;
    }
  }
  return reference::Area(vertices_) > 0;
}

}  // namespace ss::testing
