#include "synth/directors.h"

#include <cmath>
#include <string>

#include "core/option_checks.h"

namespace ss::synth {

bool DirectorOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  // The renderer (synth/renderer.cc) draws at most 64 subjects in a scene.
  check.Within(subjects, Between(0, 64), "subjects", "0..64 (the renderer draws at most 64)");
  check.Within(fps, Positive(), "fps", "a positive number of frames per second");
  check(figure_variant == 0 || figure_variant == 1, "figure_variant",
        "expected 0 (the reference figure) or 1 (the other build), got " +
            std::to_string(figure_variant));
  return check.ok();
}

}  // namespace ss::synth
