// The matcher's DP against exhaustive search and a plain quadratic DP, and the effect of
// each penalty on hand-made cost matrices.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "animate/skeleton/cost_rows.h"
#include "animate/skeleton/match_dp.h"
#include "core/error.h"

namespace ss {
namespace {

DenseCostRows RandomCosts(int targets, int sources, std::mt19937& rng, float excluded_share = 0) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> v(static_cast<size_t>(targets) * sources);
  for (auto& x : v) x = u(rng) < excluded_share ? std::numeric_limits<float>::infinity() : u(rng);
  return DenseCostRows(targets, sources, std::move(v));
}

// The minimum of PathCost over every path (sources^targets of them).
double Exhaustive(const CostRows& costs, const std::vector<int>& clips, const MatchOptions& o,
                  const MovementConstraint* m, std::vector<int>* best_path) {
  const int T = costs.targets(), S = costs.sources();
  std::vector<int> path(T, 0);
  double best = std::numeric_limits<double>::infinity();
  while (true) {
    const double c = PathCost(costs, clips, o, m, path);
    if (c < best) {
      best = c;
      *best_path = path;
    }
    int i = T - 1;
    while (i >= 0 && ++path[i] == S) path[i--] = 0;
    if (i < 0) break;
  }
  return best;
}

MatchOptions RandomOptions(std::mt19937& rng, int sources) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  MatchOptions o;
  o.max_forward_step = 1 + static_cast<int>(rng() % 3);
  o.stutter_window = static_cast<int>(rng() % 4);
  o.freeze_levels = 1 + static_cast<int>(rng() % 3);
  o.jump_cost = 0.1f + 0.4f * u(rng);
  o.skip_cost = o.jump_cost / 4 * u(rng);
  o.freeze_cost = 0.2f * u(rng);
  o.stutter_cost = 0.3f * u(rng);
  const int listed = static_cast<int>(rng() % 4);
  for (int i = 0; i < listed; ++i) {
    o.transitions.push_back(
        {static_cast<int>(rng() % sources), static_cast<int>(rng() % sources), 0.2f * u(rng)});
  }
  return o;
}

TEST(SkeletonDp, MatchesExhaustiveSearchOnSmallCases) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const int T = 5, S = 6;
    const DenseCostRows costs = RandomCosts(T, S, rng, trial % 5 == 0 ? 0.2f : 0.0f);
    const std::vector<int> clips = trial % 2 ? std::vector<int>{0, 4} : std::vector<int>{0};
    const MatchOptions o = RandomOptions(rng, S);
    std::vector<int> expected_path;
    const double expected = Exhaustive(costs, clips, o, nullptr, &expected_path);
    if (!std::isfinite(expected)) continue;
    const MatchResult r = SolveMatch(costs, clips, o);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_NEAR(r.total_cost, expected, 1e-4);
    EXPECT_NEAR(PathCost(costs, clips, o, nullptr, r.source_frames), expected, 1e-4);
  }
}

TEST(SkeletonDp, MatchesExhaustiveSearchWithMovementConstraint) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const int T = 5, S = 6;
    const DenseCostRows costs = RandomCosts(T, S, rng);
    const std::vector<int> clips = {0, 4};
    const MatchOptions o = RandomOptions(rng, S);
    MovementConstraint m;
    m.target_starts = trial % 2 ? std::vector<int>{0, 3} : std::vector<int>{0};
    m.source_starts = {0, 2, 4};
    m.jump_cost_per_frame = 0.05f * static_cast<float>(trial % 4);
    std::vector<int> expected_path;
    const double expected = Exhaustive(costs, clips, o, &m, &expected_path);
    const MatchResult r = SolveMatch(costs, clips, o, &m);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_NEAR(r.total_cost, expected, 1e-4);
    EXPECT_NEAR(PathCost(costs, clips, o, &m, r.source_frames), expected, 1e-4);
  }
}

// A plain O(T S^2 R) DP over (s, r) using PathCost's move rules, for sizes beyond
// exhaustive search (these exercise the vector kernel, its tail and the jump fix-ups).
double QuadraticDp(const DenseCostRows& costs, const std::vector<int>& clips, const MatchOptions& o,
                   const MovementConstraint* m) {
  const int T = costs.targets(), S = costs.sources(), R = o.freeze_levels;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> v(S * (R + 1), inf), next(S * (R + 1));
  for (int s = 0; s < S; ++s) v[s * (R + 1)] = costs.at(0, s);
  for (int t = 1; t < T; ++t) {
    std::fill(next.begin(), next.end(), inf);
    for (int s = 0; s < S; ++s) {
      for (int r = 1; r <= R; ++r) {  // stays
        const double from =
            r < R ? v[s * (R + 1) + r - 1] : std::min(v[s * (R + 1) + R - 1], v[s * (R + 1) + R]);
        next[s * (R + 1) + r] = from + o.freeze_cost * r + costs.at(t, s);
      }
      for (int p = 0; p < S; ++p) {  // moves p -> s: the cost of the two-frame path minus its parts
        if (p == s) continue;
        double best_p = inf;
        for (int r = 0; r <= R; ++r) best_p = std::min(best_p, v[p * (R + 1) + r]);
        if (!std::isfinite(best_p)) continue;
        // PathCost on a 2-row problem made of rows t-1 and t gives c(t-1,p) + move + c(t,s).
        std::vector<float> rows(2 * S, 0.0f);
        const DenseCostRows zero(2, S, rows);
        MovementConstraint local;
        const MovementConstraint* use = nullptr;
        if (m) {
          local = *m;
          const bool inside =
              !std::binary_search(m->target_starts.begin(), m->target_starts.end(), t);
          local.target_starts = inside ? std::vector<int>{0} : std::vector<int>{0, 1};
          use = &local;
        }
        const double move = PathCost(zero, clips, o, use, {p, s});
        next[s * (R + 1)] = std::min(next[s * (R + 1)], best_p + move + costs.at(t, s));
      }
    }
    v.swap(next);
  }
  return *std::min_element(v.begin(), v.end());
}

TEST(SkeletonDp, MatchesQuadraticDpOnLargerCases) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 8; ++trial) {
    const int T = 12, S = 45 + trial;
    const DenseCostRows costs = RandomCosts(T, S, rng, 0.05f);
    const std::vector<int> clips = {0, 17, 30};
    MatchOptions o = RandomOptions(rng, S);
    o.stutter_window = 1 + trial % 5;
    MovementConstraint m;
    m.target_starts = {0, 5, 9};
    m.source_starts = {0, 8, 17, 23, 30, 40};
    m.jump_cost_per_frame = 0.02f;
    SCOPED_TRACE("trial " + std::to_string(trial));
    const MatchResult free = SolveMatch(costs, clips, o);
    EXPECT_NEAR(free.total_cost, QuadraticDp(costs, clips, o, nullptr), 1e-4);
    EXPECT_NEAR(PathCost(costs, clips, o, nullptr, free.source_frames), free.total_cost, 1e-4);
    const MatchResult constrained = SolveMatch(costs, clips, o, &m);
    EXPECT_NEAR(constrained.total_cost, QuadraticDp(costs, clips, o, &m), 1e-4);
    EXPECT_NEAR(PathCost(costs, clips, o, &m, constrained.source_frames), constrained.total_cost,
                1e-4);
  }
}

TEST(SkeletonDp, LongSequenceUsesCheckpointsAndStaysOptimal) {
  // 300 rows: many checkpoint blocks; the path must still cost what the DP says.
  std::mt19937 rng(5);
  const DenseCostRows costs = RandomCosts(300, 37, rng);
  MatchOptions o;
  o.max_decision_bytes = 0;  // no stored decisions: the checkpoint backtrack
  const MatchResult r = SolveMatch(costs, {0, 20}, o);
  EXPECT_FALSE(r.walked_decisions);
  EXPECT_NEAR(PathCost(costs, {0, 20}, o, nullptr, r.source_frames), r.total_cost, 1e-3);
}

TEST(SkeletonDp, StoredDecisionsGiveTheCheckpointPath) {
  // The backtrack over decisions stored by the forward pass against the checkpoint
  // fallback (forced by a zero budget), which recomputes rows and re-derives every move:
  // the same frames and cost, free and constrained, packed (Kf + W <= 14) and wide codes,
  // with listed transitions, excluded frames and 0/1 costs (many exact ties).
  std::mt19937 rng(19);
  for (int trial = 0; trial < 24; ++trial) {
    const bool constrained = trial % 2 == 1;
    // 0/1 costs, free skips and stutters: equal candidates everywhere
    const bool grid = trial % 5 == 2;
    const bool wide = trial % 3 == 0;  // move codes above 15: two bytes a cell
    const int T = trial % 4 == 0 ? 160 : 30 + 3 * trial, S = 45 + 5 * trial;
    DenseCostRows costs = RandomCosts(T, S, rng, trial % 4 == 1 ? 0.05f : 0.0f);
    if (grid) {
      std::vector<float> values(static_cast<size_t>(T) * S);
      for (int t = 0; t < T; ++t) {
        for (int s = 0; s < S; ++s)
          values[static_cast<size_t>(t) * S + s] = costs.at(t, s) < 0.7f ? 0.0f : 1.0f;
      }
      costs = DenseCostRows(T, S, std::move(values));
    }
    const std::vector<int> clips = {0, 17, 30};
    MatchOptions o = RandomOptions(rng, S);
    if (grid) {
      o.max_forward_step = constrained ? 1 : 3;  // constrained: few moves, so local jumps
      o.stutter_window = constrained && trial % 3 == 2 ? 0 : 2;
      o.skip_cost = 0;
      o.jump_cost = 0.25f;
      o.freeze_cost = 0.25f;
      o.stutter_cost = 0;
    }
    if (wide) {
      o.max_forward_step = 5;
      o.stutter_window = 12;
      o.skip_cost = o.jump_cost / 8;
    }
    if (trial % 3 == 1) {
      for (int i = 0; i < 25; ++i) {
        o.transitions.push_back(
            {static_cast<int>(rng() % S), static_cast<int>(rng() % S), 0.05f * (i % 4)});
      }
    }
    MovementConstraint m;
    m.target_starts = {0, T / 3, T / 2};
    m.source_starts = {0, 8, 17, 23, 30, 40};
    m.jump_cost_per_frame = grid ? 0.0f : 0.01f * static_cast<float>(trial % 3);
    const MovementConstraint* constraint = constrained ? &m : nullptr;
    MatchOptions checkpoints = o;
    checkpoints.max_decision_bytes = 0;
    SCOPED_TRACE("trial " + std::to_string(trial));
    const MatchResult stored = SolveMatch(costs, clips, o, constraint);
    const MatchResult recomputed = SolveMatch(costs, clips, checkpoints, constraint);
    EXPECT_TRUE(stored.walked_decisions);
    EXPECT_FALSE(recomputed.walked_decisions);
    EXPECT_EQ(stored.source_frames, recomputed.source_frames);
    EXPECT_EQ(stored.total_cost, recomputed.total_cost);
    EXPECT_NEAR(PathCost(costs, clips, o, constraint, stored.source_frames), stored.total_cost,
                1e-3);
    EXPECT_GE(stored.memory_bytes, static_cast<size_t>(T) * S);  // at least a byte a cell
  }
}

TEST(SkeletonDp, ListedChoicesPastTheBudgetFallBackToCheckpoints) {
  // Free listed transitions into every frame from frame 0, whose row minimum they beat: they
  // win many cells, and their choices (8 bytes each) do not fit a budget that holds the
  // decisions alone. The solve starts over with checkpoints and gives the same path.
  std::mt19937 rng(23);
  const int T = 60, S = 80;
  const DenseCostRows costs = RandomCosts(T, S, rng, 0.0f);
  MatchOptions o;
  for (int s = 0; s < S; ++s) {
    for (int from = 0; from < S; from += 7) o.transitions.push_back({from, s, 0.0f});
  }
  const std::vector<int> clips = {0};
  MatchOptions roomy = o, tight = o, checkpoints = o;
  checkpoints.max_decision_bytes = 0;
  const MatchResult reference = SolveMatch(costs, clips, checkpoints);
  const MatchResult stored = SolveMatch(costs, clips, roomy);
  ASSERT_TRUE(stored.walked_decisions);
  // What the decisions need without the listed choices: a byte a cell and the top lists.
  tight.max_decision_bytes =
      static_cast<size_t>(T) * S + static_cast<size_t>(T) * (o.stutter_window + 2) * 4 + 64;
  const MatchResult fallen = SolveMatch(costs, clips, tight);
  EXPECT_FALSE(fallen.walked_decisions);
  EXPECT_EQ(stored.source_frames, reference.source_frames);
  EXPECT_EQ(fallen.source_frames, reference.source_frames);
  EXPECT_EQ(fallen.total_cost, reference.total_cost);
  EXPECT_GT(stored.stats.listed, 0);
}

TEST(SkeletonDp, StoredDecisionsBreakTiesLikeTheCheckpointPath) {
  // Two equal stutters back into frame 10 (from 12 or 13): both backtracks take the
  // shorter step, free (a row's minimum in the window: scalar cells) and inside a target
  // movement (the vector kernel).
  const int S = 40;
  std::vector<float> values(2 * S, 1.0f);
  values[12] = values[13] = 0;  // row 0
  values[S + 10] = 0;           // row 1
  const DenseCostRows costs(2, S, values);
  MatchOptions o;
  o.max_forward_step = 1;
  o.stutter_window = 3;
  MovementConstraint inside;
  inside.target_starts = {0};
  inside.source_starts = {0};
  for (const MovementConstraint* m : std::vector<const MovementConstraint*>{nullptr, &inside}) {
    MatchOptions checkpoints = o;
    checkpoints.max_decision_bytes = 0;
    const MatchResult stored = SolveMatch(costs, {0}, o, m);
    const MatchResult recomputed = SolveMatch(costs, {0}, checkpoints, m);
    EXPECT_TRUE(stored.walked_decisions);
    EXPECT_EQ(stored.source_frames, (std::vector<int>{12, 10}));
    EXPECT_EQ(recomputed.source_frames, (std::vector<int>{12, 10}));
  }
}

// Cost matrix with `value` everywhere and chosen cells overridden.
std::vector<float> Filled(int T, int S, float value) {
  return std::vector<float>(static_cast<size_t>(T) * S, value);
}

TEST(SkeletonDp, FreezePenaltyRemovesFreezes) {
  // Source 0..4 is the motion at half the target's rate (each frame matches two target
  // frames exactly); source 5..14 is the motion at the target's rate with a small mismatch.
  const int T = 10, S = 15;
  std::vector<float> c = Filled(T, S, 1.0f);
  for (int t = 0; t < T; ++t) {
    c[t * S + t / 2] = 0.0f;
    c[t * S + 5 + t] = 0.01f;
  }
  const DenseCostRows costs(T, S, c);
  MatchOptions o;
  o.freeze_cost = 0.05f;
  const MatchResult without = SolveMatch(costs, {0}, o.WithoutPenalties());
  const MatchResult with = SolveMatch(costs, {0}, o);
  EXPECT_EQ(without.stats.freezes, 5);
  EXPECT_EQ(with.stats.freezes, 0);
  EXPECT_EQ(with.source_frames.front(), 5);
  EXPECT_EQ(with.source_frames.back(), 14);
}

TEST(SkeletonDp, FreezePenaltyGrowsWithTheRunLength) {
  // The k-th repeat costs freeze_cost * min(k, R): a run of 6 repeats with R = 4 costs
  // (1 + 2 + 3 + 4 + 4 + 4) * freeze_cost.
  const int T = 7, S = 3;
  const DenseCostRows costs(T, S, Filled(T, S, 0.0f));
  MatchOptions o;
  o.freeze_cost = 0.01f;
  o.freeze_levels = 4;
  EXPECT_NEAR(PathCost(costs, {0}, o, nullptr, {1, 1, 1, 1, 1, 1, 1}), 0.18, 1e-6);
}

TEST(SkeletonDp, StutterPenaltyRemovesStutters) {
  // The best match alternates between source frames 3 and 4; source 10.. plays the
  // motion forward with a small mismatch.
  const int T = 8, S = 20;
  std::vector<float> c = Filled(T, S, 1.0f);
  for (int t = 0; t < T; ++t) {
    c[t * S + 3 + t % 2] = 0.0f;
    c[t * S + 10 + t] = 0.08f;
  }
  const DenseCostRows costs(T, S, c);
  MatchOptions o;
  o.jump_cost = 0.05f;
  o.skip_cost = 0.01f;
  o.stutter_cost = 0.5f;
  const MatchResult without = SolveMatch(costs, {0}, o.WithoutPenalties());
  const MatchResult with = SolveMatch(costs, {0}, o);
  EXPECT_GE(without.stats.stutters, 3);
  EXPECT_EQ(with.stats.stutters, 0);
  EXPECT_EQ(with.stats.freezes, 0);
}

TEST(SkeletonDp, JumpCostFavoursConsecutiveFrames) {
  // Noisy costs along the diagonal of a clip: the per-frame best jumps around; with a jump
  // cost the path plays the clip forward.
  const int T = 30, S = 40;
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 0.1f);
  std::vector<float> c(static_cast<size_t>(T) * S);
  for (int t = 0; t < T; ++t) {
    for (int s = 0; s < S; ++s) c[t * S + s] = 0.02f * std::abs(s - 5 - t) + u(rng);
  }
  const DenseCostRows costs(T, S, c);
  MatchOptions none;
  none.jump_cost = 0;
  none.skip_cost = 0;
  none.freeze_cost = 0;
  none.stutter_cost = 0;
  const MatchResult free = SolveMatch(costs, {0}, none);
  const MatchResult smooth = SolveMatch(costs, {0}, MatchOptions{});
  EXPECT_GT(free.stats.jumps + free.stats.stutters + free.stats.freezes, 5);
  EXPECT_EQ(smooth.stats.jumps + smooth.stats.stutters, 0);
  for (int t = 1; t < T; ++t) EXPECT_GE(smooth.source_frames[t], smooth.source_frames[t - 1]);
}

TEST(SkeletonDp, ListedTransitionJoinsClips) {
  // Clip 0 = frames 0..4, clip 1 = 5..9; the target wants 0..4 then 5..9. Crossing the
  // clip boundary is a jump unless the bank lists 4 -> 5.
  const int T = 10, S = 10;
  std::vector<float> c = Filled(T, S, 1.0f);
  for (int t = 0; t < T; ++t) c[t * S + t] = 0.0f;
  const DenseCostRows costs(T, S, c);
  MatchOptions o;
  o.jump_cost = 0.5f;
  const MatchResult plain = SolveMatch(costs, {0, 5}, o);
  EXPECT_NEAR(plain.total_cost, 0.5, 1e-6);
  EXPECT_EQ(plain.stats.jumps, 1);
  o.transitions = {{4, 5, 0.05f}};
  const MatchResult listed = SolveMatch(costs, {0, 5}, o);
  EXPECT_NEAR(listed.total_cost, 0.05, 1e-6);
  EXPECT_EQ(listed.stats.listed, 1);
  EXPECT_EQ(listed.stats.jumps, 0);
}

TEST(SkeletonDp, MovementConstraintKeepsOneSourceMovement) {
  // Inside one target movement the choice may not leave its source movement even when
  // the per-frame best does.
  const int T = 6, S = 12;
  std::vector<float> c = Filled(T, S, 0.5f);
  for (int t = 0; t < T; ++t)
    c[t * S + (t == 3 ? 9 : t)] = 0.0f;  // frame 3 prefers the other movement
  const DenseCostRows costs(T, S, c);
  MatchOptions o;
  o.jump_cost = 0.05f;
  MovementConstraint m;
  m.target_starts = {0};
  m.source_starts = {0, 6};
  const MatchResult r = SolveMatch(costs, {0}, o, &m);
  for (int s : r.source_frames) EXPECT_LT(s, 6);
  const MatchResult free = SolveMatch(costs, {0}, o);
  EXPECT_EQ(free.source_frames[3], 9);
}

TEST(SkeletonDp, RejectsBadInput) {
  const DenseCostRows costs(2, 3, Filled(2, 3, 0.0f));
  MatchOptions o;
  o.freeze_levels = 0;
  EXPECT_THROW(SolveMatch(costs, {0}, o), InputError);
  EXPECT_THROW(SolveMatch(costs, {1}, MatchOptions{}), InputError);
  MatchOptions bad_transition;
  bad_transition.transitions = {{0, 7, 0.1f}};
  EXPECT_THROW(SolveMatch(costs, {0}, bad_transition), InputError);
  const float inf = std::numeric_limits<float>::infinity();
  const DenseCostRows excluded(2, 3, std::vector<float>(6, inf));
  EXPECT_THROW(SolveMatch(excluded, {0}, MatchOptions{}), WorkError);
}

}  // namespace
}  // namespace ss
