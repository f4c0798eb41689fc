// Lucas-Kanade joint tracking (seed 003 §2.1) on rendered frames: a walking stick figure
// with a marker on each joint drifts across the image; the tracked joints must stay
// within a pixel or two of the truth, occluded frames marked by the user must be
// interpolated close to the truth, and unmarked occlusions must be reported as failures.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "animate/skeleton/lk_tracker.h"
#include "animate/skeleton/skeleton.h"
#include "core/error.h"
#include "tests/animate/skeleton_fixtures.h"

namespace ss {
namespace {

using testing::Error;
using testing::kFrames;
using testing::kOccludedFrom;
using testing::kOccludedTo;
using testing::RenderClip;
using testing::Truth;

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
