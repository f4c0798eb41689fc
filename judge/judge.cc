#include "judge/judge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <utility>

#include "animate/basic_costs.h"
#include "animate/collision_cost.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "core/bank.h"
#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + s * ab - p).norm();
}

double PolylineDistance(const Polyline& path, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < path.points().size(); ++i) {
    best = std::min(best, PointSegmentDistance(p, path.points()[i], path.points()[i + 1]));
  }
  return best;
}

std::string Point(const Eigen::Vector2d& p) {
  char text[64];
  std::snprintf(text, sizeof text, "[%.3f, %.3f]", p.x(), p.y());
  return text;
}

// The file's sequences as tracks of the scene's graph, at the file's positions.
std::vector<Track> FileTracks(const SequenceFile& file, const Scene& scene) {
  const BankGraph& bank = scene.bank();
  std::map<std::pair<int, int64_t>, int> frame_of;
  for (size_t i = 0; i < bank.frames.size(); ++i) {
    frame_of[{bank.frames[i].bank, bank.frames[i].sprite_id}] = static_cast<int>(i);
  }
  std::vector<Track> tracks;
  for (size_t s = 0; s < file.sprites.size(); ++s) {
    const SpriteSequence& seq = file.sprites[s];
    Track track;
    for (size_t t = 0; t < seq.frames.size(); ++t) {
      const auto it = frame_of.find({seq.frames[t].bank, seq.frames[t].sprite_id});
      if (it == frame_of.end()) {
        throw InputError("sequences",
                         "sprites[" + std::to_string(s) + "].steps[" + std::to_string(t) +
                             "]: bank " + std::to_string(seq.frames[t].bank) + " has no sprite " +
                             std::to_string(seq.frames[t].sprite_id) + " in a complete clip");
      }
      track.frames.push_back(it->second);
      track.positions_m.push_back(seq.positions_m[t]);
      track.velocities_m.push_back(scene.graph().velocity_m(it->second));
    }
    UpdateChunkBoxes(&track);
    tracks.push_back(std::move(track));
  }
  return tracks;
}

PathOutcome JudgePath(const PathTerm& term, const Track& track) {
  const Polyline& path = term.path();
  PathOutcome out;
  out.length_m = path.length();
  int segment = 0;
  double reached = 0.0;
  std::vector<double> deviations;
  for (int t = 0; t < track.size(); ++t) {
    const Eigen::Vector2d& p = track.positions_m[t];
    segment = path.Advance(segment, p);
    reached = std::max(reached, out.length_m - path.Remaining(segment, p));
    deviations.push_back(PolylineDistance(path, p));
    if (segment == path.num_segments()) {
      out.finished_step = t;
      break;
    }
  }
  out.swept_share = out.length_m > 0 ? std::clamp(reached / out.length_m, 0.0, 1.0) : 1.0;
  if (!deviations.empty()) {
    out.max_deviation_m = *std::max_element(deviations.begin(), deviations.end());
    out.median_deviation_m = *Quantile(deviations, 0.5);
  }
  return out;
}

LocationOutcome JudgeLocation(const LocationTerm& term, Tracks view, const Track& track) {
  LocationOutcome out;
  std::tie(out.first_step, out.end_step) = term.Window(view);
  std::vector<double> distances;
  for (int t = out.first_step; t < out.end_step; ++t) {
    distances.push_back((track.PositionAt(t) - term.TargetAt(view, t)).norm());
  }
  if (!distances.empty()) {
    out.first_m = distances.front();
    out.last_m = distances.back();
    out.min_m = *std::min_element(distances.begin(), distances.end());
    out.max_m = *std::max_element(distances.begin(), distances.end());
    out.median_m = *Quantile(distances, 0.5);
  }
  return out;
}

CollisionOutcome JudgeCollision(const CollisionTerm& term, Tracks view) {
  CollisionOutcome out;
  out.min_distance_m = term.min_distance_m();
  const Track& a = *view[term.sprites()[0]];
  const Track& b = *view[term.sprites()[1]];
  out.closest_m = std::numeric_limits<double>::infinity();
  for (int t = 0; t < std::max(a.size(), b.size()); ++t) {
    const double d = (a.PositionAt(t) - b.PositionAt(t)).norm();
    if (d < out.closest_m) {
      out.closest_m = d;
      out.closest_step = t;
    }
  }
  out.steps_closer = term.CountViolations(view);
  return out;
}

void JudgeConstraints(const SequenceFile& file, const Scene& scene, Judgement* out) {
  const AnimationSpec& spec = scene.spec();
  if (spec.sprites.size() != file.sprites.size()) {
    throw InputError(spec.path, "sprites: the spec names " + std::to_string(spec.sprites.size()) +
                                    " sprites, the sequences hold " +
                                    std::to_string(file.sprites.size()));
  }
  for (size_t s = 0; s < spec.sprites.size(); ++s) {
    if (spec.sprites[s].name != file.sprites[s].name) {
      throw InputError(spec.path, "sprites[" + std::to_string(s) + "].name: '" +
                                      spec.sprites[s].name + "', the sequences' is '" +
                                      file.sprites[s].name + "'");
    }
    const std::optional<LengthSpec>& length =
        spec.sprites[s].length ? spec.sprites[s].length : spec.length;
    if (length) out->lengths[s].min_frames = length->min_frames;
    if (spec.fixed_frames > 0) out->lengths[s].min_frames = spec.fixed_frames;
  }
  const std::vector<Track> tracks = FileTracks(file, scene);
  const std::vector<const Track*> view = TrackPointers(tracks);
  const Problem& problem = scene.problem();
  std::vector<size_t> locations_seen(tracks.size(), 0), frames_seen(tracks.size(), 0);
  for (int k = 0; k < problem.num_terms(); ++k) {
    const CostTerm& term = problem.term(k);
    const int s = term.sprites()[0];
    const SpriteSpecEntry& entry = spec.sprites[s];
    if (const auto* path = dynamic_cast<const PathTerm*>(&term)) {
      PathOutcome o = JudgePath(*path, tracks[s]);
      o.sprite = entry.name;
      o.field = entry.path->place.field;
      out->paths.push_back(std::move(o));
    } else if (const auto* location = dynamic_cast<const LocationTerm*>(&term)) {
      LocationOutcome o = JudgeLocation(*location, view, tracks[s]);
      const LocationSpec& l = entry.locations.at(locations_seen[s]++);
      o.sprite = entry.name;
      o.field = l.place.field;
      o.target =
          l.follow.empty() ? Point(l.target_m) : "follow " + l.follow + " + " + Point(l.target_m);
      out->locations.push_back(std::move(o));
    } else if (const auto* collision = dynamic_cast<const CollisionTerm*>(&term)) {
      CollisionOutcome o = JudgeCollision(*collision, view);
      o.a = entry.name;
      o.b = spec.sprites[collision->sprites()[1]].name;
      out->collisions.push_back(std::move(o));
    } else if (const auto* frame = dynamic_cast<const FrameTerm*>(&term)) {
      FrameOutcome o;
      const FrameSpec& f = entry.frames.at(frames_seen[s]++);
      o.sprite = entry.name;
      o.field = f.place.field;
      o.set = f.tag.empty() ? std::to_string(f.sprite_ids.size()) + " sprites" : "tag " + f.tag;
      std::tie(o.first_step, o.end_step) = frame->Window(view);
      const int steps = std::max(0, o.end_step - o.first_step);
      o.steps_on = steps - frame->CountViolations(view);
      o.on_share = steps > 0 ? static_cast<double>(o.steps_on) / steps : 1.0;
      out->frames.push_back(std::move(o));
    }
  }
  out->constraints_judged = true;
}

JumpFigures JudgeJumps(const SequenceFile& file, const std::vector<std::unique_ptr<Bank>>& banks,
                       const VisibleJumpOptions& options) {
  JumpFigures out;
  out.measured = true;
  std::vector<std::unique_ptr<VisibleJumpMeter>> meters(banks.size());
  auto meter = [&](int b) -> VisibleJumpMeter& {
    if (!meters[b]) meters[b] = std::make_unique<VisibleJumpMeter>(*banks[b], options);
    return *meters[b];
  };
  std::vector<double> jumps;
  for (const SpriteSequence& s : file.sprites) {
    for (size_t t = 1; t < s.frames.size(); ++t) {
      const BankFrameRef& from = s.frames[t - 1];
      const BankFrameRef& to = s.frames[t];
      TransitionJump j{s.name, static_cast<int>(t), from, to, std::nullopt, std::nullopt};
      if (from.bank == to.bank) {
        j.natural = meter(from.bank).NaturalSuccessor(from.sprite_id);
        if (j.natural && *j.natural == to.sprite_id) continue;  // the clip goes on
        if (j.natural) j.jump = meter(to.bank).JumpBetween(to.sprite_id, *j.natural);
      }
      ++out.transitions;
      if (j.jump) {
        jumps.push_back(*j.jump);
      } else {
        ++out.unmeasured;
      }
      out.each.push_back(std::move(j));
    }
  }
  out.median = Quantile(jumps, 0.5);
  out.p95 = Quantile(jumps, 0.95);
  out.max = Quantile(jumps, 1.0);
  for (size_t b = 0; b < banks.size(); ++b) {
    out.median_step_px.push_back(meters[b] ? meters[b]->MedianStep_px() : 0.0);
  }
  return out;
}

}  // namespace

bool JudgeOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(stutter_window_steps, AtLeast(1), "stutter_window_steps", "at least 1 step");
  check.Within(clone_lag_steps, AtLeast(0), "clone_lag_steps", "steps >= 0");
  check.Within(facing_min_speed_m_s, AtLeast(0), "facing_min_speed_m_s", "a speed >= 0");
  check.Within(facing_half_window_steps, AtLeast(1), "facing_half_window_steps", "at least 1 step");
  std::string jump_why;
  check.Nested(jump.IsValid(&jump_why), "jump.", jump_why);
  return check.ok();
}

StutterFigures MeasureStutter(const std::vector<SpriteSequence>& sprites, int window_steps,
                              const std::function<bool(const BankFrameRef&)>& is_still) {
  StutterFigures out;
  out.window_steps = window_steps;
  for (const SpriteSequence& s : sprites) {
    const int n = static_cast<int>(s.frames.size());
    // Each frame's last step: shown before at all (replayed), and within the window (repeats).
    std::map<std::pair<int, int64_t>, int> last_shown;
    for (int t = 0; t < n; ++t) {
      const BankFrameRef& f = s.frames[t];
      ++out.steps;
      const auto [it, first] = last_shown.try_emplace({f.bank, f.sprite_id}, t);
      const int before = it->second;
      it->second = t;
      if (is_still(f)) {
        ++out.still_steps;
        continue;
      }
      if (first) continue;
      ++out.replayed;
      if (t - before <= window_steps) ++out.repeats;
    }
  }
  const int counted = out.steps - out.still_steps;
  out.share = counted > 0 ? static_cast<double>(out.repeats) / counted : 0.0;
  out.replayed_share = counted > 0 ? static_cast<double>(out.replayed) / counted : 0.0;
  return out;
}

FacingFigures MeasureFacing(
    const std::vector<SpriteSequence>& sprites, double frame_rate, double min_speed_m_s,
    int half_window_steps,
    const std::function<std::optional<double>(const BankFrameRef&)>& heading_of) {
  FacingFigures out;
  out.min_speed_m_s = min_speed_m_s;
  out.half_window_steps = half_window_steps;
  std::vector<double> angles_deg;
  for (const SpriteSequence& s : sprites) {
    const int n = static_cast<int>(s.frames.size());
    for (int t = 0; t < n; ++t) {
      const std::optional<double> heading = heading_of(s.frames[t]);
      if (!heading) continue;
      out.measured = true;
      const int a = std::max(0, t - half_window_steps), b = std::min(n - 1, t + half_window_steps);
      if (b <= a) continue;
      const Eigen::Vector2d motion = s.positions_m[b] - s.positions_m[a];
      if (motion.norm() * frame_rate / (b - a) <= min_speed_m_s) continue;
      const double drawn = *heading + s.TurnAt(t);
      const double off = std::remainder(drawn - std::atan2(motion.y(), motion.x()), 2 * M_PI);
      angles_deg.push_back(std::abs(off) * 180 / M_PI);
    }
  }
  out.moving_steps = static_cast<int>(angles_deg.size());
  out.median_deg = Quantile(angles_deg, 0.5);
  out.p90_deg = Quantile(angles_deg, 0.9);
  return out;
}

CloneFigures MeasureClones(const std::vector<SpriteSequence>& sprites, int lag_steps) {
  CloneFigures out;
  out.lag_steps = lag_steps;
  // Every (sprite, step) showing each frame.
  std::map<std::pair<int, int64_t>, std::vector<std::pair<int, int>>> shown;
  for (size_t s = 0; s < sprites.size(); ++s) {
    for (size_t t = 0; t < sprites[s].frames.size(); ++t) {
      const BankFrameRef& f = sprites[s].frames[t];
      shown[{f.bank, f.sprite_id}].emplace_back(static_cast<int>(s), static_cast<int>(t));
    }
  }
  for (size_t s = 0; s < sprites.size(); ++s) {
    const int n = static_cast<int>(sprites[s].frames.size());
    int cloned = 0;
    for (int t = 0; t < n; ++t) {
      const BankFrameRef& f = sprites[s].frames[t];
      for (const auto& [other, u] : shown.at({f.bank, f.sprite_id})) {
        if (other != static_cast<int>(s) && std::abs(u - t) <= lag_steps) {
          ++cloned;
          break;
        }
      }
    }
    out.steps += n;
    out.cloned_steps += cloned;
    if (n > 0 && 2 * cloned >= n) ++out.sprites_cloned;
  }
  out.share = out.steps > 0 ? static_cast<double>(out.cloned_steps) / out.steps : 0.0;
  return out;
}

Judgement JudgeSequences(const SequenceFile& file, const std::vector<std::string>& bank_paths,
                         const Scene* scene, const JudgeOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("judge options", why);
  for (size_t s = 0; s < file.sprites.size(); ++s) {
    for (size_t t = 0; t < file.sprites[s].frames.size(); ++t) {
      const int b = file.sprites[s].frames[t].bank;
      if (b < 0 || b >= static_cast<int>(bank_paths.size())) {
        throw InputError("sequences", "sprites[" + std::to_string(s) + "].steps[" +
                                          std::to_string(t) + "][0]: no bank " + std::to_string(b) +
                                          " among the " + std::to_string(bank_paths.size()) +
                                          " given");
      }
    }
  }
  std::vector<std::unique_ptr<Bank>> banks;
  banks.reserve(bank_paths.size());
  for (const std::string& path : bank_paths) banks.push_back(std::make_unique<Bank>(path));

  Judgement out;
  for (const SpriteSequence& s : file.sprites) {
    out.lengths.push_back({s.name, static_cast<int>(s.frames.size()), 0});
  }
  if (scene != nullptr) JudgeConstraints(file, *scene, &out);

  std::set<std::pair<int, int64_t>> still;
  for (size_t b = 0; b < banks.size(); ++b) {
    for (const std::string& tag : options.still_tags) {
      for (int64_t id : banks[b]->SpritesTagged(tag)) still.insert({static_cast<int>(b), id});
    }
  }
  out.stutter =
      MeasureStutter(file.sprites, options.stutter_window_steps, [&](const BankFrameRef& f) {
        return still.count({f.bank, f.sprite_id}) > 0;
      });
  out.clones = MeasureClones(file.sprites, options.clone_lag_steps);
  std::map<std::pair<int, int64_t>, double> headings;  // floor sprites'
  for (size_t b = 0; b < banks.size(); ++b) {
    for (const SpriteFeatures& f : banks[b]->LoadFeatures()) {
      if (f.floor) headings[{static_cast<int>(b), f.id}] = f.heading_rad;
    }
  }
  out.facing = MeasureFacing(file.sprites, file.frame_rate, options.facing_min_speed_m_s,
                             options.facing_half_window_steps,
                             [&](const BankFrameRef& f) -> std::optional<double> {
                               const auto it = headings.find({f.bank, f.sprite_id});
                               if (it == headings.end()) return std::nullopt;
                               return it->second;
                             });
  if (options.jumps) out.jumps = JudgeJumps(file, banks, options.jump);
  return out;
}

}  // namespace ss
