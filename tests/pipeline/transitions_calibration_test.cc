// Stage 2 set for the real (rare) positive rate, stage 1 refitted as its filter, the
// early-exit stage 2 and the labels file's positive rate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "core/error.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/truth_labels.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

TEST(TransitionCalibration, AlphaKernelEqualsScalar) {
  const ComparisonWindow w;
  std::mt19937 rng(4);
  std::vector<uint8_t> a(w.ImageBytes()), b(w.ImageBytes());
  for (int trial = 0; trial < 20; ++trial) {
    for (auto& v : a) v = rng() % 256;
    for (auto& v : b) v = trial % 2 ? rng() % 256 : 0;
    EXPECT_EQ(SumAlphaDifference(a.data(), b.data(), w.PlaneStride()),
              SumPixelDifferencesScalar(a.data(), b.data(), w.PlaneStride()).alpha_abs_diff);
  }
}

TEST(TransitionCalibration, EarlyExitStageTwoDecidesAsTheFullEvaluation) {
  SyntheticSpriteOptions so;
  so.frames = 300;
  so.seed = 5;
  const auto sprites = MakeSyntheticSprites(so);
  SpriteStore store(ComparisonWindow{}, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  TransitionWeights w = PaperWeights();
  for (const double shift : {-3.0, 0.0, 3.0}) {  // tight, shipped, loose
    TransitionWeights v = w;
    v.stage2_bias = w.stage2_bias + shift;
    const TransitionClassifier c(v);
    int64_t accepted = 0, rejected = 0;
    for (int32_t i = 0; i < store.size(); i += 3) {
      for (int32_t j = 0; j < store.size(); ++j) {
        if (i == j) continue;
        const double full = c.Distance(store.Features(i, j));
        ASSERT_LE(store.SignatureAlphaBound(i, j),
                  SumAlphaDifference(store.image(i), store.image(j), store.window().PlaneStride()));
        double d = -1;
        const bool early = c.Stage2(store, i, j, &d);
        ASSERT_EQ(early, c.Stage2Accepts(full)) << i << " " << j << " shift " << shift;
        if (early) {
          EXPECT_EQ(d, full);
        }
        (early ? accepted : rejected) += 1;
      }
    }
    EXPECT_GT(rejected, 0);
    if (shift < 3.0) continue;
    EXPECT_GT(accepted, 0) << "the loose threshold must accept pairs for the test to mean anything";
  }
}

// A one-row population: `positives` true pairs with D uniform in [0, 1], the rest uniform
// in [0.3, 100] (so the best F1 is near D = 0.3, where the negatives start); the accept
// labels are another draw of the positives' distribution.
TEST(TransitionCalibration, StageTwoThresholdFollowsTheRarePositiveRate) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> unit(0, 1), wide(0.3, 100);
  const int n = 200001, positives = 100;
  PopulationSample sample;
  sample.sprites = n;
  sample.rows = {0};
  sample.distance.assign(n, INFINITY);
  std::vector<uint8_t> truth(n, 0);
  for (int j = 1; j < n; ++j) {
    truth[j] = j <= positives;
    sample.distance[j] = static_cast<float>(truth[j] ? unit(rng) : wide(rng));
  }
  std::vector<double> labels;
  labels.reserve(500);
  for (int k = 0; k < 500; ++k) labels.push_back(unit(rng));
  TransitionWeights w = PaperWeights();
  const Stage2Calibration c =
      CalibrateStage2(labels, sample, static_cast<double>(positives) / (n - 1), &w);
  // The true F1 at the chosen threshold vs the best possible.
  auto f1_at = [&](double t) {
    int64_t tp = 0, accepted = 0;
    for (int j = 1; j < n; ++j) {
      if (sample.distance[j] <= t) {
        ++accepted;
        tp += truth[j];
      }
    }
    const double p = accepted ? static_cast<double>(tp) / accepted : 0,
                 r = static_cast<double>(tp) / positives;
    return p + r > 0 ? 2 * p * r / (p + r) : 0.0;
  };
  double best = 0;
  for (double t = 0.1; t <= 1.5; t += 0.002) best = std::max(best, f1_at(t));
  EXPECT_GT(c.threshold, 0.2);
  EXPECT_LT(c.threshold, 0.45);
  EXPECT_GT(f1_at(c.threshold), 0.9 * best);
  EXPECT_LE(c.accepts_per_sprite,
            c.recall * positives / c.precision + 1e-6);  // precision is capped at 1
  // The weights now accept exactly up to that threshold.
  const TransitionClassifier classifier(w);
  EXPECT_NEAR(classifier.stage2_threshold(), c.threshold, 1e-6 * (1 + c.threshold));
  // A prior ten times too high would accept far more.
  TransitionWeights naive = PaperWeights();
  const Stage2Calibration wrong =
      CalibrateStage2(labels, sample, 10.0 * positives / (n - 1), &naive);
  EXPECT_GT(wrong.threshold, c.threshold + 0.2);
  EXPECT_THROW(CalibrateStage2({}, sample, 0.001, &w), InputError);
  EXPECT_THROW(CalibrateStage2(labels, sample, 0.0, &w), InputError);
}

TEST(TransitionCalibration, StageOneRefittedAsAFilterPassesTheRequestedShare) {
  SyntheticSpriteOptions so;
  so.frames = 1500;
  so.seed = 9;
  const auto sprites = MakeSyntheticSprites(so);
  SpriteStore store(ComparisonWindow{}, so.px_per_m);
  store.Append(AsSpriteInputs(sprites), 2);
  const TransitionWeights& w = PaperWeights();
  const PopulationSample sample = SamplePopulation(store, TransitionClassifier(w), 200, 3, 2);
  ASSERT_EQ(sample.rows.size(), 200u);
  for (const double recall : {0.95, 0.999}) {
    TransitionWeights v = w;
    const Stage1Calibration c = FitStage1Filter(store, sample, recall, 3, &v);
    ASSERT_GT(c.stage2_accepts, 100) << "the sample must hold stage-2 accepts";
    const TransitionClassifier filter(v);
    int64_t passed = 0, accepts = 0, candidates = 0;
    for (size_t r = 0; r < sample.rows.size(); ++r) {
      const int32_t i = sample.rows[r];
      for (int32_t j = 0; j < store.size(); ++j) {
        if (j == i) continue;
        const bool s1 = filter.Stage1Accepts(store.cheap(i), store.cheap(j));
        candidates += s1;
        if (filter.Stage2Accepts(sample.distance[r * store.size() + j])) {
          ++accepts;
          passed += s1;
        }
      }
    }
    EXPECT_EQ(accepts, c.stage2_accepts);
    EXPECT_GE(passed, static_cast<int64_t>(std::ceil(recall * accepts)) - 1) << recall;
    EXPECT_NEAR(c.candidates_per_sprite, static_cast<double>(candidates) / sample.rows.size(),
                1e-9);
    EXPECT_LT(c.candidates_per_sprite, 0.5 * (store.size() - 1)) << "stage 1 must filter";
    for (double u : v.stage1_weights) EXPECT_GE(u, 0.0);
  }
}

TEST(TransitionCalibration, PositiveRateOfTheTruthAndInTheLabelsFile) {
  SyntheticSpriteOptions so;
  so.frames = 300;
  const auto sprites = MakeSyntheticSprites(so);
  std::vector<SpriteTruth> truth;
  truth.reserve(sprites.size());
  for (const auto& s : sprites) truth.push_back(s.truth);
  const TruthLabelOptions o;
  int64_t positives = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    for (size_t j = 0; j < truth.size(); ++j)
      positives += i != j && TruthAccepts(truth[i], truth[j], o);
  }
  const double exact = static_cast<double>(positives) / (truth.size() * (truth.size() - 1.0));
  ASSERT_GT(exact, 0);
  EXPECT_DOUBLE_EQ(TruthPositiveRate(truth, o, 100000, 1), exact);
  EXPECT_NEAR(TruthPositiveRate(truth, o, 300, 1), exact, 0.5 * exact);

  ss::testing::ScratchDir dir;
  const std::vector<Label> labels = {{1, 2, true}, {3, 4, false}};
  double rate = 0;
  WriteLabelsCsv(labels, dir / "with.csv", 0.00125);
  EXPECT_EQ(ReadLabelsCsv(dir / "with.csv", &rate).size(), 2u);
  EXPECT_DOUBLE_EQ(rate, 0.00125);
  WriteLabelsCsv(labels, dir / "without.csv");
  EXPECT_EQ(ReadLabelsCsv(dir / "without.csv", &rate).size(), 2u);
  EXPECT_EQ(rate, -1);
  std::ofstream(dir / "bad.csv") << "# positive_rate=lots\nsprite_i,sprite_j,accept\n1,2,1\n";
  try {
    ReadLabelsCsv(dir / "bad.csv", &rate);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ss
