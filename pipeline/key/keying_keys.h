#pragma once
// The config's keying section (docs/config.md "keying", docs/keying.md), owned here beside the
// keyers it configures: every key bound to its field of KeyingConfig (its type, expected words,
// doc and bounds), and the section's rules beyond a key's own bounds. The shared keys (method,
// training_frames, despill, shadow) are bound here, each keyer's own block by the keyer's
// registration (KeyerKind::keys and ::check, pipeline/key/keyer_registry.h). The station config
// (config/) reads and checks the section through these two; nothing in config/ names a keyer's
// key, and nothing here names a keyer.
#include <string>

#include "core/options_binder.h"
#include "core/yaml_reader.h"
#include "pipeline/key/keying_config.h"

namespace ss {

// Every key of the section, relative to it ("chroma.low"), bound to `k`'s fields.
OptionsBinder KeyingKeys(KeyingConfig& k);

// Checks the section's values as set (from a file or in code), each problem at its key under
// `path` ("keying") with `msg`'s line for it: the keys' bounds, each keyer block's order rules
// (low below high), the shared blocks' rules; a despill strength outside 0..1 is clamped and
// reported as an adjustment. A key that has an error already gets no second one.
void CheckKeying(KeyingConfig& k, YamlMessages& msg, const std::string& path);

}  // namespace ss
