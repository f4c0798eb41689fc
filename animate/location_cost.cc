#include "animate/location_cost.h"

#include <algorithm>

#include "core/error.h"

namespace ss {

Eigen::Vector2d HeadingAt(const Track& track, int t, int steps) {
  t = std::min(t, track.size() - 1);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int u = t, used = 0; u >= 0; --u) {
    sum += track.velocities_m[u];
    if (++used >= steps && sum.squaredNorm() > 1e-18) break;
  }
  return sum.squaredNorm() > 1e-18 ? Eigen::Vector2d(sum.normalized()) : Eigen::Vector2d::UnitX();
}

LocationTerm::LocationTerm(int sprite, StepWindow window, const LocationTarget& target,
                           double strength)
    : StepSumTerm("location",
                  target.follow_sprite >= 0 ? std::vector<int>{sprite, target.follow_sprite}
                                            : std::vector<int>{sprite},
                  strength),
      window_(window),
      target_(target) {
  if (target.follow_sprite == sprite) {
    throw InputError("location.follow", "a sprite cannot follow itself");
  }
  if (target.heading_steps < 1) throw InputError("location.heading_steps", "must be >= 1");
  if (!target.point_m.allFinite()) throw InputError("location.target", "must be finite");
}

Eigen::Vector2d LocationTerm::TargetAt(Tracks tracks, int t) const {
  if (target_.follow_sprite < 0) return target_.point_m;
  const Track& leader = *tracks[target_.follow_sprite];
  if (!target_.offset_in_heading) return leader.PositionAt(t) + target_.point_m;
  const Eigen::Vector2d along = HeadingAt(leader, t, target_.heading_steps);
  const Eigen::Vector2d left(-along.y(), along.x());
  return leader.PositionAt(t) + target_.point_m.x() * along + target_.point_m.y() * left;
}

std::pair<int, int> LocationTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  int n = tracks[sprites()[0]]->size();
  // A formation lasts while either sprite is on: a follower that stops short holds its last
  // position and pays for every step the leader goes on (else ending early is cheapest).
  if (target_.follow_sprite >= 0) n = std::max(n, tracks[target_.follow_sprite]->size());
  return window_.Resolve(n);
}

double LocationTerm::StepCost(Tracks tracks, int t) const {
  return strength() * (tracks[sprites()[0]]->PositionAt(t) - TargetAt(tracks, t)).squaredNorm();
}

void LocationTerm::AddStartNormalEquations(Tracks tracks, int sprite, double* weight,
                                           Eigen::Vector2d* weighted_target) const {
  if (sprite != sprites()[0]) return;  // a leader's start moves both p and q: not quadratic here
  const Track& track = *tracks[sprite];
  const auto [begin, end] = Steps(tracks, EvalRequest{});
  for (int t = begin; t < end; ++t) {
    const Eigen::Vector2d displacement = track.PositionAt(t) - track.positions_m.front();
    *weight += strength();
    *weighted_target += strength() * (TargetAt(tracks, t) - displacement);
  }
}

}  // namespace ss
