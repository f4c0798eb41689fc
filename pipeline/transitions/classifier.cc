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

double TransitionClassifier::Stage1Value(const CheapDifference& d) const {
  double s = -t1_;
  for (int k = 0; k < kCheapFeatureCount; ++k) s += u1_[k] * d[k];
  return s;
}

}  // namespace ss
