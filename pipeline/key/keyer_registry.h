#pragma once
// Keyers by the config's keying.method (docs/keying.md). Each keyer's pair of files,
// pipeline/key/NAME_keyer.{h,cc}, defines `void Register<Name>Keyer()`, which calls
// RegisterKeyer with how it makes itself from the config's keying section and, as a camera
// backend does (capture/camera_backend.h), the keys and rules of its own block; one line in
// pipeline/CMakeLists.txt (spritestation_registrations) builds the call in. Nothing else in the
// project picks a keyer by its method or names one of its keys.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/options_binder.h"
#include "pipeline/key/keyer.h"
#include "pipeline/key/keying_config.h"

namespace ss {

struct KeyerKind {
  std::string method;  // the config's keying.method
  std::string doc;     // what it is for, in the docs' words: "colour-difference keying for ..."
  // Makes the keyer from the config's keying section (its own block and the shared shadow
  // one); `shadow_reach_cells` > 0 replaces its grid's (keying.shadow.reach_m at the camera's
  // scale). InputError naming the config field for a value the keyer refuses.
  std::function<std::unique_ptr<Keyer>(const KeyingConfig& keying, int shadow_reach_cells)> make;
  // Its own block of the section (keying.METHOD.*) with the config's defaults: a struct of the
  // keyer's (AnyBlock::Of), which every KeyingConfig holds by method (KeyingConfig::Block).
  // Empty: no block of its own.
  AnyBlock block;
  // Binds the keys of its own block, relative to the section ("chroma.low"), to the fields of
  // `keying.Block<T>(METHOD)` with their bounds as rules (core/options_binder.h). Unset: no keys
  // of its own.
  std::function<void(OptionsBinder& keys, KeyingConfig& keying)> keys;
  // Its block's rules beyond a key's bounds (low below high): one "KEY: reason" line per problem
  // in `why` (core/option_checks.h), KEY as bound above. Not asked while one of its keys is
  // refused already. Unset: no rules.
  std::function<bool(const KeyingConfig& keying, std::string* why)> check;
};

// Called by each keyer's registration function; a second keyer for one method is an error.
void RegisterKeyer(KeyerKind kind);
// Registers keyer type `K` for `method`, made from `options_from(keying)` (its block of the
// config's keying section and the shared ones) with the shadow reach applied to its grid;
// `block`, `keys` and `check` as in KeyerKind.
template <typename K, typename Options>
void RegisterKeyerType(std::string method, std::string doc,
                       Options (*options_from)(const KeyingConfig&), AnyBlock block = {},
                       decltype(KeyerKind::keys) keys = {}, decltype(KeyerKind::check) check = {}) {
  RegisterKeyer({std::move(method), std::move(doc),
                 [options_from](const KeyingConfig& keying, int shadow_reach_cells) {
                   Options options = options_from(keying);
                   if (shadow_reach_cells > 0) options.grid.shadow_reach_cells = shadow_reach_cells;
                   return std::unique_ptr<Keyer>(std::make_unique<K>(options));
                 },
                 std::move(block), std::move(keys), std::move(check)});
}
// Every keyer built in, by method.
std::vector<const KeyerKind*> KeyerKinds();
std::vector<std::string> KeyerMethods();
// The keyer of `keying.method`; InputError naming keying.method when it is not built in.
std::unique_ptr<Keyer> MakeKeyer(const KeyingConfig& keying, int shadow_reach_cells = 0);

}  // namespace ss
