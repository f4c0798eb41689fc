#pragma once
// The config's keying section (docs/config.md, docs/keying.md): which keyer, and the blocks
// each keyer makes its options from (pipeline/key/keyer_registry.h). The station config
// (config/station_config.h) reads it; the keyers own it.
#include <string>

#include "pipeline/key/chroma_keyer.h"
#include "pipeline/key/clean_plate_keyer.h"
#include "pipeline/key/shared_options.h"

namespace ss {

struct KeyingConfig {
  // The keyer, by the name it registered (pipeline/key/keyer_registry.h): an open set, as a
  // camera's `source` is; the config refuses a name no keyer built in has.
  std::string method = "chroma";
  int training_frames = 30;  // empty-enclosure frames to learn from
  // The chroma keyer's own options: keying.chroma.low and .high are bound to key_low_levels and
  // key_high_levels (the key difference in 8-bit levels where alpha starts to fall, and where it
  // reaches 0), whose defaults here are the config's, 20 and 60 (the keyer's own, -1, keys by
  // min_margin and ramp); despill and shadow come from the shared blocks below
  // (ChromaKeyerOptionsFrom copies them in whole).
  ChromaKeyerOptions chroma = [] {
    ChromaKeyerOptions o;
    o.key_low_levels = 20;
    o.key_high_levels = 60;
    return o;
  }();
  // The clean-plate keyer's own options: keying.clean_plate.low_sigma and .high_sigma are bound
  // to its fields, whose defaults here are the config's, 3 and 6 (the keyer's own, 4 and 0,
  // ramps by levels); shadow comes from the shared block below.
  CleanPlateKeyerOptions clean_plate = [] {
    CleanPlateKeyerOptions o;
    o.low_sigma = 3;
    o.high_sigma = 6;
    return o;
  }();
  DespillOptions despill;  // keying.despill.*, every keyer that removes spill
  // keying.shadow.*, every keyer's contact-shadow layer (the config's defaults)
  ShadowOptions shadow = {true, 0.08, 0.7};
  double shadow_reach_m = 0.5;  // keying.shadow.reach_m: shadow kept this far around the foot
  bool operator==(const KeyingConfig&) const = default;
};

}  // namespace ss
