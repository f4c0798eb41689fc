#include "synth/snapshot.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ss::synth {
namespace {

// Largest value of dir . p over the primitive's points.
double Support(const Primitive& p, const Eigen::Vector3d& dir) {
  if (p.shape == Shape::kCapsule)
    return std::max(dir.dot(p.a), dir.dot(p.b)) + p.radius * dir.norm();
  return dir.dot(p.centre) + (p.axes.transpose() * dir).norm();
}

}  // namespace

bool TouchesWall(const Studio& studio, const std::vector<Primitive>& prims, int subject,
                 double tolerance_m) {
  for (int w : studio.green_walls) {
    const Quad& q = studio.quads[static_cast<size_t>(w)];
    // The wall's inward normal (front faces the floor) and its extent along the floor.
    const Eigen::Vector3d n = q.normal;
    const Eigen::Vector3d along = q.u.z() == 0 ? q.u : q.v;
    const Eigen::Vector3d up = q.u.z() == 0 ? q.v : q.u;
    for (const Primitive& p : prims) {
      if (p.subject != subject || p.slice != 0) continue;
      const double gap = -Support(p, -n) - n.dot(q.origin);
      if (gap > tolerance_m) continue;
      const double s = (p.centre - q.origin).dot(along) / along.squaredNorm();
      if (s < 0 || s > 1 || p.LowestZ() > up.z()) continue;
      return true;
    }
  }
  return false;
}

bool LeavesFloor(const Studio& studio, const std::vector<Primitive>& prims, int subject,
                 double tolerance_m) {
  // Exact for a convex floor: a footprint leaves it when its support along an
  // edge's outward normal passes the edge.
  const auto& v = studio.floor.vertices();
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : v) centroid += p;
  centroid /= static_cast<double>(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d a = v[i], e = v[(i + 1) % v.size()] - a;
    Eigen::Vector2d m(e.y(), -e.x());
    m.normalize();
    if (m.dot(centroid - a) > 0) m = -m;  // outward
    const Eigen::Vector3d dir(m.x(), m.y(), 0.0);
    for (const Primitive& p : prims) {
      if (p.subject != subject || p.slice != 0) continue;
      if (Support(p, dir) > m.dot(a) + tolerance_m) return true;
    }
  }
  return false;
}

double TopHeight(const std::vector<Primitive>& prims, int subject) {
  double top = 0.0;
  for (const Primitive& p : prims) {
    if (p.subject == subject && p.slice == 0) top = std::max(top, p.HighestZ());
  }
  return top;
}

int StartFrame(FrameSnapshot* out, int subjects, bool motion_blur) {
  out->scene = FrameScene{};
  out->scene.subjects = subjects;
  out->subjects.clear();
  out->boards.clear();
  out->scene.slices = motion_blur ? 4 : 1;
  return out->scene.slices;
}

Eigen::Vector2d PlaceApart(const Studio& studio, Rng& rng,
                           const std::vector<Eigen::Vector2d>& placed, double margin_m,
                           double apart_m) {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  for (int attempt = 0; attempt < 200; ++attempt) {
    p = {rng.Uniform(-studio.half_x + margin_m, studio.half_x - margin_m),
         rng.Uniform(-studio.half_y + margin_m, studio.half_y - margin_m)};
    bool apart = true;
    for (const auto& q : placed) apart = apart && (p - q).norm() > apart_m;
    if (apart) break;
  }
  return p;
}

}  // namespace ss::synth
