#pragma once
// Optimization by repeated subsequence replacement (seed 000 §4.2): start from random
// sequences (by default optimized one sprite after the other first, or from beam search),
// then repeatedly pick steps k <= l of one sprite's sequence and try to replace
//   the middle    s_k..s_l  by S*(s_k->t) S*(t->s_l),  t ∈ F(s_k) ∩ B(s_l),
//   the beginning s_0..s_l  by S*(t->s_l),              t ∈ B(s_l),
//   the end       s_k..s_n  by S*(s_k->t),              t ∈ F(s_k),
// keeping the first candidate that lowers the total cost C. Several sprites take turns of
// `changes_per_turn` picks each, the others fixed. Every candidate follows real edges only.
// Hill climbing stops in a local minimum; with time left it restarts from random sequences
// (restart_when_converged) and keeps the best.
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "animate/beam_search.h"
#include "animate/problem.h"
#include "animate/reach_sets.h"
#include "animate/summary.h"

namespace ss {

// kSequential: random sequences, then the sprites one after the other, each optimized only
// against the terms that read no later sprite (as beam search plans them), then all together.
// Without it, coupled sprites pin each other: a leader cannot walk off while its follower
// stands, nor the follower move while the leader stands (a joint local minimum).
enum class StartMethod { kRandom, kBeam, kGiven, kSequential };

struct ReplacementOptions {
  ReachOptions reach;  // N = reach.set_size, threads, step cost of Ĉ
  // Ĉ also adds this fraction of the median positive transition cost per step, so long
  // zero-cost runs of a clip do not crowd the transitions out of the F/B sets.
  double step_cost_fraction = 0.05;
  double slow_frame_cost = 0.0;    // Ĉ favours fast frames: + ρ̂ max(0, v_ref - |v|) per frame
  double reference_speed_m = 0.0;  // v_ref for that, metres per step
  bool frame_constraint_sets = true;  // F/B sets with each frame constraint in Ĉ (§6.1)

  double time_budget_seconds = 10.0;  // the whole run: F/B sets, start and optimization
  uint64_t seed = 1;
  int max_tries = 2000;        // a sprite has converged after this many picks without a gain
  int changes_per_turn = 100;  // picks per sprite turn
  int max_turns = 0;           // 0: no limit
  StartMethod start = StartMethod::kSequential;  // kGiven uses SpriteSpec::initial_sequence
  // kSequential: share of the remaining time the one-by-one phase may take (each restart too).
  double sequential_fraction = 0.3;
  // Once every sprite has converged, start again from new random sequences while time
  // remains and return the best result. False: stop at convergence (seed 000 §4.2).
  bool restart_when_converged = true;
  BeamOptions beam;  // for start = kBeam; its budget (default: a quarter) comes out of this one

  // Share of the end picks of a sprite with a frame constraint whose window reaches past the
  // pick's first step that replace the end by the way to G and a run in it (toward()).
  double goal_fraction = 0.25;
  double middle_fraction = 0.6;  // share of picks replacing a middle piece
  double begin_fraction = 0.2;   // ... the beginning; the rest replace the end
  int max_span = 0;              // longest l - k picked; 0: the whole sequence
  // Share of a sprite's picks aimed at one of its collisions (a step where it is closer than
  // d_min to another sprite): k and l are drawn around that step instead of anywhere. Uniform
  // picks rarely land on the few steps of a shallow collision, which then outlive the budget.
  double collision_pick_fraction = 0.25;
  int max_candidates = 0;            // t tried per pick; 0: all of them
  bool optimize_free_starts = true;  // least-squares and pattern search on free p_0
  double progress_seconds = 0.0;     // log progress this often; 0: never
  // Called after every accepted move with the current tracks (tests, live plots).
  std::function<void(const std::vector<Track>&, const TracePoint&)> on_improvement;
  // Set by another thread: the run stops at its next pick (TerminationType::kCancelled) and
  // returns the best sequences so far. The F/B sets are built before it is read.
  const std::atomic<bool>* cancel = nullptr;

  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range;
  // the reach block's fields come out under "reach.", the beam block's (checked only for
  // start = kBeam) under "beam.".
  bool IsValid(std::string* why) const;
};

// The F/B sets for a problem: one pair for Ĉ and one per frame constraint (Ĉ + λ[f ∉ G]).
class ReplacementSets {
 public:
  static ReplacementSets Build(const Problem& problem, const ReplacementOptions& options);
  // What Build would take, before it is made: a pair of F/B sets per variant (one, and one per
  // distinct frame constraint), and the toward() pointers.
  static int64_t EstimateBytes(const Problem& problem, const ReplacementOptions& options);
  int num_variants() const { return static_cast<int>(forward_.size()); }
  const ReachSets& forward(int variant) const { return forward_[variant]; }
  const ReachSets& backward(int variant) const { return backward_[variant]; }
  // The variant for replacing steps [first, last] of `sprite`: a frame constraint's when its
  // window covers most of those steps, else 0 (plain Ĉ). With `open_end` (the end of the
  // sequence is replaced) a window reaching past the last step counts up to its end: the
  // new end may fill it (a sequence shorter than its window otherwise never gets there).
  // Pick() asks so for half of its end moves: a window past the end also stands for a path
  // not yet passed, where the plain Ĉ is the one that helps.
  int VariantFor(const Problem& problem, Tracks tracks, int sprite, int first, int last,
                 bool open_end = false) const;
  // The frame constraints: (term index, variant), in term order.
  const std::vector<std::pair<int, int>>& frame_terms() const { return frame_terms_; }
  // For a frame constraint's variant, one step toward its set G from every frame: outside G the
  // next frame on the cheapest path (by the plain Ĉ) to the nearest frame of G; in G the next
  // frame that stays in G (its natural successor when that is in G, else the cheapest edge into
  // G); -1 where there is none. A pick's F set reaches a few steps; G may lie 30 away (the
  // hamster's stands: 33 steps at the median frame of the 30-minute set), so the goal move
  // follows these pointers instead (issue 33).
  std::span<const int32_t> toward(int variant) const { return toward_[variant]; }
  double build_seconds() const { return build_seconds_; }
  size_t MemoryBytes() const;

 private:
  std::vector<ReachSets> forward_;
  std::vector<ReachSets> backward_;
  std::vector<std::pair<int, int>> frame_terms_;  // (term index, variant)
  std::vector<std::vector<int32_t>> toward_;      // per variant (empty for 0)
  double build_seconds_ = 0.0;
};

// Builds the sets (unless given), the initial sequences, and optimizes. Throws InputError
// for invalid options.
std::vector<Track> OptimizeSequences(const Problem& problem, const ReplacementOptions& options,
                                     Summary* summary, const ReplacementSets* sets = nullptr);

// Optimizes from `initial` (one valid track per sprite) with prebuilt sets.
std::vector<Track> ImproveSequences(const Problem& problem, const ReplacementOptions& options,
                                    const ReplacementSets& sets, std::vector<Track> initial,
                                    Summary* summary);

// A random walk of up to `length` frames: natural successors 9 times in 10, else a random
// out-edge; stops early at a frame without successors.
std::vector<int> RandomSequence(const TransitionGraph& graph, int length, uint64_t seed);

}  // namespace ss
