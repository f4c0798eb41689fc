#pragma once
// TransitionWeights turned into the form the hot loops use: raw-unit weights u_k =
// w_k / scale_k and thresholds T = sum_k w_k mean_k / scale_k - b, so that
//   stage 1 accepts  sum_k u1_k |d_k| <= T1   (a weighted-L1 ball, velocity as a 2-D norm)
//   stage 2 accepts  D = sum_k u2_k x_k <= T2 (D >= 0 is the visual difference D(i,j)).
#include <array>

#include "pipeline/transitions/features.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/weights.h"

namespace ss {

class TransitionClassifier {
 public:
  // Throws InputError("transition weights", "field: reason...") for invalid weights.
  explicit TransitionClassifier(const TransitionWeights& weights);

  // The stage-1 sum; the linear scan and the index both decide with exactly this.
  double Stage1Sum(const CheapFeatures& a, const CheapFeatures& b) const {
    const CheapDifference d = CheapDiff(a, b);
    return u1_[0] * d[0] + u1_[1] * d[1] + u1_[2] * d[2] + u1_[3] * d[3];
  }
  bool Stage1Accepts(const CheapFeatures& a, const CheapFeatures& b) const {
    return Stage1Sum(a, b) <= t1_;
  }
  // s1 = w.z + b of the standardized model (accept when <= 0).
  double Stage1Value(const CheapDifference& d) const;

  // D(i,j) = s2 - s2(0) >= 0; kept when D <= stage2_threshold().
  double Distance(const PairFeatures& x) const {
    double d = 0;
    for (int k = 0; k < kPairFeatureCount; ++k) d += u2_[k] * x[k];
    return d;
  }
  bool Stage2Accepts(double distance) const { return distance <= t2_; }
  // Proves without reading a pixel that stage 2 rejects the pair: the four cheap terms of
  // D (in Distance()'s order) plus the alpha term bounded from below by the sprites'
  // silhouette signatures (SpriteStore::CoarseAlphaBound, then SignatureAlphaBound) exceed
  // the threshold. Every term of D is >= 0 and the bounds are below the alpha term, so a
  // pair this returns true for is one Stage2Accepts(Distance(...)) rejects; false decides
  // nothing (run Stage2).
  // With the linf variant: true when the velocity difference exceeds its bound or
  // SpriteStore::SignatureLinfExceeds proves the largest cell difference exceeds its bound.
  // With the colour_blob variant: true when the velocity difference exceeds its bound (the
  // colour blob has no per-sprite bound: every other pair is evaluated).
  // With the colour_cells variant: true when the velocity difference exceeds its bound or
  // a silhouette-signature bound (CoarseAlphaBound, then SignatureAlphaBound) of
  // sum |A_i - A_j| exceeds colour_cells_alpha_limit() (the bounds are <= the sum, so the
  // full evaluation rejects such a pair too).
  bool SignatureRejects(const SpriteStore& store, int32_t i, int32_t j) const;
  // Stage 2 on store indices (i, j) with early exits: the sum of Distance() is built in
  // its own order (the cheap terms, then alpha from the alpha plane, then colour) and every
  // term is >= 0, so once a partial sum exceeds the threshold the pair is rejected without
  // reading the colour planes. Decides exactly as Stage2Accepts(Distance(store.Features(i, j)))
  // and, when accepted, sets *distance to that same value. Does not use the signatures:
  // the builder calls SignatureRejects first and counts only the pairs that reach this.
  // With the linf variant (weights().stage2_variant): kept when velocity <= max_velocity_mps
  // and MaxAlphaDifference <= floor(255 * max_alpha_linf); *distance = the larger of the two
  // ratios to their bounds (0..1). With the colour_blob variant: kept when velocity <=
  // max_velocity_mps and LargestColourBlob <= max_blob_cells; *distance = the larger of
  // velocity / max_velocity_mps and blob / max(1, max_blob_cells) (0..1). Distance() and
  // With the colour_cells variant: kept when velocity <= max_velocity_mps, sum |A_i - A_j| <=
  // colour_cells_alpha_limit() (the alpha plane, read first) and ColourCellCount <=
  // max_colour_cells (then the colour planes); *distance = the largest of the three ratios to
  // their bounds (0..1; a bound of 0 counts as 1). Stage2Accepts() stay the linear D (the
  // paper variant's training and the labelling page's ordering use them).
  bool Stage2(const SpriteStore& store, int32_t i, int32_t j, double* distance) const;
  bool linf() const { return weights_.stage2_variant == Stage2Variant::kLinf; }
  bool colour_blob() const { return weights_.stage2_variant == Stage2Variant::kColourBlob; }
  bool colour_cells() const { return weights_.stage2_variant == Stage2Variant::kColourCells; }
  // colour_cells: the largest accepted sum_cells |A_i - A_j| (floor(255 * max_alpha_cells)).
  uint64_t colour_cells_alpha_limit() const { return colour_cells_alpha_limit_; }
  // colour_cells: the stored d of a kept pair from its three measurements.
  double ColourCellsDistance(double velocity_mps, uint64_t alpha_abs_diff, int cells) const;
  // linf: the largest accepted MaxAlphaDifference (0..255).
  int linf_alpha_limit() const { return linf_alpha_limit_; }

  const CheapDifference& stage1_unit_weights() const { return u1_; }
  double stage1_threshold() const { return t1_; }
  const PairFeatures& stage2_unit_weights() const { return u2_; }
  double stage2_threshold() const { return t2_; }
  const TransitionWeights& weights() const { return weights_; }

 private:
  // D's four cheap terms summed in Distance()'s order: the prefix both early exits start from.
  double CheapPart(const CheapDifference& cheap) const {
    double d = 0;
    for (int k = 0; k < kCheapFeatureCount; ++k) d += u2_[k] * cheap[k];
    return d;
  }
  TransitionWeights weights_;
  CheapDifference u1_{};
  double t1_ = 0;
  PairFeatures u2_{};
  double t2_ = 0;
  int linf_alpha_limit_ = 0;
  uint64_t colour_cells_alpha_limit_ = 0;
};

}  // namespace ss
