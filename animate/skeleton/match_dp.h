#pragma once
// Dynamic programming over target frames x source frames (seed 003 §2.2): choose one source
// frame s_t per target frame t minimizing
//   sum_t c_t(s_t) + sum_{t>=1} move_t(s_{t-1} -> s_t)
// where c is the matching cost (CostRows) and a move d = s_t - s_{t-1} costs, with R =
// freeze_levels, Kf = max_forward_step, W = stutter_window, J = jump_cost:
//   d = 0, the k-th repeat in a row (freeze)     freeze_cost * min(k, R)
//   1 <= d <= Kf, same clip (play, skip d-1)     skip_cost * (d - 1)
//   -W <= d <= -1, same clip (stutter)           J + stutter_cost
//   anything else (jump)                          J
// and a listed transition from -> to (a bank transition) costs min(its cost, the above).
// Exact in O(S) per target frame: the state is (s, r), r = min(repeats so far, R); moves
// into r = 0 are advance/skip (Kf terms), stutter (W terms), listed transitions, and a jump
// from the best source outside [s, s+W] (the W+2 smallest of the previous row); a stay
// moves r to min(r+1, R). The forward pass stores each cell's decision (1 byte, 2 when
// Kf + W > 14) and the backtrack walks them; when they would not fit
// MatchOptions::max_decision_bytes, memory is O(S sqrt(T)) instead: rows are checkpointed
// and recomputed block by block for the backtrack. docs/skeletons.md has the details.
#include <cstddef>
#include <string>
#include <vector>

#include "animate/skeleton/cost_rows.h"

namespace ss {

// A listed transition: after source frame `from`, source frame `to` may follow at `cost`.
struct SourceTransition {
  int from = 0;
  int to = 0;
  float cost = 0;
};

struct MatchOptions {
  int max_forward_step = 3;   // Kf
  float skip_cost = 0.01f;    // per source frame skipped by a forward step
  float jump_cost = 0.3f;     // J
  float freeze_cost = 0.02f;  // the k-th repeat in a row costs freeze_cost * min(k, freeze_levels)
  int freeze_levels = 4;      // R, the run-length counter's cap (1..7)
  int stutter_window = 8;     // W
  float stutter_cost = 0.3f;  // added to J for a backward move of 1..W frames
  std::vector<SourceTransition> transitions;
  // The forward pass keeps every cell's decision (T x S bytes, twice that when Kf + W > 14,
  // plus 4 bytes a cell on rows inside a target movement) when that fits here; otherwise
  // the backtrack recomputes blocks of rows from checkpoints (slower; an equally optimal path,
  // the same one unless float rounding ties two jump sources). 0 forces it. Also capped at half
  // the memory available (/proc/meminfo MemAvailable) when the match starts.
  size_t max_decision_bytes = size_t{3} << 30;

  // Valid when the costs are finite and >= 0, Kf >= 1, W >= 0, 1 <= R <= 7 and a forward
  // skip never costs more than a jump (skip_cost * (Kf - 1) <= J); otherwise false with
  // "FIELD: reason" lines in `why` (core/option_checks.h).
  bool IsValid(std::string* why) const;
  // The same smoothness without the freeze and stutter penalties (Figure 2a).
  MatchOptions WithoutPenalties() const;
};

// The refinement's second pass (§2.3): inside one target movement, consecutive choices
// stay inside one source movement and a jump of |d| frames costs jump_cost_per_frame * |d|
// on top of the move costs above; across target movements the moves are as above.
struct MovementConstraint {
  std::vector<int> target_starts;  // first frame of each target movement, ascending, 0 first
  std::vector<int> source_starts;  // first frame of each source movement, ascending, 0 first;
                                   // every clip start must be among them
  float jump_cost_per_frame = 0;   // λ
};

struct MatchStats {
  int freezes = 0;         // target frames showing the same source frame as the previous one
  int freeze_runs = 0;     // maximal runs of such repeats
  int longest_freeze = 0;  // repeats in the longest run
  int stutters = 0;        // backward moves of 1..W frames within a clip
  int skips = 0;           // forward moves of 2..Kf frames
  int jumps = 0;           // other moves (listed transitions excluded)
  int listed = 0;          // moves along a listed transition that was cheaper than the rule
};

struct MatchResult {
  std::vector<int> source_frames;  // s_t, flat index over the source clips
  double total_cost = 0;           // the objective at the optimum
  double matching_cost = 0;        // its sum_t c_t(s_t) part
  MatchStats stats;
  double cost_seconds = 0;      // computing cost rows (both passes)
  double forward_seconds = 0;   // the DP rows of the forward pass
  double backward_seconds = 0;  // backtracking (and, without decisions, recomputing blocks)
  // what the backtrack keeps: decisions and top lists, or checkpoints and one block
  size_t memory_bytes = 0;
  // the backtrack walked stored decisions (else recomputed from checkpoints)
  bool walked_decisions = false;
  std::string Summary() const;  // one line
};

// The optimal path. `clip_starts`: first flat source index of each clip (0 first,
// ascending); moves across clips are jumps. Throws InputError for invalid options or
// layouts, WorkError when every path is forbidden (e.g. every source frame excluded).
MatchResult SolveMatch(const CostRows& costs, const std::vector<int>& clip_starts,
                       const MatchOptions& options, const MovementConstraint* movements = nullptr);

// The objective of a given path, straight from the definition (the reference the DP is
// tested against); +inf for a forbidden path. `matching_cost` receives sum_t c_t(s_t).
double PathCost(const CostRows& costs, const std::vector<int>& clip_starts,
                const MatchOptions& options, const MovementConstraint* movements,
                const std::vector<int>& path, double* matching_cost = nullptr);

// Counts freezes, stutters, skips, jumps and listed moves along a path.
MatchStats AnalyzePath(const std::vector<int>& path, const std::vector<int>& clip_starts,
                       const MatchOptions& options);

}  // namespace ss
