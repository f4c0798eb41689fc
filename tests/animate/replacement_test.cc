#include "animate/replacement.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <span>
#include <thread>

#include "animate/basic_costs.h"
#include "animate/collision_cost.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "core/error.h"
#include "tests/animate/animate_test_graphs.h"

namespace ss {
namespace {

using Eigen::Vector2d;
using testing::WalkingGraph;

ReplacementOptions FastOptions(double seconds) {
  ReplacementOptions options;
  options.reach.set_size = 60;
  options.time_budget_seconds = seconds;
  options.max_tries = 400;
  options.changes_per_turn = 50;
  return options;
}

// The same, stopped after `turns` sprite turns and not by a clock: a test that asserts what the
// optimizer found gets the same answer on a loaded machine (under ASan and a busy CI runner, 2 s
// gave 64 turns where a quiet one gives 224, and the path was not finished).
ReplacementOptions TurnOptions(int turns) {
  ReplacementOptions options = FastOptions(3600.0);
  options.max_turns = turns;
  return options;
}

TEST(Replacement, EveryKeptMoveIsValidAndTheCostNeverIncreases) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec walker;
  walker.initial_frames = 50;
  walker.max_frames = 90;
  problem.AddSprite(walker);
  SpriteSpec free_sprite = walker;
  free_sprite.anchor = Anchor::kFree;
  free_sprite.anchor_m = Vector2d(1, 1);
  problem.AddSprite(free_sprite);
  SpriteSpec end_sprite = walker;
  end_sprite.anchor = Anchor::kEnd;
  end_sprite.anchor_m = Vector2d(0.5, 0.5);
  problem.AddSprite(end_sprite);
  const Polyline path({{0, 0}, {1.5, 0}, {1.5, 1.0}});
  problem.AddTerm(std::make_unique<PathTerm>(0, path, PathStrengths{0.5, 4.0, 3.0}));
  auto standing = std::make_shared<std::vector<bool>>(graph.FramesWithTag("standing"));
  problem.AddTerm(
      std::make_unique<FrameTerm>(0, standing, StepWindow::All(), 1.0, PathTrigger{0, path, 8}));
  problem.AddTerm(
      std::make_unique<FrameTerm>(1, standing, StepWindow::All(), 1.0, PathTrigger{0, path, 8}));
  problem.AddTerm(std::make_unique<LocationTerm>(1, StepWindow::All(),
                                                 LocationTarget::Follow(0, {-0.3, 0.2}), 2.0));
  problem.AddTerm(
      std::make_unique<LocationTerm>(2, StepWindow::At(0), LocationTarget::Fixed({-0.5, 0}), 1.0));
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      problem.AddTerm(std::make_unique<CollisionTerm>(a, b, 0.2, 5.0));
    }
  }
  problem.AddTerm(std::make_unique<LengthTerm>(2, 60, 0.5));

  ReplacementOptions options = FastOptions(2.0);
  options.start = StartMethod::kRandom;  // every move a trace point (none in a sequential start)
  int checked = 0;
  int last_restart = 0;
  double last_cost = std::numeric_limits<double>::infinity();
  bool all_valid = true;
  options.on_improvement = [&](const std::vector<Track>& tracks, const TracePoint& point) {
    std::string why;
    if (!problem.IsValid(tracks, &why)) {
      all_valid = false;
      ADD_FAILURE() << why;
    }
    const double full = problem.TotalCost(tracks);
    EXPECT_NEAR(point.cost, full, 1e-7 * (1 + full));  // the incremental total is exact
    if (point.restart == last_restart) {  // a restart begins again from random sequences
      EXPECT_LE(full, last_cost + 1e-9 * (1 + last_cost));
    }
    last_restart = point.restart;
    for (int s = 0; s < 3; ++s) {  // the states follow the frames and the anchors
      const Track rebuilt =
          MakeTrack(graph, tracks[s].frames, s == 2 ? Anchor::kEnd : Anchor::kStart,
                    s == 2 ? Vector2d(0.5, 0.5) : tracks[s].positions_m[0]);
      for (int t = 0; t < tracks[s].size(); ++t) {
        if (!tracks[s].positions_m[t].isApprox(rebuilt.positions_m[t], 1e-9)) all_valid = false;
      }
    }
    EXPECT_TRUE(tracks[0].positions_m[0].isZero());
    last_cost = full;
    ++checked;
  };
  Summary summary;
  const std::vector<Track> tracks = OptimizeSequences(problem, options, &summary);
  EXPECT_TRUE(all_valid);
  EXPECT_GT(checked, 10);
  EXPECT_EQ(checked, summary.moves_kept);
  EXPECT_TRUE(problem.IsValid(tracks));
  EXPECT_LT(summary.final_cost.total, summary.initial_cost.total);
  for (size_t i = 1; i < summary.trace.size(); ++i) {
    EXPECT_LE(summary.trace[i].best_cost, summary.trace[i - 1].best_cost + 1e-9);
    if (summary.trace[i].restart == summary.trace[i - 1].restart) {
      EXPECT_LE(summary.trace[i].cost, summary.trace[i - 1].cost + 1e-9);
    }
  }
  EXPECT_NEAR(summary.trace.back().best_cost, summary.final_cost.total,
              1e-7 * (1 + summary.final_cost.total));
  EXPECT_NE(summary.FullReport().find("collision"), std::string::npos);
}

// Anticipation, where beam search has no look-ahead (seed 000 §4.1, §6.1, Figure 7b):
// loiter near the centre, then be in the far corner at step 79. Beam search ranks partial
// sequences by the steps so far, so the sequences that leave early enough fall out of the
// beam; replacement optimizes the whole sequence and leaves in time.
TEST(Replacement, AnticipatesALaterLocationBetterThanBeamSearchAtTheSameBudget) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 80;
  spec.max_frames = 80;
  problem.AddSprite(spec);
  const Vector2d corner(1.5, 1.0);
  problem.AddTerm(std::make_unique<LocationTerm>(0, StepWindow::Range(0, 78),
                                                 LocationTarget::Fixed({0, 0}), 0.05));
  problem.AddTerm(
      std::make_unique<LocationTerm>(0, StepWindow::At(79), LocationTarget::Fixed(corner), 100.0));
  problem.AddTerm(std::make_unique<LengthTerm>(0, 80, 10.0));
  constexpr double kBudget = 1.5;

  Summary replacement_summary;
  const auto replaced = OptimizeSequences(problem, FastOptions(kBudget), &replacement_summary);
  BeamOptions beam;
  beam.width = 8;
  beam.time_budget_seconds = kBudget;
  Summary beam_summary;
  const auto beamed = BeamSearch(problem, beam, &beam_summary);

  ASSERT_TRUE(problem.IsValid(replaced));
  ASSERT_TRUE(problem.IsValid(beamed));
  const double replaced_miss = (replaced[0].PositionAt(79) - corner).norm();
  const double beamed_miss = (beamed[0].PositionAt(79) - corner).norm();
  std::cout << "replacement: " << replacement_summary.BriefReport() << ", miss " << replaced_miss
            << " m\nbeam:        " << beam_summary.BriefReport() << ", miss " << beamed_miss
            << " m\n";
  EXPECT_EQ(replaced[0].size(), 80);
  EXPECT_LT(replaced_miss, 0.35);  // ~0.02 m when it has time for a few restarts
  EXPECT_GT(beamed_miss, replaced_miss);
  EXPECT_LT(replacement_summary.final_cost.total, 0.5 * beam_summary.final_cost.total);
}

// The stall of the formation scene (seed 000 §6.1, Figure 7e): a follower in formation that
// must copy its leader's stand-up. Three things kept the pair idle: the follower's location
// term counted only its own steps, so the cheapest follower was one frame long (held, it
// paid nothing while the leader walked away); a sequence ending before its frame window
// never got the Ĉ that includes the frame constraint; and from random sequences the two pin
// each other (the leader stands at the origin because walking off leaves the follower out
// of formation, and the follower cannot move alone) — with start: random and no restarts
// this test ends with the leader idle and its path and stand-up missed. Now the formation
// lasts while either sprite is on, half the end moves count the window past the end, and
// the sequential start plans the leader before its follower.
TEST(Replacement, AFollowerCopiesItsLeadersStandUp) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec leader;
  leader.initial_frames = 30;
  leader.max_frames = 120;
  problem.AddSprite(leader);
  SpriteSpec follower = leader;
  follower.anchor_m = Vector2d(-0.3, 0.0);  // 0.2 m off its place: copying the leader is not free
  problem.AddSprite(follower);
  const Polyline path({{0, 0}, {1.0, 0}});
  problem.AddTerm(std::make_unique<PathTerm>(0, path, PathStrengths{0.5, 20.0, 20.0}));
  auto standing = std::make_shared<std::vector<bool>>(graph.FramesWithTag("standing"));
  auto frame_term = [&](int s) {
    return std::make_unique<FrameTerm>(s, standing, StepWindow::All(), 2.0,
                                       PathTrigger{0, path, 15});
  };
  problem.AddTerm(frame_term(0));
  auto follower_frames = frame_term(1);
  const FrameTerm* follower_term = follower_frames.get();
  problem.AddTerm(std::move(follower_frames));
  problem.AddTerm(std::make_unique<LocationTerm>(1, StepWindow::All(),
                                                 LocationTarget::Follow(0, {-0.3, 0.2}), 5.0));

  // A follower one frame long, its leader walking 1.6 m on along +x: held, it is out of
  // formation by ~1 m at step 20 and more later.
  std::vector<int> straight;
  straight.reserve(32);
  for (int m = 0; m < 32; ++m)
    straight.push_back(WalkingGraph::Straight(0, m % WalkingGraph::kStraight));
  const std::vector<Track> short_follower{
      problem.MakeSpriteTrack(0, straight),
      problem.MakeSpriteTrack(1, {WalkingGraph::Straight(0, 0)})};
  const auto location = [&](const std::vector<Track>& tracks) {
    return problem.Evaluate(tracks).by_kind.at("location");
  };
  EXPECT_GT(location(short_follower), 5.0 * 12 * 1.0) << "held steps count for the formation";

  // One hill climb, as in the paper (no restarts): it used to end in the one-frame follower.
  // The budget is a ceiling: the run stops at convergence (< 1 s), and a loaded machine
  // does not cut the sequential phase short.
  ReplacementOptions options = FastOptions(20.0);
  options.restart_when_converged = false;
  options.reach.set_size = 200;  // the way into the standing clip can be 16 walking frames
  Summary summary;
  const std::vector<Track> tracks = OptimizeSequences(problem, options, &summary);
  ASSERT_TRUE(problem.IsValid(tracks));
  std::cout << summary.FullReport();
  const auto view = TrackPointers(tracks);
  const auto [begin, end] = follower_term->Window(view);
  EXPECT_EQ(end - begin, 15);
  EXPECT_GE(tracks[1].size(), end) << "the follower stops before the stand-up";
  EXPECT_LE(follower_term->CountViolations(view), 2) << "the follower does not stand up";
  // The leader walks its path and stands too. From random sequences alone (start: random)
  // the pair pins itself idle: the leader stands at the origin because walking off would
  // leave the follower out of formation, and the follower cannot move without it.
  const CostBreakdown cost = problem.Evaluate(tracks);
  EXPECT_EQ(cost.violations.at("path"), 0) << "the leader never reaches the end of its path";
  EXPECT_LE(cost.violations.at("frame"), 3) << "the leader does not stand up";
  EXPECT_LT(location(tracks),
            5.0);  // it starts 0.2 m off its place: ~5 × 0.04 per step until there
}

// Issue 33: the F/B sets reach a few steps; a stand further away was never found, and the
// scene ended where the path does, every step of its stand missing. The goal move follows the
// sets' steps toward the standing frames (ReplacementSets::toward) from any frame.
TEST(Replacement, AStandBeyondTheSetsReachIsFoundByTheGoalMove) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec walker;
  walker.initial_frames = 30;
  walker.max_frames = 120;
  problem.AddSprite(walker);
  const Polyline path({{0, 0}, {1.0, 0}});
  problem.AddTerm(std::make_unique<PathTerm>(0, path, PathStrengths{0.5, 20.0, 20.0}));
  auto standing = std::make_shared<std::vector<bool>>(graph.FramesWithTag("standing"));
  auto stand =
      std::make_unique<FrameTerm>(0, standing, StepWindow::All(), 2.0, PathTrigger{0, path, 15});
  const FrameTerm* stand_term = stand.get();
  problem.AddTerm(std::move(stand));

  ReplacementOptions options = FastOptions(20.0);
  options.restart_when_converged = false;
  options.reach.set_size = 4;  // F(s) holds s and three more
  const ReplacementSets sets = ReplacementSets::Build(problem, options);
  // Every step toward the stand is an edge, and leads there.
  const std::span<const int32_t> toward = sets.toward(1);
  ASSERT_EQ(static_cast<int>(toward.size()), graph.num_frames());
  for (int f = 0; f < graph.num_frames(); ++f) {
    int u = f, steps = 0;
    while (!(*standing)[u] && toward[u] >= 0 && steps < 100) {
      ASSERT_TRUE(graph.HasEdge(u, toward[u])) << u << " -> " << toward[u];
      u = toward[u];
      ++steps;
    }
    EXPECT_TRUE((*standing)[u]) << "from frame " << f;
  }
  EXPECT_EQ(toward[WalkingGraph::Stand(0)], WalkingGraph::Stand(1));  // in G: its own clip
  EXPECT_EQ(toward[WalkingGraph::Stand(WalkingGraph::kStand - 1)], WalkingGraph::Stand(0));

  // The path walked and passed at the last step (a straight walk of 1 m, 0.05 m a step), every
  // step of the stand after it missing. From there a pick's F set holds the next three walking
  // frames; the stand is six steps on (Straight(0, 8) leads into it).
  std::vector<int> walk;
  for (int m = 0; m <= 20; ++m)
    walk.push_back(WalkingGraph::Straight(0, m % WalkingGraph::kStraight));
  const std::vector<Track> initial{problem.MakeSpriteTrack(0, walk)};
  ASSERT_EQ(stand_term->Window(TrackPointers(initial)).first, 20);
  const auto stood = [&](double goal_fraction) {
    ReplacementOptions o = options;
    o.goal_fraction = goal_fraction;
    Summary summary;
    const std::vector<Track> tracks = ImproveSequences(problem, o, sets, initial, &summary);
    EXPECT_TRUE(problem.IsValid(tracks));
    EXPECT_EQ(problem.Evaluate(tracks).violations.at("path"), 0) << summary.FullReport();
    EXPECT_EQ(summary.goal_picks > 0, goal_fraction > 0);
    return 15 - stand_term->CountViolations(TrackPointers(tracks));
  };
  EXPECT_EQ(stood(0.0), 0) << "the stand was within the sets' reach";
  EXPECT_GE(stood(0.25), 10);  // the way in, Straight(0, 4..8), takes 5 of the 15 steps
}

TEST(Replacement, FollowsAPathToItsEnd) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 30;
  spec.max_frames = 120;
  problem.AddSprite(spec);
  const Polyline path({{0, 0}, {1.2, 0}, {1.2, 1.2}});
  auto term = std::make_unique<PathTerm>(0, path, PathStrengths{0.2, 20.0, 5.0});
  const PathTerm* path_term = term.get();
  problem.AddTerm(std::move(term));
  Summary summary;
  const auto tracks = OptimizeSequences(problem, TurnOptions(200), &summary);
  std::cout << summary.FullReport();
  ASSERT_TRUE(problem.IsValid(tracks));
  const auto view = TrackPointers(tracks);
  EXPECT_EQ(path_term->CountViolations(view), 0) << "path not passed to its end";
  EXPECT_LT(path_term->MaxDeviation(tracks[0]), 0.2);
}

// The F/B sets' memory is known before they are made (a job checks it against the station's
// budget): exactly what Build then takes, one pair of sets per distinct frame constraint.
TEST(Replacement, TheSetsMemoryIsKnownBeforeTheyAreMade) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 30;
  spec.max_frames = 120;
  problem.AddSprite(spec);
  problem.AddSprite(spec);
  ReplacementOptions options = FastOptions(1.0);
  const auto plain = ReplacementSets::Build(problem, options);
  EXPECT_EQ(ReplacementSets::EstimateBytes(problem, options),
            static_cast<int64_t>(plain.MemoryBytes()));
  auto standing = std::make_shared<std::vector<bool>>(graph.FramesWithTag("standing"));
  for (int s = 0; s < 2; ++s) {  // the same set and strength: one variant for both
    problem.AddTerm(std::make_unique<FrameTerm>(s, standing, StepWindow::All(), 2.0));
  }
  const auto sets = ReplacementSets::Build(problem, options);
  ASSERT_EQ(sets.num_variants(), 2);
  EXPECT_EQ(ReplacementSets::EstimateBytes(problem, options),
            static_cast<int64_t>(sets.MemoryBytes()));
}

// A cancel from another thread ends a run with an hour's budget at its next pick, with the
// best valid sequences so far and the termination saying why.
TEST(Replacement, ACancelFromAnotherThreadStopsTheRunAtOnce) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 30;
  spec.max_frames = 120;
  problem.AddSprite(spec);
  problem.AddSprite(spec);
  const Polyline path({{0, 0}, {1.2, 0}, {1.2, 1.2}});
  problem.AddTerm(std::make_unique<PathTerm>(0, path, PathStrengths{0.2, 20.0, 5.0}));
  problem.AddTerm(std::make_unique<CollisionTerm>(0, 1, 0.2, 5.0));
  ReplacementOptions options = FastOptions(3600.0);
  std::atomic<bool> cancel{false};
  options.cancel = &cancel;
  double cancelled_at = 0;
  std::thread canceller([&] {  // in the one-by-one start or the climb, as the machine goes
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cancelled_at = MonotonicSeconds();
    cancel = true;
  });
  Summary summary;
  const auto tracks = OptimizeSequences(problem, options, &summary);
  const double stopped_after = MonotonicSeconds() - cancelled_at;
  canceller.join();
  EXPECT_EQ(summary.termination, TerminationType::kCancelled) << summary.message;
  EXPECT_LT(stopped_after, 1.0);
  ASSERT_TRUE(problem.IsValid(tracks));
  EXPECT_LE(summary.final_cost.total, summary.initial_cost.total);
}

// Picks aimed at a collision (collision_pick_fraction): two walkers on lanes 8 cm apart pass
// each other (d_min 10 cm); while they collide, picks are aimed (and counted). A problem
// without collision terms draws no aimed pick and the same random numbers: its result is the
// same with and without them.
TEST(Replacement, PicksAimedAtACollisionAreDrawnOnlyWhereOneIs) {
  const TransitionGraph graph = WalkingGraph::Make();
  auto passing = [&](bool collide) {
    auto problem = std::make_unique<Problem>(graph);
    // Without collisions, east starts with a bend off its lane (the end of the turning ring),
    // which moves improve.
    std::vector<int> east, west;
    if (!collide) east = {44, 45, 46, 47, 0};
    for (int m = 0; m < 120; ++m) {
      if (static_cast<int>(east.size()) < 120)
        east.push_back(WalkingGraph::Straight(0, m % WalkingGraph::kStraight));
      west.push_back(WalkingGraph::Straight(4, m % WalkingGraph::kStraight));
    }
    const double length = WalkingGraph::kSpeed * 119;
    SpriteSpec a;
    a.initial_sequence = east;
    a.max_frames = 120;
    problem->AddSprite(a);
    SpriteSpec b = a;
    b.initial_sequence = west;
    b.anchor_m = Vector2d(length, 0.08);
    problem->AddSprite(b);
    problem->AddTerm(std::make_unique<PathTerm>(0, Polyline({{0, 0}, {length, 0}}),
                                                PathStrengths{0.2, 20.0, 1.0}));
    problem->AddTerm(std::make_unique<PathTerm>(1, Polyline({{length, 0.08}, {0, 0.08}}),
                                                PathStrengths{0.2, 20.0, 1.0}));
    if (collide) problem->AddTerm(std::make_unique<CollisionTerm>(0, 1, 0.10, 50.0));
    return problem;
  };
  auto optimize = [&](const Problem& problem, double fraction, Summary* summary) {
    ReplacementOptions options = FastOptions(30.0);
    options.start = StartMethod::kGiven;
    options.restart_when_converged = false;
    options.changes_per_turn = 20;
    options.max_turns = 6;
    options.collision_pick_fraction = fraction;
    return OptimizeSequences(problem, options, summary);
  };

  const auto colliding = passing(true);
  const std::vector<Track> given{
      colliding->MakeSpriteTrack(0, colliding->sprite(0).initial_sequence),
      colliding->MakeSpriteTrack(1, colliding->sprite(1).initial_sequence)};
  const int before = colliding->Evaluate(given).violations.at("collision");
  EXPECT_EQ(before, 2);  // steps 59 and 60: 5 cm apart along x, 8 cm across
  Summary aimed;
  const auto result = optimize(*colliding, 1.0, &aimed);
  EXPECT_TRUE(colliding->IsValid(result));
  EXPECT_LE(colliding->Evaluate(result).violations.at("collision"), before) << aimed.FullReport();
  EXPECT_LE(aimed.final_cost.total, aimed.initial_cost.total);
  EXPECT_GT(aimed.collision_picks, 0);

  const auto apart = passing(false);
  Summary with, without;
  const auto a = optimize(*apart, 1.0, &with);
  const auto b = optimize(*apart, 0.0, &without);
  EXPECT_EQ(with.collision_picks, 0);
  ASSERT_EQ(a.size(), b.size());
  for (size_t s = 0; s < a.size(); ++s) EXPECT_EQ(a[s].frames, b[s].frames) << "sprite " << s;
  EXPECT_GT(with.moves_kept, 0);
}

TEST(Replacement, FreeStartsAndEndAnchorsMeetTheirLocations) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec free_spec;
  free_spec.anchor = Anchor::kFree;
  free_spec.initial_frames = 40;
  free_spec.max_frames = 40;
  problem.AddSprite(free_spec);
  // Two targets 1.5 m apart along x, 39 steps apart: only a start near (-1, 0) walking
  // +x can meet both.
  problem.AddTerm(
      std::make_unique<LocationTerm>(0, StepWindow::At(0), LocationTarget::Fixed({-1, 0}), 10.0));
  problem.AddTerm(std::make_unique<LocationTerm>(0, StepWindow::LastStep(),
                                                 LocationTarget::Fixed({0.5, 0}), 10.0));
  problem.AddTerm(std::make_unique<LengthTerm>(0, 40, 10.0));
  Summary summary;
  const auto tracks = OptimizeSequences(problem, FastOptions(1.5), &summary);
  ASSERT_TRUE(problem.IsValid(tracks));
  EXPECT_LT((tracks[0].positions_m.front() - Vector2d(-1, 0)).norm(), 0.15);
  EXPECT_LT((tracks[0].positions_m.back() - Vector2d(0.5, 0)).norm(), 0.15);
}

TEST(Replacement, BeamStartAndOptionChecks) {
  const TransitionGraph graph = WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 30;
  problem.AddSprite(spec);
  problem.AddTerm(std::make_unique<LocationTerm>(0, StepWindow::LastStep(),
                                                 LocationTarget::Fixed({1, 0.5}), 1.0));
  ReplacementOptions options = FastOptions(1.0);
  options.start = StartMethod::kBeam;
  options.beam.width = 4;
  options.beam.time_budget_seconds = 0.2;
  Summary summary;
  const auto tracks = OptimizeSequences(problem, options, &summary);
  EXPECT_EQ(summary.start, "beam");
  EXPECT_TRUE(problem.IsValid(tracks));
  EXPECT_LE(summary.final_cost.total, summary.initial_cost.total);

  std::string why;
  ReplacementOptions bad;
  bad.middle_fraction = 0.9;
  bad.begin_fraction = 0.2;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("fraction"), std::string::npos);
  bad = ReplacementOptions{};
  bad.time_budget_seconds = 0;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_THROW(OptimizeSequences(problem, bad, &summary), InputError);
  EXPECT_TRUE(ReplacementOptions{}.IsValid(&why));
}

TEST(Replacement, RandomSequencesFollowRealEdges) {
  const TransitionGraph graph = WalkingGraph::Make();
  for (uint64_t seed = 0; seed < 20; ++seed) {
    const std::vector<int> frames = RandomSequence(graph, 100, seed);
    EXPECT_EQ(frames.size(), 100u);
    EXPECT_TRUE(graph.IsValidSequence(frames));
  }
}

}  // namespace
}  // namespace ss
