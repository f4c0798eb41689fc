#pragma once
// Training and labelling against a real bank (`spritestation transitions train` and
// `transitions label --from-truth`). See docs/transitions.md.
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/transitions/colour_cells_training.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/truth_labels.h"
#include "pipeline/transitions/weights.h"

namespace ss {

struct BankTrainOptions {
  TrainOptions train;  // the label fit: folds, seed, logistic regression
  // The pixel features' window (recorded in the weights): the shipped weights' (a 1 px window
  // on the contact point for the colour_cells default).
  ComparisonWindow window = DefaultWeights().window;
  // Which stage 2 to fit: kPaper (the paper's six, linear) or kColourCells (the default: the
  // paper fit is made as well, for the labelling page's ordering, then the three thresholds
  // are fitted: FitColourCells with a positive rate, FitColourCellsOnLabels without).
  Stage2Variant variant = DefaultWeights().stage2_variant;
  // share (0..1) of stage-2 accepts stage 1 must pass in the sample (0 = keep the label fit)
  double stage1_recall = 0.999;
  // Share (0..1) of all sprite pairs that are true transitions; < 0: the labels file's
  // "# positive_rate=" line; none there: stage 2 keeps the label fit's (50/50) bias.
  double positive_rate = -1;
  int calibration_rows = 300;  // sprites whose every pair stage 2 judges for the calibration (>= 1)
  int threads = 2;             // worker threads (>= 1)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct BankTrainResult {
  TransitionWeights weights;
  TrainReport report;               // cross-validated precision/recall of both stages on the labels
  int64_t calibration_accepts = 0;  // stage-2 accepted pairs the stage-1 bias was set on
  double stage1_bias_from_labels = 0;
  bool stage2_calibrated = false;  // a positive rate was known
  Stage2Calibration stage2;
  Stage1Calibration stage1;   // when stage2_calibrated and stage1_recall > 0
  bool colour_cells = false;  // the colour_cells variant was fitted (`cells`)
  ColourCellsFit cells;
};

// Trains both stages on the labelled pairs of `bank_path`'s sprites. With a positive rate
// (options or the labels file) stage 2's threshold is then set for it on a brute-force
// sample of the bank (CalibrateStage2) and stage 1 refitted as its filter
// (FitStage1Filter); without one, only the stage-1 bias is set so that stage 1 passes
// `stage1_recall` of what stage 2 accepts on the bank. InputError naming the labels file or the
// bank for an unknown sprite, too few labels or one class only.
BankTrainResult TrainOnBank(const std::string& labels_path, const std::string& bank_path,
                            const BankTrainOptions& options);

struct TruthLabelSummary {
  int64_t sprites_matched = 0;    // originals of the session's cameras given a truth
  int64_t sprites_unmatched = 0;  // no truth row at their time and place
  int64_t mirrored_skipped = 0;
  double positive_rate = 0;  // share of the matched sprites' pairs the truth accepts
  std::vector<Label> labels;
};

// Labels from a synthetic session's truth/subjects.csv for the sprites of that session in
// the bank (matched by timestamp, then by nearest subject within 0.15 m). Mirrored
// sprites are left out (their truth heading depends on the camera). InputError naming
// the session or the bank when the truth is missing or no sprite matches.
TruthLabelSummary LabelBankFromTruth(const std::string& session_dir, const std::string& bank_path,
                                     size_t count, const TruthLabelOptions& options, uint64_t seed);

}  // namespace ss
