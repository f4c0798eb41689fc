#include "animate/reach_sets.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

// Per-thread scratch of one bounded Dijkstra; arrays are stamped, never cleared.
class DijkstraWorkspace {
 public:
  explicit DijkstraWorkspace(int num_frames)
      : stamp_(num_frames, 0), dist_(num_frames), parent_(num_frames), settled_(num_frames, 0) {}

  // Fills entries[0..count) of root's set; returns count.
  int Run(const TransitionGraph& graph, ReachDirection direction, int root, int set_size,
          double step_cost, std::span<const double> entry_cost, ReachSets::Entry* entries,
          uint16_t* depths) {
    ++round_;
    using Item = std::pair<double, int>;  // (cost, frame): ties settle the lower frame first
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    Touch(root, 0.0, -1);
    heap.push({0.0, root});
    int count = 0;
    while (!heap.empty() && count < set_size) {
      const auto [d, u] = heap.top();
      heap.pop();
      if (settled_[u] == round_ || d > dist_[u]) continue;
      settled_[u] = round_;
      const int32_t entry = count++;
      entries[entry] = {u, parent_[u], static_cast<float>(d)};
      depths[entry] =
          parent_[u] < 0 ? 0 : static_cast<uint16_t>(std::min<int>(depths[parent_[u]] + 1, 65535));
      const bool forward = direction == ReachDirection::kForward;
      const std::span<const int> next = forward ? graph.successors(u) : graph.predecessors(u);
      const std::span<const double> cost =
          forward ? graph.successor_costs(u) : graph.predecessor_costs(u);
      for (size_t k = 0; k < next.size(); ++k) {
        const int v = next[k];
        if (stamp_[v] == round_ && settled_[v] == round_) continue;
        // The frame entered by the edge: v going forward, u going backward (v -> u).
        const int entered = forward ? v : u;
        const double extra = entry_cost.empty() ? 0.0 : entry_cost[entered];
        const double nd = d + cost[k] + step_cost + extra;
        if (stamp_[v] != round_ || nd < dist_[v]) {
          Touch(v, nd, entry);
          heap.push({nd, v});
        }
      }
    }
    return count;
  }

 private:
  void Touch(int v, double d, int32_t parent) {
    stamp_[v] = round_;
    dist_[v] = d;
    parent_[v] = parent;
  }

  uint32_t round_ = 0;
  std::vector<uint32_t> stamp_;
  std::vector<double> dist_;
  std::vector<int32_t> parent_;
  std::vector<uint32_t> settled_;
};

}  // namespace

bool ReachOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(set_size, Between(1, 65535), "set_size", "1..65535");
  check.Within(num_threads, Between(1, 256), "num_threads", "1..256");
  check.Within(step_cost, AtLeast(0), "step_cost", "a finite number >= 0");
  return check.ok();
}

int64_t ReachSetBytes(int num_frames, int set_size) {
  const int64_t n = std::max(num_frames, 0);
  const int64_t stride = std::min<int64_t>(std::max(set_size, 0), std::max<int64_t>(n, 1));
  return n * stride * static_cast<int64_t>(sizeof(ReachSets::Entry) + sizeof(uint16_t));
}

std::string ReachSetTooLarge(int num_frames, int set_size) {
  const int64_t bytes = ReachSetBytes(num_frames, set_size);
  if (bytes <= kMaxReachSetBytes) return "";
  const int64_t per_root = ReachSetBytes(num_frames, 1);  // one entry per root
  const int64_t most = per_root > 0 ? kMaxReachSetBytes / per_root : 0;
  char gib[32];
  std::snprintf(gib, sizeof gib, "%.1f", static_cast<double>(bytes) / (int64_t{1} << 30));
  return "set_size: " + std::to_string(set_size) + " for a bank of " + std::to_string(num_frames) +
         " frames takes " + gib + " GiB per F/B set, over the 1 GiB a set may take (at most " +
         std::to_string(most) + " for this bank)";
}

ReachSets ReachSets::Build(const TransitionGraph& graph, ReachDirection direction,
                           const ReachOptions& options, std::span<const double> entry_cost) {
  if (std::string why; !options.IsValid(&why)) throw InputError("reach options", why);
  if (const std::string why = ReachSetTooLarge(graph.num_frames(), options.set_size); !why.empty())
    throw InputError("reach options", why);
  if (!entry_cost.empty() && static_cast<int>(entry_cost.size()) != graph.num_frames()) {
    throw InputError("reach.entry_cost", "needs one value per frame");
  }
  for (double c : entry_cost) {
    if (!(c >= 0) || !std::isfinite(c)) throw InputError("reach.entry_cost", "values must be >= 0");
  }
  ReachSets sets;
  const int n = graph.num_frames();
  sets.direction_ = direction;
  sets.stride_ = std::min(options.set_size, std::max(n, 1));
  sets.entries_.resize(static_cast<size_t>(n) * sets.stride_);
  sets.depths_.resize(sets.entries_.size());
  sets.counts_.assign(n, 0);

  const int threads = std::clamp(options.num_threads, 1, std::max(1, n));
  std::atomic<int> next_root{0};
  constexpr int kChunk = 64;
  auto work = [&] {
    DijkstraWorkspace workspace(n);
    for (;;) {
      if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) return;
      const int begin = next_root.fetch_add(kChunk);
      if (begin >= n) return;
      for (int root = begin; root < std::min(n, begin + kChunk); ++root) {
        const size_t offset = static_cast<size_t>(root) * sets.stride_;
        sets.counts_[root] =
            workspace.Run(graph, direction, root, sets.stride_, options.step_cost, entry_cost,
                          sets.entries_.data() + offset, sets.depths_.data() + offset);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (options.cancel != nullptr && options.cancel->load())
    throw WorkError("reach sets", "cancelled");
  return sets;
}

void ReachSets::AppendPath(int root, int index, std::vector<int>* frames) const {
  const std::span<const Entry> set = Set(root);
  const size_t first = frames->size();
  for (int k = index; k >= 0; k = set[k].parent) frames->push_back(set[k].frame);
  // Walking parents goes t -> root: that is playback order for a backward set only.
  if (direction_ == ReachDirection::kForward) std::reverse(frames->begin() + first, frames->end());
}

int ReachSets::PathLength(int root, int index) const {
  const uint16_t depth = depths_[static_cast<size_t>(root) * stride_ + index];
  if (depth < 65535) return depth + 1;
  int length = 0;
  const std::span<const Entry> set = Set(root);
  for (int k = index; k >= 0; k = set[k].parent) ++length;
  return length;
}

}  // namespace ss
