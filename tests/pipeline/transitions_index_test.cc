// The stage-1 k-d tree returns exactly the pairs a linear scan of stage 1 returns.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/stage1_index.h"
#include "tests/pipeline/transitions_test_util.h"

namespace ss {
namespace {

// Clustered random-walk points with exact duplicates.
std::vector<CheapFeatures> Points(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<CheapFeatures> out;
  CheapFeatures f;
  for (int i = 0; i < n; ++i) {
    if (i % 97 == 0) {  // a new "clip": jump
      f.velocity_x_mps = 0.2 * g(rng);
      f.velocity_y_mps = 0.2 * g(rng);
      for (double& c : f.colour) c = 128 + 30 * g(rng);
      f.area_m2 = 0.005 + 0.001 * g(rng);
      f.eccentricity = std::clamp(0.7 + 0.2 * g(rng), 0.0, 1.0);
    } else if (i % 13 != 0) {  // else: an exact duplicate of the previous point
      f.velocity_x_mps += 0.01 * g(rng);
      f.velocity_y_mps += 0.01 * g(rng);
      for (double& c : f.colour) c += 2 * g(rng);
      f.area_m2 += 0.0001 * g(rng);
      f.eccentricity = std::clamp(f.eccentricity + 0.01 * g(rng), 0.0, 1.0);
    }
    out.push_back(f);
  }
  return out;
}

void ExpectSameAnswers(const Stage1Index& index, const std::vector<CheapFeatures>& queries,
                       int64_t* total) {
  std::vector<int32_t> fast, slow;
  for (const CheapFeatures& q : queries) {
    fast.clear();
    slow.clear();
    index.Query(q, &fast);
    index.QueryLinear(q, &slow);
    std::sort(fast.begin(), fast.end());
    ASSERT_EQ(fast, slow);  // QueryLinear is in index order already
    *total += static_cast<int64_t>(fast.size());
  }
}

TEST(TransitionIndex, TreeEqualsLinearScan) {
  const auto points = Points(4000, 3);
  for (const double t1 : {0.5, 2.0, 6.0}) {
    const TransitionClassifier c(testing::UnitWeights({0.05, 20, 0.001, 0.05, 1, 1}, t1, 1));
    Stage1Index index(c);
    index.Build(points);
    EXPECT_EQ(index.tree_size(), 4000);
    int64_t total = 0;
    ExpectSameAnswers(index, points, &total);
    EXPECT_GT(total, 4000) << "the test must find pairs beyond each point itself (t1 = " << t1
                           << ")";
    EXPECT_LT(total, 4000LL * 4000 / 4) << "and must not accept everything";
  }
}

TEST(TransitionIndex, TreeEqualsLinearScanWithZeroWeightsAndEmptyBall) {
  const auto points = Points(1500, 5);
  TransitionWeights w = testing::UnitWeights({0.05, 20, 0.001, 0.05, 1, 1}, 1.5, 1);
  w.stage1_weights = {2.0, 0.0, 0.5, 0.0};  // colour and eccentricity ignored: an unbounded slab
  {
    Stage1Index index{TransitionClassifier(w)};
    index.Build(points);
    int64_t total = 0;
    ExpectSameAnswers(index, points, &total);
    EXPECT_GT(total, 1500);
  }
  w.stage1_bias = 0.1;  // threshold below zero: nothing at all, not even a point itself
  Stage1Index index{TransitionClassifier(w)};
  index.Build(points);
  std::vector<int32_t> out;
  for (const auto& p : points) index.Query(p, &out);
  EXPECT_TRUE(out.empty());
}

TEST(TransitionIndex, InsertionsThroughRebuildsEqualLinearScan) {
  const auto points = Points(3000, 11);
  const TransitionClassifier c(testing::UnitWeights({0.05, 20, 0.001, 0.05, 1, 1}, 2.0, 1));
  Stage1Index index(c);
  index.Build(std::vector<CheapFeatures>(points.begin(), points.begin() + 100));
  std::vector<int32_t> fast, slow;
  int64_t total = 0;
  int rebuilds = 0;
  for (size_t i = 100; i < points.size(); ++i) {
    fast.clear();
    slow.clear();
    index.Query(points[i], &fast);
    index.QueryLinear(points[i], &slow);
    std::sort(fast.begin(), fast.end());
    ASSERT_EQ(fast, slow) << "point " << i;
    total += static_cast<int64_t>(fast.size());
    const int32_t before = index.tree_size();
    index.Insert(points[i]);
    rebuilds += index.tree_size() != before;
  }
  EXPECT_GE(rebuilds, 3) << "the insert buffer must have been folded into the tree";
  EXPECT_GT(total, 1000);
}

}  // namespace
}  // namespace ss
