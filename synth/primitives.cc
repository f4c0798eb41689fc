#include "synth/primitives.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "synth/angles.h"
#include "synth/random.h"

namespace ss::synth {

SubjectParts::SubjectParts(const Eigen::Vector2d& position, double heading_rad, double scale,
                           uint64_t look_seed, int subject, int slice, size_t reserve)
    : r_world_(RotZ(heading_rad)),
      t_world_(position.x(), position.y(), 0.0),
      scale_(scale),
      look_seed_(look_seed),
      subject_(subject),
      slice_(slice) {
  out_.reserve(reserve);
}

Eigen::Vector3d SubjectParts::ToGround(const Eigen::Vector3d& p) const {
  return r_world_ * (scale_ * p) + t_world_;
}

Material SubjectParts::Seeded(Material m, uint64_t part) const {
  m.seed = static_cast<uint32_t>(Mix(look_seed_, part));
  return m;
}

void SubjectParts::Ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& radii, const Material& m) {
  Primitive p = Primitive::Ellipsoid(ToGround(centre), r_world_ * rotation, scale_ * radii, m);
  p.subject = subject_;
  p.slice = slice_;
  out_.push_back(p);
}

void SubjectParts::Capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                           const Material& m) {
  Primitive p = Primitive::Capsule(ToGround(a), ToGround(b), scale_ * radius, m);
  p.subject = subject_;
  p.slice = slice_;
  out_.push_back(p);
}

Primitive Primitive::Ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                               const Eigen::Vector3d& radii, const Material& material) {
  Primitive p;
  p.shape = Shape::kEllipsoid;
  p.centre = centre;
  p.axes = rotation * radii.asDiagonal();
  p.material = material;
  return p;
}

Primitive Primitive::Capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                             const Material& material) {
  Primitive p;
  p.shape = Shape::kCapsule;
  p.a = a;
  p.b = b;
  p.radius = radius;
  p.centre = 0.5 * (a + b);
  p.material = material;
  return p;
}

double Primitive::LowestZ() const {
  if (shape == Shape::kCapsule) return std::min(a.z(), b.z()) - radius;
  return centre.z() - axes.row(2).norm();
}

double Primitive::HighestZ() const {
  if (shape == Shape::kCapsule) return std::max(a.z(), b.z()) + radius;
  return centre.z() + axes.row(2).norm();
}

std::vector<Eigen::Vector3d> Primitive::BoxPoints() const {
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(27);
  if (shape == Shape::kEllipsoid) {
    for (int i = -1; i <= 1; ++i) {
      for (int j = -1; j <= 1; ++j) {
        for (int k = -1; k <= 1; ++k) pts.push_back(centre + axes * Eigen::Vector3d(i, j, k));
      }
    }
  } else {
    const Eigen::Vector3d lo = a.cwiseMin(b).array() - radius, hi = a.cwiseMax(b).array() + radius;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j) {
        for (int k = 0; k <= 2; ++k) {
          pts.emplace_back(lo.x() + (hi.x() - lo.x()) * i / 2, lo.y() + (hi.y() - lo.y()) * j / 2,
                           lo.z() + (hi.z() - lo.z()) * k / 2);
        }
      }
    }
  }
  return pts;
}

namespace {

// Contour circle of the ellipsoid {centre + axes s : |s| = 1} seen from `eye`.
void EllipsoidContour(const Eigen::Vector3d& centre, const Eigen::Matrix3d& axes,
                      const Eigen::Vector3d& eye, int n, std::vector<Eigen::Vector3d>* out) {
  const Eigen::Vector3d o = axes.inverse() * (eye - centre);
  const double oo = o.squaredNorm();
  if (oo <= 1.0) return;
  const Eigen::Vector3d circle_centre = o / oo;
  const double r = std::sqrt(1.0 - 1.0 / oo);
  const Eigen::Vector3d w = o.normalized();
  Eigen::Vector3d u = w.unitOrthogonal();
  const Eigen::Vector3d v = w.cross(u);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    out->push_back(centre + axes * (circle_centre + r * (std::cos(a) * u + std::sin(a) * v)));
  }
}

}  // namespace

std::vector<Eigen::Vector3d> Primitive::ContourPoints(const Eigen::Vector3d& eye, int n) const {
  std::vector<Eigen::Vector3d> pts;
  if (shape == Shape::kEllipsoid) {
    EllipsoidContour(centre, axes, eye, n, &pts);
  } else {
    const double len = (b - a).norm();
    const int spheres = std::max(2, static_cast<int>(std::ceil(len / (0.4 * radius))) + 1);
    const Eigen::Matrix3d axes_r = radius * Eigen::Matrix3d::Identity();
    for (int i = 0; i < spheres; ++i) {
      EllipsoidContour(a + (b - a) * (static_cast<double>(i) / (spheres - 1)), axes_r, eye, n,
                       &pts);
    }
  }
  return pts;
}

Eigen::Vector3d Primitive::Normal(const Eigen::Vector3d& point) const {
  if (shape == Shape::kEllipsoid) {
    const Eigen::Matrix3d inv = axes.inverse();
    return (inv.transpose() * (inv * (point - centre))).normalized();
  }
  const Eigen::Vector3d ab = b - a;
  const double s = std::clamp((point - a).dot(ab) / std::max(1e-18, ab.squaredNorm()), 0.0, 1.0);
  return (point - (a + s * ab)).normalized();
}

double Primitive::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& d) const {
  if (shape == Shape::kEllipsoid) {
    const Eigen::Matrix3d inv = axes.inverse();
    const Eigen::Vector3d o = inv * (origin - centre), dd = inv * d;
    const double qa = dd.squaredNorm(), qb = o.dot(dd), qc = o.squaredNorm() - 1.0;
    const double disc = qb * qb - qa * qc;
    if (disc < 0 || qc < 0) return -1;
    const double t = (-qb - std::sqrt(disc)) / qa;
    return t > 0 ? t : -1;
  }
  const Eigen::Vector3d ba = b - a, oa = origin - a;
  const double baba = ba.dot(ba), bard = ba.dot(d), baoa = ba.dot(oa), rdoa = d.dot(oa),
               oaoa = oa.dot(oa);
  const double qa = baba - bard * bard, qb = baba * rdoa - baoa * bard,
               qc = baba * oaoa - baoa * baoa - radius * radius * baba;
  const double h = qb * qb - qa * qc;
  if (h < 0) return -1;
  const double t = (-qb - std::sqrt(h)) / qa;
  const double y = baoa + t * bard;
  if (y > 0 && y < baba && t > 0) return t;
  const Eigen::Vector3d oc = y <= 0 ? oa : Eigen::Vector3d(origin - b);
  const double sb = d.dot(oc), sc = oc.dot(oc) - radius * radius, sh = sb * sb - sc;
  if (sh > 0) {
    const double ts = -sb - std::sqrt(sh);
    return ts > 0 ? ts : -1;
  }
  return -1;
}

float PreparedPrimitive::Intersect(const float d[3]) const {
  if (shape == Shape::kEllipsoid) {
    const float dx = m[0] * d[0] + m[1] * d[1] + m[2] * d[2];
    const float dy = m[3] * d[0] + m[4] * d[1] + m[5] * d[2];
    const float dz = m[6] * d[0] + m[7] * d[1] + m[8] * d[2];
    const float qa = dx * dx + dy * dy + dz * dz;
    const float qb = o[0] * dx + o[1] * dy + o[2] * dz;
    const float disc = qb * qb - qa * c;
    if (disc < 0.f) return -1.f;
    const float t = (-qb - std::sqrt(disc)) / qa;
    return t > 0.f ? t : -1.f;
  }
  const float bard = ba[0] * d[0] + ba[1] * d[1] + ba[2] * d[2];
  const float rdoa = d[0] * o[0] + d[1] * o[1] + d[2] * o[2];
  const float qa = baba - bard * bard;
  const float qb = baba * rdoa - baoa * bard;
  const float qc = baba * oaoa - baoa * baoa - c * baba;
  const float h = qb * qb - qa * qc;
  if (h < 0.f) return -1.f;
  if (qa > 1e-12f) {
    const float t = (-qb - std::sqrt(h)) / qa;
    const float y = baoa + t * bard;
    if (y > 0.f && y < baba) return t > 0.f ? t : -1.f;
    // A cap: the sphere at a (y <= 0) or at b.
    float ocx = o[0], ocy = o[1], ocz = o[2];
    if (y > 0.f) {
      ocx -= ba[0];
      ocy -= ba[1];
      ocz -= ba[2];
    }
    const float sb = d[0] * ocx + d[1] * ocy + d[2] * ocz;
    const float sc = ocx * ocx + ocy * ocy + ocz * ocz - c;
    const float sh = sb * sb - sc;
    if (sh > 0.f) {
      const float ts = -sb - std::sqrt(sh);
      return ts > 0.f ? ts : -1.f;
    }
    return -1.f;
  }
  return -1.f;
}

bool Prepare(const Primitive& prim, int index, const SynthCamera& camera, PreparedPrimitive* out) {
  const Eigen::Vector3d eye = camera.CentreInGround();
  PreparedPrimitive& p = *out;
  p = PreparedPrimitive{};
  p.index = index;
  p.subject = prim.subject;
  p.slice = prim.slice;
  p.shape = prim.shape;
  if (prim.shape == Shape::kEllipsoid) {
    const Eigen::Matrix3d inv = prim.axes.inverse();
    const Eigen::Vector3d o = inv * (eye - prim.centre);
    if (o.squaredNorm() <= 1.0) return false;  // the camera is inside
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) p.m[r * 3 + c] = static_cast<float>(inv(r, c));
      p.o[r] = static_cast<float>(o[r]);
    }
    p.c = static_cast<float>(o.squaredNorm() - 1.0);
  } else {
    const Eigen::Vector3d ba = prim.b - prim.a, oa = eye - prim.a;
    for (int r = 0; r < 3; ++r) {
      p.ba[r] = static_cast<float>(ba[r]);
      p.o[r] = static_cast<float>(oa[r]);
    }
    p.baba = static_cast<float>(ba.dot(ba));
    p.baoa = static_cast<float>(ba.dot(oa));
    p.oaoa = static_cast<float>(oa.dot(oa));
    p.c = static_cast<float>(prim.radius * prim.radius);
  }
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const auto& q : prim.BoxPoints()) {
    const Eigen::Vector2d px = camera.ProjectGround(q);
    if (!std::isfinite(px.x())) {  // part of the box is behind the camera: the whole image
      x0 = 0;
      y0 = 0;
      x1 = camera.width - 1;
      y1 = camera.height - 1;
      break;
    }
    x0 = std::min(x0, px.x());
    x1 = std::max(x1, px.x());
    y0 = std::min(y0, px.y());
    y1 = std::max(y1, px.y());
  }
  const double margin = 2.0 + 0.02 * std::max(x1 - x0, y1 - y0);
  p.x0 = std::max(0, static_cast<int>(std::floor(x0 - margin)));
  p.y0 = std::max(0, static_cast<int>(std::floor(y0 - margin)));
  p.x1 = std::min(camera.width - 1, static_cast<int>(std::ceil(x1 + margin)));
  p.y1 = std::min(camera.height - 1, static_cast<int>(std::ceil(y1 + margin)));
  return p.x0 <= p.x1 && p.y0 <= p.y1;
}

namespace {

// Coordinates of a surface point in the primitive's own frame: unit-sphere
// coordinates for an ellipsoid; (axis fraction, two perpendicular) for a capsule.
Eigen::Vector3d LocalCoordinates(const Primitive& prim, const Eigen::Vector3d& point) {
  if (prim.shape == Shape::kEllipsoid) return prim.axes.inverse() * (point - prim.centre);
  const Eigen::Vector3d ab = prim.b - prim.a;
  const double len = std::max(1e-9, ab.norm());
  const Eigen::Vector3d w = ab / len;
  const Eigen::Vector3d u = w.unitOrthogonal(), v = w.cross(u);
  const Eigen::Vector3d rel = point - prim.a;
  return {rel.dot(w) / len, rel.dot(u) / prim.radius, rel.dot(v) / prim.radius};
}

}  // namespace

Eigen::Vector3d Shade(const Primitive& prim, const Eigen::Vector3d& point,
                      const Eigen::Vector3d& view_dir, const Lighting& lighting) {
  const Material& mat = prim.material;
  const Eigen::Vector3d n = prim.Normal(point);
  const Eigen::Vector3d local = LocalCoordinates(prim, point);
  Eigen::Vector3d albedo = mat.colour.cast<double>();
  const double s = mat.texture_scale;
  switch (mat.pattern) {
    case Pattern::kPlain:
      albedo *=
          1.0 + mat.texture * ValueNoise3(mat.seed, local.x() * s, local.y() * s, local.z() * s);
      break;
    case Pattern::kFur: {
      // Streaks along the local x axis (the body's length) and a lighter underside/muzzle.
      const double fur =
          Fbm3(mat.seed, local.x() * s * 0.5, local.y() * s * 2.0, local.z() * s * 2.0, 3);
      const double belly = std::clamp((-local.z() - 0.25) / 0.35, 0.0, 1.0);
      const double muzzle = std::clamp((local.x() - 0.55) / 0.3, 0.0, 1.0);
      const double light = std::max(belly, muzzle);
      albedo = albedo * (1.0 - light) + mat.colour2.cast<double>() * light;
      albedo *= 1.0 + mat.texture * fur;
      break;
    }
    case Pattern::kLimb: {
      // Capsules: axis fraction 0 at a (upper end); ellipsoids: local z (lower end below).
      const double lower = prim.shape == Shape::kCapsule
                               ? std::clamp((local.x() - 0.6) / 0.3, 0.0, 1.0)
                               : std::clamp((-local.z() - 0.2) / 0.4, 0.0, 1.0);
      albedo = albedo * (1.0 - lower) + mat.colour2.cast<double>() * lower;
      albedo *=
          1.0 + mat.texture * ValueNoise3(mat.seed, local.x() * s, local.y() * s, local.z() * s);
      break;
    }
    case Pattern::kCloth: {
      const double folds =
          Fbm3(mat.seed, local.x() * s * 0.3, local.y() * s * 0.3, local.z() * s * 0.3, 2);
      const double weave =
          ValueNoise3(Mix(mat.seed, 5), local.x() * s * 4, local.y() * s * 4, local.z() * s * 4);
      albedo *= 1.0 + mat.texture * (folds + 0.3 * weave);
      break;
    }
    case Pattern::kGlossy:
      break;
  }
  // Diffuse top light (a bright hemisphere), green bounce from the floor below,
  // and occlusion close to the floor.
  const double sky = 0.5 + 0.5 * n.z();
  const double e = 0.22 + 0.88 * std::pow(sky, 1.3);
  const double ao = 0.72 + 0.28 * std::clamp(point.z() / (0.3 * lighting.scale), 0.0, 1.0);
  Eigen::Vector3d radiance = 255.0 * albedo * (e * ao);
  radiance += albedo.cwiseProduct(lighting.bounce) * (0.45 * (0.5 - 0.5 * n.z()));
  if (mat.pattern == Pattern::kGlossy) {
    const Eigen::Vector3d r = view_dir - 2.0 * view_dir.dot(n) * n;
    radiance += Eigen::Vector3d::Constant(160.0 * std::pow(std::max(0.0, r.z()), 12.0));
  }
  return radiance;
}

}  // namespace ss::synth
