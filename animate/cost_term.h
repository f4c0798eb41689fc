#pragma once
// One component of the total sequence cost C(S) = Cs(S) + Cc(S) (seed 000 eq. 3): a sum
// over time steps of a per-step cost c_t (eq. 6) plus, for some terms, an end-of-sequence
// cost. Every term carries its strength coefficient and reads the tracks of one or more
// sprites. Costs are >= 0, so a partial sum is a lower bound: evaluation may stop early
// once it exceeds a budget. Per-step costs depend only on the states at (and before) that
// step, so a term can reuse the cached sum over the unchanged steps before a replaced piece.
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "animate/track.h"

namespace ss {

// A range of steps; each end counts from step 0 or back from the last step (n - 1).
struct StepWindow {
  int first = 0;
  bool first_from_end = false;
  int last = 0;  // inclusive
  bool last_from_end = true;

  static StepWindow All() { return {0, false, 0, true}; }
  static StepWindow At(int step) { return {step, false, step, false}; }
  static StepWindow Range(int first, int last) { return {first, false, last, false}; }
  static StepWindow LastStep() { return {0, true, 0, true}; }
  // [begin, end) for a sequence of n steps; may reach past n (held states); empty if end <= begin.
  std::pair<int, int> Resolve(int n) const;
};

// What a term remembers about the tracks it last saw (the accepted ones).
struct TermCache {
  std::vector<double> prefix;  // prefix[t] = sum of the (unwindowed) step costs over steps < t
  std::vector<int> state;      // per-step state of stateful terms (path segment before step t)
  int event_step = -1;         // a remembered event (step a path was completed), -1 if none
};

struct EvalRequest {
  int first_changed = 0;             // the tracks equal the cached ones at every step before this
  const TermCache* cache = nullptr;  // from BuildCache on those tracks; null: compute every step
  // The frames (not necessarily the positions: an end anchor moves them all) equal the
  // cached ones before this step; -1: the same as first_changed.
  int first_frame_changed = -1;
  // From step shifted_from on, frame t equals the cached frame t - shift (the part after a
  // replaced piece, moved in time by the change of length); INT_MAX: no such part.
  int shifted_from = std::numeric_limits<int>::max();
  int shift = 0;
  double budget = std::numeric_limits<double>::infinity();  // may stop once the cost exceeds it
  int step_limit = std::numeric_limits<int>::max();  // partial sequence: steps < limit, no end cost
  bool partial() const { return step_limit != std::numeric_limits<int>::max(); }
};

class CostTerm {
 public:
  // Throws InputError("<kind>.strength") unless strength is finite and >= 0.
  CostTerm(std::string kind, std::vector<int> sprites, double strength);
  virtual ~CostTerm() = default;

  const std::string& kind() const { return kind_; }  // "smoothness", "location", "path", ...
  const std::vector<int>& sprites() const { return sprites_; }  // the tracks it reads; [0] owns it
  double strength() const { return strength_; }

  double Evaluate(Tracks tracks) const { return Evaluate(tracks, EvalRequest{}); }
  virtual double Evaluate(Tracks tracks, const EvalRequest& request) const = 0;
  virtual void BuildCache(Tracks tracks, TermCache* cache) const = 0;
  // Steps that break the constraint (collisions, frames off the tag, unreached path); 0 if n/a.
  virtual int CountViolations(Tracks /*tracks*/) const { return 0; }
  // Terms quadratic in a free sprite's start p_0, sum_t w_t |p_0 + d_t - q_t|^2, add
  // sum w_t and sum w_t (q_t - d_t), d_t = p_t - p_0 (a least-squares start, seed 000 §6.2).
  virtual void AddStartNormalEquations(Tracks /*tracks*/, int /*sprite*/, double* /*weight*/,
                                       Eigen::Vector2d* /*weighted_target*/) const {}

 private:
  std::string kind_;
  std::vector<int> sprites_;
  double strength_;
};

// A term sum_{t in window} c_t + end cost, where c_t depends only on the states at step t
// (and t - 1). Subclasses give the window, c_t and the end cost; caching is done here.
class StepSumTerm : public CostTerm {
 public:
  using CostTerm::CostTerm;
  double Evaluate(Tracks tracks, const EvalRequest& request) const override;
  void BuildCache(Tracks tracks, TermCache* cache) const override;

 protected:
  // The summed steps [begin, end) for these tracks (the request's cache may help).
  virtual std::pair<int, int> Steps(Tracks tracks, const EvalRequest& request) const = 0;
  // c_t with the strength applied, whether or not t is in the window.
  virtual double StepCost(Tracks tracks, int t) const = 0;
  virtual double EndCost(Tracks /*tracks*/) const { return 0; }
  // c_t depends on the frames alone (not on positions): the prefix before
  // first_frame_changed is reused even when every position moved.
  virtual bool FramesOnly() const { return false; }
  // c_t also ignores t itself (frames at t and t - 1 only) and the window is [w, n): the
  // part after a replaced piece is summed from the cache with its time shift.
  virtual bool TimeInvariant() const { return false; }
  // With TimeInvariant: c_t reads the frames at steps [t - LookBack(), t] (the edge: 1).
  virtual int LookBack() const { return 1; }
  // Longest sequence among the sprites read.
  int MaxLength(Tracks tracks) const;
};

// A StepSumTerm whose c_t reads only the frames shown up to LookBack() steps back, wherever step
// t lies (smoothness, fast frames, repeats): both of StepSumTerm's caches apply.
class FrameStepTerm : public StepSumTerm {
 public:
  using StepSumTerm::StepSumTerm;

 protected:
  bool FramesOnly() const final { return true; }
  bool TimeInvariant() const final { return true; }
};

}  // namespace ss
