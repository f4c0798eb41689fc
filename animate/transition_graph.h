#pragma once
// The transition graph of seed 000 §3–4: one node per source frame (sprite), an edge
// i -> i+1 between consecutive frames of a clip (cost 0) and an edge i -> j for every
// transition found upstream, with cost C(i->j) = D(i+1, j) + D(i, j-1) (eq. 1).
// Compressed sparse rows in both directions; built once from plain vectors (the bank
// adapter fills them), read-only afterwards and safe to share between threads.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ss {

// One source frame as the optimizer sees it.
struct FrameInfo {
  int clip = 0;  // frames of one clip are consecutive in the input, in playback order
  // Ground displacement of the subject on arriving at this frame from its predecessor in
  // the source clip, metres per frame step (ground x, y).
  Eigen::Vector2d velocity_m = Eigen::Vector2d::Zero();
  std::vector<std::string> tags;  // e.g. "standing", "mirrored"
  // A floor sprite (filmed from above): the ground direction it faced. Such a sprite may be
  // turned about the vertical: a transition between two turns the sequence (Track::turns_rad).
  std::optional<double> heading_rad;
};

// A transition i -> j found upstream, cost C(i->j) >= 0 (seed 000 eq. 1).
struct TransitionEdge {
  int from = 0;
  int to = 0;
  double cost = 0;
};

class TransitionGraph {
 public:
  TransitionGraph() = default;
  // Adds the natural successors (cost 0) and `transitions`; a duplicate edge keeps its
  // lowest cost. Throws InputError for an out-of-range frame or a negative or
  // non-finite cost (the field is named "transitions[k]").
  TransitionGraph(std::vector<FrameInfo> frames, const std::vector<TransitionEdge>& transitions);

  int num_frames() const { return static_cast<int>(frames_.size()); }
  int64_t num_edges() const { return static_cast<int64_t>(out_targets_.size()); }

  // Out-edges of `i` sorted by target, with their costs.
  std::span<const int> successors(int i) const { return Row(out_offsets_, out_targets_, i); }
  std::span<const double> successor_costs(int i) const { return Row(out_offsets_, out_costs_, i); }
  // In-edges of `i` sorted by source, with their costs.
  std::span<const int> predecessors(int i) const { return Row(in_offsets_, in_sources_, i); }
  std::span<const double> predecessor_costs(int i) const { return Row(in_offsets_, in_costs_, i); }

  // C(from->to), or nullopt when there is no such edge.
  std::optional<double> EdgeCost(int from, int to) const;
  bool HasEdge(int from, int to) const { return EdgeCost(from, to).has_value(); }
  // True for i -> i+1 inside one clip.
  bool IsNaturalSuccessor(int from, int to) const;
  // True when every consecutive pair of `frames` is an edge; otherwise says which is not.
  bool IsValidSequence(std::span<const int> frames, std::string* why = nullptr) const;

  const FrameInfo& frame(int i) const { return frames_[i]; }
  // Whether any frame is a floor sprite (FrameInfo::heading_rad).
  bool has_floor_frames() const { return has_floor_frames_; }
  // How far a sequence turns going from `from` to `to` (floor sprites): the heading the
  // sprite had in its source clip after `from` (its natural successor's, or its own at a
  // clip's end) less that of `to`; 0 for a natural successor or an upright frame.
  double Turn(int from, int to) const;
  const Eigen::Vector2d& velocity_m(int i) const { return frames_[i].velocity_m; }
  double speed_m(int i) const { return frames_[i].velocity_m.norm(); }
  int clip(int i) const { return frames_[i].clip; }
  bool HasTag(int i, const std::string& tag) const;
  // Median cost of the edges with a positive cost (0 when there are none): the scale of C.
  double MedianPositiveCost() const;
  // Membership mask of the frames carrying `tag` (all false for an unknown tag).
  std::vector<bool> FramesWithTag(const std::string& tag) const;

 private:
  template <typename T>
  static std::span<const T> Row(const std::vector<int64_t>& offsets, const std::vector<T>& values,
                                int i) {
    return {values.data() + offsets[i], static_cast<size_t>(offsets[i + 1] - offsets[i])};
  }

  std::vector<FrameInfo> frames_;
  bool has_floor_frames_ = false;
  std::vector<int64_t> out_offsets_{0};
  std::vector<int> out_targets_;
  std::vector<double> out_costs_;
  std::vector<int64_t> in_offsets_{0};
  std::vector<int> in_sources_;
  std::vector<double> in_costs_;
};

}  // namespace ss
