#pragma once
// The anti-collision constraint (seed 000 §5.3, eq. 9) between sprites a and b: a conical
// error surface, linear in the distance,
//   c_t = µ max(d_min - |p_a(t) - p_b(t)|, 0),
// over the steps where either sprite exists (a finished sprite holds its last position).
// Steps are skipped a chunk at a time when the two tracks' chunk boxes are d_min apart.
#include "animate/cost_term.h"

namespace ss {

class CollisionTerm : public StepSumTerm {
 public:
  // Throws InputError for a == b or d_min <= 0.
  CollisionTerm(int sprite_a, int sprite_b, double min_distance_m, double strength,
                bool hold_after_end = true);
  double min_distance_m() const { return min_distance_m_; }
  // As StepSumTerm, but skips chunks of steps whose position boxes are d_min apart.
  double Evaluate(Tracks tracks, const EvalRequest& request) const override;
  using CostTerm::Evaluate;
  // Steps closer than d_min.
  int CountViolations(Tracks tracks) const override;
  // Smallest distance between the two sprites over the summed steps.
  double MinDistance(Tracks tracks) const;

 protected:
  std::pair<int, int> Steps(Tracks tracks, const EvalRequest& request) const override;
  double StepCost(Tracks tracks, int t) const override;

 private:
  double Distance(Tracks tracks, int t) const;

  double min_distance_m_;
  bool hold_after_end_;
};

}  // namespace ss
