#pragma once
// Labels from synthetic truth, so that tests and demos can train without a person
// (seed 000 §3 asks a person whether a pair would make a smooth transition). A pair is
// "accept" when both sprites have the same pose label and look alike:
//  - when both truths carry key points (the synthetic sets of synthetic.h do): every
//    key point visible in either sprite moved at most max_keypoint_displacement_m in the
//    billboard plane (a point hidden in both is not seen to move), the feet matched as an
//    unordered set (a picture does not show which leg is which);
//  - otherwise (e.g. a studio session's subjects.csv): headings and gait phases are close.
// Key points measure closeness the way an eye does: a phase tolerance alone would call a
// barely moving sniff "different" and a fast trot "alike" (docs/transitions.md).
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pipeline/transitions/training.h"

namespace ss {

struct SpriteTruth {
  std::string pose;                  // "walk", "trot", "idle", "stand", ...
  double heading_rad = 0;            // facing direction on the ground
  double gait_phase = std::nan("");  // cycles in [0, 1); NaN when the pose has no gait
  // Optional: key points as (x, z) pairs in the billboard plane, metres, x from the body
  // centre, z up from the floor; the same points in the same order per pose.
  std::vector<double> keypoints_m;
  // Per key point: 1 when the picture shows it, 0 when a nearer part hides it. Empty: all
  // visible. Only points visible in at least one sprite of a pair are compared.
  std::vector<uint8_t> keypoint_visible;
  // Key points from this index on (the feet) form an unordered set: a pair is compared under
  // the matching of one sprite's feet to the other's that moves them least (a side view at
  // gait phase p and p + 0.5 draws the same picture with the legs swapped). -1: every point
  // keeps its identity.
  int unordered_from = -1;
};

struct TruthLabelOptions {
  // headings further apart than this are not alike, radians (>= 0)
  double max_heading_difference_rad = 6.0 * M_PI / 180.0;
  double max_phase_difference = 0.04;  // gait phases further apart are not, cycles (>= 0)
  // when both truths have key points: the most a key point may move, metres (>= 0; 0.004 is
  // 1 px at 250 px/m)
  double max_keypoint_displacement_m = 0.004;
  // Share (0..1) of the rejects sampled as near misses (same pose, heading and phase within
  // `near_miss_factor` times the tolerances) rather than uniformly; the rest are uniform random
  // rejects.
  double near_miss_fraction = 0.5;
  double near_miss_factor = 3.0;  // how many tolerances a near miss may be off, unitless (>= 1)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The largest displacement (metres) among the key points visible in a or in b (a point
// hidden in both is not seen to move), the points from unordered_from on matched to each
// other as the set that minimizes that largest displacement (bottleneck matching; a matched
// pair hidden in both is not compared); infinity when the sets do not correspond (counts,
// flags, or unordered_from differ).
double KeypointDisplacement(const SpriteTruth& a, const SpriteTruth& b);

// Circular differences: headings in radians (0..pi), phases in cycles (0..0.5).
double HeadingDifference(double a_rad, double b_rad);
double PhaseDifference(double a, double b);

bool TruthAccepts(const SpriteTruth& a, const SpriteTruth& b, const TruthLabelOptions& options);

// The share of sprite pairs the truth accepts, from `rows` random sprites against all
// others (every pair when rows >= n): the prior stage 2 is calibrated for.
double TruthPositiveRate(std::span<const SpriteTruth> truth, const TruthLabelOptions& options,
                         int rows, uint64_t seed);

// About `count` labelled pairs of distinct sprites: half accepts (as many as exist), half
// rejects. `ids[k]` is the bank id of the sprite with truth `truth[k]`. Deterministic per seed.
std::vector<Label> LabelsFromTruth(std::span<const int64_t> ids, std::span<const SpriteTruth> truth,
                                   size_t count, const TruthLabelOptions& options, uint64_t seed);

}  // namespace ss
