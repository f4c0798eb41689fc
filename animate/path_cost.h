#pragma once
// The path constraint (seed 000 §5.2, eq. 8, after Schödl & Essa 2001). The path is a
// polyline; a tracker keeps the segment the sprite is expected to follow and moves on once
// the sprite passes the segment's end (its projection on the segment direction reaches the
// end point). Per step, on segment i with unit direction d_i and end point e_i:
//   c_t = δ |∠v_t - ∠d_i| + φ ((p_t - e_i) · d_i⊥)^2,
// and after the last step the unreached part of the path costs
//   η (max(0, (e_i - p_{n-1}) · d_i) + sum of the lengths of the segments after i).
// Once the whole path is passed the term costs nothing more.
#include <vector>

#include <Eigen/Core>

#include "animate/cost_term.h"

namespace ss {

class Polyline {
 public:
  // Drops repeated points; throws InputError(field) with fewer than two distinct points.
  Polyline(const std::vector<Eigen::Vector2d>& points_m, const std::string& field = "path.points");
  int num_segments() const { return static_cast<int>(directions_.size()); }
  const Eigen::Vector2d& end(int i) const { return points_[i + 1]; }
  const Eigen::Vector2d& direction(int i) const { return directions_[i]; }  // unit
  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  // Segment index after seeing position p while on `segment` (num_segments() = path done).
  int Advance(int segment, const Eigen::Vector2d& p) const;
  // Path length not yet reached from p on `segment`.
  double Remaining(int segment, const Eigen::Vector2d& p) const;
  double length() const { return remaining_after_.empty() ? 0 : Remaining(0, points_[0]); }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> directions_;
  std::vector<double> remaining_after_;  // total length of segments i+1..end
};

// Step at which the tracker passes the path's end on track `track` (resuming from the
// cache's per-step states when given); -1 if never.
int PathCompletionStep(const Polyline& path, const Track& track, const TermCache* cache,
                       int first_changed);
// Per-step tracker states (segment before step t) for steps 0..n, into cache->state.
void FillPathStates(const Polyline& path, const Track& track, TermCache* cache);

struct PathStrengths {
  double direction = 1.0;  // δ, per radian per step
  double distance = 1.0;   // φ, per m^2 per step
  double unreached = 1.0;  // η, per metre of path not reached at the end
};

class PathTerm : public CostTerm {
 public:
  PathTerm(int sprite, Polyline path, PathStrengths strengths);
  double Evaluate(Tracks tracks, const EvalRequest& request) const override;
  void BuildCache(Tracks tracks, TermCache* cache) const override;
  // 1 when the path was not passed to its end, else 0.
  int CountViolations(Tracks tracks) const override;
  const Polyline& path() const { return path_; }
  // Largest distance of the sprite from the polyline until it passes the path's end (or
  // over the whole sequence if it never does): a report figure.
  double MaxDeviation(const Track& track) const;

 private:
  double StepCost(const Eigen::Vector2d& p, const Eigen::Vector2d& v, int segment) const;

  Polyline path_;
  PathStrengths strengths_;
};

}  // namespace ss
