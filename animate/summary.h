#pragma once
// What an optimization run reports back (shaped after ceres::Solver::Summary).
#include <cstdint>
#include <string>
#include <vector>

#include "animate/problem.h"
#include "core/elapsed.h"  // MonotonicSeconds

namespace ss {

enum class TerminationType {
  kConverged,     // no improving replacement found in max_tries picks for every sprite
  kTimeBudget,    // the time budget ran out
  kMaxTurns,      // the turn limit was reached
  kBeamComplete,  // beam search extended to the full length
  kCancelled,     // the caller asked it to stop (ReplacementOptions::cancel)
};
const char* TerminationTypeName(TerminationType type);

// One point of the cost-versus-time curve.
struct TracePoint {
  double seconds = 0.0;    // since the start of the run, precomputation included
  double cost = 0.0;       // of the current sequences
  double best_cost = 0.0;  // lowest so far over restarts (the curve to plot)
  int restart = 0;         // costs never rise within one restart
  int64_t moves_tried = 0;
  int64_t moves_kept = 0;
  int turns = 0;  // sprite turns so far (replacement)
};

struct Summary {
  std::string method;  // "replacement" or "beam"
  std::string start;   // initial sequences: "random", "beam", "given"
  TerminationType termination = TerminationType::kConverged;
  std::string message;  // why it stopped, in words

  int num_sprites = 0;
  int turns = 0;                // sprite turns (replacement) or beam widths tried (beam)
  int restarts = 0;             // random restarts after convergence
  int64_t picks = 0;            // (k, l) pairs picked
  int64_t collision_picks = 0;  // of them, drawn around a step where the sprite collides
  int64_t goal_picks = 0;       // end moves toward a frame constraint's set (goal_fraction)
  int64_t moves_tried = 0;      // candidate sequences evaluated
  int64_t moves_kept = 0;       // improvements accepted

  double precompute_seconds = 0.0;  // F/B sets
  double start_seconds = 0.0;       // initial sequences (beam search when chosen)
  double optimize_seconds = 0.0;
  double total_seconds = 0.0;

  CostBreakdown initial_cost;
  CostBreakdown final_cost;
  std::vector<TracePoint> trace;  // one point per improvement (and at start and end)

  std::string BriefReport() const;  // one line
  std::string FullReport() const;   // several lines, costs by component
};

// Adds the seconds since construction to `*seconds` on destruction.
class ScopedTimer {
 public:
  explicit ScopedTimer(double* seconds);
  ~ScopedTimer();
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double* seconds_;
  int64_t start_ns_;
};

}  // namespace ss
