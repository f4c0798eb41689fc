#include "pipeline/transitions/classifier.h"

#include "core/error.h"

namespace ss {

TransitionClassifier::TransitionClassifier(const TransitionWeights& weights) : weights_(weights) {
  std::string why;
  if (!weights.IsValid(&why)) throw InputError("weights", why);
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
}

bool TransitionClassifier::Stage2(const SpriteStore& store, int32_t i, int32_t j, double* distance) const {
  const CheapDifference cheap = CheapDiff(store.cheap(i), store.cheap(j));
  // Same operations in the same order as Distance(): the partial sums are its prefixes.
  double d = 0;
  for (int k = 0; k < kCheapFeatureCount; ++k) d += u2_[k] * cheap[k];
  if (d > t2_) return false;
  PixelSums bound;  // the alpha term from the block sums: a lower bound of it, exact to compare
  bound.alpha_abs_diff = store.AlphaLowerBound(i, j);
  bound.weight = 1;  // colour not used here
  if (d + u2_[4] * PixelDifferenceFromSums(bound, store.box(i), store.box(j)).alpha > t2_) return false;
  const uint8_t* a = store.image(i);
  const uint8_t* b = store.image(j);
  const int stride = store.window().PlaneStride();
  PixelSums alpha_only;
  alpha_only.alpha_abs_diff = SumAlphaDifference(a, b, stride);
  alpha_only.weight = 1;  // colour not used here
  const double alpha = PixelDifferenceFromSums(alpha_only, store.box(i), store.box(j)).alpha;
  if (d + u2_[4] * alpha > t2_) return false;
  const PairFeatures x = MakePairFeatures(cheap, PixelDifferenceFromSums(SumPixelDifferences(a, b, stride),
                                                                         store.box(i), store.box(j)));
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
