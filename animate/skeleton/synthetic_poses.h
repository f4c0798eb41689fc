#pragma once
// Procedural 2D human skeletons performing labelled gestures (Y, M, C, A from the paper's
// YMCA example, walk, idle), for tests and benchmarks of the matcher: the same script
// can be played by bodies of different proportions, at different speeds and with noise.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "animate/skeleton/skeleton.h"

namespace ss {

enum class Gesture { kIdle, kY, kM, kC, kA, kWalk };

// "idle", "Y", "M", "C", "A", "walk".
std::string GestureName(Gesture gesture);

// Segment lengths in body units (the pelvis-to-neck length is 1 for the default body).
struct BodyProportions {
  float torso = 1.0f;
  float head = 0.35f;     // neck to head
  float shoulder = 0.4f;  // neck to each shoulder
  float upper_arm = 0.6f;
  float forearm = 0.55f;
  float hip = 0.2f;  // pelvis to each hip
  float thigh = 0.9f;
  float shin = 0.85f;
};

// A second body: longer legs and forearms, narrower shoulders.
BodyProportions OtherBody();

struct GestureScriptOptions {
  int transition_frames = 8;     // frames blending from one gesture into the next
  float speed = 1.0f;            // > 1: faster (fewer frames per step)
  float noise_px = 0.0f;         // Gaussian noise on every joint, pixels
  float scale_px = 100.0f;       // pixels per body unit
  float x_px = 320, y_px = 300;  // pelvis position
  uint32_t seed = 1;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct LabelledSkeletons {
  SkeletonSequence sequence;    // HumanSkeleton()
  std::vector<Gesture> labels;  // per frame; a transition's first half keeps the old label
};

// Plays `script` (gesture, frames held) with `body`. InputError("gesture script options", ...)
// for options that are not valid.
LabelledSkeletons MakeGestureSequence(const std::vector<std::pair<Gesture, int>>& script,
                                      const BodyProportions& body,
                                      const GestureScriptOptions& options = {});

}  // namespace ss
