// The transition set: C(i->j) on a hand-made clip, incremental == from scratch, edge cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "core/error.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/synthetic.h"
#include "tests/pipeline/transitions_test_util.h"

namespace ss {
namespace {

RgbaBillboard Dot() {
  RgbaBillboard b;
  b.width = b.height = 2;
  b.anchor_x_px = 0.5;
  b.anchor_y_px = 1;
  b.rgba.assign(16, 200);
  return b;
}

// Only velocity counts: D(i, j) = |v_i - v_j| (m/s), kept when <= 1.
TransitionWeights VelocityOnly() {
  TransitionWeights w = testing::UnitWeights({1, 1, 1, 1, 1, 1}, 1.0, 1.0);
  w.stage1_weights = {1, 0, 0, 0};
  w.stage2_weights = {1, 0, 0, 0, 0, 0};
  return w;
}

SpriteInput At(int64_t id, int64_t clip, double vx, const RgbaBillboard* b) {
  SpriteInput s{id, clip, {}, b};
  s.cheap.velocity_x_mps = vx;
  return s;
}

TEST(TransitionBuilder, CostMatchesFormulaOnHandMadeClips) {
  const RgbaBillboard dot = Dot();
  // Clip A: sprites 1 2 3 4 with v = 0, 0.6, 1.2, 1.8; clip B: 11 12 13 with v = 0.1, 0.7, 1.3.
  // Kept pairs (|dv| <= 1): {1,2} {2,3} {3,4} {11,12} {12,13} (0.6 each), {1,11} .1, {1,12} .7,
  // {2,11} .5, {2,12} .1, {2,13} .7, {3,12} .5, {3,13} .1, {4,13} .5.
  const std::vector<SpriteInput> in = {
      At(1, 100, 0, &dot),    At(2, 100, 0.6, &dot),  At(3, 100, 1.2, &dot), At(4, 100, 1.8, &dot),
      At(11, 200, 0.1, &dot), At(12, 200, 0.7, &dot), At(13, 200, 1.3, &dot)};
  TransitionBuilder builder(VelocityOnly(), 100.0);
  builder.BuildFromScratch(in);
  EXPECT_EQ(builder.KeptPairs().size(), 13u);

  // i -> j needs {i, j}, {i+1, j}, {i, j-1} kept; C(i->j) = D(i+1, j) + D(i, j-1):
  //   1->12: D .7, C = D(2,12) + D(1,11) = .1 + .1     2->12: D .1, C = D(3,12) + D(2,11) = .5 + .5
  //   2->13: D .7, C = D(3,13) + D(2,12) = .1 + .1     3->13: D .1, C = D(4,13) + D(3,12) = .5 + .5
  //   11->2: D .5, C = D(12,2) + D(11,1) = .1 + .1     12->2: D .1, C = D(13,2) + D(12,1) = .7 + .7
  //   12->3: D .5, C = D(13,3) + D(12,2) = .1 + .1
  // Nothing out of the last frames 4 and 13, nothing into the first frames 1 and 11.
  struct Want {
    int64_t from, to;
    double d, c;
  };
  const std::vector<Want> want = {{1, 12, .7, .2},  {2, 12, .1, 1.0}, {2, 13, .7, .2},
                                  {3, 13, .1, 1.0}, {11, 2, .5, .2},  {12, 2, .1, 1.4},
                                  {12, 3, .5, .2}};
  const auto t = builder.Transitions();
  ASSERT_EQ(t.size(), want.size());
  const auto& s = builder.store();
  for (size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(t[k].from, want[k].from);
    EXPECT_EQ(t[k].to, want[k].to);
    EXPECT_NEAR(t[k].distance, want[k].d, 1e-12);
    EXPECT_NEAR(t[k].cost, want[k].c, 1e-12);
    // And exactly the formula on the builder's own D values.
    const int32_t i = *s.IndexOf(t[k].from), j = *s.IndexOf(t[k].to);
    EXPECT_EQ(t[k].cost, builder.KeptDistance(s.next(i), j) + builder.KeptDistance(i, s.prev(j)));
    EXPECT_EQ(t[k].distance, builder.KeptDistance(i, j));
  }
  EXPECT_EQ(builder.TransitionCount(), 7);
}

TEST(TransitionBuilder, ClipEndsAndRepeatsAreNotTransitions) {
  const RgbaBillboard dot = Dot();
  // One clip 1..5 with v = 0, .5, 0, .5, 0: every pair is kept.
  const std::vector<SpriteInput> in = {At(1, 7, 0, &dot), At(2, 7, .5, &dot), At(3, 7, 0, &dot),
                                       At(4, 7, .5, &dot), At(5, 7, 0, &dot)};
  TransitionBuilder builder(VelocityOnly(), 100.0);
  builder.BuildFromScratch(in);
  EXPECT_EQ(builder.KeptPairs().size(), 10u);
  // No i -> i+1 (the clip itself), no i -> i, nothing out of 5, nothing into 1.
  std::map<std::pair<int64_t, int64_t>, double> got;
  for (const auto& t : builder.Transitions()) got[{t.from, t.to}] = t.cost;
  const std::map<std::pair<int64_t, int64_t>, double> want = {
      {{1, 3}, 1}, {{1, 4}, 0}, {{1, 5}, 1}, {{2, 4}, 1}, {{2, 5}, 0},
      {{3, 2}, 0}, {{3, 5}, 1}, {{4, 2}, 1}, {{4, 3}, 0}};
  EXPECT_EQ(got, want);
  ASSERT_EQ(builder.stats().notes.size(), 1u);
  EXPECT_NE(builder.stats().notes[0].find("one clip"), std::string::npos);
}

TEST(TransitionBuilder, EmptySetAndDuplicatesAreInputErrors) {
  TransitionBuilder builder(VelocityOnly(), 100.0);
  try {
    builder.BuildFromScratch({});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
  const RgbaBillboard dot = Dot();
  const std::vector<SpriteInput> in = {At(1, 7, 0, &dot), At(1, 7, 5, &dot)};
  try {
    builder.BuildFromScratch(in);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sprite 1"), std::string::npos) << e.what();
  }
  std::vector<SpriteInput> missing = {At(2, 7, 0, nullptr)};
  EXPECT_THROW(builder.Add(missing), InputError);
  EXPECT_THROW(TransitionBuilder(VelocityOnly(), 0.0), InputError);
}

// GenerousWeights weights for the synthetic set so that many pairs and transitions exist.
TransitionWeights GenerousWeights() {
  return testing::UnitWeights({0.03, 30, 0.0006, 0.04, 0.12, 12}, 4.0, 3.0);
}

TEST(TransitionBuilder, IncrementalEqualsFromScratch) {
  SyntheticSpriteOptions o;
  o.frames = 700;
  o.min_clip_frames = 10;
  o.max_clip_frames = 80;
  o.seed = 5;
  const auto sprites = MakeSyntheticSprites(o);
  auto inputs = AsSpriteInputs(sprites);
  // Interleave the clips as a live station would deliver them (originals with their mirrors).
  std::vector<SpriteInput> live;
  const size_t half = inputs.size() / 2;
  for (size_t k = 0; k < half; ++k) {
    live.push_back(inputs[k]);
    live.push_back(inputs[half + k]);
  }

  TransitionBuilder scratch(GenerousWeights(), o.px_per_m);
  scratch.BuildFromScratch(inputs, BuildOptions{.threads = 2});
  const auto pairs = scratch.KeptPairs();
  const auto transitions = scratch.Transitions();
  ASSERT_GT(pairs.size(), 2000u);
  ASSERT_GT(transitions.size(), 500u);

  // Start from a from-scratch build of the first 300 live sprites, then add the rest in
  // batches of random sizes; collect every delta.
  TransitionBuilder live_builder(GenerousWeights(), o.px_per_m);
  live_builder.BuildFromScratch(std::span(live).first(300), BuildOptions{.threads = 1});
  std::vector<Transition> seen = live_builder.Transitions();
  std::vector<KeptPair> seen_pairs = live_builder.KeptPairs();
  std::mt19937 rng(1);
  for (size_t k = 300; k < live.size();) {
    const size_t n = std::min(live.size() - k, size_t{1} + rng() % 5);
    const TransitionDelta d = live_builder.Add(std::span(live).subspan(k, n));
    seen.insert(seen.end(), d.transitions.begin(), d.transitions.end());
    seen_pairs.insert(seen_pairs.end(), d.pairs.begin(), d.pairs.end());
    k += n;
  }
  EXPECT_EQ(live_builder.KeptPairs(), pairs);
  EXPECT_EQ(live_builder.Transitions(), transitions);
  // The deltas hold every transition exactly once (none reported twice, none missed).
  auto by_key = [](const Transition& a, const Transition& b) {
    return std::tie(a.from, a.to) < std::tie(b.from, b.to);
  };
  std::sort(seen.begin(), seen.end(), by_key);
  EXPECT_EQ(seen, transitions);
  std::sort(seen_pairs.begin(), seen_pairs.end(), [](const KeptPair& a, const KeptPair& b) {
    return std::tie(a.sprite_a, a.sprite_b) < std::tie(b.sprite_a, b.sprite_b);
  });
  EXPECT_EQ(seen_pairs, pairs);

  // Adding everything to an empty builder gives the same set too.
  TransitionBuilder from_empty(GenerousWeights(), o.px_per_m);
  from_empty.Add(live);
  EXPECT_EQ(from_empty.Transitions(), transitions);
}

TEST(TransitionBuilder, ThreadCountDoesNotChangeTheResult) {
  SyntheticSpriteOptions o;
  o.frames = 400;
  o.seed = 9;
  const auto sprites = MakeSyntheticSprites(o);
  const auto inputs = AsSpriteInputs(sprites);
  TransitionBuilder one(GenerousWeights(), o.px_per_m), two(GenerousWeights(), o.px_per_m);
  one.BuildFromScratch(inputs, BuildOptions{.threads = 1});
  two.BuildFromScratch(inputs, BuildOptions{.threads = 2});
  EXPECT_EQ(one.KeptPairs(), two.KeptPairs());
  EXPECT_EQ(one.Transitions(), two.Transitions());
  EXPECT_EQ(one.stats().stage1_candidates, two.stats().stage1_candidates);
  EXPECT_EQ(one.stats().stage2_evaluations, two.stats().stage2_evaluations);
}

}  // namespace
}  // namespace ss
