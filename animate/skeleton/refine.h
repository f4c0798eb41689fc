#pragma once
// Matching refinement (seed 003 §2.3). Atomic movements are the stretches between local
// maxima of the sequential matching cost cost(x_t, x_{t+1}) (the moments of fastest pose
// change), found in the target and, clip by clip, in the source. A second DP pass keeps
// the choice inside one source movement for the whole of a target movement, charges
// jumps inside it per frame jumped, and an averaging window inside each target movement
// smooths the chosen frame numbers.
#include <vector>

#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/match_dp.h"

namespace ss {

// The detector's windows are durations in seconds, turned into frames with each clip's
// frame rate: at 30 fps they are the frames they were tuned as (lag 4, smoothing 5,
// minimum length 8); at 10 fps a third of those (lag 1, smoothing 2 -> 3, 3 frames).
struct MovementOptions {
  // Seconds each side of the gap between t and t+1 that the pose change is measured over:
  // cost(x_{t+1-lag}, x_{t+lag}) with lag = lag_s * fps frames (at least 1; 1 is the plain
  // sequential cost). A wider lag lifts a movement's change above tracking noise, which
  // is the same at every lag.
  double lag_s = 4.0 / 30;
  double smoothing_s = 5.0 / 30;   // centred moving average of the sequential cost first
  double min_length_s = 8.0 / 30;  // of two boundaries closer than this the weaker goes
  // A peak's height over the higher of its two bases must reach
  // max(min_prominence, noise_factor * median cost): the median is the noise floor of
  // tracked or imported joints, whose jitter alone makes peaks.
  float min_prominence = 0.02f;
  float noise_factor = 2.5f;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The windows above in frames at `fps` (rounded, at least 1).
struct MovementFrames {
  int lag = 4, smoothing_window = 5, min_length = 8;
};
MovementFrames MovementWindows(const MovementOptions& options, double fps);

// First frame of each movement (0 first) of one sequence at `fps`, from its sequential
// cost (the lag is not used here: the costs are given).
std::vector<int> FindMovements(const std::vector<float>& sequential_cost,
                               const MovementOptions& options, double fps = 30);
// The pose change across each gap t | t+1 of frames [begin, end): cost(x_{t+1-lag}, x_{t+lag}),
// clipped to the range (end - begin - 1 values).
std::vector<float> MovementCost(const PoseDescriptors& frames, int begin, int end, int lag);
// Of several clips laid end to end: every clip start, plus the movements inside each clip,
// each at its frame rate (FrameRateAt).
std::vector<int> FindMovements(const PoseDescriptors& frames, const std::vector<int>& clip_starts,
                               const MovementOptions& options);

struct RefineOptions {
  MovementOptions movements;
  float jump_cost_per_frame = 0.01f;  // λ: a jump of d frames inside a movement costs λ|d| more
  int averaging_window = 5;           // frames, centred, clipped to the movement; 1 = none
  // As MovementOptions::IsValid; the movements' fields come out under "movements.".
  bool IsValid(std::string* why) const;
};

struct RefineResult {
  std::vector<int> source_frames;     // the refined choice, after averaging
  MatchResult second_pass;            // the constrained DP, before averaging
  std::vector<int> target_movements;  // first frame of each target movement
  std::vector<int> source_movements;  // first frame of each source movement
  MatchStats stats;                   // of source_frames
  double total_cost = 0;              // PathCost of source_frames under the constraint
};

// Runs the constrained second pass and the averaging. `targets` and `sources` are the
// descriptors `costs` was built from (for the sequential costs). With `first_pass` (the
// unconstrained choice, one source frame per target frame), a target movement is also cut
// where that choice moves to another source movement for at least the minimum length
// (SplitByFirstPass): locomotion has no peak of pose change inside it, so idle, turn and
// walk can form one target movement that the source holds as several.
RefineResult RefineMatch(const CostRows& costs, const PoseDescriptors& targets,
                         const PoseDescriptors& sources, const std::vector<int>& clip_starts,
                         const MatchOptions& options, const RefineOptions& refine = {},
                         const std::vector<int>* first_pass = nullptr);

// `target_starts` plus, inside each target movement, the start of every run of at least
// `min_length` frames whose `first_pass` frames lie in one source movement, when that
// source movement differs from the previous such run's (shorter runs join the run after).
std::vector<int> SplitByFirstPass(const std::vector<int>& target_starts,
                                  const std::vector<int>& source_starts,
                                  const std::vector<int>& first_pass, int min_length);

// Centred moving average of `frames` inside each segment [starts[i], starts[i+1]),
// rounded to the nearest frame.
std::vector<int> AverageWithinSegments(const std::vector<int>& frames,
                                       const std::vector<int>& starts, int window);

}  // namespace ss
