#pragma once
// The two linear classifiers of seed 000 §3 and their versioned JSON file.
// Both act on standardized features z_k = (x_k - mean_k) / scale_k:
//   s = sum_k w_k z_k + b,  the pair is accepted when s <= 0.
// Weights are non-negative (a larger difference never makes a pair more acceptable),
// so stage 1 accepts a weighted-L1 ball and D = s - s(0) >= 0. See docs/transitions.md.
#include <array>
#include <string>

#include "pipeline/transitions/comparison.h"
#include "pipeline/transitions/features.h"

namespace ss {

inline constexpr int kWeightsFileVersion = 1;
inline constexpr const char* kWeightsFileFormat = "spritestation-transition-weights";

struct TransitionWeights {
  ComparisonWindow window;  // the pixel features are defined on this window
  PairFeatures feature_mean{};
  PairFeatures feature_scale{1, 1, 1, 1, 1, 1};
  CheapDifference stage1_weights{};
  double stage1_bias = 0;
  PairFeatures stage2_weights{};
  double stage2_bias = 0;
  std::string training_json = "{}";  // provenance and cross-validation figures (free form JSON object)

  // False (with the field and the reason) unless every field is usable.
  bool IsValid(std::string* why) const;
};

// Parses a weights file's text; `source` names it in errors. Throws
// InputError(source, "field 'stage1.weights': ...") on any wrong, missing or garbled field.
TransitionWeights ParseWeights(const std::string& text, const std::string& source);
// Reads and parses a file; InputError(path, ...) when it cannot be read or parsed.
TransitionWeights LoadWeights(const std::string& path);
std::string WeightsToJson(const TransitionWeights& weights);
// Writes the file; WorkError(path, ...) when it cannot be written.
void SaveWeights(const TransitionWeights& weights, const std::string& path);

// The weights shipped with the project (pipeline/transitions/default_weights.json,
// compiled into the binary).
const TransitionWeights& DefaultWeights();
// Their text as embedded.
const char* DefaultWeightsText();

}  // namespace ss
