// Matching refinement (seed 003 §2.3): atomic movements as local maxima of the sequential
// matching cost, one source movement per target movement, the per-frame jump penalty
// inside a movement and the averaging window.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "animate/skeleton/cost_rows.h"
#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/match_dp.h"
#include "animate/skeleton/refine.h"
#include "animate/skeleton/synthetic_poses.h"
#include "core/error.h"

namespace ss {
namespace {

// A flat cost with Gaussian bumps of `height` at `centres`.
std::vector<float> Bumps(int n, const std::vector<std::pair<int, float>>& peaks) {
  std::vector<float> q(n, 0.01f);
  for (int t = 0; t < n; ++t) {
    for (const auto& [c, h] : peaks) q[t] += h * std::exp(-0.5f * (t - c) * (t - c) / 4.0f);
  }
  return q;
}

TEST(SkeletonRefine, MovementsStartAfterLocalMaxima) {
  // Frame t + 1 starts a movement when cost(x_t, x_t+1) peaks.
  const auto q = Bumps(99, {{20, 0.5f}, {45, 0.4f}, {70, 0.3f}});
  EXPECT_EQ(FindMovements(q, MovementOptions{}), (std::vector<int>{0, 21, 46, 71}));
}

TEST(SkeletonRefine, WeakAndCrowdedPeaksAreDropped) {
  MovementOptions o;
  o.min_length_s = 8.0 / 30;  // frames at the default 30 fps
  o.smoothing_s = 3.0 / 30;
  o.noise_factor = 0;  // the fixed threshold alone
  o.min_prominence = 0.05f;
  // 85: too weak; 48: 3 frames after the stronger 45; 3: too close to the start.
  // (The two crowded bumps merge into one peak at 46, so its movement starts at 47.)
  const auto q =
      Bumps(99, {{3, 0.5f}, {20, 0.5f}, {45, 0.4f}, {48, 0.3f}, {70, 0.3f}, {85, 0.03f}});
  EXPECT_EQ(FindMovements(q, o), (std::vector<int>{0, 21, 47, 71}));
  o.min_prominence = 0.01f;
  EXPECT_EQ(FindMovements(q, o), (std::vector<int>{0, 21, 47, 71, 86}));
  EXPECT_EQ(FindMovements(std::vector<float>(50, 0.2f), o),
            (std::vector<int>{0}));  // no peak, one movement
  // Relative to the noise floor: on a floor of 0.01 the 0.03 bump is noise for a factor of 4.
  o.noise_factor = 4;
  EXPECT_EQ(FindMovements(q, o), (std::vector<int>{0, 21, 47, 71}));
}

TEST(SkeletonRefine, MovementWindowsAreSecondsAtTheClipsFrameRate) {
  // 30 fps keeps the frames the detector was tuned with; 10 fps a third of them.
  const MovementFrames at30 = MovementWindows(MovementOptions{}, 30);
  EXPECT_EQ(at30.lag, 4);
  EXPECT_EQ(at30.smoothing_window, 5);
  EXPECT_EQ(at30.min_length, 8);
  const MovementFrames at10 = MovementWindows(MovementOptions{}, 10);
  EXPECT_EQ(at10.lag, 1);
  EXPECT_EQ(at10.smoothing_window, 2);
  EXPECT_EQ(at10.min_length, 3);
  EXPECT_EQ(MovementWindows(MovementOptions{}, 60).min_length, 16);
  // Two movements 1 s apart: at 30 fps and, sampled every third frame, at 10 fps, the
  // boundaries fall at the same instants. With the 30 fps frame counts at 10 fps the
  // minimum length (8 frames = 0.8 s there) would merge the 0.5 s movement in between.
  const auto q30 = Bumps(120, {{30, 0.5f}, {45, 0.5f}, {90, 0.5f}});
  std::vector<float> q10;
  for (int t = 0; t < 120; t += 3) q10.push_back(q30[t]);
  EXPECT_EQ(FindMovements(q30, MovementOptions{}, 30), (std::vector<int>{0, 31, 46, 91}));
  EXPECT_EQ(FindMovements(q10, MovementOptions{}, 10), (std::vector<int>{0, 11, 16, 31}));
  MovementOptions frames_at_30;
  frames_at_30.min_length_s = 8.0 / 10;
  EXPECT_EQ(FindMovements(q10, frames_at_30, 10).size(), 3u);
}

// The gesture script's transitions: [first frame, last frame] of each blend.
struct GestureScript {
  std::vector<std::pair<Gesture, int>> steps;
  std::vector<std::pair<int, int>> blends;
};

GestureScript Ymca() {
  GestureScript s;
  s.steps = {{Gesture::kIdle, 30},
             {Gesture::kY, 30},
             {Gesture::kM, 30},
             {Gesture::kC, 30},
             {Gesture::kA, 30}};
  const int blend = GestureScriptOptions{}.transition_frames;
  int at = 30;
  for (int i = 1; i < 5; ++i) {
    s.blends.push_back({at, at + blend - 1});
    at += blend + 30;
  }
  return s;
}

TEST(SkeletonRefine, GestureBoundariesFallInTheTransitions) {
  // Clean and with 1.5 px of joint noise (which alone moves the frame-to-frame cost more
  // than a gesture change does: hence the lag).
  const GestureScript script = Ymca();
  for (float noise : {0.0f, 1.5f}) {
    SCOPED_TRACE("noise " + std::to_string(noise));
    GestureScriptOptions o;
    o.noise_px = noise;
    const PoseDescriptors d =
        ComputeDescriptors(MakeGestureSequence(script.steps, OtherBody(), o).sequence, {});
    const std::vector<int> starts = FindMovements(d, {0}, MovementOptions{});
    ASSERT_EQ(starts.size(), script.blends.size() + 1) << ::testing::PrintToString(starts);
    for (size_t i = 0; i < script.blends.size(); ++i) {
      EXPECT_GE(starts[i + 1], script.blends[i].first);
      EXPECT_LE(starts[i + 1], script.blends[i].second + 1);
    }
  }
  // lag 1 is the plain sequential cost.
  const PoseDescriptors d =
      ComputeDescriptors(MakeGestureSequence(script.steps, OtherBody()).sequence, {});
  EXPECT_EQ(MovementCost(d, 0, d.count, 1), SequentialCost(d));
}

TEST(SkeletonRefine, JumpPenaltyInsideAMovement) {
  // One target and one source movement. The best match follows s = t, then jumps ahead
  // by 15 frames at t = 5; staying on s = t costs 0.1 per frame more from there on.
  const int T = 10, S = 30;
  std::vector<float> c(T * S, 1.0f);
  for (int t = 0; t < T; ++t) {
    c[t * S + t] = t < 5 ? 0.0f : 0.1f;
    if (t >= 5) c[t * S + t + 15] = 0.0f;
  }
  const DenseCostRows costs(T, S, c);
  MatchOptions o;
  MovementConstraint m;
  m.target_starts = {0};
  m.source_starts = {0};
  m.jump_cost_per_frame = 0;
  const MatchResult free = SolveMatch(costs, {0}, o, &m);
  EXPECT_EQ(free.source_frames[5], 20);
  EXPECT_EQ(free.stats.jumps, 1);
  // λ|d| on top of the jump's cost: exactly 15 λ more for this path.
  m.jump_cost_per_frame = 0.05f;
  MovementConstraint none = m;
  none.jump_cost_per_frame = 0;
  EXPECT_NEAR(PathCost(costs, {0}, o, &m, free.source_frames) -
                  PathCost(costs, {0}, o, &none, free.source_frames),
              16 * 0.05, 1e-5);  // 4 -> 20
  const MatchResult penalized = SolveMatch(costs, {0}, o, &m);
  for (int t = 0; t < T; ++t) EXPECT_EQ(penalized.source_frames[t], t);
  EXPECT_EQ(penalized.stats.jumps, 0);
  // Across target movements the jump is free of λ again.
  m.target_starts = {0, 5};
  EXPECT_EQ(SolveMatch(costs, {0}, o, &m).source_frames[5], 20);
}

TEST(SkeletonRefine, AveragingWindowStaysInsideEachMovement) {
  const std::vector<int> frames = {10, 10, 20, 20, 20, 50, 50, 50};
  EXPECT_EQ(AverageWithinSegments(frames, {0, 5}, 3),
            (std::vector<int>{10, 13, 17, 20, 20, 50, 50, 50}));
  EXPECT_EQ(AverageWithinSegments(frames, {0, 5}, 1), frames);
  // Forward play with a stutter (two steps on, one back) becomes a steady run.
  const std::vector<int> stutter = {10, 12, 11, 13, 12, 14, 13, 15};
  EXPECT_EQ(AverageWithinSegments(stutter, {0}, 3),
            (std::vector<int>{11, 11, 12, 12, 13, 13, 14, 14}));
}

TEST(SkeletonRefine, TargetMovementsAreCutWhereTheFirstPassChangesSourceMovement) {
  // Source movements [0, 10), [10, 30), [30, ...). Target movements [0, 20), [20, 26).
  const std::vector<int> source_starts{0, 10, 30};
  std::vector<int> first_pass;
  first_pass.reserve(26);
  for (int t = 0; t < 10; ++t) first_pass.push_back(12 + t);  // movement 1
  first_pass.push_back(5);                                    // movement 0 for 2 frames: too short
  first_pass.push_back(6);
  for (int t = 12; t < 20; ++t)
    first_pass.push_back(31 + t);  // movement 2 for 8 frames: a cut at 12
  for (int t = 20; t < 26; ++t)
    first_pass.push_back(40 + t);  // still movement 2, its own target movement
  EXPECT_EQ(SplitByFirstPass({0, 20}, source_starts, first_pass, 3), (std::vector<int>{0, 12, 20}));
  // With a minimum of 9 frames the 8-frame run is not a movement of its own either.
  EXPECT_EQ(SplitByFirstPass({0, 20}, source_starts, first_pass, 9), (std::vector<int>{0, 20}));
  // A first pass inside one source movement cuts nothing.
  EXPECT_EQ(SplitByFirstPass({0, 20}, source_starts, std::vector<int>(26, 15), 3),
            (std::vector<int>{0, 20}));
}

TEST(SkeletonRefine, OneSourceMovementPerTargetMovement) {
  // Target: the YMCA by one body. Source: the gestures by another body, in another order
  // and at another speed, with walking between them.
  // (No idle in the target: the synthetic idle pose is also a phase of the walk, so
  // "idle" matched to standing walk frames would count as a wrong label.)
  const LabelledSkeletons target = MakeGestureSequence({{Gesture::kY, 30},
                                                        {Gesture::kM, 30},
                                                        {Gesture::kC, 30},
                                                        {Gesture::kA, 30},
                                                        {Gesture::kWalk, 40}},
                                                       BodyProportions{});
  GestureScriptOptions slow;
  slow.speed = 0.8f;
  const LabelledSkeletons source = MakeGestureSequence({{Gesture::kWalk, 40},
                                                        {Gesture::kA, 30},
                                                        {Gesture::kC, 30},
                                                        {Gesture::kIdle, 30},
                                                        {Gesture::kM, 30},
                                                        {Gesture::kWalk, 40},
                                                        {Gesture::kY, 30}},
                                                       OtherBody(), slow);
  const PoseDescriptors td = ComputeDescriptors(target.sequence, {});
  const PoseDescriptors sd = ComputeDescriptors(source.sequence, {});
  const DescriptorCostRows costs(td, sd);
  RefineOptions refine;
  const RefineResult r = RefineMatch(costs, td, sd, {0}, MatchOptions{}, refine);
  ASSERT_EQ(static_cast<int>(r.source_frames.size()), td.count);
  ASSERT_GE(r.target_movements.size(), 4u);
  ASSERT_GE(r.source_movements.size(), 7u);
  auto source_movement = [&](int s) {
    return std::upper_bound(r.source_movements.begin(), r.source_movements.end(), s) -
           r.source_movements.begin();
  };
  for (size_t m = 0; m < r.target_movements.size(); ++m) {
    const int begin = r.target_movements[m];
    const int end = m + 1 < r.target_movements.size() ? r.target_movements[m + 1] : td.count;
    std::set<long> used, used_after_averaging;
    for (int t = begin; t < end; ++t) {
      used.insert(source_movement(r.second_pass.source_frames[t]));
      used_after_averaging.insert(source_movement(r.source_frames[t]));
    }
    EXPECT_EQ(used.size(), 1u) << "target movement " << m;
    EXPECT_EQ(used_after_averaging.size(), 1u) << "target movement " << m;
  }
  int same = 0;
  for (int t = 0; t < td.count; ++t) same += target.labels[t] == source.labels[r.source_frames[t]];
  EXPECT_GE(same, td.count * 95 / 100);
  EXPECT_LE(r.stats.longest_freeze, 5);
  // A first pass of another length than the target is refused, not ignored.
  const std::vector<int> short_pass(td.count - 1, 0);
  EXPECT_THROW(RefineMatch(costs, td, sd, {0}, MatchOptions{}, refine, &short_pass), InputError);
}

}  // namespace
}  // namespace ss
