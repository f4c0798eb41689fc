#pragma once
// The config's keying section (docs/config.md, docs/keying.md): which keyer, the blocks every
// keyer shares, and each keyer's block of its own, which it makes its options from
// (pipeline/key/keyer_registry.h). The station config (config/station_config.h) reads it; the
// keyers own it, and it names none of them.
#include <map>
#include <string>

#include "core/any_block.h"
#include "pipeline/key/shared_options.h"

namespace ss {

// Every keyer's own block with the config's defaults, by method (KeyerKind::block;
// pipeline/key/keyer_registry.cc).
std::map<std::string, AnyBlock> KeyerBlockDefaults();

struct KeyingConfig {
  // The keyer, by the name it registered (pipeline/key/keyer_registry.h): an open set, as a
  // camera's `source` is; the config refuses a name no keyer built in has.
  std::string method = "chroma";
  int training_frames = 30;  // empty-enclosure frames to learn from
  // Each keyer's own block (keying.METHOD.*) by method: a struct of the keyer's with the
  // config's defaults, which the keyer binds (KeyerKind::keys) and makes its options from. Every
  // keyer built in has its block from the start, so configs compare by their values.
  std::map<std::string, AnyBlock> keyers = KeyerBlockDefaults();
  DespillOptions despill;  // keying.despill.*, every keyer that removes spill
  // keying.shadow.*, every keyer's contact-shadow layer (the config's defaults)
  ShadowOptions shadow = {true, 0.08, 0.7};
  double shadow_reach_m = 0.5;  // keying.shadow.reach_m: shadow kept this far around the foot
  bool operator==(const KeyingConfig&) const = default;

  // The block of keyer `method`, of its type T (made with T's defaults when absent).
  template <typename T>
  T& Block(const std::string& method) {
    return keyers[method].Use<T>();
  }
  // The block of keyer `method`, or T's defaults when it has none.
  template <typename T>
  const T& Block(const std::string& method) const {
    const auto it = keyers.find(method);
    return it != keyers.end() ? it->second.Get<T>() : AnyBlock().Get<T>();  // a static's
  }
};

}  // namespace ss
