#include "pipeline/transitions/classifier.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ss {

TransitionClassifier::TransitionClassifier(const TransitionWeights& weights) : weights_(weights) {
  std::string why;
  if (!weights.IsValid(&why)) throw InputError("transition weights", why);
  t1_ = -weights.stage1_bias;
  for (int k = 0; k < kCheapFeatureCount; ++k) {
    u1_[k] = weights.stage1_weights[k] / weights.feature_scale[k];
    t1_ += u1_[k] * weights.feature_mean[k];
  }
  t2_ = -weights.stage2_bias;
  for (int k = 0; k < kPairFeatureCount; ++k) {
    u2_[k] = weights.stage2_weights[k] / weights.feature_scale[k];
    t2_ += u2_[k] * weights.feature_mean[k];
  }
  linf_alpha_limit_ = static_cast<int>(std::floor(255.0 * weights.linf_max_alpha + 1e-9));
  colour_cells_alpha_limit_ =
      static_cast<uint64_t>(std::floor(255.0 * weights.colour_cells_max_alpha_cells + 1e-9));
}

double TransitionClassifier::ColourCellsDistance(double velocity_mps, uint64_t alpha_abs_diff,
                                                 int cells) const {
  const double v = velocity_mps / weights_.colour_cells_max_velocity_mps;
  const double a = static_cast<double>(alpha_abs_diff) /
                   static_cast<double>(std::max<uint64_t>(1, colour_cells_alpha_limit_));
  const double c = static_cast<double>(cells) / std::max(1, weights_.colour_cells_max_cells);
  return std::max({v, a, c});
}

namespace {

// The alpha feature from a numerator (an exact sum or a lower bound of it) and the boxes.
double AlphaFeature(uint64_t alpha_abs_diff, const CellBox& a, const CellBox& b) {
  PixelSums sums;
  sums.alpha_abs_diff = alpha_abs_diff;
  sums.weight = 1;  // colour not used here
  return PixelDifferenceFromSums(sums, a, b).alpha;
}

}  // namespace

bool TransitionClassifier::SignatureRejects(const SpriteStore& store, int32_t i, int32_t j) const {
  const CheapDifference cheap = CheapDiff(store.cheap(i), store.cheap(j));
  if (linf()) {
    return cheap[0] > weights_.linf_max_velocity_mps ||
           store.SignatureLinfExceeds(i, j, linf_alpha_limit_);
  }
  if (colour_blob()) return cheap[0] > weights_.colour_blob_max_velocity_mps;
  if (colour_cells()) {
    return cheap[0] > weights_.colour_cells_max_velocity_mps ||
           store.CoarseAlphaBound(i, j) > colour_cells_alpha_limit_ ||
           store.SignatureAlphaBound(i, j) > colour_cells_alpha_limit_;
  }
  // d is Distance()'s prefix, and the alpha feature is monotone in its numerator, so
  // d + u4 * bound <= the full sum.
  const double d = CheapPart(cheap);
  if (d > t2_) return true;
  const CellBox& box_i = store.box(i);
  const CellBox& box_j = store.box(j);
  if (d + u2_[4] * AlphaFeature(store.CoarseAlphaBound(i, j), box_i, box_j) > t2_) return true;
  return d + u2_[4] * AlphaFeature(store.SignatureAlphaBound(i, j), box_i, box_j) > t2_;
}

bool TransitionClassifier::Stage2(const SpriteStore& store, int32_t i, int32_t j,
                                  double* distance) const {
  const CheapDifference cheap = CheapDiff(store.cheap(i), store.cheap(j));
  if (linf()) {
    if (cheap[0] > weights_.linf_max_velocity_mps) return false;
    const int worst =
        MaxAlphaDifference(store.image(i), store.image(j), store.window().PlaneStride());
    if (worst > linf_alpha_limit_) return false;
    *distance = std::max(cheap[0] / weights_.linf_max_velocity_mps,
                         worst / (255.0 * weights_.linf_max_alpha));
    return true;
  }
  if (colour_blob()) {
    if (cheap[0] > weights_.colour_blob_max_velocity_mps) return false;
    const int blob = LargestColourBlob(store.image(i), store.image(j), store.window());
    if (blob > weights_.colour_blob_max_cells) return false;
    *distance = std::max(cheap[0] / weights_.colour_blob_max_velocity_mps,
                         static_cast<double>(blob) / std::max(1, weights_.colour_blob_max_cells));
    return true;
  }
  if (colour_cells()) {
    if (cheap[0] > weights_.colour_cells_max_velocity_mps) return false;
    const int stride = store.window().PlaneStride();
    const uint64_t alpha = SumAlphaDifference(store.image(i), store.image(j), stride);
    if (alpha > colour_cells_alpha_limit_) return false;
    const int cells = ColourCellCount(store.image(i), store.image(j), stride);
    if (cells > weights_.colour_cells_max_cells) return false;
    *distance = ColourCellsDistance(cheap[0], alpha, cells);
    return true;
  }
  // The partial sums are Distance()'s prefixes.
  const double d = CheapPart(cheap);
  if (d > t2_) return false;
  const uint8_t* a = store.image(i);
  const uint8_t* b = store.image(j);
  const int stride = store.window().PlaneStride();
  const double alpha = AlphaFeature(SumAlphaDifference(a, b, stride), store.box(i), store.box(j));
  if (d + u2_[4] * alpha > t2_) return false;
  const PairFeatures x = MakePairFeatures(
      cheap,
      PixelDifferenceFromSums(SumPixelDifferences(a, b, stride), store.box(i), store.box(j)));
  const double full = Distance(x);
  if (full > t2_) return false;
  *distance = full;
  return true;
}

double TransitionClassifier::Stage1Value(const CheapDifference& d) const {
  double s = -t1_;
  for (int k = 0; k < kCheapFeatureCount; ++k) s += u1_[k] * d[k];
  return s;
}

}  // namespace ss
