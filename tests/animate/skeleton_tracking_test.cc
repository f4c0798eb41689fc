// Lucas-Kanade joint tracking (seed 003 §2.1) on rendered frames: a walking stick figure
// with a marker on each joint drifts across the image; the tracked joints must stay
// within a pixel or two of the truth, occluded frames marked by the user must be
// interpolated close to the truth, and unmarked occlusions must be reported as failures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "animate/skeleton/lk_tracker.h"
#include "animate/skeleton/skeleton_json.h"
#include "animate/skeleton/synthetic_poses.h"
#include "core/error.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

constexpr int kFrames = 40;
constexpr int kOccludedFrom = 20, kOccludedTo = 24;  // inclusive

// The truth: the walk of synthetic_poses, drifting right by 2 px per frame.
SkeletonSequence Truth() {
  GestureScriptOptions o;
  o.scale_px = 80;
  o.x_px = 250;
  o.y_px = 250;
  SkeletonSequence s =
      MakeGestureSequence({{Gesture::kWalk, kFrames}}, BodyProportions{}, o).sequence;
  for (int f = 0; f < s.size(); ++f) {
    for (auto& j : s.frames[f].joints) j.x_px += 2.0f * f;
  }
  return s;
}

cv::Point Fixed(float x, float y) {  // 4 fractional bits for sub-pixel drawing
  return {static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16))};
}

// Limbs as grey lines, joints as dark discs with a bright centre, sensor noise; an
// occluder (a uniform box over the subject's left arm and leg) when `occluded`.
cv::Mat Render(const SkeletonFrame& frame, bool occluded) {
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(190));
  const SkeletonDef& def = HumanSkeleton();
  for (const Limb& l : def.limbs) {
    const JointSample& a = frame.joints[l.from];
    const JointSample& b = frame.joints[l.to];
    cv::line(image, Fixed(a.x_px, a.y_px), Fixed(b.x_px, b.y_px), cv::Scalar(120), 2, cv::LINE_AA,
             4);
  }
  for (const JointSample& j : frame.joints) {
    cv::circle(image, Fixed(j.x_px, j.y_px), 6 * 16, cv::Scalar(35), cv::FILLED, cv::LINE_AA, 4);
    cv::circle(image, Fixed(j.x_px, j.y_px), 2 * 16, cv::Scalar(235), cv::FILLED, cv::LINE_AA, 4);
  }
  if (occluded) {
    const JointSample& pelvis = frame.joints[*def.JointIndex("pelvis")];
    cv::rectangle(image, cv::Rect(static_cast<int>(pelvis.x_px) + 8, 100, 140, 360), cv::Scalar(90),
                  cv::FILLED);
  }
  cv::Mat noise(image.size(), CV_16SC1);
  cv::randn(noise, 0, 2.0);
  cv::Mat out;
  image.convertTo(out, CV_16SC1);
  out += noise;
  out.convertTo(out, CV_8UC1);
  return out;
}

std::vector<cv::Mat> RenderClip(const SkeletonSequence& truth, bool with_occluder) {
  cv::setRNGSeed(5);
  std::vector<cv::Mat> images;
  for (int f = 0; f < truth.size(); ++f) {
    images.push_back(
        Render(truth.frames[f], with_occluder && f >= kOccludedFrom && f <= kOccludedTo));
  }
  return images;
}

float Error(const JointSample& a, const JointSample& b) {
  return std::hypot(a.x_px - b.x_px, a.y_px - b.y_px);
}

// The joints the occluder hides (the subject's left is the image's right).
bool UnderOccluder(const std::string& joint) {
  return joint == "shoulder_l" || joint == "elbow_l" || joint == "wrist_l" || joint == "knee_l" ||
         joint == "ankle_l";
}

TEST(SkeletonTracking, TracksAWalkingFigureWithinAPixel) {
  const SkeletonSequence truth = Truth();
  const std::vector<cv::Mat> images = RenderClip(truth, false);
  const TrackingResult r = TrackJoints(images, truth.frames[0], {}, HumanSkeleton());
  ASSERT_EQ(r.sequence.size(), kFrames);
  EXPECT_TRUE(r.failures.empty()) << r.failures.size() << " failures, first in frame "
                                  << r.failures[0].frame;
  std::vector<float> errors;
  for (int f = 1; f < kFrames; ++f) {
    for (size_t j = 0; j < truth.frames[f].joints.size(); ++j) {
      const JointSample& got = r.sequence.frames[f].joints[j];
      ASSERT_TRUE(got.present) << "frame " << f << " joint " << HumanSkeleton().joints[j];
      errors.push_back(Error(got, truth.frames[f].joints[j]));
    }
  }
  std::sort(errors.begin(), errors.end());
  const float median = errors[errors.size() / 2];
  const float worst = errors.back();
  RecordProperty("median_error_px", std::to_string(median));
  EXPECT_LT(median, 0.5f);
  EXPECT_LT(worst, 2.0f);
}

TEST(SkeletonTracking, MarkedOcclusionIsInterpolated) {
  const SkeletonSequence truth = Truth();
  const std::vector<cv::Mat> images = RenderClip(truth, true);
  std::vector<bool> occluded(kFrames, false);
  for (int f = kOccludedFrom; f <= kOccludedTo; ++f) occluded[f] = true;
  const TrackingResult r = TrackJoints(images, truth.frames[0], occluded, HumanSkeleton());
  EXPECT_TRUE(r.failures.empty()) << r.failures.size() << " failures, first in frame "
                                  << r.failures[0].frame;
  float worst_interpolated = 0, worst_tracked = 0;
  for (int f = 1; f < kFrames; ++f) {
    for (size_t j = 0; j < truth.frames[f].joints.size(); ++j) {
      const JointSample& got = r.sequence.frames[f].joints[j];
      ASSERT_TRUE(got.present) << "frame " << f << " joint " << HumanSkeleton().joints[j];
      EXPECT_EQ(got.interpolated, occluded[f]) << "frame " << f;
      const float e = Error(got, truth.frames[f].joints[j]);
      float& worst = occluded[f] ? worst_interpolated : worst_tracked;
      worst = std::max(worst, e);
    }
  }
  // Five frames of a walk bridged by the Hermite curve; tracking resumes after them.
  EXPECT_LT(worst_interpolated, 3.0f);
  EXPECT_LT(worst_tracked, 2.0f);
}

TEST(SkeletonTracking, UnmarkedOcclusionIsReportedPerFrame) {
  const SkeletonSequence truth = Truth();
  const std::vector<cv::Mat> images = RenderClip(truth, true);
  const TrackingResult r = TrackJoints(images, truth.frames[0], {}, HumanSkeleton());
  ASSERT_FALSE(r.failures.empty());
  bool first_occluded_frame = false;
  for (const TrackingFailure& failure : r.failures) {
    SCOPED_TRACE("frame " + std::to_string(failure.frame) + " joint " +
                 HumanSkeleton().joints[failure.joint]);
    EXPECT_GE(failure.frame, kOccludedFrom);
    EXPECT_TRUE(failure.reason == "lost" || failure.reason == "forward-backward");
    // A failed joint is left missing in that frame.
    EXPECT_FALSE(r.sequence.frames[failure.frame].joints[failure.joint].present);
    if (failure.frame == kOccludedFrom && UnderOccluder(HumanSkeleton().joints[failure.joint])) {
      first_occluded_frame = true;
    }
  }
  EXPECT_TRUE(first_occluded_frame);
  // Nothing goes wrong silently: a joint the tracker keeps is where the truth is, and
  // the hidden joints are never kept while hidden.
  for (int f = 1; f < kFrames; ++f) {
    for (size_t j = 0; j < truth.frames[f].joints.size(); ++j) {
      const JointSample& got = r.sequence.frames[f].joints[j];
      if (!got.present) continue;
      SCOPED_TRACE("frame " + std::to_string(f) + " joint " + HumanSkeleton().joints[j]);
      EXPECT_LT(Error(got, truth.frames[f].joints[j]), 2.0f);
      EXPECT_FALSE(f >= kOccludedFrom && f <= kOccludedTo &&
                   UnderOccluder(HumanSkeleton().joints[j]));
    }
  }
}

TEST(SkeletonTracking, TrackCommandOnAFolderOfFrames) {
  // `spritestation skeleton track` on PNG frames, the user's joints for frame 0 and the
  // occluded frames marked on the command line.
  const SkeletonSequence truth = Truth();
  const std::vector<cv::Mat> images = RenderClip(truth, true);
  testing::ScratchDir dir;
  std::filesystem::create_directories(dir / "frames");
  for (size_t f = 0; f < images.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "frames/%04zu.png", f);
    ASSERT_TRUE(cv::imwrite(dir / name, images[f]));
  }
  nlohmann::json joints = nlohmann::json::object();
  for (size_t j = 0; j < truth.frames[0].joints.size(); ++j) {
    joints[HumanSkeleton().joints[j]] = {truth.frames[0].joints[j].x_px,
                                         truth.frames[0].joints[j].y_px};
  }
  std::ofstream(dir / "init.json")
      << nlohmann::json{{"skeleton", "human14"}, {"joints", joints}}.dump();
  const auto run = testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                             (dir / "init.json") + " --out " + (dir / "skel.json") +
                                             " --occluded " + std::to_string(kOccludedFrom) + "-" +
                                             std::to_string(kOccludedTo) + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  EXPECT_EQ(report["frames"], kFrames);
  EXPECT_EQ(report["failures"].size(), 0u);
  EXPECT_EQ(report["interpolated_joints"], 15 * (kOccludedTo - kOccludedFrom + 1));
  const SkeletonSequence s = ReadSkeletonSequence(dir / "skel.json");
  EXPECT_EQ(s.clip, "frames");
  ASSERT_EQ(s.size(), kFrames);
  float worst = 0;
  for (int f = 0; f < kFrames; ++f) {
    for (size_t j = 0; j < s.frames[f].joints.size(); ++j) {
      ASSERT_TRUE(s.frames[f].joints[j].present);
      EXPECT_EQ(s.frames[f].joints[j].interpolated, f >= kOccludedFrom && f <= kOccludedTo);
      worst = std::max(worst, Error(s.frames[f].joints[j], truth.frames[f].joints[j]));
    }
  }
  EXPECT_LT(worst, 3.0f);
  // Bad input: an occluded frame past the clip, a missing initial joint.
  const auto past = testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                              (dir / "init.json") + " --out " + (dir / "x.json") +
                                              " --occluded 100");
  EXPECT_EQ(past.exit_code, 2) << past.output;
  joints.erase("wrist_r");
  std::ofstream(dir / "bad_init.json") << nlohmann::json{{"joints", joints}}.dump();
  const auto bad =
      testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                (dir / "bad_init.json") + " --out " + (dir / "x.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("'wrist_r' is missing"), std::string::npos) << bad.output;
}

TEST(SkeletonTracking, RejectsBadInput) {
  const SkeletonSequence truth = Truth();
  LkJointTracker tracker(HumanSkeleton());
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(tracker.AddFrame(image), InputError);  // the first frame needs the user's joints
  SkeletonFrame short_frame = truth.frames[0];
  short_frame.joints.pop_back();
  EXPECT_THROW(tracker.AddFrame(image, {}, &short_frame), InputError);
  EXPECT_THROW(tracker.AddFrame(cv::Mat(48, 64, CV_32FC1), {}, &truth.frames[0]), InputError);
  LkOptions bad;
  bad.window_px = 3;
  EXPECT_THROW(LkJointTracker(HumanSkeleton(), bad), InputError);
}

}  // namespace
}  // namespace ss
