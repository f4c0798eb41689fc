#pragma once
// Training the two classifiers from labelled sprite pairs (seed 000 §3): logistic
// regression on standardized features with non-negative weights (projected FISTA),
// k-fold cross-validated precision/recall, and the calibration of stage 1 as a filter
// for stage 2. See docs/transitions.md.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/weights.h"

namespace ss {

// One line of a labels file: "sprite_i,sprite_j,accept" with accept 1 or 0.
struct Label {
  int64_t sprite_i = 0, sprite_j = 0;  // bank ids
  bool accept = false;
};
// Throws InputError("PATH:LINE", reason) for a missing file, header or malformed line.
// A comment line "# positive_rate=R" (written by `label --from-truth`) sets *positive_rate
// (the share of all sprite pairs that are true transitions); -1 when the file has none.
std::vector<Label> ReadLabelsCsv(const std::string& path, double* positive_rate = nullptr);
// positive_rate >= 0 is written as the comment line above.
void WriteLabelsCsv(const std::vector<Label>& labels, const std::string& path,
                    double positive_rate = -1);

struct LogisticOptions {
  double l2 = 1e-4;            // ridge on the weights (not the bias), unitless (>= 0)
  int max_iterations = 20000;  // FISTA steps at most (>= 1)
  // stop when the relative change of the loss stays below this, unitless (>= 0)
  double tolerance = 1e-9;
  bool balance_classes = true;  // weight both classes equally, as the paper's ~50/50 labels
  bool non_negative = true;     // project the weights onto w >= 0 after every step
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// s = w.z + b, "reject" when s > 0; z are rows of `dims` standardized features.
struct LinearModel {
  std::vector<double> weights;
  double bias = 0;
  int iterations = 0;
  double loss = 0;
};
LinearModel FitLogistic(std::span<const double> z, int dims, std::span<const uint8_t> accept,
                        const LogisticOptions& options);

struct Confusion {
  int64_t true_accept = 0, false_accept = 0, true_reject = 0, false_reject = 0;
  double precision() const;  // of accepting
  double recall() const;
};

struct TrainOptions {
  int folds = 5;             // cross-validation folds (>= 2)
  uint64_t seed = 1;         // of the fold split
  LogisticOptions logistic;  // each fit's
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};
struct TrainReport {
  int64_t samples = 0, accepts = 0;
  int folds = 0;
  Confusion stage1, stage2;  // cross-validated
  std::string ToJson() const;
};

// Trains both stages on the pairs' six features; `window` is recorded in the weights.
// Throws InputError("labels", ...) when there are fewer than 2 * folds samples or one class is
// missing.
TransitionWeights TrainWeights(std::span<const PairFeatures> features,
                               std::span<const uint8_t> accept, const ComparisonWindow& window,
                               const TrainOptions& options, TrainReport* report);

// Stage 2 on every pair of `rows` random sprites against all others (brute force);
// returns the cheap differences of the pairs it accepts.
std::vector<CheapDifference> SampleStage2Accepted(const SpriteStore& store,
                                                  const TransitionClassifier& classifier, int rows,
                                                  uint64_t seed, int threads);

// Stage 2 (brute force) on every pair of `rows` random sprites against all others: the
// population the labels cannot show (true transitions are rare: tens among tens of thousands).
struct PopulationSample {
  int32_t sprites = 0;          // n
  std::vector<int32_t> rows;    // store indices of the sampled sprites
  std::vector<float> distance;  // rows.size() x n: D(rows[r], j), +inf for j == rows[r]
  double pairs() const { return static_cast<double>(rows.size()) * (sprites - 1); }
};
PopulationSample SamplePopulation(const SpriteStore& store, const TransitionClassifier& classifier,
                                  int rows, uint64_t seed, int threads);

struct Stage2Calibration {
  double threshold = 0;                      // D threshold T2
  double positive_rate = 0;                  // used
  double accepts_per_sprite = 0;             // in the sample
  double precision = 0, recall = 0, f1 = 0;  // estimated (see CalibrateStage2)
};
// Sets the stage-2 bias for the real positive rate: a pair is a true transition with
// probability `positive_rate`, so at threshold T the expected true accepts are
// positive_rate * pairs * r(T) (r = share of `positive_distances`, the D of accept labels,
// at most T) against A(T) pairs of the sample accepted. Picks the T of the best estimated
// F1. InputError("labels", ...) without positive labels or with a rate outside (0, 1).
Stage2Calibration CalibrateStage2(std::span<const double> positive_distances,
                                  const PopulationSample& sample, double positive_rate,
                                  TransitionWeights* weights);

struct Stage1Calibration {
  double recall = 0;                 // asked share of stage-2 accepts
  int64_t stage2_accepts = 0;        // in the sample
  double candidates_per_sprite = 0;  // in the sample, with the new weights
  double fewer_than_all = 0;         // all pairs / stage-1 candidates
};
// Refits stage 1 as a filter for stage 2: logistic regression (non-negative, balanced) on
// the cheap differences of the sample, positives = the pairs stage 2 accepts, negatives a
// random subset of the rest; then sets its bias so that `recall` of the positives pass.
Stage1Calibration FitStage1Filter(const SpriteStore& store, const PopulationSample& sample,
                                  double recall, uint64_t seed, TransitionWeights* weights);

// Sets the stage-1 bias so that at least `recall` of `stage2_accepted` pass stage 1
// (stage 1 only filters for stage 2). Returns the previous bias.
double CalibrateStage1(std::span<const CheapDifference> stage2_accepted, double recall,
                       TransitionWeights* weights);

}  // namespace ss
