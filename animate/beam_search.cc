#include "animate/beam_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

constexpr double kInfiniteCost = std::numeric_limits<double>::infinity();

struct BeamChild {
  double cost;
  int parent;
  int frame;
};

class BeamPlanner {
 public:
  BeamPlanner(const Problem& problem, const BeamOptions& options, double deadline, Summary* summary)
      : problem_(problem),
        graph_(problem.graph()),
        options_(options),
        deadline_(deadline),
        summary_(summary) {}

  // Plans every sprite in turn; past the deadline the rest is planned with width 1.
  std::vector<Track> Pass(int width, bool* cut) {
    *cut = false;
    std::vector<Track> tracks(problem_.num_sprites());
    view_ = TrackPointers(tracks);
    for (int s = 0; s < problem_.num_sprites(); ++s) {
      const bool late = MonotonicSeconds() > deadline_;
      *cut = *cut || late;
      tracks[s] = PlanSprite(s, late ? 1 : width, cut);
      view_[s] = &tracks[s];
    }
    return tracks;
  }

 private:
  Track PlanSprite(int s, int width, bool* cut) {
    const SpriteSpec& spec = problem_.sprite(s);
    active_.clear();
    for (int k : problem_.TermsOf(s)) {
      const auto& sprites = problem_.term(k).sprites();
      if (std::all_of(sprites.begin(), sprites.end(), [s](int r) { return r <= s; })) {
        active_.push_back(k);
      }
    }
    int length = options_.length > 0   ? options_.length
                 : spec.max_frames > 0 ? spec.max_frames
                                       : spec.initial_frames;
    if (spec.max_frames > 0) length = std::min(length, spec.max_frames);
    const bool end_anchored = spec.anchor == Anchor::kEnd;
    const Anchor anchor = end_anchored ? Anchor::kEnd : Anchor::kStart;

    // Step 1: every start frame (or an even spread of them).
    const int num_frames = graph_.num_frames();
    const int starts =
        options_.start_frames > 0 ? std::min(options_.start_frames, num_frames) : num_frames;
    std::vector<BeamChild> children;
    std::vector<Track> beam;
    Track scratch;
    for (int i = 0; i < starts; ++i) {
      const int f = static_cast<int>(static_cast<int64_t>(i) * num_frames / starts);
      scratch = MakeTrack(graph_, {f}, anchor, spec.anchor_m, spec.anchor_facing_rad);
      children.push_back({Cost(s, scratch, 0, nullptr, 1), -1, f});
    }
    KeepBest(width, &children);
    beam.reserve(children.size());
    for (const BeamChild& c : children)
      beam.push_back(MakeTrack(graph_, {c.frame}, anchor, spec.anchor_m, spec.anchor_facing_rad));

    Track best;
    double best_cost = kInfiniteCost;
    std::vector<TermCache> caches(active_.size());
    for (int step = 1;; ++step) {
      for (const Track& track : beam) {  // the best complete sequence so far
        const double full = Cost(s, track, 0, nullptr, std::numeric_limits<int>::max());
        if (full < best_cost) {
          best_cost = full;
          best = track;
        }
      }
      if (step >= length || beam.empty()) break;
      children.clear();
      for (int p = 0; p < static_cast<int>(beam.size()); ++p) {
        if (MonotonicSeconds() > deadline_ && width > 1) {
          *cut = true;
          break;
        }
        const Track& parent = beam[p];
        view_[s] = &parent;
        for (size_t i = 0; i < active_.size(); ++i) {
          problem_.term(active_[i]).BuildCache(view_, &caches[i]);
        }
        scratch = parent;
        scratch.frames.push_back(0);
        scratch.positions_m.emplace_back();
        scratch.velocities_m.emplace_back();
        const int n = parent.size();
        for (int f : graph_.successors(parent.frames.back())) {
          scratch.frames.back() = f;
          if (end_anchored) {
            IntegrateTrack(graph_, anchor, spec.anchor_m, spec.anchor_facing_rad, &scratch);
          } else {
            IntegrateTrack(graph_, anchor, spec.anchor_m, spec.anchor_facing_rad, &scratch, n);
          }
          children.push_back({Cost(s, scratch, end_anchored ? 0 : n, &caches, n + 1), p, f});
          ++summary_->moves_tried;
        }
      }
      if (*cut && width > 1) break;
      KeepBest(width, &children);
      std::vector<Track> next;
      next.reserve(children.size());
      for (const BeamChild& c : children) {
        Track track = beam[c.parent];
        track.frames.push_back(c.frame);
        IntegrateTrack(graph_, anchor, spec.anchor_m, spec.anchor_facing_rad, &track,
                       end_anchored ? 0 : track.size() - 1);
        next.push_back(std::move(track));
      }
      beam.swap(next);
    }
    view_[s] = nullptr;
    return best;
  }

  // Sum of the active terms with sprite s on `track`; steps < step_limit only when partial.
  double Cost(int s, const Track& track, int first_changed, const std::vector<TermCache>* caches,
              int step_limit) {
    view_[s] = &track;
    double sum = 0.0;
    for (size_t i = 0; i < active_.size(); ++i) {
      EvalRequest request;
      request.first_changed = first_changed;
      request.cache = caches ? &(*caches)[i] : nullptr;
      request.step_limit = step_limit;
      sum += problem_.term(active_[i]).Evaluate(view_, request);
    }
    return sum;
  }

  static void KeepBest(int width, std::vector<BeamChild>* children) {
    auto less = [](const BeamChild& a, const BeamChild& b) {
      return a.cost < b.cost || (a.cost == b.cost && a.frame < b.frame);
    };
    if (static_cast<int>(children->size()) > width) {
      std::nth_element(children->begin(), children->begin() + width, children->end(), less);
      children->resize(width);
    }
    std::sort(children->begin(), children->end(), less);
  }

  const Problem& problem_;
  const TransitionGraph& graph_;
  const BeamOptions& options_;
  double deadline_;
  Summary* summary_;
  std::vector<const Track*> view_;
  std::vector<int> active_;
};

}  // namespace

bool BeamOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(width, AtLeast(1), "width", "at least 1");
  check.Within(length, AtLeast(0), "length", "at least 0 (0: the sprite's own)");
  check.Within(start_frames, AtLeast(0), "start_frames", "at least 0 (0: every frame)");
  check.Within(time_budget_seconds, AtLeast(0), "time_budget_seconds",
               "seconds >= 0 (0: one pass)");
  check(!(time_budget_seconds > kMaxTimeBudgetSeconds) || !std::isfinite(time_budget_seconds),
        "time_budget_seconds",
        "must be at most " + OptionProblems::Num(kMaxTimeBudgetSeconds) + " seconds (a day), got " +
            OptionProblems::Num(time_budget_seconds));
  return check.ok();
}

std::vector<Track> BeamSearch(const Problem& problem, const BeamOptions& options,
                              Summary* summary) {
  if (std::string why; !options.IsValid(&why)) throw InputError("beam options", why);
  const double run_start = MonotonicSeconds();
  const bool budgeted = options.time_budget_seconds > 0;
  const double deadline = budgeted ? run_start + options.time_budget_seconds : kInfiniteCost;
  *summary = Summary{};
  summary->method = "beam";
  summary->start = "beam";
  summary->num_sprites = problem.num_sprites();
  BeamPlanner planner(problem, options, deadline, summary);
  std::vector<Track> best;
  double best_cost = kInfiniteCost;
  bool cut = false;
  for (int width = options.width;; width *= 2) {
    std::vector<Track> tracks = planner.Pass(width, &cut);
    const CostBreakdown cost = problem.Evaluate(tracks);
    ++summary->turns;
    if (summary->turns == 1) summary->initial_cost = cost;
    if (cost.total < best_cost) {
      best_cost = cost.total;
      best = std::move(tracks);
      ++summary->moves_kept;
    }
    TracePoint point;
    point.seconds = MonotonicSeconds() - run_start;
    point.cost = cost.total;
    point.best_cost = best_cost;
    point.restart = summary->turns - 1;
    point.moves_tried = summary->moves_tried;
    point.moves_kept = summary->moves_kept;
    summary->trace.push_back(point);
    if (!budgeted || cut || MonotonicSeconds() > deadline || width > (1 << 24)) break;
  }
  summary->final_cost = problem.Evaluate(best);
  summary->termination = cut || (budgeted && MonotonicSeconds() > deadline)
                             ? TerminationType::kTimeBudget
                             : TerminationType::kBeamComplete;
  summary->message = "widest beam " + std::to_string(options.width << (summary->turns - 1)) +
                     (cut ? " (last pass cut by the time budget)" : "");
  summary->optimize_seconds = summary->total_seconds = MonotonicSeconds() - run_start;
  return best;
}

}  // namespace ss
