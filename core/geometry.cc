#include "core/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ss {

Rigid3 Rigid3::FromRt(const double rt[6]) {
  const Eigen::Vector3d r(rt[0], rt[1], rt[2]);
  const double angle = r.norm();
  Rigid3 out;
  if (angle > 1e-15) out.rotation = Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
  out.translation = Eigen::Vector3d(rt[3], rt[4], rt[5]);
  return out;
}

void Rigid3::ToRt(double rt[6]) const {
  const Eigen::AngleAxisd aa(rotation);
  const Eigen::Vector3d r = aa.axis() * aa.angle();
  for (int i = 0; i < 3; ++i) {
    rt[i] = r[i];
    rt[3 + i] = translation[i];
  }
}

std::optional<Eigen::Vector3d> IntersectGround(const Ray& ray) {
  if (!ray.origin.allFinite() || !ray.direction.allFinite()) return std::nullopt;
  const double dz = ray.direction.z();
  if (std::abs(dz) < 1e-12 * ray.direction.norm()) return std::nullopt;
  const double s = -ray.origin.z() / dz;
  if (!(s >= 0)) return std::nullopt;
  Eigen::Vector3d p = ray.origin + s * ray.direction;
  p.z() = 0.0;
  return p;
}

GroundPolygon::GroundPolygon(std::vector<Eigen::Vector2d> vertices)
    : vertices_(std::move(vertices)) {}

bool GroundPolygon::Contains(const Eigen::Vector2d& p) const { return SignedDistance(p) >= 0.0; }

static double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double GroundPolygon::SignedDistance(const Eigen::Vector2d& p) const {
  if (empty()) return -std::numeric_limits<double>::infinity();
  double best = std::numeric_limits<double>::infinity();
  const size_t n = vertices_.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    best = std::min(best, DistanceToSegment(p, vertices_[j], vertices_[i]));
  }
  if (best == 0.0) return 0.0;
  // Even-odd test without recursion into Contains().
  bool inside = false;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = vertices_[i];
    const Eigen::Vector2d& b = vertices_[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside ? best : -best;
}

bool GroundPolygon::ContainsWithMargin(const Eigen::Vector2d& p, double margin) const {
  return SignedDistance(p) >= margin;
}

namespace {

// Sign of the turn a -> b -> c: +1 left, -1 right, 0 collinear.
int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  return (cross > 0) - (cross < 0);
}

bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

// Closed segments ab and cd share at least one point.
bool SegmentsMeet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  const Eigen::Vector2d& d) {
  const int o1 = Orientation(a, b, c), o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a), o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

}  // namespace

bool GroundPolygon::IsSimple() const {
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
  return Area() > 0;
}

double GroundPolygon::Area() const {
  double twice = 0;
  const size_t n = vertices_.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    twice += vertices_[j].x() * vertices_[i].y() - vertices_[i].x() * vertices_[j].y();
  }
  return std::abs(twice) / 2.0;
}

}  // namespace ss
