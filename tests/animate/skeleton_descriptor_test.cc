// The pose descriptor (seed 003 §2.2): invariance to translation, scale and body
// proportions, robustness to a missing joint, the vectorized cost rows against PoseCost,
// and clear errors for skeleton files with missing joints or a wrong joint count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <nlohmann/json.hpp>

#include "animate/skeleton/cost_rows.h"
#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/skeleton_json.h"
#include "animate/skeleton/synthetic_poses.h"
#include "core/error.h"

namespace ss {
namespace {

using Script = std::vector<std::pair<Gesture, int>>;

const Script& AllGestures() {
  static const Script script = {{Gesture::kIdle, 30}, {Gesture::kY, 30}, {Gesture::kM, 30},
                                {Gesture::kC, 30},    {Gesture::kA, 30}, {Gesture::kWalk, 56}};
  return script;
}

// Every joint mapped by x -> scale * x + offset (and optionally rotated about the origin).
SkeletonSequence Transformed(const SkeletonSequence& in, float scale, float dx, float dy,
                             float radians = 0) {
  SkeletonSequence out = in;
  const float c = std::cos(radians), s = std::sin(radians);
  for (auto& f : out.frames) {
    for (auto& j : f.joints) {
      const float x = j.x_px, y = j.y_px;
      j.x_px = scale * (c * x - s * y) + dx;
      j.y_px = scale * (s * x + c * y) + dy;
    }
  }
  return out;
}

// Index of the frame of `b` closest to frame i of `a`.
int Nearest(const PoseDescriptors& a, int i, const PoseDescriptors& b) {
  int best = -1;
  float best_cost = std::numeric_limits<float>::infinity();
  for (int j = 0; j < b.count; ++j) {
    const float c = PoseCost(a, i, b, j);
    if (c < best_cost) {
      best_cost = c;
      best = j;
    }
  }
  return best;
}

TEST(SkeletonDescriptor, InvariantToTranslationAndScale) {
  const LabelledSkeletons poses = MakeGestureSequence(AllGestures(), BodyProportions{});
  const SkeletonSequence moved = Transformed(poses.sequence, 2.7f, -410.0f, 95.5f);
  const SkeletonSequence shrunk = Transformed(poses.sequence, 0.31f, 12.0f, 7.0f);
  const PoseDescriptors a = ComputeDescriptors(poses.sequence, {});
  const PoseDescriptors b = ComputeDescriptors(moved, {});
  const PoseDescriptors c = ComputeDescriptors(shrunk, {});
  ASSERT_EQ(a.count, b.count);
  for (size_t k = 0; k < a.features.size(); ++k) {
    ASSERT_NEAR(a.features[k], b.features[k], 1e-4)
        << "feature " << k / a.count << " frame " << k % a.count;
    ASSERT_NEAR(a.features[k], c.features[k], 1e-4);
  }
  for (int i = 0; i < a.count; i += 7) {
    EXPECT_LT(PoseCost(a, i, b, i), 1e-6);
    EXPECT_LT(PoseCost(a, i, c, i), 1e-6);
  }
  // The descriptor still tells poses apart: frames of different gestures cost far more.
  EXPECT_GT(PoseCost(a, 45, b, 80), 0.05f);  // Y against M
}

TEST(SkeletonDescriptor, RotationOnlyChangesTheOrientationTerm) {
  const LabelledSkeletons poses = MakeGestureSequence(AllGestures(), BodyProportions{});
  const SkeletonSequence turned = Transformed(poses.sequence, 1.0f, 100.0f, 0.0f, 0.5f);
  DescriptorOptions with_orientation;
  DescriptorOptions without_orientation;
  without_orientation.orientation_weight = 0;
  const PoseDescriptors a = ComputeDescriptors(poses.sequence, with_orientation);
  const PoseDescriptors b = ComputeDescriptors(turned, with_orientation);
  const PoseDescriptors a0 = ComputeDescriptors(poses.sequence, without_orientation);
  const PoseDescriptors b0 = ComputeDescriptors(turned, without_orientation);
  // 1 - cos(0.5) of weight 0.25 among 17 pairs of weight 1.5, the orientation's 0.25, 17
  // pair motion terms and the root's motion (both unchanged by the rotation).
  ASSERT_EQ(a.layout.groups, 17 + 1 + 17 + 1);
  const float expected = 0.25f * (1 - std::cos(0.5f)) /
                         (17 * 1.5f + 0.25f + 17 * with_orientation.motion_weight +
                          with_orientation.root_motion_weight);
  for (int i = 0; i < a.count; i += 11) {
    EXPECT_NEAR(PoseCost(a, i, b, i), expected, 1e-5);
    EXPECT_LT(PoseCost(a0, i, b0, i), 1e-6);
  }
}

TEST(SkeletonDescriptor, AnglesIgnoreBodyProportionsAndNormalizedRatiosToo) {
  // The same script played by two bodies: the angle features agree exactly; the ratio
  // features differ by a constant per limb pair, which normalize_ratios removes.
  const LabelledSkeletons a_poses = MakeGestureSequence(AllGestures(), BodyProportions{});
  const LabelledSkeletons b_poses = MakeGestureSequence(AllGestures(), OtherBody());
  ASSERT_EQ(a_poses.sequence.size(), b_poses.sequence.size());
  const PoseDescriptors a = ComputeDescriptors(a_poses.sequence, {});
  const PoseDescriptors b = ComputeDescriptors(b_poses.sequence, {});
  double ratio_gap = 0;
  for (int p = 0; p < a.layout.pairs; ++p) {
    for (int i = 0; i < a.count; ++i) {
      ASSERT_NEAR(a.feature(3 * p, i), b.feature(3 * p, i), 1e-4);
      ASSERT_NEAR(a.feature(3 * p + 1, i), b.feature(3 * p + 1, i), 1e-4);
      ratio_gap = std::max(ratio_gap, std::abs(static_cast<double>(a.feature(3 * p + 2, i)) -
                                               b.feature(3 * p + 2, i)));
    }
  }
  EXPECT_GT(ratio_gap, 0.1);  // the raw ratios do see the proportions
  DescriptorOptions normalized;
  normalized.normalize_ratios = true;
  const PoseDescriptors an = ComputeDescriptors(a_poses.sequence, normalized);
  const PoseDescriptors bn = ComputeDescriptors(b_poses.sequence, normalized);
  for (int i = 0; i < an.count; ++i) EXPECT_LT(PoseCost(an, i, bn, i), 1e-5) << "frame " << i;
  // Each frame's nearest frame of the other body shows the same gesture: always with
  // normalized ratios; the raw ratios' constant offset confuses some frames (92% here).
  int same = 0, same_normalized = 0;
  for (int i = 0; i < a.count; ++i) {
    same += a_poses.labels[i] == b_poses.labels[Nearest(a, i, b)];
    same_normalized += a_poses.labels[i] == b_poses.labels[Nearest(an, i, bn)];
  }
  EXPECT_GE(same, a.count * 85 / 100);
  EXPECT_EQ(same_normalized, a.count);
}

TEST(SkeletonDescriptor, RobustToAMissingJoint) {
  const LabelledSkeletons poses = MakeGestureSequence(AllGestures(), BodyProportions{});
  const PoseDescriptors library = ComputeDescriptors(poses.sequence, {});
  const int wrist = *HumanSkeleton().JointIndex("wrist_l");
  const int knee = *HumanSkeleton().JointIndex("knee_r");
  SkeletonSequence damaged = poses.sequence;
  for (size_t i = 0; i < damaged.frames.size(); ++i) {
    damaged.frames[i].joints[i % 2 ? wrist : knee].present = false;
  }
  const PoseDescriptors d = ComputeDescriptors(damaged, {});
  // One pair (elbow angle) uses the wrist; the knee's pair and the knee-hip pair use the knee.
  DescriptorOptions poses_only;
  poses_only.motion_weight = 0;
  const PoseDescriptors d0 = ComputeDescriptors(damaged, poses_only);
  EXPECT_NEAR(d0.coverage(1), 1 - 1.5f / (17 * 1.5f + 0.25f), 1e-5);
  EXPECT_NEAR(d0.coverage(0), 1 - 2 * 1.5f / (17 * 1.5f + 0.25f), 1e-5);
  // The motion terms of a pair need it in both frames of the window (5 frames each side at
  // 25 fps: there the other joint is missing). Frame 20 (knee): its two pairs and, from
  // frames 15 and 25 (wrist), the elbow's motion are gone.
  // (The coverage counts the pose terms only.)
  const float w = d.layout.total_weight, wm = DescriptorOptions{}.motion_weight;
  EXPECT_NEAR(d.present_weight[20], w - (2 * 1.5f + wm), 1e-4);
  EXPECT_NEAR(d.present_weight[21], w - (1.5f + 2 * wm), 1e-4);
  EXPECT_NEAR(d.coverage(20), d0.coverage(0), 1e-6);
  EXPECT_NEAR(d.coverage(21), d0.coverage(1), 1e-6);
  int same = 0;
  for (int i = 0; i < d.count; ++i) {
    EXPECT_LT(PoseCost(d, i, library, i), 1e-6);  // the terms it has agree exactly
    same += poses.labels[Nearest(d, i, library)] == poses.labels[i];
  }
  EXPECT_EQ(same, d.count);
  // A missing joint on the source side is handled alike.
  for (int i = 0; i < d.count; i += 5) EXPECT_LT(PoseCost(library, i, d, i), 1e-6);
}

// Every joint's track, sampled every `step`-th frame, at fps / step.
SkeletonSequence Subsampled(const SkeletonSequence& in, int step) {
  SkeletonSequence out = in;
  out.frames.clear();
  for (int i = 0; i < in.size(); i += step) {
    out.frames.push_back(in.frames[i]);
    out.frames.back().frame = i / step;
  }
  out.fps = in.fps / step;
  return out;
}

TEST(SkeletonDescriptor, MotionTermIsMeasuredInSecondsAndTellsMovingFromHolding) {
  // idle 30, Y 30 (with a blend into it), walk 56 at 25 fps.
  const LabelledSkeletons poses = MakeGestureSequence(
      {{Gesture::kIdle, 30}, {Gesture::kY, 30}, {Gesture::kWalk, 56}}, BodyProportions{});
  ASSERT_EQ(poses.sequence.fps, 25);
  DescriptorOptions o;
  o.motion_window_s = 0.24f;  // 6 frames at 25 fps, 2 at 25 / 3
  const PoseDescriptors d = ComputeDescriptors(poses.sequence, o);
  const PoseDescriptors third = ComputeDescriptors(Subsampled(poses.sequence, 3), o);
  const int m0 = d.layout.first_motion_feature;
  ASSERT_EQ(d.layout.dim, m0 + d.layout.pairs + 1);     // and the root's
  auto motion = [&](const PoseDescriptors& x, int i) {  // the mean pair motion feature
    float sum = 0;
    for (int p = 0; p < x.layout.pairs; ++p) sum += x.feature(m0 + p, i);
    return sum / x.layout.pairs;
  };
  // The same movement at a third of the frame rate: the same motion features (the window
  // ends fall on the same instants), though a frame then spans three times the change.
  for (int i = 2; i + 2 < third.count; ++i) {
    for (int p = 0; p <= d.layout.pairs; ++p) {  // and the root's
      ASSERT_NEAR(third.feature(m0 + p, i), d.feature(m0 + p, 3 * i), 1e-5)
          << "pair " << p << " frame " << 3 * i;
    }
  }
  // The idle and the held Y only sway (3 degrees; the idle's sway, at 0.2 rad of phase a
  // frame, is fast); the walk swings the legs and arms. Measured: 0.104, 0.041, 0.210.
  float idle = 0, held = 0, walk = 0;
  for (int i = 0; i < 24; ++i) idle += motion(d, i) / 24;  // (the window ends before the blend)
  for (int i = 44; i < 62; ++i) held += motion(d, i) / 18;
  for (int i = 80; i < d.count; ++i) walk += motion(d, i) / (d.count - 80);
  std::printf("mean pair motion feature: idle %.3f, Y held %.3f, walk %.3f\n", idle, held, walk);
  EXPECT_LT(idle, 0.15f);
  EXPECT_LT(held, 0.08f);
  EXPECT_GT(walk, 0.18f);
  EXPECT_GT(walk, 1.8f * idle);
  EXPECT_GT(motion(d, 33), 0.18f);  // in the blend into Y
  // Across clips: each clip's motion comes from its own frames and frame rate.
  const SkeletonSequence slow = Subsampled(poses.sequence, 3);
  const PoseDescriptors both =
      ComputeDescriptors(std::vector<const SkeletonSequence*>{&poses.sequence, &slow}, o);
  ASSERT_EQ(both.clip_starts, (std::vector<int>{0, d.count}));
  EXPECT_EQ(FrameRateAt(both, d.count + 1), 25.0 / 3);
  for (int i = 0; i < third.count; ++i) {
    for (int k = 0; k < d.layout.dim; ++k)
      ASSERT_EQ(both.feature(k, d.count + i), third.feature(k, i));
  }
  // A clip shorter than the window and a gap in the frame numbers leave the motion out.
  SkeletonSequence gap = poses.sequence;
  for (int i = 60; i < gap.size(); ++i) gap.frames[i].frame += 100;  // 4 s missing
  const PoseDescriptors g = ComputeDescriptors(gap, o);
  EXPECT_FALSE(g.has(g.layout.first_motion_group, 60));
  EXPECT_TRUE(g.has(g.layout.first_motion_group, 80));
  EXPECT_TRUE(g.complete(80));
  EXPECT_FALSE(g.complete(60));
}

TEST(SkeletonDescriptor, CostRowsAgreeWithPoseCost) {
  // The GEMM-like kernel for complete frames, the direct sums for incomplete ones, and
  // the exclusion of sources with too little coverage.
  std::mt19937 rng(4);
  GestureScriptOptions noisy;
  noisy.noise_px = 2.0f;
  const LabelledSkeletons t =
      MakeGestureSequence({{Gesture::kY, 20}, {Gesture::kWalk, 30}}, OtherBody(), noisy);
  SkeletonSequence targets = t.sequence;
  SkeletonSequence sources = MakeGestureSequence(AllGestures(), BodyProportions{}).sequence;
  std::uniform_int_distribution<int> joint(0, 14);
  for (int i = 0; i < targets.size(); i += 3) targets.frames[i].joints[joint(rng)].present = false;
  for (int i = 0; i < sources.size(); i += 4) sources.frames[i].joints[joint(rng)].present = false;
  for (int j = 0; j < 12; ++j) sources.frames[10].joints[j].present = false;  // too little left
  const PoseDescriptors td = ComputeDescriptors(targets, {});
  const PoseDescriptors sd = ComputeDescriptors(sources, {});
  const DescriptorCostRows rows(td, sd, 0.5f);
  int usable = 0;
  for (int s = 0; s < sd.count; ++s) usable += sd.coverage(s) >= 0.5f;
  EXPECT_LT(sd.coverage(10), 0.5f);
  EXPECT_EQ(rows.usable_sources(), usable);
  std::vector<float> out(static_cast<size_t>(5) * sd.count);
  for (int t0 = 0; t0 < td.count; t0 += 5) {
    const int n = std::min(5, td.count - t0);
    rows.Compute(t0, n, out.data());
    for (int i = 0; i < n; ++i) {
      for (int s = 0; s < sd.count; ++s) {
        const float got = out[static_cast<size_t>(i) * sd.count + s];
        if (sd.coverage(s) < 0.5f) {  // e.g. frame 10, or a frame without its neck
          EXPECT_TRUE(std::isinf(got));
          continue;
        }
        ASSERT_NEAR(got, PoseCost(td, t0 + i, sd, s), 1e-4)
            << "target " << t0 + i << " source " << s;
      }
    }
  }
}

TEST(SkeletonDescriptor, DifferentSkeletonsAreRefused) {
  const LabelledSkeletons poses = MakeGestureSequence({{Gesture::kY, 5}}, BodyProportions{});
  SkeletonSequence other;
  other.clip = "quadruped.json";
  other.skeleton = MakeSkeletonDef(
      "quadruped", {"snout", "withers", "tail", "front", "hind"},
      {{"withers", "snout"}, {"withers", "tail"}, {"withers", "front"}, {"tail", "hind"}}, "test");
  other.frames.push_back(EmptySkeletonFrame(other.skeleton, 0));
  try {
    ComputeDescriptors(std::vector<const SkeletonSequence*>{&poses.sequence, &other}, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("quadruped.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("same skeletal structure"), std::string::npos) << e.what();
  }
}

std::string ErrorOf(const nlohmann::json& json) {
  try {
    SkeletonSequenceFromJson(json, "clip.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SkeletonDescriptor, SkeletonFileErrorsNameTheFrameAndJoint) {
  nlohmann::json joints = nlohmann::json::object();
  for (const auto& name : HumanSkeleton().joints) joints[name] = {100, 200};
  nlohmann::json good = {{"format", "spritestation.skeleton_sequence"},
                         {"version", 1},
                         {"skeleton", "human14"},
                         {"frames", {{{"frame", 0}, {"joints", joints}}}}};
  EXPECT_EQ(SkeletonSequenceFromJson(good, "clip.json").size(), 1);

  nlohmann::json missing = good;
  missing["frames"][0]["joints"].erase("elbow_r");
  const std::string m = ErrorOf(missing);
  EXPECT_NE(m.find("clip.json"), std::string::npos) << m;
  EXPECT_NE(m.find("frame 0"), std::string::npos) << m;
  EXPECT_NE(m.find("'elbow_r' is missing"), std::string::npos) << m;

  nlohmann::json short_array = good;
  short_array["frames"][0]["joints"] = nlohmann::json::array();
  for (int j = 0; j < 14; ++j) short_array["frames"][0]["joints"].push_back({1, 2});
  const std::string s = ErrorOf(short_array);
  EXPECT_NE(s.find("has 14 joints"), std::string::npos) << s;
  EXPECT_NE(s.find("has 15"), std::string::npos) << s;

  nlohmann::json unknown = good;
  unknown["frames"][0]["joints"]["tail"] = {1, 2};
  EXPECT_NE(ErrorOf(unknown).find("unknown joint 'tail'"), std::string::npos);

  nlohmann::json bad_value = good;
  bad_value["frames"][0]["joints"]["head"] = {1};
  EXPECT_NE(ErrorOf(bad_value).find("joint 'head'"), std::string::npos);

  // A frame with a wrong joint count reaching the descriptor (built in code) is refused too.
  SkeletonSequence sequence = SkeletonSequenceFromJson(good, "clip.json");
  sequence.clip = "clip.json";
  sequence.frames[0].joints.pop_back();
  try {
    ComputeDescriptors(sequence, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has 14 joints"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ss
