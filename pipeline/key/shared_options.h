#pragma once
// Option blocks every keyer that has the feature holds as they are, so the station config's
// shared keys (keying.shadow.*, keying.despill.*; docs/config.md) bind straight to one struct
// that is copied whole into the keyer's options (docs/keying.md, "From the station config").
#include <string>

#include "core/option_checks.h"

namespace ss {

// The contact-shadow layer: how much darker than the empty floor a pixel must be to be shadow.
struct ShadowOptions {
  bool enabled = true;  // false: no contact-shadow layer (and no shaded cells)
  // Darkening (a fraction of the floor's brightness) below which there is no shadow: noise.
  double min_darkening = 0.06;
  // Darkening that counts as full shadow; a pixel darker still is the subject.
  double max_darkening = 0.8;

  // "FIELD: reason" lines in `why` for values out of range (core/option_checks.h).
  bool IsValid(std::string* why) const {
    OptionProblems check(why);
    check.Within(min_darkening, FromUpTo(0, 1), "min_darkening", "a fraction >= 0, < 1");
    check.Within(max_darkening, AboveUpTo(0, 1), "max_darkening", "a fraction > 0, <= 1");
    check(!(min_darkening >= max_darkening), "max_darkening",
          "must be above min_darkening (" + OptionProblems::Num(min_darkening) + ")");
    return check.ok();
  }
  bool operator==(const ShadowOptions&) const = default;
};

// Removing the green cast (spill) from the subject's colour.
struct DespillOptions {
  bool enabled = true;  // false: the subject's colour is the frame's
  // Share (0..1) of the green above the limit that is removed: 0 none, 1 all of it.
  double strength = 1;
  // The limit: G <= max(R,B) - bias * (max(R,B) - min(R,B)); 0 keeps yellows, 0.5 = mean(R,B).
  double bias = 0.5;

  // "FIELD: reason" lines in `why` for values out of range (core/option_checks.h).
  bool IsValid(std::string* why) const {
    OptionProblems check(why);
    check.Within(strength, Between(0, 1), "strength", "a number 0..1");
    check.Within(bias, Between(0, 1), "bias", "a number 0..1");
    return check.ok();
  }
  bool operator==(const DespillOptions&) const = default;
};

}  // namespace ss
