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

// Version 1: the paper's linear stage 2. Version 2 adds `stage2.variant` ("paper", "linf",
// "colour_blob" or "colour_cells"); files with the paper variant are still written as
// version 1, byte for byte.
inline constexpr int kWeightsFileVersion = 2;

// Which stage 2 the builder runs (docs/transitions.md "Stage-2 variants").
enum class Stage2Variant {
  kPaper,  // D = sum_k u2_k x_k <= T2 on the six features
  kLinf,   // velocity <= max_velocity_mps AND the largest cell alpha difference <= max_alpha_linf
  kColourBlob,  // velocity <= max_velocity_mps AND the largest colour-difference blob <=
                // max_blob_cells
  // velocity <= max_velocity_mps AND alpha difference <= max_alpha_cells AND
  // colour-different cells <= max_colour_cells
  kColourCells,
};
inline constexpr const char* kWeightsFileFormat = "spritestation-transition-weights";

struct TransitionWeights {
  ComparisonWindow window;  // the pixel features are defined on this window
  PairFeatures feature_mean{};
  PairFeatures feature_scale{1, 1, 1, 1, 1, 1};
  CheapDifference stage1_weights{};
  double stage1_bias = 0;
  PairFeatures stage2_weights{};
  double stage2_bias = 0;
  Stage2Variant stage2_variant = Stage2Variant::kPaper;
  double linf_max_velocity_mps = 0;          // linf: ||v_i - v_j|| bound (m/s), > 0
  double linf_max_alpha = 0;                 // linf: max_cells |A_i - A_j| / 255 bound, in (0, 1]
  double colour_blob_max_velocity_mps = 0;   // colour_blob: ||v_i - v_j|| bound (m/s), > 0
  int colour_blob_max_cells = 0;             // colour_blob: LargestColourBlob bound (cells), >= 0
  double colour_cells_max_velocity_mps = 0;  // colour_cells: ||v_i - v_j|| bound (m/s), > 0
  // colour_cells: sum_cells |A_i - A_j| / 255 bound (cells; px^2 in a 1 px window), >= 0
  double colour_cells_max_alpha_cells = 0;
  int colour_cells_max_cells = 0;  // colour_cells: ColourCellCount bound (cells), >= 0
  // provenance and cross-validation figures (free form JSON object)
  std::string training_json = "{}";

  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for every field that is not
  // usable, each named by its key in the weights file ("stage1.weights",
  // "comparison_window.cells_x").
  bool IsValid(std::string* why) const;
};

// Parses a weights file's text; `source` names it in errors. Throws
// InputError(source, "stage1.weights: ...") on a wrong, missing or garbled field (every value
// out of range, one line each, once the file's fields have been read).
TransitionWeights ParseWeights(const std::string& text, const std::string& source);
// Reads and parses a file; InputError(path, ...) when it cannot be read or parsed.
TransitionWeights LoadWeights(const std::string& path);
std::string WeightsToJson(const TransitionWeights& weights);
// Writes the file; WorkError(path, ...) when it cannot be written.
void SaveWeights(const TransitionWeights& weights, const std::string& path);

// The weights shipped with the project (pipeline/transitions/default_weights.json,
// compiled into the binary): the paper's six, linear stage 2. (The colour_cells variant is
// more precise against the synthetic truth but keeps too few transitions for the paper's
// scenes to be made: docs/transitions.md, "Why the default is the paper's six".)
const TransitionWeights& DefaultWeights();
// Their text as embedded.
const char* DefaultWeightsText();
// The paper's six (linear stage 2) trained on the synthetic set
// (pipeline/transitions/paper_weights.json, compiled in): what the benches compare with.
const TransitionWeights& PaperWeights();
const char* PaperWeightsText();
// The colour_cells variant fitted on the synthetic training seed
// (pipeline/transitions/colour_cells_weights.json, compiled in): `--weights` takes the file.
const TransitionWeights& ColourCellsWeights();
const char* ColourCellsWeightsText();

}  // namespace ss
