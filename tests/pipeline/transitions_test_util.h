#pragma once
// Shared by the transitions tests: hand-set weights.
#include "pipeline/transitions/weights.h"

namespace ss::testing {

// Weights with mean 0, the given scales and unit weights: stage 1 accepts
// sum_k |d_k| / scale_k <= t1, stage 2 accepts sum_k x_k / scale_k <= t2.
inline TransitionWeights UnitWeights(const PairFeatures& scale, double t1, double t2) {
  TransitionWeights w;
  w.feature_mean = {0, 0, 0, 0, 0, 0};
  w.feature_scale = scale;
  w.stage1_weights = {1, 1, 1, 1};
  w.stage1_bias = -t1;
  w.stage2_weights = {1, 1, 1, 1, 1, 1};
  w.stage2_bias = -t2;
  return w;
}

}  // namespace ss::testing
