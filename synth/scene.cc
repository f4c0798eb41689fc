#include "synth/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "synth/angles.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

// A quad whose front faces `front_normal` (u and v swapped when needed).
Quad MakeQuad(const Eigen::Vector3d& origin, Eigen::Vector3d u, Eigen::Vector3d v,
              const Eigen::Vector3d& front_normal, Surface front, Surface back) {
  if (u.cross(v).dot(front_normal) < 0) std::swap(u, v);
  Quad q;
  q.origin = origin;
  q.u = u;
  q.v = v;
  q.normal = u.cross(v).normalized();
  q.front = front;
  q.back = back;
  return q;
}

double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

Eigen::Vector3d GreenPaper(uint64_t seed, double s, double t) {
  // Albedo of the green paper at paper coordinates (s, t) in metres: low-frequency
  // brightness and hue variation plus a fine paper grain.
  Eigen::Vector3d albedo(0.20, 0.60, 0.17);
  const double bright = 1.0 + 0.08 * Fbm2(Mix(seed, 1), s / 0.30, t / 0.30, 3);
  const double hue = 0.12 * Fbm2(Mix(seed, 2), s / 0.9, t / 0.9, 2);
  const double grain = 0.025 * ValueNoise2(Mix(seed, 3), s / 0.004, t / 0.004);
  albedo.x() *= 1.0 + hue;
  albedo.z() *= 1.0 - hue;
  return albedo * (bright + grain);
}

}  // namespace

std::string StudioKindName(StudioKind kind) {
  return kind == StudioKind::kEnclosure ? "enclosure" : "stage";
}

Studio MakeStudio(StudioKind kind, uint64_t seed, bool room_backdrop) {
  Studio s;
  s.kind = kind;
  s.seed = StreamSeed(seed, "studio");
  s.room_backdrop = room_backdrop;
  double room_x = 3.0, room_y = 3.0, room_z = 2.6;
  if (kind == StudioKind::kEnclosure) {
    s.half_x = 0.6;
    s.half_y = 0.4;
    s.wall_height = 0.25;
    s.subject_scale = 0.1;
  } else {
    s.half_x = 2.0;
    s.half_y = 1.5;
    s.wall_height = 2.5;
    s.subject_scale = 1.0;
    room_x = 7.0;
    room_y = 8.0;
    room_z = 4.0;
  }
  const double hx = s.half_x, hy = s.half_y, h = s.wall_height;
  s.floor = GroundPolygon({{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}});
  using V = Eigen::Vector3d;
  // [0]: the whole floor of the room; green where the floor polygon holds the point.
  s.quads.push_back(MakeQuad(V(-room_x, -room_y, 0), V(2 * room_x, 0, 0), V(0, 2 * room_y, 0),
                             V::UnitZ(), Surface::kRoomFloor, Surface::kRoomFloor));
  // Room walls and ceiling, facing in.
  s.quads.push_back(MakeQuad(V(-room_x, -room_y, 0), V(2 * room_x, 0, 0), V(0, 0, room_z),
                             V::UnitY(), Surface::kRoomWall, Surface::kRoomWall));
  s.quads.push_back(MakeQuad(V(-room_x, room_y, 0), V(2 * room_x, 0, 0), V(0, 0, room_z),
                             -V::UnitY(), Surface::kRoomWall, Surface::kRoomWall));
  s.quads.push_back(MakeQuad(V(-room_x, -room_y, 0), V(0, 2 * room_y, 0), V(0, 0, room_z),
                             V::UnitX(), Surface::kRoomWall, Surface::kRoomWall));
  s.quads.push_back(MakeQuad(V(room_x, -room_y, 0), V(0, 2 * room_y, 0), V(0, 0, room_z),
                             -V::UnitX(), Surface::kRoomWall, Surface::kRoomWall));
  s.quads.push_back(MakeQuad(V(-room_x, -room_y, room_z), V(2 * room_x, 0, 0), V(0, 2 * room_y, 0),
                             -V::UnitZ(), Surface::kCeiling, Surface::kCeiling));
  // Green walls, green on the inside.
  auto wall = [&](const V& a, const V& b, const V& inward) {
    s.green_walls.push_back(static_cast<int>(s.quads.size()));
    s.quads.push_back(
        MakeQuad(a, b - a, V(0, 0, h), inward, Surface::kGreenWall, Surface::kWallOutside));
  };
  if (kind == StudioKind::kEnclosure) wall(V(-hx, -hy, 0), V(hx, -hy, 0), V::UnitY());
  wall(V(-hx, hy, 0), V(hx, hy, 0), -V::UnitY());
  wall(V(-hx, -hy, 0), V(-hx, hy, 0), V::UnitX());
  wall(V(hx, -hy, 0), V(hx, hy, 0), -V::UnitX());
  return s;
}

BackgroundHit Studio::Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  BackgroundHit best;
  best.t = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < quads.size(); ++i) {
    const Quad& q = quads[i];
    const double denom = q.normal.dot(direction);
    if (std::abs(denom) < 1e-12) continue;
    const double t = q.normal.dot(q.origin - origin) / denom;
    if (!(t > 1e-9) || t >= best.t) continue;
    const Eigen::Vector3d p = origin + t * direction;
    const Eigen::Vector3d rel = p - q.origin;
    const double a = rel.dot(q.u) / q.u.squaredNorm();
    const double b = rel.dot(q.v) / q.v.squaredNorm();
    if (a < 0 || a > 1 || b < 0 || b > 1) continue;
    best.t = t;
    best.quad = static_cast<int>(i);
    best.point = p;
    best.surface = denom < 0 ? q.front : q.back;
    best.normal = denom < 0 ? q.normal : Eigen::Vector3d(-q.normal);
  }
  if (best.quad == 0 && floor.Contains(best.point.head<2>())) best.surface = Surface::kGreenFloor;
  return best;
}

double Studio::DistanceToWall(const Eigen::Vector2d& p) const {
  double d = std::numeric_limits<double>::infinity();
  for (int i : green_walls) {
    const Quad& q = quads[i];
    d = std::min(d, SegmentDistance(p, q.origin.head<2>(), (q.origin + q.u).head<2>()));
  }
  return d;
}

Eigen::Vector3d Studio::FloorBounce() const {
  return 255.0 * Eigen::Vector3d(0.20, 0.60, 0.17) * 1.05;
}

Eigen::Vector3d Studio::Radiance(const BackgroundHit& hit) const {
  const Eigen::Vector3d& p = hit.point;
  const double ao_scale = kind == StudioKind::kEnclosure ? 0.035 : 0.25;
  Surface surface = hit.surface;
  if (!room_backdrop && surface != Surface::kGreenFloor && surface != Surface::kGreenWall) {
    surface = Surface::kGreenWall;
  }
  switch (surface) {
    case Surface::kGreenFloor: {
      Eigen::Vector3d albedo = GreenPaper(seed, p.x(), p.y());
      // Sheets of paper 0.5 m wide, each a little different, with a darker seam.
      const double sheet_pos = (p.x() + half_x) / 0.5 + 0.37;
      const double sheet = std::floor(sheet_pos);
      const double seam = std::abs(sheet_pos - std::round(sheet_pos)) * 0.5;
      albedo *=
          1.0 + 0.035 * (static_cast<double>(Mix(seed, static_cast<uint64_t>(sheet + 100)) % 1000) /
                             500.0 -
                         1.0);
      if (seam < 0.0015) albedo *= 0.9;
      const double rx = p.x() / half_x, ry = p.y() / half_y;
      double e = 1.08 - 0.14 * 0.5 * (rx * rx + ry * ry);
      if (std::isfinite(DistanceToWall(p.head<2>()))) {
        e *= 1.0 - 0.28 * std::exp(-DistanceToWall(p.head<2>()) / ao_scale);
      }
      return 255.0 * albedo * e;
    }
    case Surface::kGreenWall: {
      const double s = std::abs(p.x()) > half_x - 1e-6 ? p.y() : p.x();
      Eigen::Vector3d albedo = GreenPaper(Mix(seed, 7), s, p.z());
      double e = 0.60 + 0.14 * std::min(1.0, p.z() / wall_height);
      e *= 1.0 - 0.22 * std::exp(-p.z() / ao_scale);
      const double corner = std::min(half_x - std::abs(p.x()), half_y - std::abs(p.y()));
      if (std::abs(p.x()) <= half_x + 1e-6 && std::abs(p.y()) <= half_y + 1e-6) {
        e *= 1.0 - 0.18 * std::exp(-std::max(0.0, corner) / ao_scale);
      }
      return 255.0 * albedo * e;
    }
    case Surface::kWallOutside: {
      const double s = std::abs(p.x()) > half_x - 1e-6 ? p.y() : p.x();
      const double grain = 0.06 * Fbm2(Mix(seed, 11), s * 4.0, p.z() * 60.0, 2);
      return 255.0 * Eigen::Vector3d(0.50, 0.62, 0.72) * (0.55 + grain);
    }
    case Surface::kRoomFloor: {
      const double tile = 0.5;
      const double fx = p.x() / tile - std::floor(p.x() / tile),
                   fy = p.y() / tile - std::floor(p.y() / tile);
      double albedo = 0.34 + 0.03 * Fbm2(Mix(seed, 13), p.x() / 0.2, p.y() / 0.2, 3);
      if (fx < 0.01 || fy < 0.01) albedo *= 0.8;
      const double r2 = p.head<2>().squaredNorm();
      return 255.0 * Eigen::Vector3d(albedo * 0.97, albedo, albedo * 1.03) *
             (0.8 / (1.0 + 0.04 * r2));
    }
    case Surface::kRoomWall: {
      double albedo = 0.66 + 0.04 * Fbm2(Mix(seed, 17), (p.x() + p.y()) / 0.5, p.z() / 0.5, 3);
      if (p.z() < 0.1) albedo = 0.25;
      return 255.0 * Eigen::Vector3d(albedo * 0.95, albedo, albedo * 1.04) * 0.45;
    }
    case Surface::kCeiling: {
      const double fx = std::abs(std::fmod(p.x() + 100.25, 1.5) - 0.75),
                   fy = std::abs(std::fmod(p.y() + 100.4, 1.5) - 0.75);
      const double e = (fx < 0.3 && fy < 0.3) ? 1.6 : 0.35;
      return 255.0 * Eigen::Vector3d(0.8, 0.8, 0.8) * e;
    }
  }
  return Eigen::Vector3d::Zero();
}

Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll_rad) {
  const Eigen::Vector3d z = (target - centre).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d ground_from_cam;
  ground_from_cam.col(0) = x;
  ground_from_cam.col(1) = y;
  ground_from_cam.col(2) = z;
  ground_from_cam =
      ground_from_cam * Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Rigid3 cam_from_ground;
  cam_from_ground.rotation = ground_from_cam.transpose();
  cam_from_ground.translation = -(cam_from_ground.rotation * centre);
  return cam_from_ground;
}

std::vector<SynthCamera> MakeCameras(const Studio& studio, int count, int width, int height,
                                     uint64_t seed, CameraView view) {
  Rng rng(StreamSeed(seed, StudioKindName(studio.kind) + "-cameras"));
  std::vector<SynthCamera> cameras;
  const bool enclosure = studio.kind == StudioKind::kEnclosure;
  for (int k = 0; k < count; ++k) {
    SynthCamera cam;
    cam.name = "cam" + std::to_string(k);
    cam.width = width;
    cam.height = height;
    cam.lensmodel = "LENSMODEL_OPENCV8";
    const double fx = width * rng.Uniform(0.80, 0.95);
    const double fy = fx * rng.Uniform(0.998, 1.002);
    const double cx = (width - 1) / 2.0 + rng.Uniform(-0.015, 0.015) * width;
    const double cy = (height - 1) / 2.0 + rng.Uniform(-0.015, 0.015) * height;
    const double r_corner =
        std::hypot(std::max(cx, width - cx) / fx, std::max(cy, height - cy) / fy);
    for (int attempt = 0; attempt < 100; ++attempt) {
      cam.intrinsics = {fx,
                        fy,
                        cx,
                        cy,
                        rng.Uniform(-0.28, 0.05),
                        rng.Uniform(-0.04, 0.10),  // k1 k2
                        rng.Uniform(-0.0012, 0.0012),
                        rng.Uniform(-0.0012, 0.0012),  // p1 p2
                        rng.Uniform(-0.015, 0.015),
                        rng.Uniform(0.0, 0.06),  // k3 k4
                        rng.Uniform(-0.01, 0.01),
                        rng.Uniform(-0.005, 0.005)};  // k5 k6
      cam.lens = Lens(cam.lensmodel, cam.intrinsics);
      if (cam.lens.MinRadialSlope(1.4 * r_corner) > 0.35) break;
    }
    double azimuth = 0, distance = 0, elevation = 0, roll = rng.Uniform(-2.5, 2.5) * kDeg;
    Eigen::Vector3d target;
    if (enclosure) {
      azimuth = (-90.0 + 360.0 * k / count + rng.Uniform(-12, 12)) * kDeg;
      distance = rng.Uniform(1.25, 1.7);
      elevation = rng.Uniform(38, 62) * kDeg;
      target = {rng.Uniform(-0.04, 0.04), rng.Uniform(-0.03, 0.03), 0.0};
      // Overhead: the same draws (lenses and gains as the oblique view's), a steep elevation.
      if (view == CameraView::kOverhead) elevation = (90.0 - (62.0 - elevation / kDeg) / 3) * kDeg;
    } else {
      const double spread = count == 1 ? 0.0 : -30.0 + 60.0 * k / (count - 1);
      azimuth = (-90.0 + spread + rng.Uniform(-6, 6)) * kDeg;
      distance = rng.Uniform(4.3, 5.0);
      elevation = std::atan2(rng.Uniform(1.1, 1.8) - 0.9, distance);
      target = {rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.2), rng.Uniform(0.85, 0.95)};
    }
    // What must be in view: the floor and the wall tops, or the figure's space.
    std::vector<Eigen::Vector3d> must_see;
    if (enclosure) {
      for (double sx : {-1.0, 1.0}) {
        for (double sy : {-1.0, 1.0}) {
          must_see.emplace_back(sx * studio.half_x, sy * studio.half_y, 0.0);
          must_see.emplace_back(sx * studio.half_x, sy * studio.half_y, studio.wall_height);
        }
      }
    } else {
      for (double sx : {-1.3, 1.3}) {
        for (double sy : {-1.0, 1.0}) {
          for (double z : {0.0, 2.2}) must_see.emplace_back(sx, sy, z);
        }
      }
    }
    const double margin = 6.0;
    for (int attempt = 0; attempt < 60; ++attempt) {
      const Eigen::Vector3d offset(std::cos(azimuth) * std::cos(elevation),
                                   std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
      const Eigen::Vector3d centre =
          (enclosure ? Eigen::Vector3d::Zero() : Eigen::Vector3d(target.x(), target.y(), 0.9)) +
          distance * offset;
      cam.cam_from_ground = LookAt(centre, target, roll);
      bool all_in = true;
      for (const auto& p : must_see) {
        const Eigen::Vector2d px = cam.ProjectGround(p);
        if (!(px.x() >= margin && px.y() >= margin && px.x() <= width - 1 - margin &&
              px.y() <= height - 1 - margin)) {
          all_in = false;
        }
      }
      if (all_in) break;
      distance *= 1.05;
    }
    cam.gain[0] = rng.Uniform(0.95, 1.05);
    cam.gain[1] = rng.Uniform(0.97, 1.03);
    cam.gain[2] = rng.Uniform(0.95, 1.05);
    cam.vignetting = rng.Uniform(0.12, 0.26);
    cameras.push_back(std::move(cam));
  }
  return cameras;
}

double RoomAhead(const Studio& studio, const Eigen::Vector2d& position, double heading_rad) {
  const Eigen::Vector2d d(std::cos(heading_rad), std::sin(heading_rad));
  const auto& v = studio.floor.vertices();
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d a = v[i], e = v[(i + 1) % v.size()] - a;
    const double den = d.x() * e.y() - d.y() * e.x();
    if (std::abs(den) < 1e-12) continue;
    const Eigen::Vector2d w = a - position;
    const double t = (w.x() * e.y() - w.y() * e.x()) / den;
    const double u = (w.x() * d.y() - w.y() * d.x()) / den;
    if (t >= 0 && u >= 0 && u <= 1) best = std::min(best, t);
  }
  return best;
}

}  // namespace ss::synth
