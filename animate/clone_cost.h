#pragma once
// The clone term (ours, not the paper's) between sprites a and b: what a viewer sees as one
// sprite copied, two sprites showing the same frame at about the same time (judge/judge.h,
// "clones"). Each coincidence, a showing at step t1 the frame b shows at step t2 with
// |t1 - t2| <= lag, costs κ once, at the later of the two steps, so that a step's cost reads
// only the steps before it:
//   c_t = κ [s^a_t ∈ {s^b_u : t - lag <= u <= t}] + κ [s^b_t ∈ {s^a_u : t - lag <= u < t}]
// over the steps both sprites show a frame. The 64 flies of §6.2 are symmetric: each has the
// same best sequence, and without this term they walked in lockstep.
#include "animate/cost_term.h"
#include "animate/spec_term.h"

namespace ss {

class CloneTerm : public StepSumTerm {
 public:
  // Throws InputError for a == b or lag_steps < 0.
  CloneTerm(int sprite_a, int sprite_b, int lag_steps, double strength);
  // Steps where a coincidence is charged.
  int CountViolations(Tracks tracks) const override;

 protected:
  std::pair<int, int> Steps(Tracks tracks, const EvalRequest& request) const override;
  double StepCost(Tracks tracks, int t) const override;
  bool FramesOnly() const override { return true; }

 private:
  int Coincidences(Tracks tracks, int t) const;

  int lag_steps_;
};

// The spec's `clones:` block (animate/spec_term.h): a CloneTerm between every pair of sprites.
// Off unless the spec sets it.
struct CloneSpec : SpecTerm {
  int lag_steps = 2;
  double strength = 0.0;
  void AddTerms(const TransitionGraph& graph, Problem& problem) const override;
};

}  // namespace ss
