// Each cost term against values worked out by hand, and the cached (incremental)
// evaluation against the full one.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "animate/animate_run.h"
#include "animate/basic_costs.h"
#include "animate/clone_cost.h"
#include "animate/collision_cost.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "animate/problem.h"
#include "core/error.h"
#include "tests/animate/animate_test_graphs.h"

namespace ss {
namespace {

using Eigen::Vector2d;
constexpr double kPi = std::numbers::pi;

// Frames 0,1,2 walk +x (1 m per step), frames 3,4,5 walk +y; 2->3 costs 0.5, 1->4 0.25.
TransitionGraph SmallGraph() {
  std::vector<FrameInfo> frames(6);
  for (int i = 0; i < 6; ++i) {
    frames[i].clip = i < 3 ? 0 : 1;
    frames[i].velocity_m = i < 3 ? Vector2d(1, 0) : Vector2d(0, 1);
  }
  return TransitionGraph(std::move(frames), {{2, 3, 0.5}, {1, 4, 0.25}, {5, 0, 1.0}});
}

class CostTermsTest : public ::testing::Test {
 protected:
  double Eval(const CostTerm& term) { return term.Evaluate(TrackPointers(tracks_)); }
  TransitionGraph graph_ = SmallGraph();
  // p = (0,0) (1,0) (2,0) (2,1) (2,2)
  std::vector<Track> tracks_{MakeTrack(graph_, {0, 1, 2, 3, 4}, Anchor::kStart, Vector2d(0, 0))};
};

TEST_F(CostTermsTest, TrackIntegratesVelocitiesFromEitherEnd) {
  const Track& t = tracks_[0];
  EXPECT_TRUE(t.positions_m[4].isApprox(Vector2d(2, 2)));
  EXPECT_TRUE(t.PositionAt(9).isApprox(Vector2d(2, 2)));  // held after the end
  EXPECT_TRUE(t.VelocityAt(9).isZero());
  const Track end = MakeTrack(graph_, {0, 1, 2, 3, 4}, Anchor::kEnd, Vector2d(5, 5));
  EXPECT_TRUE(end.positions_m[0].isApprox(Vector2d(3, 3)));
  EXPECT_TRUE(end.positions_m[4].isApprox(Vector2d(5, 5)));
}

TEST_F(CostTermsTest, Smoothness) {
  EXPECT_DOUBLE_EQ(Eval(SmoothnessTerm(graph_, 0, 2.0)), 1.0);  // 2 * C(2->3)
  tracks_[0] = MakeTrack(graph_, {0, 1, 4, 5, 0}, Anchor::kStart, Vector2d(0, 0));
  EXPECT_DOUBLE_EQ(Eval(SmoothnessTerm(graph_, 0, 1.0)), 1.25);
}

TEST_F(CostTermsTest, LocationAtAStepARangeAndTheEnd) {
  EXPECT_DOUBLE_EQ(Eval(LocationTerm(0, StepWindow::At(2), LocationTarget::Fixed({2, 3}), 3.0)),
                   27.0);  // 3 * |(2,0)-(2,3)|^2
  // Steps 3..6: (2,1) then (2,2) held: 1 + 0 + 0 + 0.
  EXPECT_DOUBLE_EQ(
      Eval(LocationTerm(0, StepWindow::Range(3, 6), LocationTarget::Fixed({2, 2}), 1.0)), 1.0);
  EXPECT_DOUBLE_EQ(
      Eval(LocationTerm(0, StepWindow::LastStep(), LocationTarget::Fixed({0, 2}), 0.5)), 2.0);
  // The whole sequence against (1,0): 1 + 0 + 1 + 2 + 5.
  EXPECT_DOUBLE_EQ(Eval(LocationTerm(0, StepWindow::All(), LocationTarget::Fixed({1, 0}), 1.0)),
                   9.0);
}

TEST_F(CostTermsTest, LocationFollowingALeaderForFormations) {
  // Leader (sprite 0) walks +x from the origin; the follower (sprite 1) is asked to be
  // 1 m behind and 0.5 m to the left: q_t = p_leader(t) + (-1, 0.5).
  tracks_[0] = MakeTrack(graph_, {0, 1, 2}, Anchor::kStart, Vector2d(0, 0));
  tracks_.push_back(MakeTrack(graph_, {0, 1, 2}, Anchor::kStart, Vector2d(-1, 0)));
  const LocationTerm behind(1, StepWindow::All(), LocationTarget::Follow(0, {-1, 0.5}), 2.0);
  EXPECT_DOUBLE_EQ(Eval(behind), 3 * 2 * 0.25);
  EXPECT_TRUE(behind.TargetAt(TrackPointers(tracks_), 2).isApprox(Vector2d(1, 0.5)));
  // In ground axes the offset does not turn with the leader.
  tracks_[0] = MakeTrack(graph_, {3, 4, 5}, Anchor::kStart, Vector2d(0, 0));  // leader walks +y
  const LocationTerm turned(1, StepWindow::At(1), LocationTarget::Follow(0, {-1, 0.5}), 1.0);
  EXPECT_TRUE(turned.TargetAt(TrackPointers(tracks_), 1).isApprox(Vector2d(-0.5, 0)));
  const LocationTerm ground(1, StepWindow::At(1), LocationTarget::Follow(0, {-1, 0.5}, false), 1.0);
  EXPECT_TRUE(ground.TargetAt(TrackPointers(tracks_), 1).isApprox(Vector2d(-1, 1.5)));
  EXPECT_THROW(LocationTerm(1, StepWindow::All(), LocationTarget::Follow(1, {0, 0}), 1.0),
               InputError);
  // A follower that stops short holds its place while the formation goes on: leader at
  // (0,0) (1,0) (2,0), follower one frame at (-1, 0.5), targets (-1,0.5) (0,0.5) (1,0.5):
  // 2 * (0 + 1 + 4).
  tracks_[0] = MakeTrack(graph_, {0, 1, 2}, Anchor::kStart, Vector2d(0, 0));
  tracks_[1] = MakeTrack(graph_, {0}, Anchor::kStart, Vector2d(-1, 0.5));
  EXPECT_DOUBLE_EQ(Eval(behind), 10.0);
}

TEST_F(CostTermsTest, LocationGivesTheLeastSquaresStart) {
  // Targets at steps 0 and 4 of displacements (0,0) and (2,2): the best p_0 is the
  // weighted mean of (1,0)-(0,0) and (3,4)-(2,2) with weights 1 and 3: (1, 1.5).
  const LocationTerm a(0, StepWindow::At(0), LocationTarget::Fixed({1, 0}), 1.0);
  const LocationTerm b(0, StepWindow::At(4), LocationTarget::Fixed({3, 4}), 3.0);
  double w = 0;
  Vector2d wx = Vector2d::Zero();
  a.AddStartNormalEquations(TrackPointers(tracks_), 0, &w, &wx);
  b.AddStartNormalEquations(TrackPointers(tracks_), 0, &w, &wx);
  EXPECT_DOUBLE_EQ(w, 4.0);
  EXPECT_TRUE((wx / w).isApprox(Vector2d(1, 1.5)));
}

TEST_F(CostTermsTest, PathFollowsSegmentsAndChargesTheUnreachedPart) {
  // Path (0,0) -> (2,0) -> (2,2): steps 0,1 on segment 0 with no cost; step 2 at (2,0)
  // moves to segment 1 while still walking +x: δ π/2; step 4 passes the end.
  const Polyline path({{0, 0}, {2, 0}, {2, 2}});
  EXPECT_DOUBLE_EQ(path.length(), 4.0);
  const PathTerm term(0, path, {1.0, 2.0, 3.0});
  EXPECT_NEAR(Eval(term), kPi / 2, 1e-12);
  EXPECT_EQ(term.CountViolations(TrackPointers(tracks_)), 0);
  // Stopping at (2,1) leaves 1 m unreached: + η * 1.
  tracks_[0] = MakeTrack(graph_, {0, 1, 2, 3}, Anchor::kStart, Vector2d(0, 0));
  EXPECT_NEAR(Eval(term), kPi / 2 + 3.0, 1e-12);
  EXPECT_EQ(term.CountViolations(TrackPointers(tracks_)), 1);
  // One metre off the first segment for two steps: φ * 1^2 each.
  tracks_[0] = MakeTrack(graph_, {0, 1, 2, 3, 4}, Anchor::kStart, Vector2d(0, 1));
  EXPECT_NEAR(Eval(term), 2 * 2.0 + kPi / 2, 1e-12);
  EXPECT_DOUBLE_EQ(term.MaxDeviation(tracks_[0]), 1.0);
  // Partial evaluation (beam search) has no end cost and only the first steps.
  tracks_[0] = MakeTrack(graph_, {0, 1, 2, 3}, Anchor::kStart, Vector2d(0, 0));
  EvalRequest partial;
  partial.step_limit = 3;
  EXPECT_NEAR(term.Evaluate(TrackPointers(tracks_), partial), kPi / 2, 1e-12);
  EXPECT_THROW(Polyline({{1, 1}, {1, 1}}), InputError);
}

TEST_F(CostTermsTest, CollisionIsConicalAndHoldsFinishedSprites) {
  tracks_[0] = MakeTrack(graph_, {0, 1, 2}, Anchor::kStart, Vector2d(0, 0));  // (0,0) (1,0) (2,0)
  tracks_.push_back(
      MakeTrack(graph_, {3, 4, 5}, Anchor::kStart, Vector2d(1, -1)));  // (1,-1) (1,0) (1,1)
  const CollisionTerm term(0, 1, 1.5, 2.0);
  EXPECT_NEAR(Eval(term), 2.0 * (1.5 - std::sqrt(2.0)) * 2 + 2.0 * 1.5, 1e-12);
  EXPECT_EQ(term.CountViolations(TrackPointers(tracks_)), 3);
  EXPECT_DOUBLE_EQ(term.MinDistance(TrackPointers(tracks_)), 0.0);
  // Sprite 0 stops at (1,0) after two steps and is still there at step 2, 1 m from (1,1).
  tracks_[0] = MakeTrack(graph_, {0, 1}, Anchor::kStart, Vector2d(0, 0));
  EXPECT_NEAR(Eval(term), 2.0 * (1.5 - std::sqrt(2.0)) + 2.0 * 1.5 + 2.0 * 0.5, 1e-12);
  EXPECT_NEAR(Eval(CollisionTerm(0, 1, 1.5, 2.0, false)), 2.0 * (1.5 - std::sqrt(2.0)) + 3.0,
              1e-12);
  EXPECT_DOUBLE_EQ(Eval(CollisionTerm(0, 1, 0.5, 2.0, false)), 1.0);
  EXPECT_THROW(CollisionTerm(0, 0, 1.0, 1.0), InputError);
}

TEST_F(CostTermsTest, FramePoseOverAWindowOrAfterAPath) {
  auto g = std::make_shared<std::vector<bool>>(std::vector<bool>{0, 0, 0, 1, 1, 0});
  // Steps 1..4 show frames 1, 2, 3, 4: two off G.
  const FrameTerm window(0, g, StepWindow::Range(1, 4), 5.0);
  EXPECT_DOUBLE_EQ(Eval(window), 10.0);
  EXPECT_EQ(window.CountViolations(TrackPointers(tracks_)), 2);
  // Steps 5 and 6 come after the end: the pose is not shown there.
  EXPECT_DOUBLE_EQ(Eval(FrameTerm(0, g, StepWindow::Range(3, 6), 5.0)), 10.0);
  // After passing (2,0) (at step 2) for 2 steps: steps 2 (frame 2, off) and 3 (on).
  const FrameTerm after(0, g, StepWindow::All(), 5.0,
                        PathTrigger{0, Polyline({{0, 0}, {2, 0}}), 2});
  EXPECT_DOUBLE_EQ(Eval(after), 5.0);
  EXPECT_EQ(after.Window(TrackPointers(tracks_)), std::make_pair(2, 4));
  // A path never passed opens the window at the end: every step is a violation.
  const FrameTerm never(0, g, StepWindow::All(), 5.0,
                        PathTrigger{0, Polyline({{0, 0}, {9, 0}}), 3});
  EXPECT_DOUBLE_EQ(Eval(never), 15.0);
}

TEST_F(CostTermsTest, LengthAndFastFrames) {
  EXPECT_DOUBLE_EQ(Eval(LengthTerm(0, 10, 0.5)), 2.5);
  EXPECT_DOUBLE_EQ(Eval(LengthTerm(0, 3, 0.5)), 0.0);
  EXPECT_DOUBLE_EQ(Eval(FastFrameTerm(0, 2.0, 1.5)), 5 * 1.5);
  EXPECT_DOUBLE_EQ(Eval(FastFrameTerm(0, 0.5, 1.5)), 0.0);
  EXPECT_THROW(LengthTerm(0, 0, 1.0), InputError);
  EXPECT_THROW(LengthTerm(0, 3, -1.0), InputError);
}

// Floor frames moving 1 m a step: 0 faces its motion, 1 moves sideways (heading +y, moving +x), 2
// moves backwards, 3 moves sideways 0.1 m; 4 is upright (no heading).
TEST(FacingCosts, AreTheMetresMovedOtherThanForward) {
  std::vector<FrameInfo> frames(5);
  const double heading[] = {0, kPi / 2, kPi, -kPi / 2};
  for (int i = 0; i < 5; ++i) frames[i].velocity_m = Vector2d(i == 3 ? 0.1 : 1.0, 0);
  for (int i = 0; i < 4; ++i) frames[i].heading_rad = heading[i];
  const TransitionGraph graph(std::move(frames), {});
  const std::vector<double> cost = FacingCosts(graph, 2.0);
  ASSERT_EQ(cost.size(), 5u);
  EXPECT_NEAR(cost[0], 0.0, 1e-12);
  EXPECT_NEAR(cost[1], 2.0 * 0.5, 1e-12);
  EXPECT_NEAR(cost[2], 2.0 * 1.0, 1e-12);
  EXPECT_NEAR(cost[3], 2.0 * 0.1 * 0.5, 1e-12);  // slow sideways costs its metres too
  EXPECT_DOUBLE_EQ(cost[4], 0.0);
  // The term sums φ over the steps shown.
  std::vector<Track> tracks{MakeTrack(graph, {0, 1, 2, 3}, Anchor::kStart, Vector2d(0, 0))};
  const FacingTerm facing(0, std::make_shared<std::vector<double>>(cost));
  const CostTerm& term = facing;
  EXPECT_NEAR(term.Evaluate(TrackPointers(tracks)), 2.0 * 1.55, 1e-12);
}

// Frames 0 1 2 1 3 0: frame 1 comes back after 2 steps, frame 0 after 5.
TEST_F(CostTermsTest, RepeatsWithinTheWindowUnlessStill) {
  tracks_ = {MakeTrack(graph_, {0, 1, 2, 1, 3, 0}, Anchor::kStart, Vector2d(0, 0))};
  const RepeatTerm three(0, 3, 2.0);
  EXPECT_DOUBLE_EQ(Eval(three), 2.0);
  EXPECT_EQ(three.CountViolations(TrackPointers(tracks_)), 1);
  EXPECT_DOUBLE_EQ(Eval(RepeatTerm(0, 5, 2.0)), 4.0);
  auto still = std::make_shared<std::vector<bool>>(
      std::vector<bool>{false, true, false, false, false, false});
  EXPECT_DOUBLE_EQ(Eval(RepeatTerm(0, 5, 2.0, still)), 2.0);  // frame 1 may hold still
  EXPECT_THROW(RepeatTerm(0, 0, 1.0), InputError);
}

// a: 0 1 2 3 4; b: 4 0 1 2 5. With a lag of 2: b's 0, 1, 2 come a step after a's (charged at
// b's steps 1, 2, 3), a's 4 comes 4 steps after b's (past the lag).
TEST_F(CostTermsTest, ClonesAreChargedOncePerCoincidenceAtItsLaterStep) {
  tracks_ = {MakeTrack(graph_, {0, 1, 2, 3, 4}, Anchor::kStart, Vector2d(0, 0)),
             MakeTrack(graph_, {4, 0, 1, 2, 5}, Anchor::kStart, Vector2d(0, 0))};
  const CloneTerm lag2(0, 1, 2, 2.0);
  EXPECT_DOUBLE_EQ(Eval(lag2), 3 * 2.0);
  EXPECT_EQ(lag2.CountViolations(TrackPointers(tracks_)), 3);
  EXPECT_DOUBLE_EQ(Eval(CloneTerm(1, 0, 2, 2.0)), 3 * 2.0);  // the same either way round
  EXPECT_DOUBLE_EQ(Eval(CloneTerm(0, 1, 0, 2.0)), 0.0);      // never at the same step
  EXPECT_DOUBLE_EQ(Eval(CloneTerm(0, 1, 4, 2.0)), 4 * 2.0);  // a's 4 too, at its step 4
  EXPECT_THROW(CloneTerm(0, 0, 1, 1.0), InputError);
  EXPECT_THROW(CloneTerm(0, 1, -1, 1.0), InputError);
}

TEST_F(CostTermsTest, ProblemSumsAndBreaksDownByKind) {
  Problem problem(graph_);
  SpriteSpec spec;
  problem.AddSprite(spec);
  problem.AddTerm(std::make_unique<LengthTerm>(0, 10, 0.5));
  problem.AddTerm(
      std::make_unique<LocationTerm>(0, StepWindow::At(2), LocationTarget::Fixed({2, 3}), 3.0));
  const CostBreakdown cost = problem.Evaluate(tracks_);
  EXPECT_DOUBLE_EQ(cost.total, 0.5 + 2.5 + 27.0);
  EXPECT_DOUBLE_EQ(cost.by_kind.at("smoothness"), 0.5);
  EXPECT_DOUBLE_EQ(cost.by_kind.at("length"), 2.5);
  EXPECT_EQ(cost.violations.at("length"), 1);
  EXPECT_THROW(problem.AddTerm(std::make_unique<LengthTerm>(3, 10, 0.5)), InputError);
}

// Evaluation from a cache with the unchanged steps before `first_changed` must equal the
// full evaluation, for every term, on random sequences of a random graph.
// The figures the scenes report (bench animate, `animate --json`), worked out by hand.
TEST_F(CostTermsTest, ConstraintFigures) {
  // Sprite 0: (0,0) (1,0) (2,0) (2,1) (2,2); sprite 1: (2,-1) (2,0) (2,1), then held.
  tracks_.push_back(MakeTrack(graph_, {3, 4, 5}, Anchor::kStart, Vector2d(2, -1)));
  Problem problem(graph_);
  for (int s = 0; s < 2; ++s) problem.AddSprite(SpriteSpec{});
  // 0.5 m beside sprite 0 until it turns, then on it; its end (2,3) is never reached.
  problem.AddTerm(
      std::make_unique<PathTerm>(0, Polyline({{0, 0.5}, {2, 0.5}, {2, 3}}), PathStrengths{}));
  // Sprite 1 passes (2, 0.5) at step 2, on the line.
  problem.AddTerm(std::make_unique<PathTerm>(1, Polyline({{2, -1}, {2, 0.5}}), PathStrengths{}));
  // Distances sqrt(5), 1, 1, 0, 1: one step closer than 0.5 m.
  problem.AddTerm(std::make_unique<CollisionTerm>(0, 1, 0.5, 1.0));
  // Steps 2..4 show frames 2, 3, 4: one off the set {3, 4}.
  auto g = std::make_shared<std::vector<bool>>(
      std::vector<bool>{false, false, false, true, true, false});
  problem.AddTerm(std::make_unique<FrameTerm>(0, g, StepWindow::Range(2, 4), 1.0));
  problem.AddTerm(std::make_unique<LengthTerm>(0, 5, 1.0));
  problem.AddTerm(std::make_unique<LengthTerm>(1, 4, 1.0));  // 3 frames: short
  const ConstraintFigures f = MeasureConstraints(problem, tracks_);
  EXPECT_DOUBLE_EQ(f.max_path_deviation_m, 0.5);
  EXPECT_EQ(f.paths_unfinished, 1);
  EXPECT_EQ(f.collision_steps, 1);
  EXPECT_EQ(f.colliding_pairs, 1);
  EXPECT_DOUBLE_EQ(f.min_distance_m, 0.0);
  EXPECT_EQ(f.frame_steps, 3);
  EXPECT_EQ(f.frame_steps_off, 1);
  EXPECT_EQ(f.sprites_short, 1);
}

TEST(CostTermCache, IncrementalEqualsFullEvaluation) {
  const TransitionGraph graph = testing::RandomGraph(60, 400, 5);
  auto g = std::make_shared<std::vector<bool>>(graph.FramesWithTag("special"));
  std::vector<std::unique_ptr<CostTerm>> terms;
  terms.push_back(std::make_unique<SmoothnessTerm>(graph, 0, 1.5));
  terms.push_back(std::make_unique<LocationTerm>(0, StepWindow::Range(3, 30),
                                                 LocationTarget::Fixed({0.2, 0.1}), 2.0));
  terms.push_back(std::make_unique<LocationTerm>(0, StepWindow{5, true, 0, true},
                                                 LocationTarget::Fixed({0.5, 0}), 1.0));
  terms.push_back(std::make_unique<LocationTerm>(0, StepWindow::All(),
                                                 LocationTarget::Follow(1, {-0.2, 0.1}), 1.0));
  terms.push_back(std::make_unique<LocationTerm>(1, StepWindow::All(),
                                                 LocationTarget::Follow(0, {-0.2, 0.1}), 1.0));
  terms.push_back(std::make_unique<PathTerm>(0, Polyline({{0, 0}, {0.3, 0}, {0.3, 0.3}}),
                                             PathStrengths{1, 2, 3}));
  terms.push_back(std::make_unique<CollisionTerm>(0, 1, 0.3, 2.0));
  terms.push_back(std::make_unique<FrameTerm>(0, g, StepWindow::Range(4, 12), 1.0));
  terms.push_back(std::make_unique<FrameTerm>(1, g, StepWindow::All(), 1.0,
                                              PathTrigger{0, Polyline({{0, 0}, {0.1, 0}}), 5}));
  terms.push_back(std::make_unique<LengthTerm>(0, 25, 1.0));
  terms.push_back(std::make_unique<FastFrameTerm>(0, 0.08, 1.0));
  terms.push_back(std::make_unique<CloneTerm>(0, 1, 2, 1.5));
  terms.push_back(std::make_unique<CloneTerm>(1, 0, 0, 1.0));

  std::mt19937_64 rng(3);
  auto random_walk = [&](int length) {
    std::vector<int> frames{static_cast<int>(rng() % graph.num_frames())};
    while (static_cast<int>(frames.size()) < length) {
      const auto next = graph.successors(frames.back());
      if (next.empty()) break;
      frames.push_back(next[rng() % next.size()]);
    }
    return frames;
  };
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Track> before{
        MakeTrack(graph, random_walk(20 + trial % 17), Anchor::kStart, {0, 0}),
        MakeTrack(graph, random_walk(15 + trial % 13), Anchor::kStart, {0.1, 0})};
    // Sprite (trial % 2) keeps a prefix and gets a new random tail.
    const int s = trial % 2;
    const int k = static_cast<int>(rng() % before[s].size());
    std::vector<int> frames(before[s].frames.begin(), before[s].frames.begin() + k + 1);
    for (int f : random_walk(1 + rng() % 30)) {
      if (graph.HasEdge(frames.back(), f)) frames.push_back(f);
    }
    std::vector<Track> after = before;
    after[s] = MakeTrack(graph, frames, Anchor::kStart, before[s].positions_m[0]);
    const auto before_view = TrackPointers(before);
    const auto after_view = TrackPointers(after);
    for (const auto& term : terms) {
      TermCache cache;
      term->BuildCache(before_view, &cache);
      EvalRequest request;
      request.first_changed = k + 1;
      request.cache = &cache;
      EXPECT_NEAR(term->Evaluate(after_view, request), term->Evaluate(after_view),
                  1e-9 * (1 + term->Evaluate(after_view)))
          << term->kind() << " trial " << trial;
      // The beam search's use: a partial sequence extended by steps after the cache.
      EvalRequest partial = request;
      partial.step_limit = after[s].size();
      EvalRequest partial_full;
      partial_full.step_limit = after[s].size();
      EXPECT_NEAR(term->Evaluate(after_view, partial), term->Evaluate(after_view, partial_full),
                  1e-9 * (1 + term->Evaluate(after_view)))
          << term->kind() << " (partial) trial " << trial;
    }
  }
}

// The replacement's use: a piece replaced in the middle, the tail after it moved in time.
// Terms reading the frames alone sum the moved tail from the cache, shifted; for the repeat
// term only the steps whose whole window lies in the moved tail.
TEST(CostTermCache, AMovedTailEqualsFullEvaluation) {
  const TransitionGraph graph = testing::RandomGraph(8, 40, 5);
  std::vector<std::unique_ptr<CostTerm>> terms;
  terms.push_back(std::make_unique<RepeatTerm>(0, 4, 1.5));
  terms.push_back(std::make_unique<RepeatTerm>(0, 15, 1.0));
  terms.push_back(std::make_unique<FastFrameTerm>(0, 0.08, 1.0));
  std::mt19937_64 rng(5);
  auto random_frames = [&](int n) {
    std::vector<int> frames(static_cast<size_t>(n));
    for (int& f : frames) f = static_cast<int>(rng() % graph.num_frames());
    return frames;
  };
  for (int trial = 0; trial < 300; ++trial) {
    const std::vector<int> old_frames = random_frames(30 + trial % 20);
    const int n = static_cast<int>(old_frames.size());
    const int k = 1 + static_cast<int>(rng() % (n / 2));      // first changed step
    const int l = k + static_cast<int>(rng() % (n - k - 1));  // old tail from here
    const std::vector<int> piece = random_frames(static_cast<int>(rng() % 12));
    std::vector<int> frames(old_frames.begin(), old_frames.begin() + k);
    frames.insert(frames.end(), piece.begin(), piece.end());
    frames.insert(frames.end(), old_frames.begin() + l, old_frames.end());
    const std::vector<Track> before{MakeTrack(graph, old_frames, Anchor::kStart, {0, 0})};
    const std::vector<Track> after{MakeTrack(graph, frames, Anchor::kStart, {0, 0})};
    for (const auto& term : terms) {
      TermCache cache;
      term->BuildCache(TrackPointers(before), &cache);
      EvalRequest request;
      request.first_changed = k;
      request.cache = &cache;
      request.shifted_from = k + static_cast<int>(piece.size());
      request.shift = request.shifted_from - l;
      const double full = term->Evaluate(TrackPointers(after));
      EXPECT_NEAR(term->Evaluate(TrackPointers(after), request), full, 1e-9 * (1 + full))
          << term->kind() << " trial " << trial;
    }
  }
}

}  // namespace
}  // namespace ss
