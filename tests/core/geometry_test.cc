// Ground geometry against hand-computed answers and against mrcal's own
// Rodrigues conversion (poseutils), the convention .cameramodel files use.
#include "core/geometry.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

extern "C" {
#include <mrcal/poseutils.h>
}

namespace ss {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

Eigen::Matrix3d MrcalRFromR(const Vector3d& r) {
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R;
  mrcal_R_from_r(R.data(), nullptr, r.data());
  return R;
}

TEST(Rigid3, FromRtMatchesMrcalRodrigues) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    Vector3d axis(u(rng), u(rng), u(rng));
    axis.normalize();
    const double angle =
        (i % 4 == 0) ? 1e-9 * (i + 1) : M_PI * (0.5 + 0.5 * u(rng));  // tiny and large angles
    const Vector3d r = axis * angle;
    const double rt[6] = {r.x(), r.y(), r.z(), u(rng), u(rng), u(rng)};
    const Rigid3 pose = Rigid3::FromRt(rt);
    EXPECT_LT((pose.rotation - MrcalRFromR(r)).cwiseAbs().maxCoeff(), 1e-15)
        << "r = " << r.transpose();
    EXPECT_EQ(pose.translation, Vector3d(rt[3], rt[4], rt[5]));
  }
}

TEST(Rigid3, RtRoundTrip) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    Vector3d axis(u(rng), u(rng), u(rng));
    axis.normalize();
    // Angles over (0, pi), including near 0 and near pi where Rodrigues is delicate.
    double angle = M_PI * std::abs(u(rng));
    if (i % 5 == 0) angle = 1e-7 * std::abs(u(rng));
    if (i % 5 == 1) angle = M_PI - 1e-7 * std::abs(u(rng));
    const Vector3d r = axis * angle;
    const double rt[6] = {r.x(), r.y(), r.z(), u(rng), u(rng), u(rng)};
    double back[6];
    Rigid3::FromRt(rt).ToRt(back);
    // Near pi the rotation fixes r only to the precision of 1 - cos; elsewhere to ~1e-15.
    const double tolerance = angle > M_PI - 1e-6 ? 1e-8 : 1e-14;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[k], rt[k], tolerance) << "angle " << angle;
    for (int k = 3; k < 6; ++k) EXPECT_EQ(back[k], rt[k]);
  }
  double zero[6] = {0, 0, 0, 1, 2, 3};
  const Rigid3 identity = Rigid3::FromRt(zero);
  EXPECT_EQ(identity.rotation, Eigen::Matrix3d::Identity());
  double back[6];
  identity.ToRt(back);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(back[k], zero[k]);
}

TEST(Rigid3, ComposeAndInverse) {
  const double rt_a[6] = {0.1, -0.7, 0.3, 1.0, 2.0, -0.5};
  const double rt_b[6] = {-1.2, 0.4, 0.9, -0.3, 0.2, 4.0};
  const Rigid3 b_from_a = Rigid3::FromRt(rt_a);
  const Rigid3 c_from_b = Rigid3::FromRt(rt_b);
  const Vector3d p(0.3, -1.1, 2.5);
  EXPECT_LT(((c_from_b * b_from_a) * p - c_from_b * (b_from_a * p)).norm(), 1e-14);
  EXPECT_LT((b_from_a.Inverse() * (b_from_a * p) - p).norm(), 1e-14);
  const Rigid3 identity = b_from_a * b_from_a.Inverse();
  EXPECT_LT((identity.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT(identity.translation.norm(), 1e-15);
}

TEST(IntersectGround, HitsTheFloorWhereExpected) {
  // From (0, 0, 2) towards (1, 2, -2): the floor is reached at s = 1.
  const auto hit = IntersectGround({Vector3d(0, 0, 2), Vector3d(1, 2, -2)});
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(*hit, Vector3d(1, 2, 0));
  // A camera looking up, a ray along the floor, a ray pointing away: no hit.
  EXPECT_FALSE(IntersectGround({Vector3d(0, 0, 2), Vector3d(0, 0, 1)}).has_value());
  EXPECT_FALSE(IntersectGround({Vector3d(0, 0, 2), Vector3d(1, 0, 0)}).has_value());
  EXPECT_FALSE(IntersectGround({Vector3d(0, 0, -1), Vector3d(0, 0, -1)}).has_value());
  // A ray from below the floor going up meets it too.
  const auto from_below = IntersectGround({Vector3d(1, 1, -1), Vector3d(0, 0, 0.5)});
  ASSERT_TRUE(from_below.has_value());
  EXPECT_EQ(*from_below, Vector3d(1, 1, 0));
  // NaN rays (a pixel mrcal cannot unproject) never hit.
  EXPECT_FALSE(IntersectGround({Vector3d(0, 0, 2), Vector3d(NAN, NAN, NAN)}).has_value());
}

GroundPolygon Square() { return GroundPolygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}); }
// An L: the unit square [0,2]x[0,2] minus its top-right quarter. Area 3.
GroundPolygon ElShape() { return GroundPolygon({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}); }

TEST(GroundPolygon, ContainsSquare) {
  const GroundPolygon sq = Square();
  EXPECT_TRUE(sq.Contains({0.5, 0.5}));
  EXPECT_TRUE(sq.Contains({0.0, 0.5}));  // on an edge
  EXPECT_TRUE(sq.Contains({1.0, 1.0}));  // on a vertex
  EXPECT_FALSE(sq.Contains({1.0001, 0.5}));
  EXPECT_FALSE(sq.Contains({-0.5, -0.5}));
  EXPECT_FALSE(GroundPolygon().Contains({0, 0}));  // empty polygon holds nothing
}

TEST(GroundPolygon, ContainsConcave) {
  const GroundPolygon el = ElShape();
  EXPECT_TRUE(el.Contains({0.5, 1.5}));
  EXPECT_TRUE(el.Contains({1.5, 0.5}));
  EXPECT_FALSE(el.Contains({1.5, 1.5}));  // the notch
  EXPECT_FALSE(el.Contains({2.5, 0.5}));
}

TEST(GroundPolygon, SignedDistance) {
  const GroundPolygon sq = Square();
  EXPECT_DOUBLE_EQ(sq.SignedDistance({0.5, 0.25}), 0.25);
  EXPECT_DOUBLE_EQ(sq.SignedDistance({0.5, 0.5}), 0.5);
  EXPECT_DOUBLE_EQ(sq.SignedDistance({2.0, 0.5}), -1.0);
  EXPECT_DOUBLE_EQ(sq.SignedDistance({2.0, 2.0}), -std::sqrt(2.0));  // nearest is the corner
  EXPECT_EQ(sq.SignedDistance({1.0, 0.3}), 0.0);
  const GroundPolygon el = ElShape();
  // In the notch, 0.5 from the inner corner's two edges; the inner corner (1,1) is nearer
  // diagonally.
  EXPECT_DOUBLE_EQ(el.SignedDistance({1.5, 1.5}), -0.5);
  EXPECT_DOUBLE_EQ(el.SignedDistance({1.2, 1.2}), -0.2);
  EXPECT_NEAR(el.SignedDistance({0.5, 1.9}), 0.1, 1e-15);
  // Near the inner corner from inside: the corner point (1, 1) is nearest.
  EXPECT_NEAR(el.SignedDistance({0.9, 0.9}), std::sqrt(0.02), 1e-15);
}

TEST(GroundPolygon, ContainsWithMargin) {
  const GroundPolygon el = ElShape();
  EXPECT_TRUE(el.ContainsWithMargin({0.5, 0.5}, 0.4));
  EXPECT_FALSE(el.ContainsWithMargin({0.5, 0.5}, 0.6));
  // Close to the inner corner: inside, but within 0.2 m of the walls.
  EXPECT_TRUE(el.Contains({0.9, 0.9}));
  EXPECT_FALSE(el.ContainsWithMargin({0.9, 0.9}, 0.2));
  EXPECT_TRUE(el.ContainsWithMargin({0.7, 0.7}, 0.2));
}

TEST(GroundPolygon, Area) {
  EXPECT_DOUBLE_EQ(Square().Area(), 1.0);
  EXPECT_DOUBLE_EQ(ElShape().Area(), 3.0);
  // Clockwise order gives the same area.
  std::vector<Vector2d> cw = ElShape().vertices();
  std::reverse(cw.begin(), cw.end());
  EXPECT_DOUBLE_EQ(GroundPolygon(cw).Area(), 3.0);
  EXPECT_DOUBLE_EQ(GroundPolygon({{0, 0}, {4, 0}, {0, 3}}).Area(), 6.0);
  EXPECT_EQ(GroundPolygon().Area(), 0.0);
}

TEST(GroundPolygon, IsSimple) {
  EXPECT_TRUE(Square().IsSimple());
  EXPECT_TRUE(ElShape().IsSimple());
  EXPECT_FALSE(GroundPolygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}}).IsSimple());  // bow tie
  EXPECT_FALSE(GroundPolygon({{0, 0}, {1, 0}}).IsSimple());                  // too few vertices
  EXPECT_FALSE(GroundPolygon({{0, 0}, {1, 0}, {2, 0}}).IsSimple());          // no area
  EXPECT_FALSE(GroundPolygon({{0, 0}, {1, 0}, {1, 0}, {1, 1}}).IsSimple());  // repeated vertex
  EXPECT_FALSE(GroundPolygon({{0, 0}, {2, 0}, {1, 0}, {1, 1}}).IsSimple());  // edge folds back
  EXPECT_FALSE(
      GroundPolygon({{0, 0}, {2, 0}, {2, 2}, {1, 0}, {0, 2}}).IsSimple());  // vertex on an edge
  EXPECT_FALSE(GroundPolygon({{0, 0}, {1, 0}, {NAN, 1}}).IsSimple());
}

}  // namespace
}  // namespace ss
