#include "animate/basic_costs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "animate/problem.h"
#include "core/error.h"
#include "core/options_binder.h"

namespace ss {

SmoothnessTerm::SmoothnessTerm(const TransitionGraph& graph, int sprite, double strength)
    : FrameStepTerm("smoothness", {sprite}, strength), graph_(graph) {}

std::pair<int, int> SmoothnessTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  return {1, std::max(1, tracks[sprites()[0]]->size())};
}

double SmoothnessTerm::StepCost(Tracks tracks, int t) const {
  const Track& track = *tracks[sprites()[0]];
  if (t < 1 || t >= track.size()) return 0.0;
  const std::optional<double> cost = graph_.EdgeCost(track.frames[t - 1], track.frames[t]);
  // Sequences are built from real edges only; a missing one is a bug upstream.
  return cost ? strength() * *cost : std::numeric_limits<double>::max();
}

FastFrameTerm::FastFrameTerm(int sprite, double reference_speed_m, double strength)
    : FrameStepTerm("fast", {sprite}, strength), reference_speed_m_(reference_speed_m) {
  if (!(reference_speed_m > 0) || !std::isfinite(reference_speed_m)) {
    throw InputError("fast.reference_speed", "must be > 0 metres per step");
  }
}

std::pair<int, int> FastFrameTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  return {0, tracks[sprites()[0]]->size()};
}

double FastFrameTerm::StepCost(Tracks tracks, int t) const {
  return strength() *
         std::max(0.0, reference_speed_m_ - tracks[sprites()[0]]->VelocityAt(t).norm());
}

RepeatTerm::RepeatTerm(int sprite, int window_steps, double strength,
                       std::shared_ptr<const std::vector<bool>> exempt)
    : FrameStepTerm("repeat", {sprite}, strength),
      window_steps_(window_steps),
      exempt_(std::move(exempt)) {
  if (window_steps < 1) throw InputError("repeat.window_steps", "must be >= 1");
}

std::pair<int, int> RepeatTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  return {1, std::max(1, tracks[sprites()[0]]->size())};
}

bool RepeatTerm::Repeats(const Track& track, int t) const {
  if (t < 1 || t >= track.size()) return false;
  const int frame = track.frames[t];
  if (exempt_ && (*exempt_)[frame]) return false;
  for (int u = std::max(0, t - window_steps_); u < t; ++u) {
    if (track.frames[u] == frame) return true;
  }
  return false;
}

double RepeatTerm::StepCost(Tracks tracks, int t) const {
  return Repeats(*tracks[sprites()[0]], t) ? strength() : 0.0;
}

int RepeatTerm::CountViolations(Tracks tracks) const {
  const Track& track = *tracks[sprites()[0]];
  int n = 0;
  for (int t = 1; t < track.size(); ++t) n += Repeats(track, t);
  return n;
}

std::vector<double> FacingCosts(const TransitionGraph& graph, double strength) {
  std::vector<double> cost(graph.num_frames(), 0.0);
  for (int i = 0; i < graph.num_frames(); ++i) {
    const std::optional<double>& heading = graph.frame(i).heading_rad;
    const Eigen::Vector2d& v = graph.velocity_m(i);
    if (!heading || v.isZero()) continue;
    const double off = *heading - std::atan2(v.y(), v.x());
    cost[i] = strength * v.norm() * (1 - std::cos(off)) / 2;
  }
  return cost;
}

FacingTerm::FacingTerm(int sprite, std::shared_ptr<const std::vector<double>> cost)
    : FrameStepTerm("facing", {sprite}, 1.0), cost_(std::move(cost)) {
  if (!cost_) throw InputError("facing", "missing frame costs");
}

std::pair<int, int> FacingTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  return {0, tracks[sprites()[0]]->size()};
}

double FacingTerm::StepCost(Tracks tracks, int t) const {
  const Track& track = *tracks[sprites()[0]];
  return t < track.size() ? (*cost_)[track.frames[t]] : 0.0;
}

LengthTerm::LengthTerm(int sprite, int min_frames, double strength)
    : StepSumTerm("length", {sprite}, strength), min_frames_(min_frames) {
  if (min_frames < 1) throw InputError("length.min_frames", "must be >= 1");
}

double LengthTerm::EndCost(Tracks tracks) const {
  return strength() * std::max(0, min_frames_ - tracks[sprites()[0]]->size());
}

int LengthTerm::CountViolations(Tracks tracks) const {
  return tracks[sprites()[0]]->size() < min_frames_ ? 1 : 0;
}

FrameTerm::FrameTerm(int sprite, std::shared_ptr<const std::vector<bool>> allowed,
                     StepWindow window, double strength, std::optional<PathTrigger> trigger)
    : StepSumTerm("frame",
                  trigger && trigger->sprite != sprite ? std::vector<int>{sprite, trigger->sprite}
                                                       : std::vector<int>{sprite},
                  strength),
      allowed_(std::move(allowed)),
      window_(window),
      trigger_(std::move(trigger)) {
  if (!allowed_) throw InputError("frame.frames", "missing frame set");
  if (trigger_ && trigger_->duration_steps < 1) {
    throw InputError("frame.duration", "must be >= 1 step");
  }
}

bool FrameTerm::Allowed(const Track& track, int t) const {
  if (t >= track.size()) return false;  // the sprite is gone: the pose is not shown
  const int f = track.frames[t];
  return f < static_cast<int>(allowed_->size()) && (*allowed_)[f];
}

std::pair<int, int> FrameTerm::Steps(Tracks tracks, const EvalRequest& request) const {
  if (!trigger_) return window_.Resolve(tracks[sprites()[0]]->size());
  const Track& anchor = *tracks[trigger_->sprite];
  int begin = PathCompletionStep(trigger_->path, anchor, request.cache, request.first_changed);
  if (begin < 0) begin = anchor.size();
  return {begin, begin + trigger_->duration_steps};
}

double FrameTerm::StepCost(Tracks tracks, int t) const {
  return Allowed(*tracks[sprites()[0]], t) ? 0.0 : strength();
}

void FrameTerm::BuildCache(Tracks tracks, TermCache* cache) const {
  StepSumTerm::BuildCache(tracks, cache);
  if (trigger_) FillPathStates(trigger_->path, *tracks[trigger_->sprite], cache);
}

int FrameTerm::CountViolations(Tracks tracks) const {
  const auto [begin, end] = Window(tracks);
  int count = 0;
  for (int t = begin; t < end; ++t) count += Allowed(*tracks[sprites()[0]], t) ? 0 : 1;
  return count;
}

void RepeatSpec::AddTerms(const TransitionGraph& graph, Problem& problem) const {
  if (strength <= 0) return;
  std::shared_ptr<const std::vector<bool>> still;  // frames that may repeat
  if (!still_tag.empty())
    still = std::make_shared<std::vector<bool>>(graph.FramesWithTag(still_tag));
  for (int id = 0; id < problem.num_sprites(); ++id)
    problem.AddTerm(std::make_unique<RepeatTerm>(id, window_steps, strength, still));
}

std::vector<std::string> RepeatSpec::Tags() const {
  if (strength > 0 && !still_tag.empty()) return {still_tag};
  return {};
}

void FacingSpec::AddTerms(const TransitionGraph& graph, Problem& problem) const {
  if (strength <= 0 || !graph.has_floor_frames()) return;
  // φ per frame, shared by the sprites.
  const auto cost = std::make_shared<const std::vector<double>>(FacingCosts(graph, strength));
  for (int id = 0; id < problem.num_sprites(); ++id)
    problem.AddTerm(std::make_unique<FacingTerm>(id, cost));
}

void RegisterRepeatsSpecTerm() {
  RegisterSpecTerm({"repeats", "{strength, window_steps, still_tag}",
                    TermBlockReader<RepeatSpec>(
                        [](OptionsBinder& keys, RepeatSpec& r) {
                          keys.Add("strength", &r.strength, "a number >= 0",
                                   "per step showing a frame shown just before")
                              .Rule(AtLeast(0))
                              .Add("window_steps", &r.window_steps, "1..1000 steps", "how far back")
                              .Rule(Between(1, 1000))
                              .Add("still_tag", &r.still_tag, "a tag", "frames that may repeat");
                        },
                        {"strength"})});
}

void RegisterFacingSpecTerm() {
  RegisterSpecTerm({"facing", "{strength}",
                    TermBlockReader<FacingSpec>(
                        [](OptionsBinder& keys, FacingSpec& f) {
                          keys.Add("strength", &f.strength, "a number >= 0",
                                   "per metre moved other than forward")
                              .Rule(AtLeast(0));
                        },
                        {"strength"}),
                    [] { return std::make_shared<FacingSpec>(); }});
}

}  // namespace ss
