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
std::vector<Label> ReadLabelsCsv(const std::string& path);
void WriteLabelsCsv(const std::vector<Label>& labels, const std::string& path);

struct LogisticOptions {
  double l2 = 1e-4;             // ridge on the weights (not the bias)
  int max_iterations = 20000;
  double tolerance = 1e-9;      // stop when the relative change of the loss stays below this
  bool balance_classes = true;  // weight both classes equally, as the paper's ~50/50 labels
  bool non_negative = true;     // project the weights onto w >= 0 after every step
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
  int folds = 5;
  uint64_t seed = 1;
  LogisticOptions logistic;
};
struct TrainReport {
  int64_t samples = 0, accepts = 0;
  int folds = 0;
  Confusion stage1, stage2;  // cross-validated
  std::string ToJson() const;
};

// Trains both stages on the pairs' six features; `window` is recorded in the weights.
// Throws InputError("labels", ...) when there are fewer than 2 * folds samples or one class is missing.
TransitionWeights TrainWeights(std::span<const PairFeatures> features, std::span<const uint8_t> accept,
                               const ComparisonWindow& window, const TrainOptions& options,
                               TrainReport* report);

// Stage 2 on every pair of `rows` random sprites against all others (brute force);
// returns the cheap differences of the pairs it accepts.
std::vector<CheapDifference> SampleStage2Accepted(const SpriteStore& store, const TransitionClassifier& classifier,
                                                  int rows, uint64_t seed, int threads);

// Sets the stage-1 bias so that at least `recall` of `stage2_accepted` pass stage 1
// (stage 1 only filters for stage 2). Returns the previous bias.
double CalibrateStage1(std::span<const CheapDifference> stage2_accepted, double recall,
                       TransitionWeights* weights);

}  // namespace ss
