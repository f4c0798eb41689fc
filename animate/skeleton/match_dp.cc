#include "animate/skeleton/match_dp.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "animate/skeleton/match_dp_detail.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

// The driver: the options, the row rules and the Engine's set-up; the row step is in
// match_dp_kernels.cc, the two backtracks in match_dp_decisions.cc and
// match_dp_checkpoints.cc, PathCost and AnalyzePath in match_path_cost.cc.

namespace ss {

bool MatchOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  for (const auto& [v, field] :
       {std::pair{skip_cost, "skip_cost"}, std::pair{jump_cost, "jump_cost"},
        std::pair{freeze_cost, "freeze_cost"}, std::pair{stutter_cost, "stutter_cost"}}) {
    check(std::isfinite(v) && v >= 0, field,
          "must be a finite cost >= 0, got " + OptionProblems::Num(v));
  }
  const auto within = [&](int v, int low, int high, const char* field) {
    check(v >= low && v <= high, field,
          "must be within " + std::to_string(low) + ".." + std::to_string(high) + ", got " +
              std::to_string(v));
  };
  within(max_forward_step, 1, 64, "max_forward_step");
  within(stutter_window, 0, 64, "stutter_window");
  within(freeze_levels, 1, 7, "freeze_levels");
  check(!(skip_cost * static_cast<float>(max_forward_step - 1) > jump_cost), "skip_cost",
        "a forward skip may not cost more than a jump: skip_cost * (max_forward_step - 1) <= "
        "jump_cost");
  for (size_t i = 0; i < transitions.size(); ++i) {
    const float cost = transitions[i].cost;
    check(std::isfinite(cost) && cost >= 0, "transitions[" + std::to_string(i) + "].cost",
          "must be a finite cost >= 0, got " + OptionProblems::Num(cost));
  }
  return check.ok();
}

MatchOptions MatchOptions::WithoutPenalties() const {
  MatchOptions o = *this;
  o.freeze_cost = 0;
  o.stutter_cost = 0;
  return o;
}

std::string MatchResult::Summary() const {
  std::ostringstream s;
  s << source_frames.size() << " target frames, cost " << total_cost << " (matching "
    << matching_cost << "), " << stats.freezes << " freezes in " << stats.freeze_runs
    << " runs (longest " << stats.longest_freeze << "), " << stats.stutters << " stutters, "
    << stats.skips << " skips, " << stats.jumps << " jumps, " << stats.listed << " listed; "
    << cost_seconds << " s costs, " << forward_seconds << " s forward, " << backward_seconds
    << " s backward, " << memory_bytes / (1 << 20) << " MiB ("
    << (walked_decisions ? "decisions" : "checkpoints") << ")";
  return s.str();
}

namespace match_dp_detail {

void CheckStarts(const std::vector<int>& starts, int count, const std::string& what) {
  if (starts.empty() || starts.front() != 0) throw InputError(what, "must start with 0");
  for (size_t i = 1; i < starts.size(); ++i) {
    if (starts[i] <= starts[i - 1]) throw InputError(what, "must be ascending");
  }
  if (starts.back() >= count) {
    throw InputError(what, "start " + std::to_string(starts.back()) + " is beyond the " +
                               std::to_string(count) + " frames");
  }
}

std::vector<int> SegmentIds(const std::vector<int>& starts, int count) {
  std::vector<int> id(count);
  for (size_t g = 0; g < starts.size(); ++g) {
    const int end = g + 1 < starts.size() ? starts[g + 1] : count;
    std::fill(id.begin() + starts[g], id.begin() + end, static_cast<int>(g));
  }
  return id;
}

RowRules MakeRules(const std::vector<int>& starts, int count, const MatchOptions& o, bool local) {
  RowRules rules;
  rules.local_jumps = local;
  rules.fwd_limit.resize(count);
  rules.back_limit.resize(count);
  const std::vector<int> seg = SegmentIds(starts, count);
  for (size_t g = 0; g < starts.size(); ++g) {
    const int begin = starts[g];
    const int end = (g + 1 < starts.size() ? starts[g + 1] : count) - 1;
    rules.seg_begin.push_back(begin);
    rules.seg_end.push_back(end);
    for (int s = begin; s <= end; ++s) {
      rules.fwd_limit[s] = static_cast<float>(std::min(o.max_forward_step, s - begin));
      rules.back_limit[s] = static_cast<float>(std::min(o.stutter_window, end - s));
      if (s - begin < o.max_forward_step || end - s < o.stutter_window) rules.edges.push_back(s);
    }
  }
  for (const auto& tr : o.transitions) {
    if (tr.from == tr.to) continue;
    if (local && seg[tr.from] != seg[tr.to]) continue;
    rules.listed.push_back(tr);
  }
  std::stable_sort(
      rules.listed.begin(), rules.listed.end(),
      [](const SourceTransition& a, const SourceTransition& b) { return a.to < b.to; });
  rules.listed_begin.assign(count + 1, 0);
  for (const auto& tr : rules.listed) ++rules.listed_begin[tr.to + 1];
  for (int s = 0; s < count; ++s) rules.listed_begin[s + 1] += rules.listed_begin[s];
  return rules;
}

Engine::Engine(const CostRows& costs, const std::vector<int>& clip_starts,
               const MatchOptions& options, const MovementConstraint* movements)
    : costs_(costs), o_(options), movements_(movements) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("match options", why);
  T_ = costs.targets();
  S_ = costs.sources();
  R_ = options.freeze_levels;
  if (S_ <= 0) throw InputError("sources", "no source frame to match against");
  CheckStarts(clip_starts, S_, "clip starts");
  for (size_t i = 0; i < options.transitions.size(); ++i) {
    const auto& tr = options.transitions[i];
    if (tr.from < 0 || tr.from >= S_ || tr.to < 0 || tr.to >= S_) {
      throw InputError("transitions[" + std::to_string(i) + "]",
                       "frame out of range 0.." + std::to_string(S_ - 1));
    }
  }
  stride_ = (static_cast<size_t>(S_) + kLanes - 1) / kLanes * kLanes;
  pad_ = std::max(o_.max_forward_step, o_.stutter_window) + kLanes;
  free_ = MakeRules(clip_starts, S_, o_, false);
  skip_.assign(o_.max_forward_step + 1, 0.0f);
  for (int k = 2; k <= o_.max_forward_step; ++k)
    skip_[k] = o_.skip_cost * static_cast<float>(k - 1);
  stutter_.assign(o_.stutter_window + 1, o_.jump_cost + o_.stutter_cost);
  freeze_.assign(R_ + 1, 0.0f);
  for (int r = 1; r <= R_; ++r) freeze_[r] = o_.freeze_cost * static_cast<float>(r);
  if (movements_) {
    const auto& m = *movements_;
    if (!(m.jump_cost_per_frame >= 0) || !std::isfinite(m.jump_cost_per_frame)) {
      throw InputError("movement constraint", "jump_cost_per_frame must be finite and >= 0");
    }
    CheckStarts(m.source_starts, S_, "source movement starts");
    for (int c : clip_starts) {
      if (!std::binary_search(m.source_starts.begin(), m.source_starts.end(), c)) {
        throw InputError("source movement starts",
                         "clip start " + std::to_string(c) + " is not a movement start");
      }
    }
    if (T_ > 0) CheckStarts(m.target_starts, T_, "target movement starts");
    inside_ = MakeRules(m.source_starts, S_, o_, true);
    inside_row_.assign(T_, 1);
    for (int t : m.target_starts) inside_row_[t] = 0;
    if (T_ > 0) inside_row_[0] = 0;
    local_stutter_.assign(o_.stutter_window + 1, 0.0f);
    for (int k = 1; k <= o_.stutter_window; ++k) {
      local_stutter_[k] =
          (o_.jump_cost + o_.stutter_cost) + m.jump_cost_per_frame * static_cast<float>(k);
    }
    jump_.assign(stride_, kInf);
    suffix_.assign(S_ + 1, kInf);
    suffix_at_.assign(S_ + 1, -1);
  }
}

void Engine::ComputeCosts(int t0, int n, double* seconds) {
  const auto start = std::chrono::steady_clock::now();
  tile_.resize(static_cast<size_t>(kCostTile) * S_ + kLanes);
  costs_.Compute(t0, n, tile_.data());
  tile_first_ = t0;
  tile_count_ = n;
  *seconds += Seconds(start);
}

MatchResult Engine::Solve() {
  MatchResult result;
  if (T_ == 0) return result;
  if (!SolveWithDecisions(&result)) SolveWithCheckpoints(&result);
  return result;
}

}  // namespace match_dp_detail

using match_dp_detail::Engine;

MatchResult SolveMatch(const CostRows& costs, const std::vector<int>& clip_starts,
                       const MatchOptions& options, const MovementConstraint* movements) {
  Engine engine(costs, clip_starts, options, movements);
  MatchResult result = engine.Solve();
  if (!result.source_frames.empty()) {
    double matching = 0;
    PathCost(costs, clip_starts, options, movements, result.source_frames, &matching);
    result.matching_cost = matching;
    result.stats = AnalyzePath(result.source_frames, clip_starts, options);
  }
  Log("animate.match")->debug("{}", result.Summary());
  return result;
}

}  // namespace ss
