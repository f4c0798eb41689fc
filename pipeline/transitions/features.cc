#include "pipeline/transitions/features.h"

namespace ss {

const std::array<std::string, kPairFeatureCount>& FeatureNames() {
  static const std::array<std::string, kPairFeatureCount> names = {
      "velocity", "mean_colour", "area", "eccentricity", "alpha", "pixel_colour"};
  return names;
}

}  // namespace ss
