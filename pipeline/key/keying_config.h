#pragma once
// The config's keying section (docs/config.md, docs/keying.md): which keyer, and the blocks
// each keyer makes its options from (pipeline/key/keyer_registry.h). The station config
// (config/station_config.h) reads it; the keyers own it.
#include "core/enum_text.h"
#include "pipeline/key/chroma_keyer.h"

namespace ss {

// Closed sets are enums in the program and text only in the config file and the API.
enum class KeyingMethod { kChroma, kCleanPlate };

inline constexpr EnumText<KeyingMethod> kKeyingMethodTexts[] = {
    {KeyingMethod::kChroma, "chroma"}, {KeyingMethod::kCleanPlate, "clean_plate"}};

inline const char* ToText(KeyingMethod method) { return TextOf(method, kKeyingMethodTexts); }

struct KeyingConfig {
  KeyingMethod method = KeyingMethod::kChroma;
  int training_frames = 30;  // empty-enclosure frames to learn from
  // The chroma keyer's own options: keying.chroma.low and .high are bound to key_low_levels and
  // key_high_levels (the key difference in 8-bit levels where alpha starts to fall, and where it
  // reaches 0), whose defaults here are the config's, 20 and 60 (the keyer's own, -1, keys by
  // min_margin and ramp); despill and shadow come from the shared blocks below
  // (ChromaKeyerOptionsFrom).
  ChromaKeyerOptions chroma = [] {
    ChromaKeyerOptions o;
    o.key_low_levels = 20;
    o.key_high_levels = 60;
    return o;
  }();
  double plate_low_sigma = 3;  // clean_plate: difference in noise sigmas where alpha starts to rise
  double plate_high_sigma = 6;  // clean_plate: ... and where it reaches 1
  bool despill = true;
  double despill_strength = 1.0;  // 0..1
  bool shadow = true;             // keep the contact-shadow layer
  // fraction of plate brightness below which there is no shadow
  double shadow_min_darkening = 0.08;
  double shadow_max_darkening = 0.7;  // darkening that counts as full shadow
  double shadow_reach_m = 0.5;        // shadow kept this far around the subject's foot
  bool operator==(const KeyingConfig&) const = default;
};

}  // namespace ss
