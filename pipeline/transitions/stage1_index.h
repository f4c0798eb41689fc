#pragma once
// Sub-quadratic stage-1 search. Stage 1 accepts the pair (q, p) when
//   u_v |v_q - v_p|_2 + u_c |c_q - c_p|_1 + u_a |a_q - a_p| + u_e |e_q - e_p| <= T1,
// a ball of a mixed norm in the 7-D cheap-feature space (x = scaled (vx, vy, r, g, b,
// area, eccentricity)): a disc (L2) in the two velocity dimensions, L1 in the other five.
// A k-d tree over the scaled points prunes a node when a lower bound of that norm from
// the query to the node's bounding box exceeds T1; survivors are decided by exactly the
// classifier's Stage1Accepts, so the answer equals a linear scan's, pair for pair.
// Points appended after the last build sit in a small buffer that is scanned linearly;
// the tree is rebuilt when the buffer outgrows max(512, size / 64).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pipeline/transitions/classifier.h"

namespace ss {

class Stage1Index {
 public:
  explicit Stage1Index(const TransitionClassifier& classifier);

  // Rebuilds over `points` (point k gets index k).
  void Build(std::span<const CheapFeatures> points);
  // Appends one point with index size().
  void Insert(const CheapFeatures& point);
  int32_t size() const { return static_cast<int32_t>(raw_.size()); }

  // Appends to `out` the index of every point p with Stage1Accepts(query, p), in no order.
  void Query(const CheapFeatures& query, std::vector<int32_t>* out) const;
  // The same answer by testing every point (the reference for tests).
  void QueryLinear(const CheapFeatures& query, std::vector<int32_t>* out) const;

  int32_t tree_size() const { return static_cast<int32_t>(order_.size()); }

 private:
  static constexpr int kDims = 7;
  static constexpr int kLeafSize = 12;
  using Point = std::array<double, kDims>;
  struct Node {
    Point lo, hi;
    int32_t begin = 0, end = 0;  // range in order_
    int32_t left = -1, right = -1;
  };
  Point Scaled(const CheapFeatures& f) const;
  int32_t BuildNode(int32_t begin, int32_t end);
  void Rebuild();

  TransitionClassifier classifier_;
  double threshold_;
  double slack_ = 0;                     // pruning tolerance for rounding (decisions never use it)
  std::vector<CheapFeatures> raw_;       // by index
  std::vector<Point> scaled_;            // by index
  std::vector<int32_t> order_;           // tree points, leaf ranges contiguous
  std::vector<CheapFeatures> tree_raw_;  // raw_ in order_ order (sequential leaf scans)
  std::vector<Node> nodes_;
  double max_abs_coordinate_ = 0;
};

}  // namespace ss
