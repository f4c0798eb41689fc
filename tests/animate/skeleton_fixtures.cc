// The skeleton clips of skeleton_fixtures.h: the match's gesture scripts and the tracker's
// rendered walking stick figure.
#include "tests/animate/skeleton_fixtures.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace ss::testing {
namespace {

cv::Point Fixed(float x, float y) {  // 4 fractional bits for sub-pixel drawing
  return {static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16))};
}

// One frame of the clip; the occluder when `occluded`.
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

}  // namespace

LabelledSkeletons Target() {
  GestureScriptOptions o;
  o.noise_px = 1.0f;
  o.seed = 3;
  return MakeGestureSequence({{Gesture::kY, 30},
                              {Gesture::kM, 30},
                              {Gesture::kC, 30},
                              {Gesture::kA, 30},
                              {Gesture::kWalk, 40}},
                             BodyProportions{}, o);
}

LabelledSkeletons Source() {
  GestureScriptOptions o;
  o.noise_px = 1.0f;
  o.speed = 0.7f;
  o.scale_px = 70;
  o.x_px = 150;
  o.seed = 9;
  return MakeGestureSequence({{Gesture::kWalk, 50},
                              {Gesture::kA, 35},
                              {Gesture::kIdle, 30},
                              {Gesture::kC, 35},
                              {Gesture::kY, 35},
                              {Gesture::kWalk, 30},
                              {Gesture::kM, 35}},
                             OtherBody(), o);
}

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

std::vector<cv::Mat> RenderClip(const SkeletonSequence& truth, bool with_occluder) {
  cv::setRNGSeed(5);
  std::vector<cv::Mat> images;
  images.reserve(truth.size());
  for (int f = 0; f < truth.size(); ++f) {
    images.push_back(
        Render(truth.frames[f], with_occluder && f >= kOccludedFrom && f <= kOccludedTo));
  }
  return images;
}

float Error(const JointSample& a, const JointSample& b) {
  return std::hypot(a.x_px - b.x_px, a.y_px - b.y_px);
}

}  // namespace ss::testing
