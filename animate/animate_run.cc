#include "animate/animate_run.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "animate/basic_costs.h"
#include "animate/beam_search.h"
#include "animate/collision_cost.h"
#include "animate/path_cost.h"
#include "animate/replacement.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {

namespace {

std::vector<std::string> SpriteNames(const Scene& scene) {
  std::vector<std::string> names;
  for (const SpriteSpecEntry& s : scene.spec().sprites) names.push_back(s.name);
  return names;
}

}  // namespace

ConstraintFigures MeasureConstraints(const Problem& problem, const std::vector<Track>& tracks) {
  ConstraintFigures f;
  const std::vector<const Track*> view = TrackPointers(tracks);
  double min_distance = std::numeric_limits<double>::infinity();
  bool any_pair = false;
  for (int k = 0; k < problem.num_terms(); ++k) {
    const CostTerm& term = problem.term(k);
    if (const auto* path = dynamic_cast<const PathTerm*>(&term)) {
      f.max_path_deviation_m =
          std::max(f.max_path_deviation_m, path->MaxDeviation(tracks[path->sprites()[0]]));
      f.paths_unfinished += path->CountViolations(view);
    } else if (const auto* collision = dynamic_cast<const CollisionTerm*>(&term)) {
      const int steps = collision->CountViolations(view);
      f.collision_steps += steps;
      f.colliding_pairs += steps > 0 ? 1 : 0;
      min_distance = std::min(min_distance, collision->MinDistance(view));
      any_pair = true;
    } else if (const auto* frame = dynamic_cast<const FrameTerm*>(&term)) {
      const auto [begin, end] = frame->Window(view);
      f.frame_steps += std::max(0, end - begin);
      f.frame_steps_off += frame->CountViolations(view);
    } else if (const auto* length = dynamic_cast<const LengthTerm*>(&term)) {
      f.sprites_short += length->CountViolations(view);
    }
  }
  f.min_distance_m = any_pair ? min_distance : -1.0;
  return f;
}

bool AnimateRunOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(progress_every_s, AtLeast(0), "progress_every_s", "seconds >= 0 (0: never)");
  check.Within(max_turns, AtLeast(0), "max_turns", "at least 0 (0: the time budget alone)");
  // Either optimizer stops at the replacement's budget (the spec's optimizer.time_budget_s).
  const double budget = optimizer.replacement.time_budget_seconds;
  check(budget > 0 && std::isfinite(budget), "optimizer.replacement.time_budget_seconds",
        "must be a positive number of seconds, got " + OptionProblems::Num(budget));
  check(!(budget > kMaxTimeBudgetSeconds) || !std::isfinite(budget),
        "optimizer.replacement.time_budget_seconds",
        "must be at most " + OptionProblems::Num(kMaxTimeBudgetSeconds) + " seconds (a day), got " +
            OptionProblems::Num(budget));
  // Each snapshot keeps every sequence: at most kMaxSpecSnapshots of them over the budget.
  const double every = optimizer.snapshot_every_s;
  check(every == 0 || (every > 0 && every * kMaxSpecSnapshots >= budget),
        "optimizer.snapshot_every_s",
        "must be 0 or >= " + OptionProblems::Num(budget / kMaxSpecSnapshots) +
            " s (the time budget / " + std::to_string(kMaxSpecSnapshots) + "), got " +
            OptionProblems::Num(every));
  return check.ok();
}

AnimateResult RunAnimation(const Scene& scene, const AnimateRunOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("animate options", why);
  const OptimizerSpec& o = options.optimizer;
  AnimateResult result;
  const Problem& problem = scene.problem();
  const std::vector<std::string> names = SpriteNames(scene);
  if (o.method == OptimizerMethod::kBeam) {
    result.tracks = BeamSearch(problem, o.Beam(), &result.summary);
  } else {
    ReplacementOptions replace = scene.MakeReplacementOptions(o.replacement);
    replace.progress_seconds = options.progress_every_s;
    if (options.max_turns > 0) replace.max_turns = options.max_turns;
    replace.cancel = options.cancel;
    double next_snapshot = o.snapshot_every_s;
    if (o.snapshot_every_s > 0 || options.on_improvement) {
      replace.on_improvement = [&](const std::vector<Track>& tracks, const TracePoint& point) {
        if (options.on_improvement) options.on_improvement(tracks, point);
        if (o.snapshot_every_s <= 0 || point.seconds < next_snapshot) return;
        while (next_snapshot <= point.seconds) next_snapshot += o.snapshot_every_s;
        result.stages.push_back(
            {point.seconds, point.cost, ToSpriteSequences(scene.bank(), names, tracks)});
      };
    }
    result.tracks = OptimizeSequences(problem, replace, &result.summary);
  }
  std::string why;
  if (!problem.IsValid(result.tracks, &why)) throw WorkError("animate", "invalid result: " + why);
  result.figures = MeasureConstraints(problem, result.tracks);
  return result;
}

SequenceFile MakeSequenceFile(const Scene& scene, const AnimateResult& result) {
  SequenceFile file;
  file.frame_rate = scene.spec().frame_rate;
  file.camera_path = scene.spec().camera_path;
  file.background_path = scene.spec().background_path;
  file.bank_paths = scene.bank().bank_paths;
  file.sprites = ToSpriteSequences(scene.bank(), SpriteNames(scene), result.tracks);
  file.num_steps = LongestSequence(file.sprites);
  file.stages = result.stages;
  file.summary = SummaryJson(result);
  return file;
}

nlohmann::json SummaryJson(const AnimateResult& result) {
  const Summary& s = result.summary;
  const ConstraintFigures& f = result.figures;
  nlohmann::json trace = nlohmann::json::array();
  for (const TracePoint& p : s.trace) {
    trace.push_back({p.seconds, p.cost, p.best_cost, p.moves_tried, p.moves_kept});
  }
  std::vector<int> lengths;
  for (const Track& t : result.tracks) lengths.push_back(t.size());
  return {{"method", s.method},
          {"start", s.start},
          {"termination", TerminationTypeName(s.termination)},
          {"message", s.message},
          {"sprites", s.num_sprites},
          {"lengths", lengths},
          {"turns", s.turns},
          {"restarts", s.restarts},
          {"moves_tried", s.moves_tried},
          {"moves_kept", s.moves_kept},
          {"seconds",
           {{"precompute", s.precompute_seconds},
            {"start", s.start_seconds},
            {"optimize", s.optimize_seconds},
            {"total", s.total_seconds}}},
          {"initial_cost", {{"total", s.initial_cost.total}, {"by_kind", s.initial_cost.by_kind}}},
          {"final_cost",
           {{"total", s.final_cost.total},
            {"by_kind", s.final_cost.by_kind},
            {"violations", s.final_cost.violations}}},
          {"figures",
           {{"max_path_deviation_m", f.max_path_deviation_m},
            {"paths_unfinished", f.paths_unfinished},
            {"collision_steps", f.collision_steps},
            {"colliding_pairs", f.colliding_pairs},
            {"min_distance_m", f.min_distance_m},
            {"frame_steps_off", f.frame_steps_off},
            {"frame_steps", f.frame_steps},
            {"sprites_short", f.sprites_short}}},
          {"trace", std::move(trace)}};
}

}  // namespace ss
