#pragma once
// The six difference features of a sprite pair (seed 000 §3), in a fixed order:
//   0 velocity      |v_i - v_j|_2, m/s (norm of the vector difference)
//   1 mean_colour   |c_i - c_j|_1 over R, G, B, 0..765
//   2 area          |area_i - area_j|, m^2
//   3 eccentricity  |e_i - e_j|, 0..1
//   4 alpha         PixelDifference::alpha, 0..1
//   5 pixel_colour  PixelDifference::colour, 0..255
// The first four are "cheap" (stage 1), all six feed stage 2.
#include <array>
#include <cmath>
#include <string>

#include "pipeline/transitions/billboard.h"
#include "pipeline/transitions/comparison.h"

namespace ss {

inline constexpr int kCheapFeatureCount = 4;
inline constexpr int kPairFeatureCount = 6;
using CheapDifference = std::array<double, kCheapFeatureCount>;
using PairFeatures = std::array<double, kPairFeatureCount>;

// Names as they appear in the weights file, in feature order.
const std::array<std::string, kPairFeatureCount>& FeatureNames();

inline CheapDifference CheapDiff(const CheapFeatures& a, const CheapFeatures& b) {
  const double dvx = a.velocity_x_mps - b.velocity_x_mps, dvy = a.velocity_y_mps - b.velocity_y_mps;
  return {std::sqrt(dvx * dvx + dvy * dvy),
          std::abs(a.colour[0] - b.colour[0]) + std::abs(a.colour[1] - b.colour[1]) +
              std::abs(a.colour[2] - b.colour[2]),
          std::abs(a.area_m2 - b.area_m2), std::abs(a.eccentricity - b.eccentricity)};
}

inline PairFeatures MakePairFeatures(const CheapDifference& cheap, const PixelDifference& pixels) {
  return {cheap[0], cheap[1], cheap[2], cheap[3], pixels.alpha, pixels.colour};
}

}  // namespace ss
