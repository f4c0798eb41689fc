#pragma once
// Ground geometry. One convention everywhere: `b_from_a` maps a point in frame a
// to frame b (x_b = R x_a + t). The ground frame is the world: z up, z = 0 is
// the floor, metres.
#include <cstdint>
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
  // and 1.4 s; a million: 1.7 GB and 10 s). Points in bulk (the pipeline's floor mask): use a
  // GroundPolygonIndex, which tests only the edges near each point.
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

// GroundPolygon::Contains for many points, bit for bit the same answer (the same even-odd rule,
// the boundary inside), from the edges near each point only: the edges are filed in bands of
// ground y, and a point tests only its band's (those the horizontal line through it crosses,
// and those within rounding of it). A point then costs the edges near its y, not all n
// (bench/RESULTS.md, geometry). Borrows nothing: it copies the vertices.
class GroundPolygonIndex {
 public:
  explicit GroundPolygonIndex(const GroundPolygon& polygon);
  bool Contains(const Eigen::Vector2d& point_in_ground) const;

 private:
  int Band(double y) const;  // monotone in y, clamped to [0, bands)
  GroundPolygon polygon_;    // the fallback for points or vertices beyond the bands' reach
  bool indexed_ = false;
  double y0_ = 0, scale_ = 0;
  int bands_ = 1;
  std::vector<uint32_t>
      band_start_;  // band b's edges: band_edges_[band_start_[b] .. band_start_[b + 1])
  std::vector<uint32_t> band_edges_;  // edge k runs from vertex k - 1 (n - 1 for k = 0) to vertex k
  std::vector<Eigen::Vector2d> x_range_;  // edge k's x extent, widened by its rounding reach
};

}  // namespace ss
