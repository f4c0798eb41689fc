#pragma once
// The location constraint (seed 000 §5.1, eq. 7): per step t of a window,
//   c_t = γ |p_t - q_t|^2.
// The target q_t is a fixed point, or follows another sprite for formations:
//   q_t = p_leader(t) + R(heading_leader(t)) o     (o = (along, left) in the leader's frame)
// or q_t = p_leader(t) + o in ground axes. The leader's heading is the direction of its mean
// velocity over the last few steps (only past steps, so the cost stays causal). A window
// counted from the end, for a follower, counts from the end of the longer of the two
// sequences: the formation lasts while either sprite is on (a finished sprite holds).
#include <Eigen/Core>

#include "animate/cost_term.h"

namespace ss {

struct LocationTarget {
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();  // the target, or the offset o from a leader
  int follow_sprite = -1;                             // >= 0: formation behind/beside this sprite
  bool offset_in_heading = true;  // o is (along, left) of the leader's heading; else ground axes
  int heading_steps = 5;          // the leader's heading averages this many past velocities

  static LocationTarget Fixed(const Eigen::Vector2d& point_m) { return {point_m}; }
  static LocationTarget Follow(int leader, const Eigen::Vector2d& offset_m,
                               bool in_heading = true) {
    return {offset_m, leader, in_heading};
  }
};

class LocationTerm : public StepSumTerm {
 public:
  // Throws InputError for a sprite following itself or heading_steps < 1.
  LocationTerm(int sprite, StepWindow window, const LocationTarget& target, double strength);
  // q_t for these tracks.
  Eigen::Vector2d TargetAt(Tracks tracks, int t) const;
  void AddStartNormalEquations(Tracks tracks, int sprite, double* weight,
                               Eigen::Vector2d* weighted_target) const override;
  const StepWindow& window() const { return window_; }
  const LocationTarget& target() const { return target_; }
  // The steps [begin, end) of the window for these tracks (a formation's counts from the
  // longer sequence's end).
  std::pair<int, int> Window(Tracks tracks) const { return Steps(tracks, EvalRequest{}); }

 protected:
  std::pair<int, int> Steps(Tracks tracks, const EvalRequest& request) const override;
  double StepCost(Tracks tracks, int t) const override;

 private:
  StepWindow window_;
  LocationTarget target_;
};

// Unit heading of a track at step t: its mean velocity over steps (t - steps, t], looking
// further back past standing frames; +x when it never moved.
Eigen::Vector2d HeadingAt(const Track& track, int t, int steps);

}  // namespace ss
