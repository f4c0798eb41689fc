// The whole articulated-sprite match: gesture accuracy across bodies and the penalties'
// effect (Figure 2). The `spritestation skeleton import` / `match` commands are tested in
// tests/e2e/skeleton_cli_test.cc.
#include <gtest/gtest.h>

#include <vector>

#include "animate/skeleton/skeleton_match.h"
#include "animate/skeleton/synthetic_poses.h"
#include "tests/animate/skeleton_fixtures.h"

namespace ss {
namespace {

using testing::Source;
using testing::Target;

double Accuracy(const std::vector<int>& path, const LabelledSkeletons& t,
                const LabelledSkeletons& s) {
  int same = 0;
  for (size_t i = 0; i < path.size(); ++i) same += t.labels[i] == s.labels[path[i]];
  return static_cast<double>(same) / static_cast<double>(path.size());
}

TEST(SkeletonMatch, ChoosesFramesOfTheSameGestureAcrossBodies) {
  const LabelledSkeletons target = Target();
  const LabelledSkeletons source = Source();
  SkeletonMatchOptions options;
  options.descriptor.normalize_ratios = true;  // two bodies: remove the limb ratios' offset
  const SkeletonMatchResult r = MatchSkeletons(target.sequence, {&source.sequence}, options);
  ASSERT_TRUE(r.without_penalties && r.refined);
  // Measured 77% here (1 px joint noise on both sides): below the 95% target,
  // which the noise-free case reaches (SkeletonRefine.OneSourceMovementPerTargetMovement).
  EXPECT_GE(Accuracy(r.with_penalties.source_frames, target, source), 0.75);
  EXPECT_GE(Accuracy(r.source_frames, target, source), 0.75);
  // Figure 2: the penalties remove the freezes and stutters the plain match has.
  const MatchStats& without = r.without_penalties->stats;
  const MatchStats& with = r.with_penalties.stats;
  EXPECT_GT(without.freezes + without.stutters, 3 * (with.freezes + with.stutters) + 5);
  EXPECT_LE(with.longest_freeze, 5);
  EXPECT_LE(r.refined->stats.longest_freeze, 5);
  ASSERT_EQ(r.chosen.size(), target.labels.size());
  EXPECT_EQ(r.chosen[10].frame, source.sequence.frames[r.source_frames[10]].frame);
}

}  // namespace
}  // namespace ss
