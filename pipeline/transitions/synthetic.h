#pragma once
// A synthetic sprite set for tests and the "transitions" benchmark: clips of a
// hamster-like animal whose truth (pose, heading, speed, gait phase, lighting) follows
// a random walk (every pose has a motion cycle: the gait, an idle sniff, a standing
// sway; its phase is the truth's gait_phase), rendered into small RGBA billboards at a fixed
// px_per_m with the cheap features computed from them, plus the horizontally mirrored clips. (The
// full studio renderer is synth/; this one only needs to exercise transitions.)
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/transitions/billboard.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/truth_labels.h"

namespace ss {

struct SyntheticSpriteOptions {
  int frames = 15000;         // originals (>= 0); mirrors double the count
  bool mirrors = true;        // add the horizontally mirrored clips
  double px_per_m = 250;      // billboard scale, px per metre (> 0)
  double fps = 30;            // frame rate the random walk steps at, frames per second (> 0)
  int min_clip_frames = 20;   // shortest clip, frames (>= 1)
  int max_clip_frames = 240;  // longest clip, frames (>= min_clip_frames)
  // velocity noise, m/s (std. dev., >= 0) per component, as a tracker's estimate would have
  double velocity_noise_mps = 0.008;
  int pixel_noise = 3;  // +- uniform colour noise per pixel, levels of 255 (0..255)
  uint64_t seed = 1;    // of the random walk and the noise
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
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
