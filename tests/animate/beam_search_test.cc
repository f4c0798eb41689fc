#include "animate/beam_search.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <memory>

#include "animate/basic_costs.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "core/error.h"
#include "tests/animate/animate_test_graphs.h"

namespace ss {
namespace {

// The lowest full cost over every valid sequence of 1..max_length frames (one sprite).
double BruteForceBest(const Problem& problem, int max_length) {
  const TransitionGraph& graph = problem.graph();
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> frames;
  std::function<void()> extend = [&] {
    best = std::min(best, problem.TotalCost({problem.MakeSpriteTrack(0, frames)}));
    if (static_cast<int>(frames.size()) == max_length) return;
    for (int f : graph.successors(frames.back())) {
      frames.push_back(f);
      extend();
      frames.pop_back();
    }
  };
  for (int f = 0; f < graph.num_frames(); ++f) {
    frames = {f};
    extend();
  }
  return best;
}

TEST(BeamSearch, AWideEnoughBeamIsExhaustive) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    const TransitionGraph graph = testing::RandomGraph(12, 20, seed);
    Problem problem(graph);
    SpriteSpec spec;
    spec.max_frames = 5;
    problem.AddSprite(spec);
    problem.AddTerm(std::make_unique<LocationTerm>(0, StepWindow::At(4),
                                                   LocationTarget::Fixed({0.15, -0.1}), 5.0));
    problem.AddTerm(std::make_unique<PathTerm>(0, Polyline({{0, 0}, {0.2, 0.1}}),
                                               PathStrengths{0.1, 1.0, 2.0}));
    problem.AddTerm(std::make_unique<LengthTerm>(0, 4, 0.3));
    BeamOptions options;
    options.width = 100000;  // more than all sequences of 5 frames
    Summary summary;
    const std::vector<Track> tracks = BeamSearch(problem, options, &summary);
    ASSERT_TRUE(problem.IsValid(tracks));
    EXPECT_LE(tracks[0].size(), 5);
    EXPECT_NEAR(summary.final_cost.total, BruteForceBest(problem, 5), 1e-9) << "seed " << seed;
    EXPECT_EQ(summary.termination, TerminationType::kBeamComplete);
  }
}

TEST(BeamSearch, NarrowBeamsGiveValidSequencesAndWidenWithinTheBudget) {
  const TransitionGraph graph = testing::WalkingGraph::Make();
  Problem problem(graph);
  SpriteSpec spec;
  spec.initial_frames = 40;
  problem.AddSprite(spec);
  problem.AddSprite(spec);
  auto path = std::make_unique<PathTerm>(0, Polyline({{0, 0}, {1.5, 0}}), PathStrengths{});
  const PathTerm* path_term = path.get();
  problem.AddTerm(std::move(path));
  BeamOptions options;
  options.width = 2;
  options.time_budget_seconds = 0.3;
  Summary summary;
  const std::vector<Track> tracks = BeamSearch(problem, options, &summary);
  std::string why;
  ASSERT_TRUE(problem.IsValid(tracks, &why)) << why;
  EXPECT_LE(tracks[0].size(), 40);
  EXPECT_LE(tracks[1].size(), 40);  // only smoothness: any zero-cost sequence is best
  EXPECT_GT(tracks[0].positions_m.back().x(), 1.5 - 1e-6);  // walked the path to its end
  EXPECT_LT(path_term->MaxDeviation(tracks[0]), 0.05);
  EXPECT_GT(summary.turns, 1);  // doubled the width at least once
  EXPECT_LE(summary.final_cost.total, summary.initial_cost.total);
  EXPECT_NEAR(summary.final_cost.total, problem.TotalCost(tracks), 1e-9);
  EXPECT_FALSE(summary.BriefReport().empty());
  BeamOptions bad;
  bad.width = 0;
  EXPECT_THROW(BeamSearch(problem, bad, &summary), InputError);
}

}  // namespace
}  // namespace ss
