#include "animate/collision_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace ss {

CollisionTerm::CollisionTerm(int sprite_a, int sprite_b, double min_distance_m, double strength,
                             bool hold_after_end)
    : StepSumTerm("collision", {sprite_a, sprite_b}, strength),
      min_distance_m_(min_distance_m),
      hold_after_end_(hold_after_end) {
  if (sprite_a == sprite_b) throw InputError("collision.sprites", "needs two different sprites");
  if (!(min_distance_m > 0) || !std::isfinite(min_distance_m)) {
    throw InputError("collision.min_distance", "must be > 0 metres");
  }
}

std::pair<int, int> CollisionTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  const int na = tracks[sprites()[0]]->size();
  const int nb = tracks[sprites()[1]]->size();
  return {0, hold_after_end_ ? std::max(na, nb) : std::min(na, nb)};
}

double CollisionTerm::Evaluate(Tracks tracks, const EvalRequest& request) const {
  auto [begin, end] = Steps(tracks, request);
  end = std::min(end, request.step_limit);
  double sum = 0.0;
  int from = begin;
  if (request.cache != nullptr && !request.cache->prefix.empty()) {
    const std::vector<double>& prefix = request.cache->prefix;
    const int cached_end =
        std::min({request.first_changed, static_cast<int>(prefix.size()) - 1, end});
    if (cached_end > begin) {
      sum = prefix[cached_end] - prefix[begin];
      from = cached_end;
    }
  }
  const Track& a = *tracks[sprites()[0]];
  const Track& b = *tracks[sprites()[1]];
  const double min_squared = min_distance_m_ * min_distance_m_;
  Eigen::AlignedBox2d held_a;
  Eigen::AlignedBox2d held_b;
  for (int t = from; t < end;) {
    const int chunk = t / Track::kChunkSteps;
    const int chunk_end = std::min(end, (chunk + 1) * Track::kChunkSteps);
    const Eigen::AlignedBox2d* box_a = a.ChunkBox(chunk, &held_a);
    const Eigen::AlignedBox2d* box_b = b.ChunkBox(chunk, &held_b);
    if (box_a != nullptr && box_b != nullptr &&
        box_a->squaredExteriorDistance(*box_b) >= min_squared) {
      t = chunk_end;  // every step of this chunk costs 0
      continue;
    }
    for (; t < chunk_end; ++t) {
      sum += StepCost(tracks, t);
      if (sum > request.budget) return sum;
    }
  }
  return sum;
}

double CollisionTerm::Distance(Tracks tracks, int t) const {
  return (tracks[sprites()[0]]->PositionAt(t) - tracks[sprites()[1]]->PositionAt(t)).norm();
}

double CollisionTerm::StepCost(Tracks tracks, int t) const {
  return strength() * std::max(min_distance_m_ - Distance(tracks, t), 0.0);
}

int CollisionTerm::CountViolations(Tracks tracks) const {
  const auto [begin, end] = Steps(tracks, EvalRequest{});
  int count = 0;
  for (int t = begin; t < end; ++t) count += Distance(tracks, t) < min_distance_m_ ? 1 : 0;
  return count;
}

double CollisionTerm::MinDistance(Tracks tracks) const {
  const auto [begin, end] = Steps(tracks, EvalRequest{});
  double best = std::numeric_limits<double>::infinity();
  for (int t = begin; t < end; ++t) best = std::min(best, Distance(tracks, t));
  return best;
}

}  // namespace ss
