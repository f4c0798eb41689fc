#pragma once
// A synthetic sprite set for tests and the "transitions" benchmark: clips of a
// hamster-like animal whose truth (pose, heading, speed, gait phase, lighting) follows
// a random walk (every pose has a motion cycle: the gait, an idle sniff, a standing
// sway; its phase is the truth's gait_phase), rendered into small RGBA billboards at a fixed
// px_per_m with the cheap features computed from them, plus the horizontally mirrored clips. (The
// full studio renderer is synth/; this one only needs to exercise transitions.)
#include <cstdint>
#include <vector>

#include "pipeline/transitions/billboard.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/truth_labels.h"

namespace ss {

struct SyntheticSpriteOptions {
  int frames = 15000;  // originals; mirrors double the count
  bool mirrors = true;
  double px_per_m = 250;
  double fps = 30;
  int min_clip_frames = 20;
  int max_clip_frames = 240;
  double velocity_noise_mps = 0.008;  // per component, as a tracker's estimate would have
  int pixel_noise = 3;                // +- uniform colour noise per pixel
  uint64_t seed = 1;
};

struct SyntheticSprite {
  int64_t id = 0;    // 1-based, originals first in frame order, then mirrors
  int64_t clip = 0;  // 1-based
  CheapFeatures cheap;
  RgbaBillboard billboard;
  SpriteTruth truth;
  double speed_mps = 0;
};

// Deterministic for a given options.seed.
std::vector<SyntheticSprite> MakeSyntheticSprites(const SyntheticSpriteOptions& options);

// Views for the builder (borrowing the billboards).
std::vector<SpriteInput> AsSpriteInputs(const std::vector<SyntheticSprite>& sprites);

}  // namespace ss
