#include "animate/transition_graph.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/error.h"

namespace ss {
namespace {

struct RawEdge {
  int from;
  int to;
  double cost;
};

// Sorts by (key, other, cost), keeps the cheapest of duplicates and fills one CSR side.
void FillCsr(std::vector<RawEdge> edges, int num_frames, bool by_source,
             std::vector<int64_t>* offsets, std::vector<int>* neighbours,
             std::vector<double>* costs) {
  auto key = [by_source](const RawEdge& e) {
    return by_source ? std::tie(e.from, e.to, e.cost) : std::tie(e.to, e.from, e.cost);
  };
  std::sort(edges.begin(), edges.end(),
            [&](const RawEdge& a, const RawEdge& b) { return key(a) < key(b); });
  offsets->assign(num_frames + 1, 0);
  neighbours->clear();
  costs->clear();
  for (size_t k = 0; k < edges.size(); ++k) {
    const RawEdge& e = edges[k];
    if (k > 0 && e.from == edges[k - 1].from && e.to == edges[k - 1].to) continue;  // dup
    const int row = by_source ? e.from : e.to;
    ++(*offsets)[row + 1];
    neighbours->push_back(by_source ? e.to : e.from);
    costs->push_back(e.cost);
  }
  for (int i = 0; i < num_frames; ++i) (*offsets)[i + 1] += (*offsets)[i];
}

}  // namespace

TransitionGraph::TransitionGraph(std::vector<FrameInfo> frames,
                                 const std::vector<TransitionEdge>& transitions)
    : frames_(std::move(frames)) {
  const int n = num_frames();
  for (const FrameInfo& f : frames_) has_floor_frames_ = has_floor_frames_ || f.heading_rad;
  std::vector<RawEdge> edges;
  edges.reserve(transitions.size() + frames_.size());
  for (int i = 0; i + 1 < n; ++i) {
    if (frames_[i].clip == frames_[i + 1].clip) edges.push_back({i, i + 1, 0.0});
  }
  for (size_t k = 0; k < transitions.size(); ++k) {
    const TransitionEdge& t = transitions[k];
    const std::string field = "transitions[" + std::to_string(k) + "]";
    if (t.from < 0 || t.from >= n || t.to < 0 || t.to >= n) {
      throw InputError(field, "frame " + std::to_string(t.from) + " -> " + std::to_string(t.to) +
                                  " outside 0.." + std::to_string(n - 1));
    }
    if (!std::isfinite(t.cost) || t.cost < 0) {
      throw InputError(field, "cost must be finite and >= 0, got " + std::to_string(t.cost));
    }
    edges.push_back({t.from, t.to, t.cost});
  }
  FillCsr(edges, n, true, &out_offsets_, &out_targets_, &out_costs_);
  FillCsr(std::move(edges), n, false, &in_offsets_, &in_sources_, &in_costs_);
}

std::optional<double> TransitionGraph::EdgeCost(int from, int to) const {
  if (from < 0 || from >= num_frames()) return std::nullopt;
  const std::span<const int> targets = successors(from);
  const auto it = std::lower_bound(targets.begin(), targets.end(), to);
  if (it == targets.end() || *it != to) return std::nullopt;
  return successor_costs(from)[it - targets.begin()];
}

double TransitionGraph::Turn(int from, int to) const {
  if (IsNaturalSuccessor(from, to)) return 0.0;
  const auto& to_heading = frames_[to].heading_rad;
  if (!to_heading || !frames_[from].heading_rad) return 0.0;
  const int after = IsNaturalSuccessor(from, from + 1) ? from + 1 : from;
  return std::remainder(frames_[after].heading_rad.value_or(0.0) - *to_heading, 2 * M_PI);
}

bool TransitionGraph::IsNaturalSuccessor(int from, int to) const {
  return to == from + 1 && from >= 0 && to < num_frames() && clip(from) == clip(to);
}

bool TransitionGraph::IsValidSequence(std::span<const int> frames, std::string* why) const {
  if (frames.empty()) {
    if (why) *why = "empty sequence";
    return false;
  }
  for (size_t t = 0; t < frames.size(); ++t) {
    if (frames[t] < 0 || frames[t] >= num_frames()) {
      if (why) *why = "step " + std::to_string(t) + ": no frame " + std::to_string(frames[t]);
      return false;
    }
    if (t > 0 && !HasEdge(frames[t - 1], frames[t])) {
      if (why) {
        *why = "step " + std::to_string(t) + ": no edge " + std::to_string(frames[t - 1]) + " -> " +
               std::to_string(frames[t]);
      }
      return false;
    }
  }
  return true;
}

bool TransitionGraph::HasTag(int i, const std::string& tag) const {
  const auto& tags = frames_[i].tags;
  return std::find(tags.begin(), tags.end(), tag) != tags.end();
}

double TransitionGraph::MedianPositiveCost() const {
  std::vector<double> positive;
  for (double c : out_costs_) {
    if (c > 0) positive.push_back(c);
  }
  if (positive.empty()) return 0.0;
  const auto middle = positive.begin() + positive.size() / 2;
  std::nth_element(positive.begin(), middle, positive.end());
  return *middle;
}

std::vector<bool> TransitionGraph::FramesWithTag(const std::string& tag) const {
  std::vector<bool> mask(frames_.size(), false);
  for (int i = 0; i < num_frames(); ++i) mask[i] = HasTag(i, tag);
  return mask;
}

}  // namespace ss
