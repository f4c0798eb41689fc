// The keying section's keys and rules (pipeline/key/keying_keys.h).
#include "pipeline/key/keying_keys.h"

#include <algorithm>
#include <cmath>

#include "core/option_checks.h"
#include "pipeline/key/keyer_registry.h"

namespace ss {

OptionsBinder KeyingKeys(KeyingConfig& k) {
  OptionsBinder b;
  // The keyers built in, each with its own words (pipeline/key/keyer_registry.h).
  std::string methods, docs;
  for (const KeyerKind* keyer : KeyerKinds()) {
    methods += (methods.empty() ? "`" : " | `") + keyer->method + "`";
    docs += (docs.empty() ? "`" : "; `") + keyer->method + "`: " + keyer->doc;
  }
  b.Add("method", &k.method, "one of " + yaml_text::Join(KeyerMethods(), ", "), docs)
      .Type(methods)
      .Add("training_frames", &k.training_frames, "at least 1 frame",
           "frames of the empty enclosure learnt at start (key colour, plate, noise). Each camera "
           "holds them at once, full size (BGR): the largest camera's frames (a camera of unset "
           "size counts as 1920x1080) must fit in 1 GiB, and 1000 frames at most: 172 at "
           "1920x1080, 43 at 3840x2160 (2000000000 made the daemon fail every frame with "
           "bad_alloc)")
      .Rule(AtLeast(1));
  // Each keyer's own block, bound by the keyer (KeyerKind::keys).
  for (const KeyerKind* keyer : KeyerKinds())
    if (keyer->keys) keyer->keys(b, k);
  b.Add("despill.enabled", &k.despill.enabled, "remove the screen's colour cast from subject edges")
      .Add("despill.strength", &k.despill.strength, "a number 0..1",
           "how much of the cast to remove (clamped to 0..1, adjusted)")
      .Type("number 0..1")
      .Add("shadow.enabled", &k.shadow.enabled,
           "keep the contact shadow as its own layer (seed 000 §6)")
      .Add("shadow.min_darkening", &k.shadow.min_darkening, "a fraction 0..1",
           "floor darker than the plate by less than this fraction is not shadow (noise)")
      .Type("number in [0, 1)")
      .Add("shadow.max_darkening", &k.shadow.max_darkening, "a fraction 0..1",
           "darkening that counts as full shadow; must be above `min_darkening`")
      .Type("number in (0, 1]")
      .Add("shadow.reach_m", &k.shadow_reach_m, "a positive distance in metres",
           "shadow is kept this far (ground metres) around the subject's contact point")
      .Rule(Positive());
  return b;
}

void CheckKeying(KeyingConfig& k, YamlMessages& msg, const std::string& path) {
  using yaml_text::Child;
  using yaml_text::Num;
  const auto check = [&](bool ok, const std::string& key, const std::string& reason) {
    if (!ok && !msg.Failed(Child(path, key))) msg.Error(Child(path, key), reason);
  };
  KeyingKeys(k).CheckRules(msg, path);  // the bounds its keys are bound with
  const std::vector<std::string> methods = KeyerMethods();
  check(std::find(methods.begin(), methods.end(), k.method) != methods.end(), "method",
        "expected one of " + yaml_text::Join(methods, ", ") + ", got \"" + k.method + "\"");
  // Each keyer's block's own rules (KeyerKind::check), unless a key of the block is refused
  // already: against a bound that is itself wrong, the order says nothing more.
  for (const KeyerKind* keyer : KeyerKinds()) {
    if (!keyer->check) continue;
    OptionsBinder own;
    if (keyer->keys) keyer->keys(own, k);
    const std::vector<std::string> keys = own.Keys();
    if (std::any_of(keys.begin(), keys.end(),
                    [&](const std::string& key) { return msg.Failed(Child(path, key)); }))
      continue;
    std::string why;
    if (keyer->check(k, &why)) continue;
    for (const auto& [field, reason] : OptionProblems::Split(why))
      check(false, field.empty() ? "method" : field, reason);
  }
  double& strength = k.despill.strength;
  check(std::isfinite(strength), "despill.strength",
        "expected a finite number, got " + Num(strength));
  if (std::isfinite(strength) && (strength < 0 || strength > 1)) {
    const double clamped = std::clamp(strength, 0.0, 1.0);
    msg.Adjust(Child(path, "despill.strength"),
               Num(strength) + " is outside 0..1; clamped to " + Num(clamped));
    strength = clamped;
  }
  // The shared blocks' own rules (pipeline/key/shared_options.h), after the clamp above.
  std::string why;
  const auto rules = [&](bool ok, const std::string& block) {
    if (ok) return;
    for (const auto& [field, reason] : OptionProblems::Split(why))
      check(false, field.empty() ? block : block + "." + field, reason);
  };
  rules(k.despill.IsValid(&why), "despill");
  rules(k.shadow.IsValid(&why), "shadow");
}

}  // namespace ss
