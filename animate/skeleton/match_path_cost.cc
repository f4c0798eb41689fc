// PathCost and AnalyzePath (match_dp.h): the objective of a given path straight from the
// definition, the reference the DP is tested against, and the count of its kinds of moves.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "animate/skeleton/match_dp.h"
#include "animate/skeleton/match_dp_detail.h"
#include "core/error.h"

namespace ss {

using match_dp_detail::SegmentIds;

namespace {

// The cost of move s' -> s at a free row, by the rules (listed transitions aside).
double RuleCost(int from, int to, const std::vector<int>& clip, const MatchOptions& o) {
  const int d = to - from;
  if (clip[from] == clip[to] && d >= 1 && d <= o.max_forward_step)
    return o.skip_cost * static_cast<double>(d - 1);
  if (clip[from] == clip[to] && d < 0 && -d <= o.stutter_window) {
    return static_cast<double>(o.jump_cost) + o.stutter_cost;
  }
  return o.jump_cost;
}

double ListedCost(int from, int to, const MatchOptions& o) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& tr : o.transitions) {
    if (tr.from == from && tr.to == to && tr.from != tr.to) best = std::min<double>(best, tr.cost);
  }
  return best;
}

}  // namespace

double PathCost(const CostRows& costs, const std::vector<int>& clip_starts,
                const MatchOptions& options, const MovementConstraint* movements,
                const std::vector<int>& path, double* matching_cost) {
  const double inf = std::numeric_limits<double>::infinity();
  const int T = costs.targets(), S = costs.sources();
  if (static_cast<int>(path.size()) != T)
    throw InputError("path", "needs one source frame per target frame");
  const std::vector<int> clip = SegmentIds(clip_starts, S);
  std::vector<int> movement;
  std::vector<uint8_t> inside(T, 0);
  if (movements) {
    movement = SegmentIds(movements->source_starts, S);
    std::fill(inside.begin(), inside.end(), 1);
    for (int t : movements->target_starts) inside[t] = 0;
    if (T > 0) inside[0] = 0;
  }
  double match = 0, total = 0;
  int run = 0;
  for (int t = 0; t < T; ++t) {
    const int s = path[t];
    if (s < 0 || s >= S)
      throw InputError("path", "source frame " + std::to_string(s) + " out of range");
    match += costs.At(t, s);
    if (t == 0) continue;
    const int from = path[t - 1];
    if (s == from) {
      ++run;
      total += options.freeze_cost * static_cast<double>(std::min(run, options.freeze_levels));
      continue;
    }
    run = 0;
    if (inside[t] && movement[from] != movement[s]) {
      total = inf;
      continue;
    }
    double move = RuleCost(from, s, clip, options);
    const int d = s - from;
    if (inside[t] && !(d >= 1 && d <= options.max_forward_step)) {
      move += static_cast<double>(movements->jump_cost_per_frame) * std::abs(d);
    }
    total += std::min(move, ListedCost(from, s, options));
  }
  if (matching_cost) *matching_cost = match;
  return total + match;
}

MatchStats AnalyzePath(const std::vector<int>& path, const std::vector<int>& clip_starts,
                       const MatchOptions& options) {
  MatchStats stats;
  if (path.empty()) return stats;
  const int S = *std::max_element(path.begin(), path.end()) + 1;
  std::vector<int> starts;
  for (int c : clip_starts) {
    if (c < S) starts.push_back(c);
  }
  const std::vector<int> clip = SegmentIds(starts.empty() ? std::vector<int>{0} : starts, S);
  int run = 0;
  for (size_t t = 1; t < path.size(); ++t) {
    const int from = path[t - 1], to = path[t];
    if (to == from) {
      if (run == 0) ++stats.freeze_runs;
      ++run;
      ++stats.freezes;
      stats.longest_freeze = std::max(stats.longest_freeze, run);
      continue;
    }
    run = 0;
    const double rule = RuleCost(from, to, clip, options);
    if (ListedCost(from, to, options) < rule) {
      ++stats.listed;
      continue;
    }
    const int d = to - from;
    if (clip[from] == clip[to] && d >= 1 && d <= options.max_forward_step) {
      if (d >= 2) ++stats.skips;
    } else if (clip[from] == clip[to] && d < 0 && -d <= options.stutter_window) {
      ++stats.stutters;
    } else {
      ++stats.jumps;
    }
  }
  return stats;
}

}  // namespace ss
