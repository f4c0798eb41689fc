#include "core/geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <set>

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

// How far rounding can carry an edge's computed points (DistanceToSegment's nearest point, the
// even-odd test's crossing) beyond its extent along one axis, with coordinates a and b: a few
// ulps, here a thousand-fold margin, plus the distance whose square underflows to 0.
double RoundingReach(double a, double b) { return 1e-12 * (std::abs(a) + std::abs(b)) + 1e-150; }
// Vertices beyond this are not indexed (differences and products could overflow).
constexpr double kIndexedCoordinateLimit = 1e150;

}  // namespace

GroundPolygonIndex::GroundPolygonIndex(const GroundPolygon& polygon) : polygon_(polygon) {
  const std::vector<Eigen::Vector2d>& v = polygon_.vertices();
  const size_t n = v.size();
  if (polygon_.empty() || n >= std::numeric_limits<uint32_t>::max() / 16) return;
  for (const Eigen::Vector2d& p : v) {
    if (!(std::abs(p.x()) < kIndexedCoordinateLimit && std::abs(p.y()) < kIndexedCoordinateLimit))
      return;
  }
  // Edge k runs from vertex k - 1 to vertex k, as the loops of SignedDistance take them.
  std::vector<Eigen::Vector2d> y_range(n);
  x_range_.resize(n);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, spans = 0;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d& a = v[k];
    const Eigen::Vector2d& b = v[k ? k - 1 : n - 1];
    const double ry = RoundingReach(a.y(), b.y()), rx = RoundingReach(a.x(), b.x());
    y_range[k] = {std::min(a.y(), b.y()) - ry, std::max(a.y(), b.y()) + ry};
    x_range_[k] = {std::min(a.x(), b.x()) - rx, std::max(a.x(), b.x()) + rx};
    lo = std::min(lo, y_range[k][0]);
    hi = std::max(hi, y_range[k][1]);
    spans += y_range[k][1] - y_range[k][0];
  }
  // An edge is filed in every band its y extent meets: as many bands as keep that near 8 entries
  // an edge (n + bands * spans / height), at most 2 per edge. Edges spanning much of the height
  // (a comb's teeth) thus make few wide bands, and the memory stays linear in n.
  const double height = hi - lo;
  double bands = 2.0 * static_cast<double>(n);
  if (spans > 0 && height > 0)
    bands = std::min(bands, 7.0 * static_cast<double>(n) * height / spans);
  bands_ = height > 0 ? static_cast<int>(std::clamp(bands, 1.0, 4194304.0)) : 1;
  y0_ = lo;
  scale_ = height > 0 ? bands_ / height : 0.0;
  band_start_.assign(static_cast<size_t>(bands_) + 1, 0);
  for (size_t k = 0; k < n; ++k) {
    for (int b = Band(y_range[k][0]), last = Band(y_range[k][1]); b <= last; ++b)
      ++band_start_[b + 1];
  }
  for (int b = 0; b < bands_; ++b) band_start_[b + 1] += band_start_[b];
  band_edges_.resize(band_start_.back());
  std::vector<uint32_t> next(band_start_.begin(), band_start_.end() - 1);
  for (size_t k = 0; k < n; ++k) {
    for (int b = Band(y_range[k][0]), last = Band(y_range[k][1]); b <= last; ++b) {
      band_edges_[next[b]++] = static_cast<uint32_t>(k);
    }
  }
  indexed_ = true;
}

int GroundPolygonIndex::Band(double y) const {
  if (!(y > y0_)) return 0;
  const double t = (y - y0_) * scale_;  // monotone in y: so is the band
  if (!(t < bands_)) return bands_ - 1;
  return static_cast<int>(t);
}

bool GroundPolygonIndex::Contains(const Eigen::Vector2d& p) const {
  if (!indexed_ || !p.allFinite()) return polygon_.Contains(p);
  // GroundPolygon::Contains is "on an edge (distance exactly 0) or inside by the even-odd rule".
  // An edge outside p's band is neither: the even-odd test needs p.y within its y extent, a zero
  // distance needs p within rounding of it, and the band holds every edge within that reach.
  const std::vector<Eigen::Vector2d>& v = polygon_.vertices();
  const size_t n = v.size();
  const int band = Band(p.y());
  bool inside = false, on_edge = false;
  for (uint32_t e = band_start_[band]; e < band_start_[band + 1]; ++e) {
    const size_t k = band_edges_[e];
    const Eigen::Vector2d& a = v[k];
    const Eigen::Vector2d& b = v[k ? k - 1 : n - 1];
    if ((a.y() > p.y()) != (b.y() > p.y())) {  // as in SignedDistance
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
    if (!on_edge && x_range_[k][0] <= p.x() && p.x() <= x_range_[k][1] &&
        DistanceToSegment(p, b, a) == 0.0) {
      on_edge = true;
    }
  }
  return on_edge || inside;
}

namespace {

// Exact signs of orientation determinants for double coordinates (Shewchuk, "Adaptive
// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997): a
// floating-point filter settles nearly every case; the rest is summed exactly as an expansion.
// Exact while no product overflows or underflows (coordinates and their differences between
// about 1e-140 and 1e150 in magnitude, or 0): any floor in metres.
constexpr double kEpsilon = 0x1p-53;  // half an ulp of 1.0
constexpr double kOrientErrorBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;

// a + b == s + e exactly, s the rounded sum.
void TwoSum(double a, double b, double& s, double& e) {
  s = a + b;
  const double b_virtual = s - a;
  e = (a - (s - b_virtual)) + (b - b_virtual);
}

// a * b == p + e exactly, p the rounded product.
void TwoProduct(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// Sign of the exact sum of `terms`, kept as a nonoverlapping expansion (Shewchuk's
// Grow-Expansion with zero elimination): its largest component, the last, carries the sign.
template <size_t N>
int ExactSumSign(const std::array<double, N>& terms) {
  std::array<double, N> e{};
  size_t m = 0;
  for (const double term : terms) {
    double q = term;
    size_t k = 0;
    for (size_t i = 0; i < m; ++i) {
      double sum = 0, error = 0;
      TwoSum(q, e[i], sum, error);
      if (error != 0) e[k++] = error;
      q = sum;
    }
    if (q != 0) e[k++] = q;
    m = k;
  }
  return m == 0 ? 0 : (e[m - 1] > 0) - (e[m - 1] < 0);
}

// Sign of the turn a -> b -> c, exactly: +1 left, -1 right, 0 collinear.
int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double left = (b.x() - a.x()) * (c.y() - a.y());
  const double right = (b.y() - a.y()) * (c.x() - a.x());
  const double det = left - right;
  const auto sign = [](double v) { return (v > 0) - (v < 0); };
  // A difference of doubles is 0 only when they are equal, and rounding keeps signs: when the
  // two products' signs differ (or one is 0), det's sign is exact.
  double magnitude = 0;
  if (left > 0) {
    if (right <= 0) return sign(det);
    magnitude = left + right;
  } else if (left < 0) {
    if (right >= 0) return sign(det);
    magnitude = -left - right;
  } else {
    return sign(det);
  }
  if (std::abs(det) >= kOrientErrorBound * magnitude) return sign(det);
  // (bx - ax)(cy - ay) - (by - ay)(cx - ax), each difference an exact pair, each product of
  // pairs four exact pairs: 16 terms.
  std::array<double, 2> bax, cay, bay, cax;
  TwoSum(b.x(), -a.x(), bax[0], bax[1]);
  TwoSum(c.y(), -a.y(), cay[0], cay[1]);
  TwoSum(b.y(), -a.y(), bay[0], bay[1]);
  TwoSum(c.x(), -a.x(), cax[0], cax[1]);
  std::array<double, 16> terms{};
  size_t t = 0;
  for (const double u : bax) {
    for (const double v : cay) {
      TwoProduct(u, v, terms[t], terms[t + 1]);
      t += 2;
    }
  }
  for (const double u : bay) {
    for (const double v : cax) {
      TwoProduct(-u, v, terms[t], terms[t + 1]);
      t += 2;
    }
  }
  return ExactSumSign(terms);
}

// p within the box of a and b (on segment ab when collinear with it).
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

// Sweep order of points: by x, then y (a sweep line turned by an infinitesimal angle, so that
// no segment is vertical to it).
bool SweepsFirst(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

// Whether two edges of the polygon that are not neighbours share a point: the Shamos-Hoey sweep
// (Shamos and Hoey, "Geometric intersection problems", 1976), O(n log n). The sweep line moves
// over the edges' endpoints; the edges it crosses are kept in their order along it, and an edge
// is tested against its neighbours in that order whenever it gets new ones. The first pair that
// meets is always neighbours by the time the sweep reaches their meeting point, so it is found.
// At a point where edges start and end, the starting ones are added before the ending ones
// leave: edges that only touch there are then neighbours, and found too.
class EdgeSweep {
 public:
  explicit EdgeSweep(const std::vector<Eigen::Vector2d>& v) : v_(v), n_(v.size()) {}

  bool AnyNonNeighboursMeet() {
    // The vertices in sweep order (each is where its two edges start or leave), with their
    // coordinates beside them so that the sort reads memory in order.
    struct Stop {
      double x, y;
      size_t vertex;
    };
    std::vector<Stop> stops(n_);
    for (size_t k = 0; k < n_; ++k) stops[k] = {v_[k].x(), v_[k].y(), k};
    std::sort(stops.begin(), stops.end(), [](const Stop& a, const Stop& b) {
      return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.vertex < b.vertex;
    });
    std::set<size_t, Below> crossed(Below{this});
    std::vector<std::set<size_t, Below>::iterator> where(n_);
    std::vector<size_t> starting, leaving;
    for (size_t first = 0; first < n_;) {
      // Every vertex at this point (more than one: the polygon passes it twice).
      size_t last = first + 1;
      while (last < n_ && stops[last].x == stops[first].x && stops[last].y == stops[first].y)
        ++last;
      starting.clear();
      leaving.clear();
      for (size_t s = first; s < last; ++s) {
        const size_t k = stops[s].vertex;
        for (const size_t edge : {k == 0 ? n_ - 1 : k - 1, k}) {
          (&Left(edge) == &v_[k] ? starting : leaving).push_back(edge);
        }
      }
      first = last;
      // Edges starting here join before those ending here leave: edges that only touch at
      // this point are then neighbours for a moment, and found.
      for (const size_t edge : starting) {
        const auto it = crossed.insert(edge).first;  // always new: ties are broken by index
        where[edge] = it;
        if (it != crossed.begin() && Meet(*std::prev(it), edge)) return true;
        if (std::next(it) != crossed.end() && Meet(*std::next(it), edge)) return true;
      }
      for (const size_t edge : leaving) {
        const auto it = where[edge];
        if (it != crossed.begin() && std::next(it) != crossed.end() &&
            Meet(*std::prev(it), *std::next(it))) {
          return true;
        }
        crossed.erase(it);
      }
    }
    return false;
  }

 private:
  // Edge i runs from vertex i to vertex i + 1 (the last back to the first).
  const Eigen::Vector2d& A(size_t i) const { return v_[i]; }
  const Eigen::Vector2d& B(size_t i) const { return v_[i + 1 == n_ ? 0 : i + 1]; }
  const Eigen::Vector2d& Left(size_t i) const { return SweepsFirst(B(i), A(i)) ? B(i) : A(i); }
  const Eigen::Vector2d& Right(size_t i) const { return SweepsFirst(B(i), A(i)) ? A(i) : B(i); }

  // Edges i and j meet, unless they are neighbours (which share a vertex; that they do not fold
  // back onto each other is checked beforehand).
  bool Meet(size_t i, size_t j) const {
    const size_t d = i > j ? i - j : j - i;
    if (d == 1 || d == n_ - 1) return false;
    return SegmentsMeet(A(i), B(i), A(j), B(j));
  }

  // Edge s lies below edge t along the sweep line, judged where the later of the two starts:
  // that start against the other edge's line, then (when on it) the later edge's other end. The
  // same test decides (s, t) and (t, s), so the order is antisymmetric; edges on one line from
  // one point are ordered by index.
  struct Below {
    const EdgeSweep* sweep;
    bool operator()(size_t s, size_t t) const {
      if (s == t) return false;
      const EdgeSweep& w = *sweep;
      if (SweepsFirst(w.Left(t), w.Left(s))) {
        int o = Orientation(w.Left(t), w.Right(t), w.Left(s));
        if (o == 0) o = Orientation(w.Left(t), w.Right(t), w.Right(s));
        return o != 0 ? o < 0 : s < t;
      }
      int o = Orientation(w.Left(s), w.Right(s), w.Left(t));
      if (o == 0) o = Orientation(w.Left(s), w.Right(s), w.Right(t));
      return o != 0 ? o > 0 : s < t;
    }
  };

  const std::vector<Eigen::Vector2d>& v_;
  const size_t n_;
};

}  // namespace

bool GroundPolygon::IsSimple() const {
  const size_t n = vertices_.size();
  if (n < 3) return false;
  for (const auto& v : vertices_) {
    if (!v.allFinite()) return false;
  }
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = vertices_[i == 0 ? n - 1 : i - 1];
    const Eigen::Vector2d& shared = vertices_[i];
    const Eigen::Vector2d& q = vertices_[i + 1 == n ? 0 : i + 1];
    if (shared == q) return false;  // a repeated vertex makes a zero-length edge
    // Neighbours share one vertex; they must not fold back onto each other.
    if (Orientation(p, shared, q) == 0 && (p - shared).dot(q - shared) > 0) return false;
  }
  return !EdgeSweep(vertices_).AnyNonNeighboursMeet() && Area() > 0;
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
