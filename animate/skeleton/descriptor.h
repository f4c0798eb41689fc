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
// Motion (not in the paper: single poses cannot tell a slow step or a turn from standing),
// measured between the frames a and b motion_window_s seconds before and after a frame
// (one-sided at a clip's ends; Δt = t_b - t_a from the frame numbers and the clip's fps):
//   per limb pair, how fast its angle and log ratio change,
//     m = |(Δcos θ, Δsin θ, Δlog r)| / Δt  [1/s],       feature μ = m / (m + motion_scale);
//   the root limb's midpoint, how fast it crosses the image in root-limb lengths,
//     v = |Δ midpoint| / (mean root length) / Δt [1/s], feature ν = v / (v + root_motion_scale).
// Translation, scale and rotation of the image leave both unchanged; so do body proportions
// for μ (a constant log-ratio offset cancels in Δlog r), while ν is relative to the root
// limb (a body with a shorter root limb crossing the image as fast has a larger ν).
//
// Cost between two frames = weighted mean of the terms both frames have:
//   angle pair:  w_angle * (1 - cos(θ_a - θ_b))
//   ratio pair:  w_ratio * (log r_a - log r_b)^2
//   orientation: w_orient * (1 - cos(φ_a - φ_b))
//   motion pair: w_motion * (μ_a - μ_b)^2
//   root motion: w_root_motion * (ν_a - ν_b)^2
// A term needs all its joints present and its limbs longer than min_limb_px (a motion
// term: its pair in both frames of the window); terms a frame lacks are dropped and the
// sum renormalized by the weight that remains.
#include <cstdint>
#include <string>
#include <vector>

#include "animate/skeleton/skeleton.h"

namespace ss {

struct DescriptorOptions {
  float angle_weight = 1.0f;         // per limb pair, on 1 - cos(Δangle)
  float ratio_weight = 0.5f;         // per limb pair, on (Δ log length ratio)^2
  float orientation_weight = 0.25f;  // root limb's image orientation; 0 = rotation invariant
  bool normalize_ratios = false;     // subtract each sequence's median log ratio per pair
  float min_limb_px = 1.0f;          // shorter limbs leave their terms undefined
  float no_overlap_cost = 1.0f;      // cost when two frames share no term
  float motion_weight = 1.0f;        // per limb pair, on (Δμ)^2; 0 = poses only
  float motion_window_s = 0.2f;      // seconds before and after a frame the rate is measured over
  float motion_scale = 0.25f;        // rate (1/s) at which μ = 1/2
  float root_motion_weight = 2.0f;   // on (Δν)^2; 0 = none (only with motion_weight > 0)
  float root_motion_scale = 0.15f;   // root speed (root lengths per second) at which ν = 1/2
  double default_fps = 30;           // for sequences that do not give theirs
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// Where each feature sits. Per limb pair p: features 3p, 3p+1 = cos, sin of the angle,
// 3p+2 = log ratio (one term group); then cos, sin of the root orientation (one group);
// then one motion feature per pair (a group each) and the root's motion (one group).
struct DescriptorLayout {
  int pairs = 0;
  int first_motion_group = 0;    // == groups when there is no motion term
  int first_motion_feature = 0;  // == dim likewise
  int dim = 0;
  int groups = 0;
  std::vector<float> feature_weight;  // w_k: the 1 - cos terms are 1/2 |Δ(cos, sin)|^2
  std::vector<int> feature_group;
  std::vector<float> group_weight;  // W_g: sum of its terms' weights
  float total_weight = 0;
  float pose_total_weight = 0;  // of the groups before the motion terms
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
  std::vector<float> pose_weight;     // [i]: the same over its pose groups (no motion)
  std::vector<int> clip_starts;       // first frame of each clip
  std::vector<double> clip_fps;       // its frame rate (the default where the clip gives none)

  float feature(int k, int i) const { return features[static_cast<size_t>(k) * count + i]; }
  bool has(int g, int i) const { return present[static_cast<size_t>(g) * count + i] != 0; }
  bool complete(int i) const { return present_weight[i] >= layout.total_weight; }
  // Share of the pose terms' weight frame i has (motion terms aside: a clip too short
  // for the motion window is still as usable).
  float coverage(int i) const { return pose_weight[i] / layout.pose_total_weight; }
};

// Descriptors of every frame of `sequence`.
PoseDescriptors ComputeDescriptors(const SkeletonSequence& sequence,
                                   const DescriptorOptions& options);
// Of several clips (same skeleton definition) one after the other; throws InputError when
// their definitions differ.
PoseDescriptors ComputeDescriptors(const std::vector<const SkeletonSequence*>& clips,
                                   const DescriptorOptions& options);

// The cost between frame i of `a` (a target) and frame j of `b` (a source), from the
// definition above; 0 when target frame i has no term at all. `motion` = false leaves the
// motion terms out (the refinement's movement detector compares poses only).
float PoseCost(const PoseDescriptors& a, int i, const PoseDescriptors& b, int j,
               bool motion = true);

// cost(x_t, x_{t+1}) for t = 0..n-2, poses only: how much the sequence moves per frame (§2.3).
std::vector<float> SequentialCost(const PoseDescriptors& sequence);

// The frame rate of the clip frame i belongs to (30 when `d` has no clips: built by hand).
double FrameRateAt(const PoseDescriptors& d, int i);

}  // namespace ss
