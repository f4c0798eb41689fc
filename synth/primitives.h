#pragma once
// The shapes subjects are made of (ellipsoids and capsules in the ground frame),
// their materials and shading under the studio's diffuse top light, and the
// per-camera form the renderer intersects pixel rays with.
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "synth/lens.h"

namespace ss::synth {

enum class Pattern : uint8_t {
  kPlain,   // colour with a faint grain
  kFur,     // fur: 3-D noise, lighter belly (local z < 0), lighter muzzle (local x > 0.55)
  kLimb,    // colour, turning to colour2 toward the capsule's / ellipsoid's lower end
  kCloth,   // cloth: weave grain and soft folds
  kGlossy,  // dark and shiny (eyes)
};

struct Material {
  Pattern pattern = Pattern::kPlain;
  Eigen::Vector3f colour{0.5f, 0.5f, 0.5f};   // albedo, B G R in 0..1
  Eigen::Vector3f colour2{0.8f, 0.8f, 0.8f};  // belly, muzzle or lower end
  float texture = 0.1f;                       // relative strength of the texture
  float texture_scale = 8.0f;                 // texture cycles per unit of local coordinates
  uint32_t seed = 0;
};

enum class Shape : uint8_t { kEllipsoid, kCapsule };

struct Primitive {
  Shape shape = Shape::kEllipsoid;
  int subject = 0;  // which subject it belongs to
  int slice = 0;    // motion-blur time slice
  Material material;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // ellipsoid
  // ellipsoid: columns = semi-axis vectors (ground)
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  // capsule end points
  double radius = 0.0;                                                       // capsule

  static Primitive Ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& radii, const Material& material);
  static Primitive Capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                           const Material& material);
  // Lowest z of the shape.
  double LowestZ() const;
  // Highest z of the shape.
  double HighestZ() const;
  // Points bounding the shape (corners, face and edge centres of its box).
  std::vector<Eigen::Vector3d> BoxPoints() const;
  // Points on the shape's contour seen from `eye` (ground frame), `n` per circle.
  std::vector<Eigen::Vector3d> ContourPoints(const Eigen::Vector3d& eye, int n) const;
  // Outward unit normal at a surface point (ground frame).
  Eigen::Vector3d Normal(const Eigen::Vector3d& point) const;
  // Distance (ray parameter for a unit direction) of the first hit; < 0 for a miss.
  double Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
};

// One subject's primitives, made in its own frame (x forward, z up, at scale 1) and placed on
// the ground: scaled by `scale`, turned by `heading_rad` about z, moved to `position`. Each part's
// material gets a texture seed of its own from the look's seed and the part's number.
class SubjectParts {
 public:
  SubjectParts(const Eigen::Vector2d& position, double heading_rad, double scale,
               uint64_t look_seed, int subject, int slice, size_t reserve);
  // A point of the subject's frame on the ground.
  Eigen::Vector3d ToGround(const Eigen::Vector3d& p) const;
  // `m` with part `part`'s texture seed.
  Material Seeded(Material m, uint64_t part) const;
  // `rotation` and `radii` in the subject's frame.
  void Ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                 const Eigen::Vector3d& radii, const Material& m);
  void Capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
               const Material& m);
  std::vector<Primitive> Take() && { return std::move(out_); }

 private:
  Eigen::Matrix3d r_world_;
  Eigen::Vector3d t_world_;
  double scale_;
  uint64_t look_seed_;
  int subject_, slice_;
  std::vector<Primitive> out_;
};

// Shading constants of one studio.
struct Lighting {
  Eigen::Vector3d bounce{0.0, 0.0, 0.0};  // green light from the floor, radiance units
  double scale = 0.1;                     // subject size in metres (height ambient occlusion)
};

// Radiance (B G R, 0..255 before camera gain and vignetting) of a subject surface point.
Eigen::Vector3d Shade(const Primitive& prim, const Eigen::Vector3d& point,
                      const Eigen::Vector3d& view_dir, const Lighting& lighting);

// A primitive in one camera's terms (floats, relative to the camera centre).
struct PreparedPrimitive {
  int index = 0;  // into the frame's primitive list
  int subject = 0;
  int slice = 0;
  Shape shape = Shape::kEllipsoid;
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // pixel bounding box, inclusive
  float m[9] = {};                       // ellipsoid: inverse of axes (row-major)
  float o[3] = {};   // ellipsoid: eye in unit-sphere coordinates; capsule: eye - a
  float c = 0;       // ellipsoid: |o|^2 - 1; capsule: r^2
  float ba[3] = {};  // capsule: b - a
  float baba = 0, baoa = 0, oaoa = 0;

  // Hit distance along the unit direction `d`, or -1.
  float Intersect(const float d[3]) const;
};

// Prepares `prim` for the camera; false when it cannot be seen at all.
bool Prepare(const Primitive& prim, int index, const SynthCamera& camera, PreparedPrimitive* out);

}  // namespace ss::synth
