#include "animate/path_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"

namespace ss {
namespace {

constexpr double kMinSpeedM = 1e-9;  // below this a frame has no direction

// Angle between two vectors in [0, π].
double AngleBetween(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
}

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + s * ab - p).norm();
}

}  // namespace

Polyline::Polyline(const std::vector<Eigen::Vector2d>& points_m, const std::string& field) {
  for (const Eigen::Vector2d& p : points_m) {
    if (!p.allFinite()) throw InputError(field, "points must be finite");
    if (points_.empty() || (p - points_.back()).norm() > 1e-12) points_.push_back(p);
  }
  if (points_.size() < 2) throw InputError(field, "needs at least two distinct points");
  const int m = static_cast<int>(points_.size()) - 1;
  directions_.resize(m);
  remaining_after_.assign(m, 0.0);
  for (int i = 0; i < m; ++i) directions_[i] = (points_[i + 1] - points_[i]).normalized();
  for (int i = m - 2; i >= 0; --i) {
    remaining_after_[i] = remaining_after_[i + 1] + (points_[i + 2] - points_[i + 1]).norm();
  }
}

int Polyline::Advance(int segment, const Eigen::Vector2d& p) const {
  while (segment < num_segments() && (p - end(segment)).dot(direction(segment)) >= 0) ++segment;
  return segment;
}

double Polyline::Remaining(int segment, const Eigen::Vector2d& p) const {
  if (segment >= num_segments()) return 0.0;
  return std::max(0.0, (end(segment) - p).dot(direction(segment))) + remaining_after_[segment];
}

int PathCompletionStep(const Polyline& path, const Track& track, const TermCache* cache,
                       int first_changed) {
  int from = 0;
  int segment = 0;
  if (cache != nullptr && !cache->state.empty()) {
    if (cache->event_step >= 0 && cache->event_step < first_changed) return cache->event_step;
    from = std::min({first_changed, static_cast<int>(cache->state.size()) - 1, track.size()});
    segment = cache->state[from];
  }
  for (int t = from; t < track.size(); ++t) {
    segment = path.Advance(segment, track.positions_m[t]);
    if (segment == path.num_segments()) return t;
  }
  return -1;
}

void FillPathStates(const Polyline& path, const Track& track, TermCache* cache) {
  cache->state.assign(track.size() + 1, 0);
  cache->event_step = -1;
  int segment = 0;
  for (int t = 0; t < track.size(); ++t) {
    segment = path.Advance(segment, track.positions_m[t]);
    if (segment == path.num_segments() && cache->event_step < 0) cache->event_step = t;
    cache->state[t + 1] = segment;
  }
}

PathTerm::PathTerm(int sprite, Polyline path, PathStrengths strengths)
    : CostTerm("path", {sprite}, 1.0), path_(std::move(path)), strengths_(strengths) {
  for (double s : {strengths.direction, strengths.distance, strengths.unreached}) {
    if (!std::isfinite(s) || s < 0) throw InputError("path.strength", "must be finite and >= 0");
  }
}

double PathTerm::StepCost(const Eigen::Vector2d& p, const Eigen::Vector2d& v, int segment) const {
  if (segment >= path_.num_segments()) return 0.0;
  const Eigen::Vector2d& d = path_.direction(segment);
  const double angle = v.norm() < kMinSpeedM ? std::numbers::pi / 2 : AngleBetween(v, d);
  const Eigen::Vector2d normal(-d.y(), d.x());
  const double offset = (p - path_.end(segment)).dot(normal);
  return strengths_.direction * angle + strengths_.distance * offset * offset;
}

double PathTerm::Evaluate(Tracks tracks, const EvalRequest& request) const {
  const Track& track = *tracks[sprites()[0]];
  const int end = std::min(track.size(), request.step_limit);
  int from = 0;
  int segment = 0;
  double sum = 0.0;
  if (request.cache != nullptr && !request.cache->state.empty()) {
    const TermCache& cache = *request.cache;
    from = std::min({request.first_changed, static_cast<int>(cache.state.size()) - 1, end});
    from = std::max(from, 0);
    segment = cache.state[from];
    sum = cache.prefix[from];
  }
  for (int t = from; t < end; ++t) {
    segment = path_.Advance(segment, track.positions_m[t]);
    sum += StepCost(track.positions_m[t], track.velocities_m[t], segment);
    if (sum > request.budget) return sum;
  }
  if (!request.partial() && !track.empty()) {
    sum += strengths_.unreached * path_.Remaining(segment, track.positions_m.back());
  }
  return sum;
}

void PathTerm::BuildCache(Tracks tracks, TermCache* cache) const {
  const Track& track = *tracks[sprites()[0]];
  FillPathStates(path_, track, cache);
  cache->prefix.assign(track.size() + 1, 0.0);
  for (int t = 0; t < track.size(); ++t) {
    cache->prefix[t + 1] = cache->prefix[t] + StepCost(track.positions_m[t], track.velocities_m[t],
                                                       cache->state[t + 1]);
  }
}

int PathTerm::CountViolations(Tracks tracks) const {
  const Track& track = *tracks[sprites()[0]];
  return PathCompletionStep(path_, track, nullptr, 0) < 0 ? 1 : 0;
}

double PathTerm::MaxDeviation(const Track& track) const {
  double worst = 0.0;
  const int done = PathCompletionStep(path_, track, nullptr, 0);
  const int end = done < 0 ? track.size() : done + 1;
  for (int t = 0; t < end; ++t) {
    const Eigen::Vector2d& p = track.positions_m[t];
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i + 1 < path_.points().size(); ++i) {
      best = std::min(best, PointSegmentDistance(p, path_.points()[i], path_.points()[i + 1]));
    }
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace ss
