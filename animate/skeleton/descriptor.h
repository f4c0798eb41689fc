#pragma once
// The pose descriptor and matching cost of seed 003 §2.2: not joint positions but, for
// every pair of limbs sharing a joint, the signed angle between them and the log of their
// length ratio (plus, optionally, the image orientation of the root limb).
//
// Invariance (exact): translation and uniform scale of the image, for every term; body
// proportions for the angle terms (a longer forearm does not change the elbow angle);
// rotation in the image for everything but the orientation term. The ratio terms change
// with proportions by a constant per pair, log(L_b / L_a); `normalize_ratios` subtracts
// each sequence's median log ratio, which removes that constant. docs/skeletons.md.
//
// Cost between two frames = weighted mean of the terms both frames have:
//   angle pair:  w_angle * (1 - cos(θ_a - θ_b))
//   ratio pair:  w_ratio * (log r_a - log r_b)^2
//   orientation: w_orient * (1 - cos(φ_a - φ_b))
// A term needs all its joints present and its limbs longer than min_limb_px; terms a
// frame lacks are dropped and the sum renormalized by the weight that remains.
#include <cstdint>
#include <string>
#include <vector>

#include "animate/skeleton/skeleton.h"

namespace ss {

struct DescriptorOptions {
  float angle_weight = 1.0f;        // per limb pair, on 1 - cos(Δangle)
  float ratio_weight = 0.5f;        // per limb pair, on (Δ log length ratio)^2
  float orientation_weight = 0.25f;  // root limb's image orientation; 0 = rotation invariant
  bool normalize_ratios = false;    // subtract each sequence's median log ratio per pair
  float min_limb_px = 1.0f;         // shorter limbs leave their terms undefined
  float no_overlap_cost = 1.0f;     // cost when two frames share no term
  bool IsValid(std::string* why) const;
};

// Where each feature sits. Per limb pair p: features 3p, 3p+1 = cos, sin of the angle,
// 3p+2 = log ratio (one term group); then cos, sin of the root orientation (one group).
struct DescriptorLayout {
  int pairs = 0;
  int dim = 0;
  int groups = 0;
  std::vector<float> feature_weight;  // w_k: the 1 - cos terms are 1/2 |Δ(cos, sin)|^2
  std::vector<int> feature_group;
  std::vector<float> group_weight;    // W_g: sum of its terms' weights
  float total_weight = 0;
  float no_overlap_cost = 1.0f;
};

DescriptorLayout MakeDescriptorLayout(const SkeletonDef& def, const DescriptorOptions& options);

// Descriptors of a run of frames, feature-major (the matcher streams one feature of many
// frames at a time).
struct PoseDescriptors {
  DescriptorLayout layout;
  int count = 0;
  std::vector<float> features;        // [k * count + i]; 0 where the term is undefined
  std::vector<uint8_t> present;       // [g * count + i]
  std::vector<float> present_weight;  // [i]: sum of W_g over the frame's groups

  float feature(int k, int i) const { return features[static_cast<size_t>(k) * count + i]; }
  bool has(int g, int i) const { return present[static_cast<size_t>(g) * count + i] != 0; }
  bool complete(int i) const { return present_weight[i] >= layout.total_weight; }
  float coverage(int i) const { return present_weight[i] / layout.total_weight; }
};

// Descriptors of every frame of `sequence`.
PoseDescriptors ComputeDescriptors(const SkeletonSequence& sequence, const DescriptorOptions& options);
// Of several clips (same skeleton definition) one after the other; throws InputError when
// their definitions differ.
PoseDescriptors ComputeDescriptors(const std::vector<const SkeletonSequence*>& clips,
                                   const DescriptorOptions& options);

// The cost between frame i of `a` (a target) and frame j of `b` (a source), from the
// definition above; 0 when target frame i has no term at all.
float PoseCost(const PoseDescriptors& a, int i, const PoseDescriptors& b, int j);

// cost(x_t, x_{t+1}) for t = 0..n-2: how much the sequence moves per frame (§2.3).
std::vector<float> SequentialCost(const PoseDescriptors& sequence);

}  // namespace ss
