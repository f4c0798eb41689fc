#include "pipeline/transitions/stage1_index.h"

#include <algorithm>
#include <cmath>

namespace ss {

Stage1Index::Stage1Index(const TransitionClassifier& classifier)
    : classifier_(classifier), threshold_(classifier.stage1_threshold()) {}

Stage1Index::Point Stage1Index::Scaled(const CheapFeatures& f) const {
  const CheapDifference& u = classifier_.stage1_unit_weights();
  return {u[0] * f.velocity_x_mps, u[0] * f.velocity_y_mps, u[1] * f.colour[0],
          u[1] * f.colour[1],      u[1] * f.colour[2],      u[2] * f.area_m2,
          u[3] * f.eccentricity};
}

void Stage1Index::Build(std::span<const CheapFeatures> points) {
  raw_.assign(points.begin(), points.end());
  scaled_.clear();
  scaled_.reserve(raw_.size());
  max_abs_coordinate_ = 0;
  for (const CheapFeatures& f : raw_) {
    scaled_.push_back(Scaled(f));
    for (double c : scaled_.back())
      max_abs_coordinate_ = std::max(max_abs_coordinate_, std::abs(c));
  }
  Rebuild();
}

void Stage1Index::Insert(const CheapFeatures& point) {
  raw_.push_back(point);
  scaled_.push_back(Scaled(point));
  for (double c : scaled_.back()) max_abs_coordinate_ = std::max(max_abs_coordinate_, std::abs(c));
  const size_t buffered = raw_.size() - order_.size();
  if (buffered > std::max<size_t>(512, raw_.size() / 64)) Rebuild();
}

void Stage1Index::Rebuild() {
  // Rounding in the scaled coordinates is ~1e-16 of their size; the slack is far larger
  // and only makes pruning slightly less eager.
  slack_ = 1e-9 * (std::abs(threshold_) + max_abs_coordinate_) + 1e-300;
  const int32_t n = static_cast<int32_t>(raw_.size());
  order_.resize(n);
  for (int32_t i = 0; i < n; ++i) order_[i] = i;
  nodes_.clear();
  nodes_.reserve(n > 0 ? 2 * (n / kLeafSize + 1) : 0);
  if (n > 0) BuildNode(0, n);
  tree_raw_.resize(n);
  for (int32_t k = 0; k < n; ++k) tree_raw_[k] = raw_[order_[k]];
}

int32_t Stage1Index::BuildNode(int32_t begin, int32_t end) {
  const int32_t id = static_cast<int32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin;
  node.end = end;
  node.lo.fill(INFINITY);
  node.hi.fill(-INFINITY);
  for (int32_t k = begin; k < end; ++k) {
    const Point& p = scaled_[order_[k]];
    for (int d = 0; d < kDims; ++d) {
      node.lo[d] = std::min(node.lo[d], p[d]);
      node.hi[d] = std::max(node.hi[d], p[d]);
    }
  }
  if (end - begin > kLeafSize) {
    int split = 0;
    for (int d = 1; d < kDims; ++d) {
      if (node.hi[d] - node.lo[d] > node.hi[split] - node.lo[split]) split = d;
    }
    if (node.hi[split] > node.lo[split]) {  // all points equal: stay a (large) leaf
      const int32_t mid = begin + (end - begin) / 2;
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](int32_t a, int32_t b) { return scaled_[a][split] < scaled_[b][split]; });
      node.left = BuildNode(begin, mid);
      node.right = BuildNode(mid, end);
    }
  }
  nodes_[id] = node;
  return id;
}

void Stage1Index::Query(const CheapFeatures& query, std::vector<int32_t>* out) const {
  if (!nodes_.empty()) {
    const Point q = Scaled(query);
    const double limit = threshold_ + slack_;
    int32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      // Lower bound of the mixed norm from q to any point of the box.
      double g[kDims];
      for (int d = 0; d < kDims; ++d) g[d] = std::max({node.lo[d] - q[d], q[d] - node.hi[d], 0.0});
      const double bound = std::sqrt(g[0] * g[0] + g[1] * g[1]) + g[2] + g[3] + g[4] + g[5] + g[6];
      if (bound > limit) continue;
      if (node.left < 0) {
        for (int32_t k = node.begin; k < node.end; ++k) {
          if (classifier_.Stage1Accepts(query, tree_raw_[k])) out->push_back(order_[k]);
        }
      } else {
        stack[top++] = node.left;
        stack[top++] = node.right;
      }
    }
  }
  for (int32_t i = tree_size(); i < size(); ++i) {
    if (classifier_.Stage1Accepts(query, raw_[i])) out->push_back(i);
  }
}

void Stage1Index::QueryLinear(const CheapFeatures& query, std::vector<int32_t>* out) const {
  for (int32_t i = 0; i < size(); ++i) {
    if (classifier_.Stage1Accepts(query, raw_[i])) out->push_back(i);
  }
}

}  // namespace ss
