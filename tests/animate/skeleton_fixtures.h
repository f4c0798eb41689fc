#pragma once
// Skeleton clips shared by the skeleton unit tests (tests/animate) and the `skeleton track` /
// `match` command tests (tests/e2e/skeleton_cli_test.cc): the match's target and source
// (gesture scripts played by two bodies) and the tracker's rendered walking stick figure.
#include <vector>

#include <opencv2/core.hpp>

#include "animate/skeleton/skeleton.h"
#include "animate/skeleton/synthetic_poses.h"

namespace ss::testing {

// The target: YMCA and walking by the reference body. The source: the same gestures in
// another order, slower, by a differently proportioned body, with noise. (No idle in the
// target: the synthetic idle pose is also a phase of the walk.)
LabelledSkeletons Target();
LabelledSkeletons Source();

// The tracked clip: kFrames frames, an occluder over the subject's left arm and leg in
// frames kOccludedFrom..kOccludedTo when asked for.
constexpr int kFrames = 40;
constexpr int kOccludedFrom = 20, kOccludedTo = 24;  // inclusive

// The truth: the walk of synthetic_poses, drifting right by 2 px per frame.
SkeletonSequence Truth();

// Limbs as grey lines, joints as dark discs with a bright centre, sensor noise; the
// occluder (a uniform box over the subject's left arm and leg) in the occluded frames
// when `with_occluder`.
std::vector<cv::Mat> RenderClip(const SkeletonSequence& truth, bool with_occluder);

// The distance between two joints, pixels.
float Error(const JointSample& a, const JointSample& b);

}  // namespace ss::testing
