#pragma once
// Describe (seed 000 §3): the per-sprite numbers the cheap transition features
// compare, measured on the perspective-corrected billboard so that they mean
// the same for near and far sprites. Velocity needs the clip: see
// EstimateVelocities.
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ss {

struct SpriteDescription {
  double mean_r = 0, mean_g = 0,
         mean_b = 0;        // mean colour under the matte (alpha-weighted), 0..255
  double area_px = 0;       // sum of alpha / 255, billboard pixels
  double eccentricity = 0;  // sqrt(1 - l_min / l_max) of the alpha-weighted second moments
};

// Throws InputError when `bgra` is not CV_8UC4. An empty matte describes as all zeros.
SpriteDescription DescribeBillboard(const cv::Mat& bgra);

// Ground velocity (m/s) of every frame of a clip: the least-squares slope of
// the contact points over a window of +-`half_window` frames (shrunk at the
// clip's ends; a one-frame clip stands still). `timestamps_ns` must increase.
// The same for frame `i` alone.
Eigen::Vector2d EstimateVelocity(const std::vector<int64_t>& timestamps_ns,
                                 const std::vector<Eigen::Vector2d>& points_in_ground, int i,
                                 int half_window = 2);
std::vector<Eigen::Vector2d> EstimateVelocities(
    const std::vector<int64_t>& timestamps_ns, const std::vector<Eigen::Vector2d>& points_in_ground,
    int half_window = 2);

}  // namespace ss
