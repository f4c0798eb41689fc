#pragma once
// Fitting the colour_cells stage 2 (docs/transitions.md "Stage-2 variants"): a pair is kept
// when its velocity difference, its alpha difference (sum |A_i - A_j| / 255, cells) and its
// count of colour-different cells are each at most a threshold. The three thresholds are
// chosen on a grid for the best estimated F1 for the real positive rate, the way
// CalibrateStage2 sets the paper's T2: the recall r from the accept labels, the accepts A
// from every pair of some sampled sprites of the bank, the expected true accepts
// positive_rate * pairs * r.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/weights.h"

namespace ss {

// The three measurements of a pair, on the store's comparison images.
struct ColourCellsMeasure {
  double velocity_mps = 0;  // ||v_i - v_j||
  double alpha_cells = 0;   // sum_cells |A_i - A_j| / 255
  int colour_cells = 0;     // ColourCellCount
};
ColourCellsMeasure MeasureColourCells(const SpriteStore& store, int32_t i, int32_t j);

struct ColourCellsFitOptions {
  // Sprites whose every pair is measured: the population (>= 1; all of them when more).
  int rows = 300;
  uint64_t seed = 7;  // of the sampled rows
  int threads = 2;    // (>= 1)
  // Among grid points whose estimated F1 is within this of the best, the one with the smallest
  // alpha bound is taken: the signature filter then reads fewer pixels (0..1).
  double f1_tolerance = 0.005;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct ColourCellsFit {
  double max_velocity_mps = 0, max_alpha_cells = 0;
  int max_colour_cells = 0;
  // estimated on the sample, for the positive rate (see the header comment)
  double precision = 0, recall = 0, f1 = 0;
  double accepts_per_sprite = 0;  // in the sample; -1 when the fit had no sample of sprites
  double positive_rate = 0;
  int64_t sampled_pairs = 0, positives = 0;
};

// Chooses the thresholds for `positives` (the measurements of accept labels) against every pair
// of `options.rows` random sprites of `store` (true with probability positive_rate, in (0, 1)),
// and writes them into `weights` as the colour_cells variant, with the velocity ball as stage 1
// (stage1.weights [1, 0, 0, 0]: it passes every pair within the velocity bound, as the
// variant's filters need). InputError("labels", ...) without positives or with a rate outside
// (0, 1); InputError("training options", ...) for invalid options.
ColourCellsFit FitColourCells(const SpriteStore& store,
                              std::span<const ColourCellsMeasure> positives, double positive_rate,
                              const ColourCellsFitOptions& options, TransitionWeights* weights);

// Without a positive rate: the same choice on the labels alone (a 50/50 world: the population is
// the labelled pairs, the rate their share of accepts). InputError("labels", ...) without both
// classes.
ColourCellsFit FitColourCellsOnLabels(std::span<const ColourCellsMeasure> positives,
                                      std::span<const ColourCellsMeasure> negatives,
                                      const ColourCellsFitOptions& options,
                                      TransitionWeights* weights);

// With a truth (synthetic sets): every unit is a measure — a pair's, or a transition's, whose
// three pairs must all be kept, so its measure is the componentwise largest of theirs — and
// whether the truth accepts it. `true_total` counts every true unit of the sample, those beyond
// the grid too (the recall's denominator). The precision is then counted, not estimated: the
// point of the best F1 among those of precision >= min_precision (0..1; none: the best F1).
// InputError("truth", ...) when no unit is true.
ColourCellsFit FitColourCellsOnTruth(std::span<const ColourCellsMeasure> units,
                                     std::span<const uint8_t> truth, int64_t true_total,
                                     double min_precision, const ColourCellsFitOptions& options,
                                     TransitionWeights* weights);

}  // namespace ss
