#include "animate/replacement.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <span>

#include "animate/basic_costs.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {
namespace {

enum class MoveKind { kMiddle, kBegin, kEnd };

// One random walk per sprite (its initial_frames long, cut at max_frames).
std::vector<Track> RandomTracks(const Problem& problem, uint64_t seed) {
  std::vector<Track> tracks;
  for (int s = 0; s < problem.num_sprites(); ++s) {
    const SpriteSpec& spec = problem.sprite(s);
    int length = spec.initial_frames;
    if (spec.max_frames > 0) length = std::min(length, spec.max_frames);
    tracks.push_back(problem.MakeSpriteTrack(
        s, RandomSequence(problem.graph(), length, seed * 1000003ULL + static_cast<uint64_t>(s))));
  }
  return tracks;
}

// The optimization loop of one run; owns the current tracks and the terms' caches.
class Replacer {
 public:
  Replacer(const Problem& problem, const ReplacementOptions& options, const ReplacementSets& sets,
           std::vector<Track> initial, Summary* summary, double run_start, double deadline)
      : problem_(problem),
        graph_(problem.graph()),
        options_(options),
        sets_(sets),
        tracks_(std::move(initial)),
        summary_(summary),
        run_start_(run_start),
        deadline_(deadline),
        rng_(options.seed),
        stamp_(problem.graph().num_frames(), 0),
        local_(problem.graph().num_frames(), 0) {
    for (int sprite = 0; sprite < problem_.num_sprites(); ++sprite) {
      terms_of_.push_back(problem_.TermsOf(sprite));
      collides_.push_back(std::any_of(terms_of_.back().begin(), terms_of_.back().end(), [&](int k) {
        return problem_.term(k).kind() == "collision";
      }));
    }
    Reset();
    neighbours_.resize(problem_.num_sprites());
    for (int k = 0; k < problem_.num_terms(); ++k) {
      for (int a : problem_.term(k).sprites()) {
        for (int b : problem_.term(k).sprites()) {
          if (a != b) neighbours_[a].push_back(b);
        }
      }
    }
  }

  std::vector<Track> Run() {
    const double optimize_start = MonotonicSeconds();
    if (options_.start == StartMethod::kSequential) SequentialStart();
    AddTracePoint();
    const int num_sprites = problem_.num_sprites();
    std::vector<int>& failures = failures_;
    failures.assign(num_sprites, 0);
    double next_progress = optimize_start + options_.progress_seconds;
    TerminationType termination = TerminationType::kConverged;
    std::string message;
    bool running = num_sprites > 0;
    while (running) {
      for (int s = 0; s < num_sprites && running; ++s) {
        for (int c = 0; c < options_.changes_per_turn; ++c) {
          if (Cancelled()) {
            termination = TerminationType::kCancelled;
            message = "cancelled";
            running = false;
            break;
          }
          if (MonotonicSeconds() > deadline_) {
            termination = TerminationType::kTimeBudget;
            message = "time budget of " + std::to_string(options_.time_budget_seconds) + " s used";
            running = false;
            break;
          }
          ++summary_->picks;
          if (Pick(s)) {
            failures[s] = 0;
          } else if (++failures[s] >= options_.max_tries) {
            break;
          }
        }
        if (running && options_.optimize_free_starts &&
            problem_.sprite(s).anchor == Anchor::kFree) {
          RefineFreeStart(s);
        }
        ++summary_->turns;
        if (options_.progress_seconds > 0 && MonotonicSeconds() >= next_progress) {
          next_progress = MonotonicSeconds() + options_.progress_seconds;
          Log("animate")->info("{:.1f} s  cost {:.6g}  moves {}/{} kept  turn {}",
                               MonotonicSeconds() - run_start_, total_, summary_->moves_kept,
                               summary_->moves_tried, summary_->turns);
        }
      }
      if (!running) break;
      if (std::all_of(failures.begin(), failures.end(),
                      [&](int f) { return f >= options_.max_tries; })) {
        message =
            "no improvement in " + std::to_string(options_.max_tries) + " picks for every sprite";
        if (!options_.restart_when_converged || MonotonicSeconds() > deadline_ || Cancelled()) {
          break;
        }
        KeepBest();
        ++restart_;
        ++summary_->restarts;
        tracks_ = RandomTracks(problem_, options_.seed + 7919ULL * restart_);
        Reset();
        if (options_.start == StartMethod::kSequential) SequentialStart();
        failures.assign(num_sprites, 0);
        AddTracePoint();
        continue;
      }
      if (options_.max_turns > 0 && summary_->turns >= options_.max_turns) {
        termination = TerminationType::kMaxTurns;
        message = "turn limit reached";
        break;
      }
    }
    if (num_sprites == 0) message = "no sprites";
    if (summary_->restarts > 0) {
      message += "; best of " + std::to_string(summary_->restarts + 1) + " restarts";
    }
    summary_->termination = termination;
    summary_->message = message;
    summary_->optimize_seconds += MonotonicSeconds() - optimize_start;
    KeepBest();
    AddTracePoint();
    return std::move(best_tracks_);
  }

 private:
  // The one-by-one phase of StartMethod::kSequential: sprite s is hill-climbed against the
  // terms whose sprites are all <= s (later sprites are not there yet), until it converges
  // or its share of the phase's time is used. Its moves are not trace points: the phase
  // is part of making the start, and the total it sees is not C.
  void SequentialStart() {
    const int num_sprites = problem_.num_sprites();
    if (num_sprites < 2) return;
    const double start = MonotonicSeconds();
    const double until =
        std::min(deadline_, start + options_.sequential_fraction * (deadline_ - start));
    std::vector<std::vector<int>> all = terms_of_;
    for (int s = 0; s < num_sprites; ++s) {
      terms_of_[s].clear();
      for (int k : all[s]) {
        const std::vector<int>& read = problem_.term(k).sprites();
        if (std::all_of(read.begin(), read.end(), [s](int r) { return r <= s; })) {
          terms_of_[s].push_back(k);
        }
      }
    }
    warming_up_ = true;
    for (int s = 0; s < num_sprites; ++s) {
      // Terms joining s to earlier sprites were not refreshed when those moved.
      for (int k : terms_of_[s]) {
        problem_.term(k).BuildCache(view_, &caches_[k]);
        term_cost_[k] = problem_.term(k).Evaluate(view_);
      }
      const double now = MonotonicSeconds();
      const double share_end = now + std::max(0.0, until - now) / (num_sprites - s);
      for (int failures = 0;
           failures < options_.max_tries && MonotonicSeconds() < share_end && !Cancelled();) {
        ++summary_->picks;
        failures = Pick(s) ? 0 : failures + 1;
      }
      if (options_.optimize_free_starts && problem_.sprite(s).anchor == Anchor::kFree) {
        RefineFreeStart(s);
      }
    }
    warming_up_ = false;
    terms_of_ = std::move(all);
    Reset();
    summary_->start_seconds += MonotonicSeconds() - start;
  }

  // One (k, l) pick of sprite s; true when a candidate lowered the cost.
  bool Pick(int s) {
    const Track& current = tracks_[s];
    const int n = current.size();
    const double r = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
    const MoveKind kind = r < options_.middle_fraction ? MoveKind::kMiddle
                          : r < options_.middle_fraction + options_.begin_fraction
                              ? MoveKind::kBegin
                              : MoveKind::kEnd;
    int k = 0;
    int l = n - 1;
    if (kind != MoveKind::kBegin) k = UniformInt(0, n - 1);
    if (kind == MoveKind::kMiddle) {
      int max_span = n - 1 - k;
      if (options_.max_span > 0) max_span = std::min(max_span, options_.max_span);
      l = k + LogUniformInt(max_span);
    } else if (kind == MoveKind::kBegin) {
      l = UniformInt(0, n - 1);
    }
    if (kind == MoveKind::kEnd && options_.goal_fraction > 0 && !sets_.frame_terms().empty() &&
        std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < options_.goal_fraction) {
      if (const std::optional<bool> kept = GoalMove(s, k)) return *kept;
    }
    if (options_.collision_pick_fraction > 0 && n > 1 && collides_[s] &&
        std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < options_.collision_pick_fraction) {
      // Around a colliding step v (past the end: the held last state, changed from the end):
      // a piece of log-uniform width from k <= v, replaced as the pick's kind says. (A piece
      // keeps s_k, so k = v leaves step v itself and changes the steps after it, which a
      // collision mostly spans too. Drawing k < v only was tried: scene 7 608 and 2 pairs
      // instead of 515 and 1, scene 3 3.76 instead of 2.63; one run each.)
      const int v = CollidingStep(s);
      if (v >= 0) {
        ++summary_->collision_picks;
        const int last = std::min(v, n - 1);
        const int width =
            LogUniformInt(options_.max_span > 0 ? std::min(options_.max_span, n - 1) : n - 1);
        if (kind == MoveKind::kMiddle) {
          k = std::max(0, last - UniformInt(0, width));
          l = std::min(n - 1, std::max(last, k + width));
        } else if (kind == MoveKind::kBegin) {
          l = std::min(n - 1, last + width);
        } else {
          k = std::max(0, last - width);
        }
      }
    }
    int variant = sets_.VariantFor(problem_, view_, s, k, l);
    if (variant == 0 && kind == MoveKind::kEnd &&
        std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < 0.5) {
      // Half of the end moves count a window past the last step (the new end may fill it).
      variant = sets_.VariantFor(problem_, view_, s, k, l, /*open_end=*/true);
    }
    const ReachSets& forward = sets_.forward(variant);
    const ReachSets& backward = sets_.backward(variant);
    const int sk = current.frames[k];
    const int sl = current.frames[l];

    candidates_.clear();
    if (kind == MoveKind::kMiddle) {
      ++round_;
      const auto f_set = forward.Set(sk);
      for (int i = 0; i < static_cast<int>(f_set.size()); ++i) {
        stamp_[f_set[i].frame] = round_;
        local_[f_set[i].frame] = i;
      }
      const auto b_set = backward.Set(sl);
      for (int j = 0; j < static_cast<int>(b_set.size()); ++j) {
        if (stamp_[b_set[j].frame] == round_) candidates_.push_back({local_[b_set[j].frame], j});
      }
    } else if (kind == MoveKind::kBegin) {
      for (int j = 0; j < static_cast<int>(backward.Set(sl).size()); ++j) {
        candidates_.push_back({-1, j});
      }
    } else {
      for (int i = 0; i < static_cast<int>(forward.Set(sk).size()); ++i) {
        candidates_.push_back({i, -1});
      }
    }
    std::shuffle(candidates_.begin(), candidates_.end(), rng_);
    if (options_.max_candidates > 0 &&
        static_cast<int>(candidates_.size()) > options_.max_candidates) {
      candidates_.resize(options_.max_candidates);
    }

    for (const auto& [fi, bj] : candidates_) {
      piece_.clear();
      if (kind == MoveKind::kMiddle) {
        forward.AppendPath(sk, fi, &piece_);  // s_k .. t
        tail_.clear();
        backward.AppendPath(sl, bj, &tail_);  // t .. s_l
        piece_.insert(piece_.end(), tail_.begin() + 1, tail_.end());
      } else if (kind == MoveKind::kBegin) {
        backward.AppendPath(sl, bj, &piece_);  // t .. s_l
      } else {
        forward.AppendPath(sk, fi, &piece_);  // s_k .. t
      }
      if (std::equal(piece_.begin(), piece_.end(), current.frames.begin() + k,
                     current.frames.begin() + l + 1)) {
        continue;  // the same piece again
      }
      if (TryPiece(s, k, l)) return true;
    }
    return false;
  }

  // Tries sprite s's sequence with steps k..l replaced by piece_ (cut to its max_frames); a
  // candidate equal to the current sequence is not tried. True when it lowered the cost.
  bool TryPiece(int s, int k, int l) {
    const Track& current = tracks_[s];
    const int n = current.size();
    const int max_frames = problem_.sprite(s).max_frames;
    Track& candidate = candidate_;
    candidate.frames.assign(current.frames.begin(), current.frames.begin() + k);
    candidate.frames.insert(candidate.frames.end(), piece_.begin(), piece_.end());
    candidate.frames.insert(candidate.frames.end(), current.frames.begin() + l + 1,
                            current.frames.end());
    if (max_frames > 0 && candidate.size() > max_frames) candidate.frames.resize(max_frames);
    int first_diff = k;
    const int common = std::min(candidate.size(), n);
    while (first_diff < common && candidate.frames[first_diff] == current.frames[first_diff]) {
      ++first_diff;
    }
    if (first_diff == candidate.size() && candidate.size() == n) return false;  // itself again
    return TryCandidate(s, first_diff);
  }

  // The end of sprite s from step k replaced by the way to a frame constraint's set G and a run
  // in G to the end of its window (ReplacementSets::toward). nullopt when s has no frame
  // constraint whose window reaches past k; else whether a candidate lowered the cost.
  std::optional<bool> GoalMove(int s, int k) {
    constexpr int kMaxGoalSteps = 2000;  // without a sprite's max_frames
    const Track& current = tracks_[s];
    const int max_frames = problem_.sprite(s).max_frames;
    const int limit = max_frames > 0 ? max_frames - k : kMaxGoalSteps;
    std::optional<bool> kept;
    for (const auto& [term_index, variant] : sets_.frame_terms()) {
      const auto& term = static_cast<const FrameTerm&>(problem_.term(term_index));
      if (term.sprites()[0] != s) continue;
      const int window_end = term.Window(view_).second;
      if (window_end - 1 <= k) continue;  // the window ends before the piece starts
      kept = false;
      const std::span<const int32_t> toward = sets_.toward(variant);
      const std::vector<bool>& allowed = term.allowed();
      const auto in_g = [&](int f) { return f < static_cast<int>(allowed.size()) && allowed[f]; };
      int u = current.frames[k];
      piece_.assign(1, u);
      bool reached = in_g(u);
      while (static_cast<int>(piece_.size()) < limit &&
             !(reached && k + static_cast<int>(piece_.size()) >= window_end)) {
        u = toward[u];
        if (u < 0) break;
        piece_.push_back(u);
        reached = reached || in_g(u);
      }
      if (!reached) continue;
      ++summary_->goal_picks;
      if (TryPiece(s, k, current.size() - 1)) return true;
    }
    return kept;
  }

  // Positions candidate_ (frames set, equal to the current ones before `first_diff`) and
  // keeps it when it lowers the cost.
  bool TryCandidate(int s, int first_diff) {
    const Track& current = tracks_[s];
    const SpriteSpec& spec = problem_.sprite(s);
    Track& candidate = candidate_;
    const int n = candidate.size();
    const int keep = std::min(first_diff, current.size());
    candidate.positions_m.assign(current.positions_m.begin(), current.positions_m.begin() + keep);
    candidate.velocities_m.assign(current.velocities_m.begin(),
                                  current.velocities_m.begin() + keep);
    candidate.turns_rad.assign(current.turns_rad.begin(),
                               current.turns_rad.begin() +
                                   std::min<int>(keep, static_cast<int>(current.turns_rad.size())));
    candidate.chunk_boxes_m.assign(
        current.chunk_boxes_m.begin(),
        current.chunk_boxes_m.begin() +
            std::min<int>(keep / Track::kChunkSteps, current.chunk_boxes_m.size()));
    candidate.positions_m.resize(n);
    candidate.velocities_m.resize(n);
    const bool end_anchored = spec.anchor == Anchor::kEnd;
    const Eigen::Vector2d anchor_m = end_anchored ? spec.anchor_m : current.positions_m.front();
    IntegrateTrack(graph_, end_anchored ? Anchor::kEnd : Anchor::kStart, anchor_m,
                   spec.anchor_facing_rad, &candidate, keep);
    const int first_changed = end_anchored ? 0 : keep;

    const double current_sum = InvolvedCost(s);
    ++summary_->moves_tried;
    double best = EvaluateInvolved(s, candidate, first_changed, current_sum, &values_);
    Track* chosen = &candidate;
    if (spec.anchor == Anchor::kFree && options_.optimize_free_starts) {
      Eigen::Vector2d start;
      if (LeastSquaresStart(s, candidate, &start) &&
          (start - candidate.positions_m.front()).norm() > 1e-9) {
        shifted_ = candidate;
        ShiftTrack(start - candidate.positions_m.front(), &shifted_);
        ++summary_->moves_tried;
        const double value =
            EvaluateInvolved(s, shifted_, 0, std::min(best, current_sum), &values_shifted_);
        if (value < best) {
          best = value;
          chosen = &shifted_;
          values_.swap(values_shifted_);
        }
      }
    }
    if (!Improves(best, current_sum)) return false;
    Accept(s, chosen);
    return true;
  }

  static bool Improves(double value, double current) {
    return value < current - 1e-12 * std::max(1.0, std::abs(current));
  }

  // Sum of the terms reading sprite s when its track is `track`; stops once over `budget`.
  double EvaluateInvolved(int s, const Track& track, int first_changed, double budget,
                          std::vector<double>* values) {
    const std::vector<int>& terms = terms_of_[s];
    values->assign(terms.size(), 0.0);
    view_[s] = &track;
    double sum = 0.0;
    for (size_t i = 0; i < terms.size(); ++i) {
      EvalRequest request;
      request.first_changed = first_changed;
      request.cache = &caches_[terms[i]];
      request.budget = budget - sum;
      (*values)[i] = problem_.term(terms[i]).Evaluate(view_, request);
      sum += (*values)[i];
      if (sum >= budget) break;
    }
    view_[s] = &tracks_[s];
    return sum;
  }

  double InvolvedCost(int s) const {
    double sum = 0.0;
    for (int k : terms_of_[s]) sum += term_cost_[k];
    return sum;
  }

  void Accept(int s, Track* chosen) {
    std::swap(tracks_[s], *chosen);
    view_[s] = &tracks_[s];
    const std::vector<int>& terms = terms_of_[s];
    for (size_t i = 0; i < terms.size(); ++i) {
      term_cost_[terms[i]] = values_[i];
      problem_.term(terms[i]).BuildCache(view_, &caches_[terms[i]]);
    }
    RecomputeTotal();
    if (warming_up_) return;  // the other terms are stale until the phase's Reset()
    ++summary_->moves_kept;
    for (int r : neighbours_[s]) failures_[r] = 0;
    AddTracePoint();
    if (options_.on_improvement) options_.on_improvement(tracks_, summary_->trace.back());
  }

  bool Cancelled() const {
    return options_.cancel != nullptr && options_.cancel->load(std::memory_order_relaxed);
  }

  // p_0 minimizing the location terms of a free sprite; false when none constrain it.
  bool LeastSquaresStart(int s, const Track& track, Eigen::Vector2d* start) {
    view_[s] = &track;
    double weight = 0.0;
    Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
    for (int k : terms_of_[s]) {
      problem_.term(k).AddStartNormalEquations(view_, s, &weight, &weighted);
    }
    view_[s] = &tracks_[s];
    if (weight <= 0) return false;
    *start = weighted / weight;
    return true;
  }

  // Pattern search on a free start: steps of ±h along x and y, halving h on failure.
  void RefineFreeStart(int s) {
    Eigen::Vector2d least_squares;
    if (LeastSquaresStart(s, tracks_[s], &least_squares))
      TryShift(s, least_squares - tracks_[s].positions_m.front());
    for (double h = 0.25; h > 1e-3 && MonotonicSeconds() < deadline_ && !Cancelled();) {
      bool improved = false;
      for (const Eigen::Vector2d& step : {Eigen::Vector2d(h, 0), Eigen::Vector2d(-h, 0),
                                          Eigen::Vector2d(0, h), Eigen::Vector2d(0, -h)}) {
        if (TryShift(s, step)) {
          improved = true;
          break;
        }
      }
      if (!improved) h *= 0.5;
    }
  }

  bool TryShift(int s, const Eigen::Vector2d& offset_m) {
    if (offset_m.norm() < 1e-12) return false;
    shifted_ = tracks_[s];
    ShiftTrack(offset_m, &shifted_);
    const double current_sum = InvolvedCost(s);
    ++summary_->moves_tried;
    const double value = EvaluateInvolved(s, shifted_, 0, current_sum, &values_);
    if (!Improves(value, current_sum)) return false;
    Accept(s, &shifted_);
    return true;
  }

  // Views, caches and term costs for the current tracks.
  void Reset() {
    view_ = TrackPointers(tracks_);
    caches_.assign(problem_.num_terms(), TermCache{});
    term_cost_.assign(problem_.num_terms(), 0.0);
    for (int k = 0; k < problem_.num_terms(); ++k) {
      problem_.term(k).BuildCache(view_, &caches_[k]);
      term_cost_[k] = problem_.term(k).Evaluate(view_);
    }
    RecomputeTotal();
  }

  // Remembers the current tracks when they are the best so far.
  void KeepBest() {
    if (best_tracks_.empty() || total_ < best_total_) {
      best_tracks_ = tracks_;
      best_total_ = total_;
    }
  }

  void RecomputeTotal() {
    total_ = 0.0;
    for (double c : term_cost_) total_ += c;
  }

  void AddTracePoint() {
    const double best = best_tracks_.empty() ? total_ : std::min(total_, best_total_);
    summary_->trace.push_back({MonotonicSeconds() - run_start_, total_, best, restart_,
                               summary_->moves_tried, summary_->moves_kept, summary_->turns});
  }

  // A step where sprite s collides (one of its collision terms costs something there), drawn
  // uniformly over all of them; -1 when it collides nowhere.
  int CollidingStep(int s) {
    colliding_steps_.clear();
    for (int k : terms_of_[s]) {
      if (term_cost_[k] <= 0 || problem_.term(k).kind() != "collision") continue;
      const std::vector<double>& prefix = caches_[k].prefix;
      for (size_t t = 0; t + 1 < prefix.size(); ++t) {
        if (prefix[t + 1] > prefix[t]) colliding_steps_.push_back(static_cast<int>(t));
      }
    }
    if (colliding_steps_.empty()) return -1;
    return colliding_steps_[UniformInt(0, static_cast<int>(colliding_steps_.size()) - 1)];
  }

  int UniformInt(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  // 0..max, log-uniformly: short spans are as likely as long ones per octave.
  int LogUniformInt(int max) {
    if (max <= 0) return 0;
    const double u = std::uniform_real_distribution<double>(0.0, std::log(max + 2.0))(rng_);
    return std::clamp(static_cast<int>(std::floor(std::exp(u))) - 1, 0, max);
  }

  const Problem& problem_;
  const TransitionGraph& graph_;
  const ReplacementOptions& options_;
  const ReplacementSets& sets_;
  std::vector<Track> tracks_;
  Summary* summary_;
  double run_start_;
  double deadline_;
  std::mt19937_64 rng_;

  std::vector<const Track*> view_;
  std::vector<TermCache> caches_;
  std::vector<double> term_cost_;
  double total_ = 0.0;
  std::vector<std::vector<int>> neighbours_;
  std::vector<std::vector<int>> terms_of_;  // the terms a move of sprite s is judged by
  bool warming_up_ = false;
  std::vector<int> failures_;
  std::vector<Track> best_tracks_;
  double best_total_ = 0.0;
  int restart_ = 0;

  // Scratch reused across picks.
  uint32_t round_ = 0;
  std::vector<uint32_t> stamp_;
  std::vector<int> local_;
  std::vector<std::pair<int, int>> candidates_;
  std::vector<int> colliding_steps_;  // CollidingStep's scratch
  std::vector<char> collides_;        // per sprite: it has collision terms
  std::vector<int> piece_;
  std::vector<int> tail_;
  Track candidate_;
  Track shifted_;
  std::vector<double> values_;
  std::vector<double> values_shifted_;
};

// Ĉ's cost of entering each frame: slow frames (when asked) and the problem's facing cost (the
// first FacingTerm's: every sprite shares one); empty when neither applies.
std::vector<double> FrameEntryCosts(const Problem& problem, const ReplacementOptions& o) {
  const TransitionGraph& graph = problem.graph();
  std::vector<double> cost;
  if (o.slow_frame_cost > 0 && o.reference_speed_m > 0) {
    cost.resize(graph.num_frames());
    for (int i = 0; i < graph.num_frames(); ++i) {
      cost[i] = o.slow_frame_cost * std::max(0.0, o.reference_speed_m - graph.speed_m(i));
    }
  }
  for (int k = 0; k < problem.num_terms(); ++k) {
    const auto* facing = dynamic_cast<const FacingTerm*>(&problem.term(k));
    if (facing == nullptr) continue;
    cost.resize(graph.num_frames(), 0.0);
    for (int i = 0; i < graph.num_frames(); ++i) cost[i] += facing->frame_costs()[i];
    break;
  }
  return cost;
}

std::vector<Track> InitialTracks(const Problem& problem, const ReplacementOptions& options,
                                 double deadline, Summary* summary) {
  std::vector<Track> tracks;
  const double start = MonotonicSeconds();
  if (options.start == StartMethod::kBeam) {
    BeamOptions beam = options.beam;
    const double remaining = std::max(1e-3, deadline - start);
    beam.time_budget_seconds = beam.time_budget_seconds > 0
                                   ? std::min(beam.time_budget_seconds, remaining)
                                   : 0.25 * remaining;
    Summary beam_summary;
    tracks = BeamSearch(problem, beam, &beam_summary);
    summary->start = "beam";
  } else {
    summary->start = options.start == StartMethod::kGiven        ? "given"
                     : options.start == StartMethod::kSequential ? "sequential"
                                                                 : "random";
    tracks = RandomTracks(problem, options.seed);
    for (int s = 0; s < problem.num_sprites() && options.start == StartMethod::kGiven; ++s) {
      const SpriteSpec& spec = problem.sprite(s);
      if (spec.initial_sequence.empty()) continue;
      std::vector<int> frames = spec.initial_sequence;
      if (spec.max_frames > 0 && static_cast<int>(frames.size()) > spec.max_frames) {
        frames.resize(spec.max_frames);
      }
      tracks[s] = problem.MakeSpriteTrack(s, std::move(frames));
    }
  }
  summary->start_seconds += MonotonicSeconds() - start;
  return tracks;
}

std::vector<Track> Improve(const Problem& problem, const ReplacementOptions& options,
                           const ReplacementSets& sets, std::vector<Track> initial,
                           Summary* summary, double run_start, double deadline) {
  std::string why;
  if (!problem.IsValid(initial, &why)) throw InputError("initial sequences", why);
  summary->method = "replacement";
  summary->num_sprites = problem.num_sprites();
  summary->initial_cost = problem.Evaluate(initial);
  Replacer replacer(problem, options, sets, std::move(initial), summary, run_start, deadline);
  std::vector<Track> result = replacer.Run();
  summary->final_cost = problem.Evaluate(result);
  summary->total_seconds = MonotonicSeconds() - run_start;
  return result;
}

}  // namespace

bool ReplacementOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(reach.IsValid(&part), "reach.", part);
  check.Within(step_cost_fraction, AtLeast(0), "step_cost_fraction", "a finite number >= 0");
  check.Within(slow_frame_cost, AtLeast(0), "slow_frame_cost", "at least 0");
  check.Within(reference_speed_m, AtLeast(0), "reference_speed_m", "metres >= 0");
  check.Within(time_budget_seconds, Positive(), "time_budget_seconds",
               "a positive number of seconds");
  check(!(time_budget_seconds > kMaxTimeBudgetSeconds) || !std::isfinite(time_budget_seconds),
        "time_budget_seconds",
        "must be at most " + OptionProblems::Num(kMaxTimeBudgetSeconds) + " seconds (a day), got " +
            OptionProblems::Num(time_budget_seconds));
  check.Within(max_tries, AtLeast(1), "max_tries", "at least 1");
  check.Within(changes_per_turn, AtLeast(1), "changes_per_turn", "at least 1");
  check.Within(max_turns, AtLeast(0), "max_turns", "at least 0 (0: no limit)");
  check.Within(sequential_fraction, Between(0, 1), "sequential_fraction", "a fraction 0..1");
  // The beam block is used only to start with a beam search.
  if (start == StartMethod::kBeam) check.Nested(beam.IsValid(&part), "beam.", part);
  check.Within(middle_fraction, AtLeast(0), "middle_fraction", "at least 0");
  check.Within(begin_fraction, AtLeast(0), "begin_fraction", "at least 0");
  check(!(middle_fraction >= 0 && begin_fraction >= 0) || middle_fraction + begin_fraction <= 1,
        "begin_fraction",
        "must leave middle_fraction + begin_fraction <= 1, got " +
            OptionProblems::Num(middle_fraction + begin_fraction));
  check.Within(max_span, AtLeast(0), "max_span", "at least 0 (0: the whole sequence)");
  check.Within(collision_pick_fraction, Between(0, 1), "collision_pick_fraction",
               "a fraction 0..1");
  check.Within(goal_fraction, Between(0, 1), "goal_fraction", "a fraction 0..1");
  check.Within(max_candidates, AtLeast(0), "max_candidates", "at least 0 (0: all of them)");
  check.Within(progress_seconds, AtLeast(0), "progress_seconds", "seconds >= 0 (0: never)");
  return check.ok();
}

namespace {

// ReplacementSets::toward() for the set G: a multi-source Dijkstra back from G over the plain
// Ĉ (edge cost + step cost), then, in G, the step that stays in G.
std::vector<int32_t> TowardSet(const TransitionGraph& graph, const std::vector<bool>& in_g,
                               double step_cost) {
  const int n = graph.num_frames();
  std::vector<int32_t> next(n, -1);
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  for (int i = 0; i < n; ++i) {
    if (in_g[i]) {
      dist[i] = 0;
      heap.emplace(0.0, i);
    }
  }
  while (!heap.empty()) {
    const auto [d, u] = heap.top();
    heap.pop();
    if (d > dist[u]) continue;
    const auto preds = graph.predecessors(u);
    const auto costs = graph.predecessor_costs(u);
    for (size_t e = 0; e < preds.size(); ++e) {
      const int p = preds[e];
      if (in_g[p]) continue;
      const double nd = d + costs[e] + step_cost;
      if (nd < dist[p]) {
        dist[p] = nd;
        next[p] = u;
        heap.emplace(nd, p);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    if (!in_g[i]) continue;
    if (i + 1 < n && in_g[i + 1] && graph.IsNaturalSuccessor(i, i + 1)) {
      next[i] = i + 1;
      continue;
    }
    const auto succ = graph.successors(i);
    const auto costs = graph.successor_costs(i);
    double best = std::numeric_limits<double>::infinity();
    for (size_t e = 0; e < succ.size(); ++e) {
      if (succ[e] != i && in_g[succ[e]] && costs[e] < best) {
        best = costs[e];
        next[i] = succ[e];
      }
    }
  }
  return next;
}

}  // namespace

ReplacementSets ReplacementSets::Build(const Problem& problem, const ReplacementOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("replacement options", why);
  ReplacementSets sets;
  ScopedTimer timer(&sets.build_seconds_);
  const TransitionGraph& graph = problem.graph();
  const std::vector<double> base = FrameEntryCosts(problem, options);
  ReachOptions reach = options.reach;
  reach.cancel = options.cancel;
  reach.step_cost += options.step_cost_fraction * graph.MedianPositiveCost();
  auto add_variant = [&](const std::vector<double>& entry_cost) {
    sets.forward_.push_back(ReachSets::Build(graph, ReachDirection::kForward, reach, entry_cost));
    sets.backward_.push_back(ReachSets::Build(graph, ReachDirection::kBackward, reach, entry_cost));
  };
  add_variant(base);
  sets.toward_.emplace_back();
  if (options.frame_constraint_sets) {
    // One variant per distinct (frame set, strength); terms sharing both share it.
    std::vector<std::pair<const std::vector<bool>*, double>> made;
    for (int k = 0; k < problem.num_terms(); ++k) {
      const auto* frame = dynamic_cast<const FrameTerm*>(&problem.term(k));
      if (frame == nullptr || frame->strength() <= 0) continue;
      const std::pair<const std::vector<bool>*, double> key{&frame->allowed(), frame->strength()};
      auto it = std::find(made.begin(), made.end(), key);
      int variant = 1 + static_cast<int>(it - made.begin());
      if (it == made.end()) {
        std::vector<double> entry(graph.num_frames(), 0.0);
        std::vector<bool> g(graph.num_frames(), false);
        for (int i = 0; i < graph.num_frames(); ++i) {
          const bool in_g = i < static_cast<int>(frame->allowed().size()) && frame->allowed()[i];
          g[i] = in_g;
          entry[i] = (base.empty() ? 0.0 : base[i]) + (in_g ? 0.0 : frame->strength());
        }
        add_variant(entry);
        sets.toward_.push_back(TowardSet(graph, g, reach.step_cost));
        made.push_back(key);
      }
      sets.frame_terms_.push_back({k, variant});
    }
  }
  return sets;
}

int64_t ReplacementSets::EstimateBytes(const Problem& problem, const ReplacementOptions& options) {
  const int frames = problem.graph().num_frames();
  int variants = 1;
  if (options.frame_constraint_sets) {  // as Build counts them: by (frame set, strength)
    std::vector<std::pair<const std::vector<bool>*, double>> made;
    for (int k = 0; k < problem.num_terms(); ++k) {
      const auto* frame = dynamic_cast<const FrameTerm*>(&problem.term(k));
      if (frame == nullptr || frame->strength() <= 0) continue;
      const std::pair<const std::vector<bool>*, double> key{&frame->allowed(), frame->strength()};
      if (std::find(made.begin(), made.end(), key) == made.end()) made.push_back(key);
    }
    variants += static_cast<int>(made.size());
  }
  const int64_t pair =  // entries and depths, and a count per root
      2 * (ReachSetBytes(frames, options.reach.set_size) + int64_t{frames} * 4);
  return variants * pair + (variants - 1) * int64_t{frames} * int64_t{sizeof(int32_t)};
}

int ReplacementSets::VariantFor(const Problem& problem, Tracks tracks, int sprite, int first,
                                int last, bool open_end) const {
  for (const auto& [k, variant] : frame_terms_) {
    const auto& term = static_cast<const FrameTerm&>(problem.term(k));
    if (term.sprites()[0] != sprite) continue;
    const auto [begin, end] = term.Window(tracks);
    if (open_end) last = std::max(last, end - 1);
    const int overlap = std::min(end, last + 1) - std::max(begin, first);
    if (2 * overlap > last - first + 1) return variant;
  }
  return 0;
}

size_t ReplacementSets::MemoryBytes() const {
  size_t bytes = 0;
  for (const auto& s : forward_) bytes += s.MemoryBytes();
  for (const auto& s : backward_) bytes += s.MemoryBytes();
  for (const auto& t : toward_) bytes += t.size() * sizeof(int32_t);
  return bytes;
}

std::vector<int> RandomSequence(const TransitionGraph& graph, int length, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<int> starts;
  for (int i = 0; i < graph.num_frames(); ++i) {
    if (!graph.successors(i).empty()) starts.push_back(i);
  }
  if (starts.empty()) starts.push_back(0);
  std::vector<int> frames{starts[std::uniform_int_distribution<size_t>(0, starts.size() - 1)(rng)]};
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  while (static_cast<int>(frames.size()) < length) {
    const int u = frames.back();
    const auto next = graph.successors(u);
    if (next.empty()) break;
    if (coin(rng) < 0.9 && graph.IsNaturalSuccessor(u, u + 1)) {
      frames.push_back(u + 1);
    } else {
      frames.push_back(next[std::uniform_int_distribution<size_t>(0, next.size() - 1)(rng)]);
    }
  }
  return frames;
}

std::vector<Track> OptimizeSequences(const Problem& problem, const ReplacementOptions& options,
                                     Summary* summary, const ReplacementSets* sets) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("replacement options", why);
  const double run_start = MonotonicSeconds();
  const double deadline = run_start + options.time_budget_seconds;
  *summary = Summary{};
  ReplacementSets built;
  if (sets == nullptr) {
    built = ReplacementSets::Build(problem, options);
    summary->precompute_seconds = built.build_seconds();
    sets = &built;
  }
  std::vector<Track> initial = InitialTracks(problem, options, deadline, summary);
  return Improve(problem, options, *sets, std::move(initial), summary, run_start, deadline);
}

std::vector<Track> ImproveSequences(const Problem& problem, const ReplacementOptions& options,
                                    const ReplacementSets& sets, std::vector<Track> initial,
                                    Summary* summary) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("replacement options", why);
  const double run_start = MonotonicSeconds();
  *summary = Summary{};
  summary->start = "given";
  ReplacementOptions given = options;  // improve these sequences, not one-by-one new ones
  if (given.start == StartMethod::kSequential) given.start = StartMethod::kGiven;
  return Improve(problem, given, sets, std::move(initial), summary, run_start,
                 run_start + options.time_budget_seconds);
}

}  // namespace ss
