#pragma once
// The forward and backward sets of seed 000 §4.2. For every frame i, bounded Dijkstra on
// the approximating cost Ĉ settles the N frames t with the cheapest S*(i->t) (forward set
// F(i)) or the cheapest S*(t->i) (backward set B(i)) and keeps the shortest-path tree, so
// that every S* can be read back. Ĉ of one edge a -> b is
//   Ĉ(a->b) = C(a->b) + step_cost + entry_cost[b],
// i.e. the smoothness cost (eq. 5), optionally raised per frame entered (frames outside a
// required tag, slow frames) and per step (so long zero-cost runs are not free).
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animate/transition_graph.h"

namespace ss {

enum class ReachDirection { kForward, kBackward };

struct ReachOptions {
  int set_size = 200;      // N: frames kept per set, the root included
  int num_threads = 2;     // Dijkstra runs are independent; split over this many threads (1..256)
  double step_cost = 0.0;  // added to every edge of Ĉ
  // Set by another thread: Build stops within a chunk of roots and throws WorkError (not
  // a spec key: the studio's jobs set it).
  const std::atomic<bool>* cancel = nullptr;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The memory one F or B set of `num_frames` roots takes at `set_size` (entries and depths), and
// the most a set may take: a bank of 50,000 frames at set_size 65535 would take 33 GiB.
inline constexpr int64_t kMaxReachSetBytes = int64_t{1} << 30;  // 1 GiB per set
int64_t ReachSetBytes(int num_frames, int set_size);
// Why `set_size` is too large for a bank of `num_frames` frames (with the largest that fits), or
// "".
std::string ReachSetTooLarge(int num_frames, int set_size);

class ReachSets {
 public:
  // One settled frame of a set; entries are in settling order (non-decreasing cost).
  struct Entry {
    int32_t frame;
    int32_t parent;  // entry index one step closer to the root; -1 for the root
    float cost;      // Ĉ of S*(root->frame) (forward) or S*(frame->root) (backward)
  };

  ReachSets() = default;
  // Runs bounded Dijkstra from every frame. `entry_cost` is empty or one value >= 0 per frame.
  static ReachSets Build(const TransitionGraph& graph, ReachDirection direction,
                         const ReachOptions& options, std::span<const double> entry_cost = {});

  ReachDirection direction() const { return direction_; }
  int num_frames() const { return static_cast<int>(counts_.size()); }
  // F(root) or B(root); entry 0 is the root itself at cost 0.
  std::span<const Entry> Set(int root) const {
    return {entries_.data() + static_cast<int64_t>(root) * stride_,
            static_cast<size_t>(counts_[root])};
  }
  // Appends the frames of the tree path of entry `index` of Set(root): S*(root->t) in
  // playback order (root first) for forward sets, S*(t->root) (t first) for backward sets.
  void AppendPath(int root, int index, std::vector<int>* frames) const;
  // Number of frames on that path, both ends included.
  int PathLength(int root, int index) const;
  size_t MemoryBytes() const {
    return entries_.size() * sizeof(Entry) + depths_.size() * sizeof(uint16_t) +
           counts_.size() * sizeof(int32_t);
  }

 private:
  ReachDirection direction_ = ReachDirection::kForward;
  int stride_ = 0;  // = set_size; set r occupies entries [r*stride, r*stride+count)
  std::vector<Entry> entries_;
  std::vector<int32_t> counts_;
  std::vector<uint16_t> depths_;  // path length - 1 per entry (saturates at 65535)
};

}  // namespace ss
