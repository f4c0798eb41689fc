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
  const double dz = ray.direction.z();
  if (std::abs(dz) < 1e-12) return std::nullopt;
  const double s = -ray.origin.z() / dz;
  if (s < 0) return std::nullopt;
  Eigen::Vector3d p = ray.origin + s * ray.direction;
  p.z() = 0.0;
  return p;
}

GroundPolygon::GroundPolygon(std::vector<Eigen::Vector2d> vertices) : vertices_(std::move(vertices)) {}

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

double GroundPolygon::Area() const {
  double twice = 0;
  const size_t n = vertices_.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    twice += vertices_[j].x() * vertices_[i].y() - vertices_[i].x() * vertices_[j].y();
  }
  return std::abs(twice) / 2.0;
}

}  // namespace ss
