#pragma once
// One optimization run of a scene, as `spritestation animate` and the scene benchmark do
// it: repeated subsequence replacement (or the beam search baseline) within a time budget,
// with optional snapshots of the sequences for a video of the intermediate stages, and
// the figures that say how well the constraints are met.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animate/scene.h"
#include "animate/sequence_io.h"
#include "animate/summary.h"

namespace ss {

struct AnimateRunOptions {
  // The spec's optimizer block (method, budget, seed, threads, snapshots), as a caller changed it.
  OptimizerSpec optimizer;
  double progress_every_s = 0.0;  // log the progress this often; 0: never
  // Replacement: stop after this many sprite turns (0: the time budget alone). With a budget
  // that is never reached, the same work on any machine, loaded or not (tests).
  int max_turns = 0;
  // Replacement only: another thread stops the run early (ReplacementOptions::cancel), and
  // sees every accepted move (live progress; called on the optimizer's thread).
  const std::atomic<bool>* cancel = nullptr;
  std::function<void(const std::vector<Track>&, const TracePoint&)> on_improvement;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// How well the result meets its constraints (the scenes' figures).
struct ConstraintFigures {
  double max_path_deviation_m = 0.0;  // over the sprites with a path
  int paths_unfinished = 0;           // sprites that never reach their path's end
  int collision_steps = 0;            // steps closer than d_min, summed over pairs
  int colliding_pairs = 0;            // pairs that come closer than d_min at least once
  double min_distance_m = -1.0;       // smallest pair distance (-1: no collision terms)
  int frame_steps_off = 0;            // steps of frame constraints outside their set
  int frame_steps = 0;                // steps under frame constraints
  int sprites_short = 0;              // sprites under their length constraint
};

struct AnimateResult {
  std::vector<Track> tracks;
  Summary summary;
  std::vector<SequenceStage> stages;
  ConstraintFigures figures;
};

AnimateResult RunAnimation(const Scene& scene, const AnimateRunOptions& options);
ConstraintFigures MeasureConstraints(const Problem& problem, const std::vector<Track>& tracks);

// The sequence file for a run's result (frame rate, camera, background, banks from the spec).
SequenceFile MakeSequenceFile(const Scene& scene, const AnimateResult& result);
// The summary as JSON: costs by component, violations, figures, times, trace.
nlohmann::json SummaryJson(const AnimateResult& result);

}  // namespace ss
