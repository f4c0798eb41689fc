#include "animate/scene.h"

#include <algorithm>
#include <cmath>

#include "animate/basic_costs.h"
#include "animate/collision_cost.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "core/error.h"

namespace ss {

Scene::Scene(AnimationSpec spec, BankGraph bank) : spec_(std::move(spec)), bank_(std::move(bank)) {
  problem_ = std::make_unique<Problem>(bank_.graph);
  AddTerms();
}

std::unique_ptr<Scene> Scene::Load(AnimationSpec spec, const std::atomic<bool>* cancel) {
  std::vector<std::string> tags;
  for (const SpriteSpecEntry& s : spec.sprites) {
    for (const FrameSpec& f : s.frames) {
      if (!f.tag.empty()) tags.push_back(f.tag);
    }
    for (const auto& constraint : s.constraints) {
      for (std::string& tag : constraint->Tags()) tags.push_back(std::move(tag));
    }
  }
  for (const auto& [key, term] : spec.terms) {
    for (std::string& tag : term->Tags()) tags.push_back(std::move(tag));
  }
  BankGraph bank = LoadBankGraph(spec.bank_paths, tags, cancel);
  return std::make_unique<Scene>(std::move(spec), std::move(bank));
}

void Scene::AddTerms() {
  const TransitionGraph& graph = bank_.graph;
  const double interval = IntervalS();
  for (const SpriteSpecEntry& entry : spec_.sprites) {
    // A floor sprite may be turned about the vertical: one with a path starts facing along it
    // (or, anchored at its end, ends facing along its last stretch), whatever frame it shows.
    std::optional<double> facing;
    if (graph.has_floor_frames() && entry.path && entry.path->points_m.size() >= 2) {
      const std::vector<Eigen::Vector2d>& points = entry.path->points_m;
      const size_t n = points.size();
      const Eigen::Vector2d along =
          entry.anchor == Anchor::kEnd ? points[n - 1] - points[n - 2] : points[1] - points[0];
      if (!along.isZero()) facing = std::atan2(along.y(), along.x());
    }
    problem_->AddSprite({.name = entry.name,
                         .anchor = entry.anchor,
                         .anchor_m = entry.anchor_m,
                         .anchor_facing_rad = facing,
                         .smoothness = entry.smoothness,
                         .initial_frames = spec_.initial_frames,
                         .max_frames = spec_.max_frames});
  }
  for (int id = 0; id < static_cast<int>(spec_.sprites.size()); ++id) {
    const SpriteSpecEntry& entry = spec_.sprites[id];
    for (const LocationSpec& l : entry.locations) {
      const LocationTarget target = l.follow.empty()
                                        ? LocationTarget::Fixed(l.target_m)
                                        : LocationTarget::Follow(spec_.SpriteIndex(l.follow),
                                                                 l.target_m, l.offset_in_heading);
      problem_->AddTerm(std::make_unique<LocationTerm>(id, l.window, target, l.strength));
    }
    if (entry.path) {
      problem_->AddTerm(std::make_unique<PathTerm>(
          id, Polyline(entry.path->points_m, spec_.Where(entry.path->place) + ".points"),
          entry.path->strengths));
    }
    for (const FrameSpec& f : entry.frames) {
      auto allowed = std::make_shared<std::vector<bool>>(graph.num_frames(), false);
      if (!f.tag.empty()) {
        *allowed = graph.FramesWithTag(f.tag);
      } else {
        for (int i = 0; i < graph.num_frames(); ++i) {
          (*allowed)[i] = std::find(f.sprite_ids.begin(), f.sprite_ids.end(),
                                    bank_.frames[i].sprite_id) != f.sprite_ids.end();
        }
      }
      if (std::none_of(allowed->begin(), allowed->end(), [](bool b) { return b; })) {
        throw InputError(spec_.Where(f.place) + (f.tag.empty() ? ".sprites" : ".tag"),
                         f.tag.empty() ? "none of these sprites is in the banks"
                                       : "no sprite of the banks carries the tag " + f.tag);
      }
      std::optional<PathTrigger> trigger;
      if (!f.after_path_of.empty()) {
        const int owner = spec_.SpriteIndex(f.after_path_of);
        const PathSpec& path = *spec_.sprites[owner].path;
        trigger = PathTrigger{owner, Polyline(path.points_m), f.duration_steps};
      }
      problem_->AddTerm(std::make_unique<FrameTerm>(id, std::move(allowed), f.window, f.strength,
                                                    std::move(trigger)));
    }
    // The constraints registered apart (animate/spec_term.h).
    for (const auto& constraint : entry.constraints) constraint->AddTerms(graph, *problem_, id);
    const std::optional<LengthSpec>& length = entry.length ? entry.length : spec_.length;
    if (length) {
      problem_->AddTerm(std::make_unique<LengthTerm>(id, length->min_frames, length->strength));
    }
    const std::optional<FastFrameSpec>& fast = entry.fast ? entry.fast : spec_.fast;
    if (fast && fast->strength > 0) {
      // Graph speeds are metres per source frame: convert the reference and the strength.
      problem_->AddTerm(std::make_unique<FastFrameTerm>(id, fast->reference_speed_m_s * interval,
                                                        fast->strength / interval));
    }
  }
  // The terms registered apart (animate/spec_term.h): repeats, facing, clones.
  for (const auto& [key, term] : spec_.terms) term->AddTerms(graph, *problem_);
  for (const CollisionSpec& c : spec_.collisions) {
    std::vector<int> ids;
    if (c.sprites.empty()) {
      for (int i = 0; i < problem_->num_sprites(); ++i) ids.push_back(i);
    } else {
      for (const std::string& name : c.sprites) ids.push_back(spec_.SpriteIndex(name));
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (size_t a = 0; a < ids.size(); ++a) {
      for (size_t b = a + 1; b < ids.size(); ++b) {
        problem_->AddTerm(
            std::make_unique<CollisionTerm>(ids[a], ids[b], c.min_distance_m, c.strength));
      }
    }
  }
}

ReplacementOptions Scene::MakeReplacementOptions(ReplacementOptions options) const {
  // Ĉ favours fast frames when the spec does (seed 000 §6.2, the fly).
  std::optional<FastFrameSpec> fast = spec_.fast;
  for (const SpriteSpecEntry& s : spec_.sprites) {
    if (!fast && s.fast) fast = s.fast;
  }
  if (fast && fast->strength > 0) {
    options.reference_speed_m = fast->reference_speed_m_s * IntervalS();
    options.slow_frame_cost = fast->strength / IntervalS();
  }
  return options;
}

}  // namespace ss
