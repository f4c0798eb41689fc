#include "animate/reach_sets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <limits>

#include "core/error.h"
#include "tests/animate/animate_test_graphs.h"

namespace ss {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// All-pairs Ĉ distances by Floyd–Warshall: dist[a][b] = cheapest a -> b.
std::vector<std::vector<double>> AllPairs(const TransitionGraph& graph,
                                          const std::vector<double>& entry, double step) {
  const int n = graph.num_frames();
  std::vector<std::vector<double>> dist(n, std::vector<double>(n, kInf));
  for (int a = 0; a < n; ++a) {
    dist[a][a] = 0.0;
    for (size_t k = 0; k < graph.successors(a).size(); ++k) {
      const int b = graph.successors(a)[k];
      if (b != a) {
        dist[a][b] = std::min(dist[a][b], graph.successor_costs(a)[k] + step + entry[b]);
      }
    }
  }
  for (int m = 0; m < n; ++m) {
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) dist[a][b] = std::min(dist[a][b], dist[a][m] + dist[m][b]);
    }
  }
  return dist;
}

// Ĉ of a frame sequence, or +inf if it leaves the graph.
double PathCost(const TransitionGraph& graph, const std::vector<int>& path,
                const std::vector<double>& entry, double step) {
  double cost = 0.0;
  for (size_t t = 1; t < path.size(); ++t) {
    const auto c = graph.EdgeCost(path[t - 1], path[t]);
    if (!c) return kInf;
    cost += *c + step + entry[path[t]];
  }
  return cost;
}

void CheckAgainstBruteForce(uint64_t seed, int set_size, double step, bool with_entry,
                            int threads) {
  SCOPED_TRACE("seed " + std::to_string(seed));
  const TransitionGraph graph = testing::RandomGraph(40, 90, seed);
  std::vector<double> entry(graph.num_frames(), 0.0);
  std::mt19937_64 rng(seed);
  if (with_entry) {
    for (double& e : entry) e = (rng() % 4) * 0.3;
  }
  const auto dist = AllPairs(graph, entry, step);
  const ReachOptions options{set_size, threads, step};
  for (ReachDirection direction : {ReachDirection::kForward, ReachDirection::kBackward}) {
    const ReachSets sets =
        ReachSets::Build(graph, direction, options,
                         with_entry ? std::span<const double>(entry) : std::span<const double>());
    const bool forward = direction == ReachDirection::kForward;
    for (int root = 0; root < graph.num_frames(); ++root) {
      auto d = [&](int t) { return forward ? dist[root][t] : dist[t][root]; };
      int reachable = 0;
      for (int t = 0; t < graph.num_frames(); ++t) reachable += d(t) < kInf ? 1 : 0;
      const auto set = sets.Set(root);
      ASSERT_EQ(static_cast<int>(set.size()), std::min(set_size, reachable));
      ASSERT_EQ(set[0].frame, root);
      ASSERT_EQ(set[0].cost, 0.0f);
      std::vector<bool> member(graph.num_frames(), false);
      double worst = 0.0;
      for (int i = 0; i < static_cast<int>(set.size()); ++i) {
        const int t = set[i].frame;
        ASSERT_FALSE(member[t]) << "frame twice in a set";
        member[t] = true;
        EXPECT_NEAR(set[i].cost, d(t), 1e-5 * (1 + d(t)));
        worst = std::max(worst, d(t));
        std::vector<int> path;
        sets.AppendPath(root, i, &path);
        ASSERT_EQ(static_cast<int>(path.size()), sets.PathLength(root, i));
        EXPECT_EQ(forward ? path.front() : path.back(), root);
        EXPECT_EQ(forward ? path.back() : path.front(), t);
        EXPECT_TRUE(graph.IsValidSequence(path));
        EXPECT_NEAR(PathCost(graph, path, entry, step), d(t), 1e-5 * (1 + d(t)));
      }
      // Nothing left out is cheaper than what was kept: these are the N lowest.
      for (int t = 0; t < graph.num_frames(); ++t) {
        if (!member[t]) {
          EXPECT_GE(d(t), worst - 1e-9);
        }
      }
    }
  }
}

TEST(ReachSets, MatchBruteForceOnRandomGraphs) {
  for (uint64_t seed = 1; seed <= 6; ++seed) CheckAgainstBruteForce(seed, 8, 0.0, false, 1);
}

TEST(ReachSets, MatchBruteForceWithEntryAndStepCostsOnTwoThreads) {
  for (uint64_t seed = 11; seed <= 14; ++seed) CheckAgainstBruteForce(seed, 12, 0.05, true, 2);
}

TEST(ReachSets, LargeSetsHoldEveryReachableFrame) {
  CheckAgainstBruteForce(21, 1000, 0.0, true, 2);
}

TEST(ReachSets, ACancelStopsTheBuild) {
  const TransitionGraph graph = testing::RandomGraph(2000, 10, 1);
  const std::atomic<bool> cancel{true};
  ReachOptions options;
  options.cancel = &cancel;
  EXPECT_THROW(ReachSets::Build(graph, ReachDirection::kForward, options), WorkError);
}

TEST(ReachSets, RejectsBadOptions) {
  const TransitionGraph graph = testing::RandomGraph(10, 10, 1);
  EXPECT_ANY_THROW(ReachSets::Build(graph, ReachDirection::kForward, {0, 1, 0.0}));
  EXPECT_ANY_THROW(ReachSets::Build(graph, ReachDirection::kForward, {5, 1, -1.0}));
  const std::vector<double> short_entry(3, 0.0);
  EXPECT_ANY_THROW(ReachSets::Build(graph, ReachDirection::kForward, {5, 1, 0.0}, short_entry));
}

// Issue 39: set_size sizes the F/B sets (frames x set_size entries): bounded by memory, so that a
// spec's set_size: 65535 over a large bank is refused before it is allocated.
TEST(ReachSets, SetSizeIsBoundedByMemory) {
  EXPECT_EQ(ReachSetBytes(1000, 200), int64_t{1000} * 200 * 14);
  EXPECT_EQ(ReachSetBytes(100, 200), int64_t{100} * 100 * 14);  // a set holds at most every frame
  EXPECT_EQ(ReachSetTooLarge(50000, 200), "");
  EXPECT_EQ(ReachSetTooLarge(50000, 65535),
            "set_size: 65535 for a bank of 50000 frames takes 32.6 GiB per F/B set, over the 1 GiB "
            "a set may take (at most 1533 for this bank)");
  EXPECT_EQ(ReachSetTooLarge(50000, 1533), "");
  EXPECT_NE(ReachSetTooLarge(50000, 1534), "");
}

}  // namespace
}  // namespace ss
