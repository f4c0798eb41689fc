#pragma once
// Ground geometry. One convention everywhere: `b_from_a` maps a point in frame a
// to frame b (x_b = R x_a + t). The ground frame is the world: z up, z = 0 is
// the floor, metres.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ss {

struct Rigid3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return rotation * p + translation; }
  Rigid3 operator*(const Rigid3& o) const {
    return {rotation * o.rotation, rotation * o.translation + translation};
  }
  Rigid3 Inverse() const { return {rotation.transpose(), -(rotation.transpose() * translation)}; }
  // mrcal's rt form: Rodrigues rotation vector r (axis * angle, |r| <= pi) then translation t.
  static Rigid3 FromRt(const double rt[6]);
  void ToRt(double rt[6]) const;
  bool operator==(const Rigid3& o) const {
    return rotation == o.rotation && translation == o.translation;
  }
};

// A ray in the ground frame: origin + s * direction, s >= 0.
struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;
};

// Where the ray meets the floor z = 0 in front of its origin; nullopt when it
// runs parallel to the floor, points away from it or is not finite (NaN).
std::optional<Eigen::Vector3d> IntersectGround(const Ray& ray);

// A simple polygon on the floor (ground x, y in metres), vertices in order.
class GroundPolygon {
 public:
  // The most vertices a floor polygon may have; every reader of a floor refuses more, naming
  // it. IsSimple no longer bounds it (a million vertices: 0.1-1.1 s, bench/RESULTS.md); the
  // config reader does: yaml-cpp holds ~1.5 KB a point while it parses (100,000 points: 250 MB
  // and 1.4 s; a million: 1.7 GB and 10 s). Beware that the pipeline's floor mask tests every
  // pixel against every edge (FloorMask: ~13 s a 640x480 camera at 10,000 vertices, linear in both).
  static constexpr size_t kMaxVertices = 100000;

  GroundPolygon() = default;
  explicit GroundPolygon(std::vector<Eigen::Vector2d> vertices);

  const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }
  bool empty() const { return vertices_.size() < 3; }
  // Inside (or on the boundary) by the even-odd rule.
  bool Contains(const Eigen::Vector2d& point_in_ground) const;
  // Distance to the nearest edge; positive inside, negative outside.
  double SignedDistance(const Eigen::Vector2d& point_in_ground) const;
  // Inside and at least `margin` metres from every edge (exact for any simple polygon).
  bool ContainsWithMargin(const Eigen::Vector2d& point_in_ground, double margin) const;
  double Area() const;  // square metres, whatever the vertex order
  // At least 3 finite vertices, no two edges crossing or touching except
  // neighbours at their shared vertex, and a non-zero area. O(n log n) (a sweep), in exact
  // arithmetic for any floor in metres.
  bool IsSimple() const;
  bool operator==(const GroundPolygon& o) const { return vertices_ == o.vertices_; }

 private:
  std::vector<Eigen::Vector2d> vertices_;
};

}  // namespace ss
