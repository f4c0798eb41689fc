#pragma once
// The visible jump (visible_jump.h) of a transition table's kept transitions, for judging a
// classifier without a truth (issue 34): `bench transitions` on the synthetic sets and
// `transitions BANK` on any bank. A bounded sample of the transitions, spread evenly over the
// table, keeps it fast on any bank; the figures say how many were measured.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/transitions/visible_jump.h"

namespace ss {

// Linear-interpolated quantile q in [0, 1] of `values` (nullopt when empty).
std::optional<double> Quantile(std::vector<double> values, double q);

struct TransitionJumpOptions {
  // At most this many transitions are measured, spread evenly over the table (all of a smaller
  // one); 0 measures none.
  int max_transitions = 2000;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The jumps of the measured transitions of one kind (or of all).
struct JumpStats {
  int64_t sampled = 0;     // transitions of the sample
  int64_t measured = 0;    // of them, with a jump
  int64_t unmeasured = 0;  // leaving their clip's last frame (nothing replaced), or unknown
  std::optional<double> median, p95, max;  // of the measured jumps
};

struct TransitionJumpSummary {
  int64_t transitions = 0;    // in the table
  double median_step_px = 0;  // the meter's MedianStep_px (0 when nothing was sampled)
  JumpStats all, within_clip, joining_clips, original_mirror;
  // {"transitions", "median_step_px", "sampled", "measured", "unmeasured", "median", "p95",
  //  "max", "by_kind": {"within_clip": {...}, "joining_clips": {...}, "original_mirror": {...}}};
  // figures of an empty set are null.
  nlohmann::json ToJson() const;
  // One line: "visible jump of N of M transitions: median X, p95 Y (...)".
  std::string ToText() const;
};

// The jumps of `transitions` (from, to), a sample of at most options.max_transitions of them.
// InputError for invalid options.
TransitionJumpSummary MeasureTransitionJumps(
    VisibleJumpMeter& meter, const std::vector<std::pair<int64_t, int64_t>>& transitions,
    const TransitionJumpOptions& options = {});

}  // namespace ss
