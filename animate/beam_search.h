#pragma once
// Beam search (Schödl & Essa 2001), the baseline of seed 000 §4.1: keep the `width`
// partial sequences with the lowest cost so far, extend each by every out-edge of its last
// frame, keep the best `width` again; over all steps remember the best sequence by the
// full cost. Partial sequences are ranked by the per-step costs of the steps they cover
// (no end-of-sequence costs). Several sprites are planned one after the other, each with
// the earlier ones fixed; terms that read a sprite not yet planned are left out.
#include <string>
#include <vector>

#include "animate/problem.h"
#include "animate/summary.h"

namespace ss {

// The longest time budget an optimizer takes (a spec's time_budget_s, `--time-budget`): a day.
inline constexpr double kMaxTimeBudgetSeconds = 86400;

struct BeamOptions {
  int width = 32;        // partial sequences kept per step
  int length = 0;        // steps to extend to; 0: the sprite's max_frames, else initial_frames
  int start_frames = 0;  // first frames tried (evenly spread); 0: every frame
  // > 0: after a pass, rerun with twice the width while time remains and keep the best
  // result; a pass cut by the budget returns the best sequences found so far.
  double time_budget_seconds = 0.0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// Throws InputError("beam options", ...) when the options are not valid.
std::vector<Track> BeamSearch(const Problem& problem, const BeamOptions& options, Summary* summary);

}  // namespace ss
