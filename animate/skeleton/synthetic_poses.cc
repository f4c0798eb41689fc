#include "animate/skeleton/synthetic_poses.h"

#include <cmath>
#include <random>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

constexpr float kDeg = 3.14159265f / 180.0f;

// Joint angles in degrees. Arms: upper arm from straight down, outward positive; elbow
// bend added to it. Legs likewise. Left and right are the subject's, facing the camera.
struct Pose {
  float arm_l = 10, elbow_l = 10, arm_r = 10, elbow_r = 10;
  float leg_l = 4, knee_l = 0, leg_r = 4, knee_r = 0;
  float forearm_scale_l = 1,
        forearm_scale_r = 1;  // foreshortening of a forearm swinging out of plane
  float lean = 0;             // torso tilt
};

Pose Blend(const Pose& a, const Pose& b, float u) {
  auto mix = [u](float x, float y) { return x + (y - x) * u; };
  return {mix(a.arm_l, b.arm_l),
          mix(a.elbow_l, b.elbow_l),
          mix(a.arm_r, b.arm_r),
          mix(a.elbow_r, b.elbow_r),
          mix(a.leg_l, b.leg_l),
          mix(a.knee_l, b.knee_l),
          mix(a.leg_r, b.leg_r),
          mix(a.knee_r, b.knee_r),
          mix(a.forearm_scale_l, b.forearm_scale_l),
          mix(a.forearm_scale_r, b.forearm_scale_r),
          mix(a.lean, b.lean)};
}

// The pose of `gesture` at phase `phase` (frames into the gesture).
Pose GesturePose(Gesture gesture, float phase) {
  Pose p;
  const float sway = std::sin(phase * 0.21f);
  switch (gesture) {
    case Gesture::kIdle:
      p.arm_l = 10 + 3 * sway;
      p.arm_r = 10 - 3 * sway;
      p.lean = 1.5f * sway;
      break;
    case Gesture::kY:
      p.arm_l = p.arm_r = 145 + 4 * sway;
      p.elbow_l = p.elbow_r = 0;
      break;
    case Gesture::kM:
      p.arm_l = p.arm_r = 115 + 3 * sway;
      p.elbow_l = p.elbow_r = 115;
      break;
    case Gesture::kC:
      p.arm_l = 150 + 3 * sway;
      p.elbow_l = 50;
      p.arm_r = 60;
      p.elbow_r = -70 + 3 * sway;
      p.lean = -8;
      break;
    case Gesture::kA:
      p.arm_l = p.arm_r = 165 + 2 * sway;
      p.elbow_l = p.elbow_r = 30;
      break;
    case Gesture::kWalk: {
      const float w = std::sin(phase * 2 * 3.14159265f / 28);
      p.arm_l = 8;
      p.arm_r = 8;
      p.elbow_l = 15 + 10 * w;
      p.elbow_r = 15 - 10 * w;
      p.forearm_scale_l = 0.85f + 0.15f * w;
      p.forearm_scale_r = 0.85f - 0.15f * w;
      p.leg_l = 4 + 14 * w;
      p.leg_r = 4 - 14 * w;
      p.knee_l = 20 * std::max(0.0f, w);
      p.knee_r = 20 * std::max(0.0f, -w);
      break;
    }
  }
  return p;
}

SkeletonFrame Draw(const Pose& p, const BodyProportions& b, const GestureScriptOptions& o,
                   std::mt19937& rng, int64_t frame) {
  const SkeletonDef& def = HumanSkeleton();
  SkeletonFrame f = EmptySkeletonFrame(def, frame);
  std::normal_distribution<float> noise(0.0f, o.noise_px);
  const float k = o.scale_px;
  // side = +1 for the subject's left (image right).
  auto dir = [](float degrees, float side) {
    return std::pair<float, float>(side * std::sin(degrees * kDeg), std::cos(degrees * kDeg));
  };
  auto set = [&](const char* name, float x, float y) {
    JointSample& s = f.joints[*def.JointIndex(name)];
    s.x_px = x + (o.noise_px > 0 ? noise(rng) : 0.0f);
    s.y_px = y + (o.noise_px > 0 ? noise(rng) : 0.0f);
    s.confidence = 1;
    s.present = true;
  };
  const float px = o.x_px, py = o.y_px;
  const auto up = dir(180 + p.lean, 1);
  const float nx = px + up.first * b.torso * k, ny = py + up.second * b.torso * k;
  set("pelvis", px, py);
  set("neck", nx, ny);
  set("head", nx + up.first * b.head * k, ny + up.second * b.head * k);
  for (float side : {1.0f, -1.0f}) {
    const bool left = side > 0;
    const float sx = nx + side * b.shoulder * k, sy = ny;
    const auto ua = dir(left ? p.arm_l : p.arm_r, side);
    const float ex = sx + ua.first * b.upper_arm * k, ey = sy + ua.second * b.upper_arm * k;
    const auto fa = dir((left ? p.arm_l + p.elbow_l : p.arm_r + p.elbow_r), side);
    const float fl = b.forearm * k * (left ? p.forearm_scale_l : p.forearm_scale_r);
    const float hx = px + side * b.hip * k, hy = py;
    const auto th = dir(left ? p.leg_l : p.leg_r, side);
    const float kx = hx + th.first * b.thigh * k, ky = hy + th.second * b.thigh * k;
    const auto sh = dir((left ? p.leg_l - p.knee_l : p.leg_r - p.knee_r), side);
    set(left ? "shoulder_l" : "shoulder_r", sx, sy);
    set(left ? "elbow_l" : "elbow_r", ex, ey);
    set(left ? "wrist_l" : "wrist_r", ex + fa.first * fl, ey + fa.second * fl);
    set(left ? "hip_l" : "hip_r", hx, hy);
    set(left ? "knee_l" : "knee_r", kx, ky);
    set(left ? "ankle_l" : "ankle_r", kx + sh.first * b.shin * k, ky + sh.second * b.shin * k);
  }
  return f;
}

}  // namespace

std::string GestureName(Gesture gesture) {
  switch (gesture) {
    case Gesture::kIdle:
      return "idle";
    case Gesture::kY:
      return "Y";
    case Gesture::kM:
      return "M";
    case Gesture::kC:
      return "C";
    case Gesture::kA:
      return "A";
    case Gesture::kWalk:
      return "walk";
  }
  return "?";
}

BodyProportions OtherBody() {
  return {.torso = 0.9f,
          .head = 0.3f,
          .shoulder = 0.33f,
          .upper_arm = 0.62f,
          .forearm = 0.65f,
          .hip = 0.17f,
          .thigh = 1.05f,
          .shin = 1.0f};
}

bool GestureScriptOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(transition_frames, AtLeast(0), "transition_frames", "frames >= 0");
  check.Within(speed, Positive(), "speed", "a positive factor");
  check.Within(noise_px, AtLeast(0), "noise_px", "pixels >= 0");
  check.Within(scale_px, Positive(), "scale_px", "a positive number of pixels per body unit");
  check(std::isfinite(x_px), "x_px",
        "must be a finite pixel position, got " + OptionProblems::Num(x_px));
  check(std::isfinite(y_px), "y_px",
        "must be a finite pixel position, got " + OptionProblems::Num(y_px));
  return check.ok();
}

LabelledSkeletons MakeGestureSequence(const std::vector<std::pair<Gesture, int>>& script,
                                      const BodyProportions& body,
                                      const GestureScriptOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("gesture script options", why);
  LabelledSkeletons out;
  out.sequence.skeleton = HumanSkeleton();
  out.sequence.fps = 25;
  std::mt19937 rng(options.seed);
  const float step = options.speed;
  int64_t frame = 0;
  Pose last = GesturePose(Gesture::kIdle, 0);
  Gesture last_label = Gesture::kIdle;
  bool first = true;
  for (const auto& [gesture, hold] : script) {
    const int blend =
        first ? 0 : std::max(1, static_cast<int>(std::lround(options.transition_frames / step)));
    for (int i = 0; i < blend; ++i) {
      const float u = static_cast<float>(i + 1) / (blend + 1);
      const float smooth = u * u * (3 - 2 * u);
      out.sequence.frames.push_back(
          Draw(Blend(last, GesturePose(gesture, 0), smooth), body, options, rng, frame++));
      out.labels.push_back(u < 0.5f ? last_label : gesture);
    }
    const int frames = std::max(1, static_cast<int>(std::lround(hold / step)));
    for (int i = 0; i < frames; ++i) {
      last = GesturePose(gesture, static_cast<float>(i) * step);
      out.sequence.frames.push_back(Draw(last, body, options, rng, frame++));
      out.labels.push_back(gesture);
    }
    last_label = gesture;
    first = false;
  }
  return out;
}

}  // namespace ss
