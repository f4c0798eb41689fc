// Ground geometry against hand-computed answers and against mrcal's own
// Rodrigues conversion (poseutils), the convention .cameramodel files use.
#include "core/geometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

extern "C" {
#include <mrcal/poseutils.h>
}

#include "tests/core/polygon_fixtures.h"

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
    // tiny and large angles
    const double angle = (i % 4 == 0) ? 1e-9 * (i + 1) : M_PI * (0.5 + 0.5 * u(rng));
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

// --- IsSimple: the sweep against the brute force it replaced (issue 20) ---

using Poly = std::vector<Vector2d>;

using testing::Comb;
using testing::Star;

// Random vertices on a small grid: collinear points, repeats and touching edges are common.
Poly GridPolygon(std::mt19937& rng, int grid, size_t n) {
  std::uniform_int_distribution<int> c(0, grid);
  Poly v;
  for (size_t i = 0; i < n; ++i) v.push_back({c(rng), c(rng)});
  return v;
}

// The same polygon seen otherwise: verdicts must not change. Scales and shifts are powers of two
// and integers, so the arithmetic of both checks stays exact.
std::vector<Poly> Variants(const Poly& p, std::mt19937& rng) {
  std::vector<Poly> out = {p};
  Poly r = p;
  std::reverse(r.begin(), r.end());
  out.push_back(r);
  Poly rotated = p;
  std::rotate(rotated.begin(), rotated.begin() + static_cast<long>(rng() % p.size()),
              rotated.end());
  out.push_back(rotated);
  Poly swapped = p, mirrored = p, scaled = p;
  for (size_t i = 0; i < p.size(); ++i) {
    swapped[i] = {p[i].y(), p[i].x()};
    mirrored[i] = {-p[i].x(), p[i].y()};
    scaled[i] = p[i] * 0x1p-20 + Vector2d(3, -5);
  }
  out.push_back(swapped);
  out.push_back(mirrored);
  out.push_back(scaled);
  return out;
}

// Counts verdicts and fails on the first that differs from the brute force, naming the case.
struct Agreement {
  int simple = 0, not_simple = 0;
  void Check(const Poly& p, const std::string& what) {
    const bool sweep = GroundPolygon(p).IsSimple();
    const bool brute = testing::BruteForceIsSimple(p);
    if (sweep != brute) {
      std::string text;
      for (const Vector2d& v : p)
        text += "(" + std::to_string(v.x()) + ", " + std::to_string(v.y()) + ") ";
      ADD_FAILURE() << what << ": sweep says " << sweep << ", the brute force " << brute << " for "
                    << p.size() << " vertices: " << text.substr(0, 2000);
    }
    ++(brute ? simple : not_simple);
  }
};

TEST(GroundPolygon, IsSimpleAgreesWithTheBruteForceOnRandomGridPolygons) {
  std::mt19937 rng(20);
  Agreement a;
  for (int i = 0; i < 20000; ++i) {
    const int grid = 2 + i % 7;
    const Poly p = GridPolygon(rng, grid, 3 + rng() % 9);
    for (const Poly& v : Variants(p, rng))
      a.Check(v, "grid " + std::to_string(grid) + " case " + std::to_string(i));
  }
  std::printf("random grid polygons: %d simple, %d not\n", a.simple, a.not_simple);
  EXPECT_GT(a.simple, 1000);
  EXPECT_GT(a.not_simple, 1000);
}

TEST(GroundPolygon, IsSimpleAgreesWithTheBruteForceOnAdversarialPolygons) {
  std::mt19937 rng(21);
  Agreement a;
  const auto check = [&](const Poly& p, const std::string& what) {
    for (const Poly& v : Variants(p, rng)) a.Check(v, what);
  };
  // Stars: simple ones, and star polygons {n/k} whose edges cross.
  for (size_t n : {3, 4, 5, 17, 200}) check(Star(n, rng), "star " + std::to_string(n));
  for (int n = 5; n <= 13; ++n) {
    for (int k = 1; k < n / 2 + 1; ++k) {
      Poly p;
      for (int i = 0; i < n; ++i) {
        const double angle = 2 * M_PI * k * i / n;
        p.push_back({std::round(1000 * std::cos(angle)), std::round(1000 * std::sin(angle))});
      }
      check(p, "star polygon {" + std::to_string(n) + "/" + std::to_string(k) + "}");
    }
  }
  // Combs, with one tooth leaning onto, against or through its neighbour, or to a gap's bottom.
  for (size_t teeth : {1, 2, 3, 8, 20}) {
    const Poly comb = Comb(teeth);
    check(comb, "comb");
    for (size_t k = 2; k + 2 < comb.size(); k += 4) {
      for (double dx : {0.5, 1.0, 1.5, 2.0, 3.0}) {
        Poly lean = comb;
        lean[k].x() += dx;  // a tooth's top-right corner pushed right
        check(lean, "comb, tooth corner " + std::to_string(k) + " moved " + std::to_string(dx));
      }
      for (double dy : {-9.0, -10.0, -10.5, -11.0}) {
        Poly low = comb;
        low[k].y() += dy;  // down to, onto or through the bar
        check(low, "comb, tooth corner " + std::to_string(k) + " lowered " + std::to_string(dy));
      }
    }
  }
  // Collinear: every vertex on one line; straight vertices; an edge running back over another.
  check({{0, 0}, {1, 1}, {2, 2}, {3, 3}}, "all on a line");
  check({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {0, 1}}, "a straight vertex");
  check({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {3, 1}, {2, 1}, {1, 1}, {0, 1}},
        "straight vertices both sides");
  check({{0, 0}, {4, 0}, {4, 2}, {3, 0}, {2, 0}, {1, 2}}, "a notch down onto the bottom edge");
  check({{0, 0}, {4, 0}, {4, 2}, {2, 2}, {2, 0}, {1, 0}, {1, 2}, {0, 2}},
        "edges overlapping on one line");
  check({{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 3}, {2, 3}, {2, 1}, {0, 1}},
        "a gap closed on the left edge");
  // Repeated vertices: in a row, or a figure of eight through one point.
  check({{0, 0}, {2, 0}, {2, 0}, {2, 2}, {0, 2}}, "a vertex twice in a row");
  check({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}, "two loops through one vertex");
  check({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}}, "the first vertex again at the end");
  // Spikes: out and back along one line (folds), or a thin one through another edge.
  check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 6}, {2, 4}, {0, 4}}, "a spike out and straight back");
  check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 6}, {2, 5}, {0, 4}}, "a spike folding back half way");
  check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, -1}, {1.9, 4}, {0, 4}},
        "a spike through the bottom edge");
  check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 0}, {1.9, 4}, {0, 4}},
        "a spike down to the bottom edge");
  check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 0.5}, {1.9, 4}, {0, 4}},
        "a spike short of the bottom edge");
  // Tiny crossings: a notch's tip a hair above, on or below the bottom edge (exact in doubles).
  for (double delta :
       {0x1p-20, 0x1p-30, 0x1p-40, 0x1p-50, 1e-12, 0.0, -1e-12, -0x1p-50, -0x1p-40, -0x1p-20}) {
    check({{0, 0}, {4, 0}, {4, 4}, {2, delta}, {0, 4}}, "notch tip at " + std::to_string(delta));
    check({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2 + delta, 0}, {1, 4}, {0, 4}},
          "leaning spike at " + std::to_string(delta));
  }
  // The same tiny crossings turned by an angle: rounded, but the old arithmetic still gets their
  // signs right at these sizes.
  for (double angle : {0.1, 0.7, 2.0}) {
    const Eigen::Rotation2Dd turn(angle);
    for (double delta : {1e-6, 1e-9, -1e-9, -1e-6}) {
      Poly p = {{0, 0}, {4, 0}, {4, 4}, {2, delta}, {0, 4}};
      for (Vector2d& v : p) v = turn * v;
      check(p, "turned notch tip at " + std::to_string(delta));
    }
  }
  // Random grid polygons made simple by construction (a star on a grid) and then broken.
  for (int i = 0; i < 2000; ++i) {
    Poly p = Star(6 + i % 20, rng);
    for (Vector2d& v : p) v = (v * 16).array().round();
    check(p, "star on a grid, case " + std::to_string(i));
    p[rng() % p.size()] = p[rng() % p.size()];
    check(p, "star on a grid with a vertex copied, case " + std::to_string(i));
  }
  std::printf("adversarial polygons: %d simple, %d not\n", a.simple, a.not_simple);
  EXPECT_GT(a.simple, 1000);
  EXPECT_GT(a.not_simple, 1000);
}

// Near-degenerate polygons where the old floating-point products rounded: vertices of a grid
// polygon (full of collinear points and touching edges) scaled by 2^40 and moved by a few units,
// so that the verdict hangs on a cross product's last bits. The sweep's orientation test is
// exact: it agrees with 128-bit integer arithmetic, where the old check sometimes did not.
TEST(GroundPolygon, IsSimpleIsExactWhereTheOldArithmeticRounded) {
  const auto exact = [](const Poly& p) {
    // The brute force with the orientation in exact integers (every coordinate is one, < 2^53).
    const auto orientation = [](const Vector2d& a, const Vector2d& b, const Vector2d& c) {
      const __int128 bx = static_cast<int64_t>(b.x()) - static_cast<int64_t>(a.x());
      const __int128 by = static_cast<int64_t>(b.y()) - static_cast<int64_t>(a.y());
      const __int128 cx = static_cast<int64_t>(c.x()) - static_cast<int64_t>(a.x());
      const __int128 cy = static_cast<int64_t>(c.y()) - static_cast<int64_t>(a.y());
      const __int128 cross = bx * cy - by * cx;
      return (cross > 0) - (cross < 0);
    };
    const size_t n = p.size();
    const auto meet = [&](const Vector2d& a, const Vector2d& b, const Vector2d& c,
                          const Vector2d& d) {
      const int o1 = orientation(a, b, c), o2 = orientation(a, b, d), o3 = orientation(c, d, a),
                o4 = orientation(c, d, b);
      if (o1 != o2 && o3 != o4) return true;
      using testing::reference::OnSegment;
      return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
             (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
    };
    for (size_t i = 0; i < n; ++i) {
      const Vector2d &a = p[i], &b = p[(i + 1) % n];
      if (a == b) return false;
      for (size_t j = i + 1; j < n; ++j) {
        const Vector2d &c = p[j], &d = p[(j + 1) % n];
        if (j == i + 1 || (i == 0 && j == n - 1)) {
          const Vector2d& shared = j == i + 1 ? b : a;
          const Vector2d& q1 = j == i + 1 ? a : b;
          const Vector2d& q2 = j == i + 1 ? d : c;
          if (orientation(q1, shared, q2) == 0 && (q1 - shared).dot(q2 - shared) > 0) return false;
          continue;
        }
        if (meet(a, b, c, d)) return false;
      }
    }
    return testing::reference::Area(p) > 0;
  };
  std::mt19937 rng(22);
  std::uniform_int_distribution<int> nudge(-2, 2);
  int simple = 0, not_simple = 0, old_differs = 0;
  for (int i = 0; i < 20000; ++i) {
    Poly p =
        i % 2 ? GridPolygon(rng, 3 + i % 5, 4 + rng() % 6) : Comb(1 + rng() % 3, 1 + rng() % 3);
    for (Vector2d& v : p) v = v * 0x1p40 + Vector2d(nudge(rng), nudge(rng));
    const bool truth = exact(p);
    EXPECT_EQ(GroundPolygon(p).IsSimple(), truth) << "case " << i;
    old_differs += testing::BruteForceIsSimple(p) != truth;
    ++(truth ? simple : not_simple);
  }
  std::printf("near-degenerate polygons: %d simple, %d not; the old check was wrong on %d\n",
              simple, not_simple, old_differs);
  EXPECT_GT(simple, 1000);
  EXPECT_GT(not_simple, 1000);
}

// GroundPolygonIndex::Contains must answer as GroundPolygon::Contains (every edge) does, bit for
// bit. Probed where they could differ: on vertices, on edges (points rounded onto them), at a
// vertex's y (the even-odd rule's half-open test), a few ulps off each, and anywhere around.
std::vector<Vector2d> ProbePoints(const Poly& p, std::mt19937& rng, size_t random) {
  std::vector<Vector2d> points;
  Vector2d lo = p[0], hi = p[0];
  for (const Vector2d& v : p) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vector2d pad = 0.1 * (hi - lo) + Vector2d::Constant(1e-300);
  std::uniform_real_distribution<double> ux(lo.x() - pad.x(), hi.x() + pad.x()),
      uy(lo.y() - pad.y(), hi.y() + pad.y());
  // at most ~500 vertices probed closely
  const size_t stride = std::max<size_t>(1, p.size() / 500);
  for (size_t i = 0; i < p.size(); i += stride) {
    const Vector2d& a = p[i];
    const Vector2d& b = p[(i + 1) % p.size()];
    points.push_back(a);
    for (int k = 1; k < 8; ++k) points.push_back(a + (k / 8.0) * (b - a));
    for (const double d : {-1.0, 1.0}) {
      points.push_back({std::nextafter(a.x(), a.x() + d), a.y()});
      points.push_back({a.x(), std::nextafter(a.y(), a.y() + d)});
      const Vector2d m = 0.5 * (a + b);
      points.push_back({std::nextafter(m.x(), m.x() + d), m.y()});
    }
    points.push_back({ux(rng), a.y()});  // a horizontal line through a vertex
  }
  for (size_t i = 0; i < random; ++i) points.push_back({ux(rng), uy(rng)});
  const double inf = std::numeric_limits<double>::infinity();
  for (const Vector2d& far :
       {Vector2d(1e300, 0), Vector2d(0, -1e300), Vector2d(-inf, lo.y()), Vector2d(lo.x(), inf),
        Vector2d(std::nan(""), 0), Vector2d(-inf, 0.5 * (lo.y() + hi.y()))}) {
    points.push_back(far);
  }
  return points;
}

struct IndexAgreement {
  int inside = 0, outside = 0, on_boundary = 0, failures = 0;
  void Check(const Poly& p, std::mt19937& rng, const std::string& what, size_t random = 200) {
    const GroundPolygon polygon(p);
    const GroundPolygonIndex index(polygon);
    for (const Vector2d& q : ProbePoints(p, rng, random)) {
      const double distance = polygon.SignedDistance(q);  // Contains is distance >= 0
      const bool all_edges = distance >= 0.0;
      if (index.Contains(q) != all_edges && ++failures <= 10) {
        ADD_FAILURE() << what << " (" << p.size() << " vertices): the index says " << !all_edges
                      << " at (" << q.x() << ", " << q.y() << "), every edge " << all_edges;
      }
      ++(all_edges ? inside : outside);
      if (distance == 0.0) ++on_boundary;
    }
  }
};

TEST(GroundPolygonIndex, AnswersAsEveryEdgeDoesOnRandomAndAdversarialPolygons) {
  std::mt19937 rng(24);
  IndexAgreement a;
  // Random grid polygons, simple or not (collinear points, repeats, touching edges), seen
  // otherwise.
  for (int i = 0; i < 1000; ++i) {
    const Poly p = GridPolygon(rng, 2 + i % 7, 3 + rng() % 9);
    for (const Poly& v : Variants(p, rng)) a.Check(v, rng, "grid case " + std::to_string(i), 20);
  }
  // Stars (zigzag edges: many cross a horizontal line) and combs (teeth spanning the height: few,
  // wide bands), up to 2,000 vertices (each probe tests every edge the old way).
  for (size_t n : {3, 17, 300, 2000})
    a.Check(Star(n, rng, 0.9), rng, "star " + std::to_string(n), 1000);
  for (size_t teeth : {1, 10, 500})
    a.Check(Comb(teeth), rng, "comb " + std::to_string(teeth), 1000);
  // Scales: a floor in metres far from the origin, tiny coordinates (squares underflow: a point
  // near an edge is "on" it), huge ones (beyond the index's reach: the polygon answers).
  Poly offset = Star(300, rng, 0.5), tiny = offset, huge = offset;
  for (size_t i = 0; i < offset.size(); ++i) {
    offset[i] = 1e-3 * offset[i] + Vector2d(1e5, -3e4);
    tiny[i] *= 1e-160;
    huge[i] *= 1e200;
  }
  a.Check(offset, rng, "offset star");
  a.Check(tiny, rng, "tiny star");
  a.Check(huge, rng, "huge star");
  // Degenerate: flat (every y alike), a spike, fewer than 3 vertices.
  a.Check({{0, 1}, {2, 1}, {5, 1}}, rng, "flat");
  a.Check({{0, 0}, {4, 0}, {4, 4}, {4, 8}, {4, 4}, {0, 4}}, rng, "spike");
  a.Check({{0, 0}, {1, 1}}, rng, "two vertices");
  std::printf("index agreement: %d inside (%d on the boundary), %d outside\n", a.inside,
              a.on_boundary, a.outside);
  EXPECT_EQ(a.failures, 0);
  EXPECT_GT(a.inside, 5000);
  EXPECT_GT(a.on_boundary, 2000);
  EXPECT_GT(a.outside, 5000);
}

// Issue 20: a floor of 100k points took 43 s to check. A million now: a comb (half its edges
// cross the sweep line at once), simple, and with one tooth bent onto the next, not; and a star
// of 200,000 (its edges zigzag: thousands cross the sweep line), simple, and with two vertices
// swapped, not.
TEST(GroundPolygon, IsSimpleChecksAMillionVertices) {
  const auto timed = [](const Poly& p) {
    const auto start = std::chrono::steady_clock::now();
    const bool simple = GroundPolygon(p).IsSimple();
    std::printf("%zu vertices: %s in %.2f s\n", p.size(), simple ? "simple" : "not simple",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return simple;
  };
  Poly comb = Comb(250'000);
  ASSERT_EQ(comb.size(), 1'000'000u);
  EXPECT_TRUE(timed(comb));
  comb[500'002].x() += 1;  // a tooth's top-right corner onto the next tooth's left side
  EXPECT_FALSE(timed(comb));
  std::mt19937 rng(23);
  Poly star = Star(200'000, rng, 0.9);
  EXPECT_TRUE(timed(star));
  std::swap(star[10], star[100'000]);
  EXPECT_FALSE(timed(star));
}

}  // namespace
}  // namespace ss
