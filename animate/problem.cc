#include "animate/problem.h"

#include <algorithm>
#include <cstdio>

#include "animate/basic_costs.h"
#include "core/error.h"

namespace ss {

std::string CostBreakdown::ToString() const {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "total %.6g", total);
  std::string out = buffer;
  const char* separator = " (";
  for (const auto& [kind, value] : by_kind) {
    std::snprintf(buffer, sizeof buffer, "%s%s %.6g", separator, kind.c_str(), value);
    out += buffer;
    separator = ", ";
  }
  if (!by_kind.empty()) out += ")";
  return out;
}

int Problem::AddSprite(SpriteSpec spec) {
  const int id = num_sprites();
  const std::string field = "sprites[" + std::to_string(id) + "]";
  if (!spec.anchor_m.allFinite()) throw InputError(field + ".position", "must be finite");
  if (spec.initial_frames < 1) throw InputError(field + ".initial_frames", "must be >= 1");
  if (spec.max_frames < 0) throw InputError(field + ".max_frames", "must be >= 0");
  if (!spec.initial_sequence.empty()) {
    std::string why;
    if (!graph_.IsValidSequence(spec.initial_sequence, &why)) {
      throw InputError(field + ".initial_sequence", why);
    }
  }
  if (graph_.num_frames() == 0) throw InputError(field, "the transition graph has no frames");
  const double smoothness = spec.smoothness;
  sprites_.push_back(std::move(spec));
  terms_of_.emplace_back();
  AddTerm(std::make_unique<SmoothnessTerm>(graph_, id, smoothness));
  return id;
}

void Problem::AddTerm(std::unique_ptr<CostTerm> term) {
  for (int s : term->sprites()) {
    if (s < 0 || s >= num_sprites()) {
      throw InputError(term->kind() + ".sprite", "no sprite " + std::to_string(s));
    }
  }
  const int index = num_terms();
  for (int s : term->sprites()) {
    if (std::find(terms_of_[s].begin(), terms_of_[s].end(), index) == terms_of_[s].end()) {
      terms_of_[s].push_back(index);
    }
  }
  terms_.push_back(std::move(term));
}

CostBreakdown Problem::Evaluate(const std::vector<Track>& tracks) const {
  const std::vector<const Track*> pointers = TrackPointers(tracks);
  CostBreakdown breakdown;
  for (const auto& term : terms_) {
    const double value = term->Evaluate(pointers);
    breakdown.total += value;
    breakdown.by_kind[term->kind()] += value;
    breakdown.violations[term->kind()] += term->CountViolations(pointers);
  }
  return breakdown;
}

Track Problem::MakeSpriteTrack(int s, std::vector<int> frames) const {
  return MakeTrack(graph_, std::move(frames), sprites_[s].anchor, sprites_[s].anchor_m,
                   sprites_[s].anchor_facing_rad);
}

bool Problem::IsValid(const std::vector<Track>& tracks, std::string* why) const {
  if (static_cast<int>(tracks.size()) != num_sprites()) {
    if (why) *why = "expected one track per sprite";
    return false;
  }
  for (int s = 0; s < num_sprites(); ++s) {
    std::string reason;
    const Track& track = tracks[s];
    if (!graph_.IsValidSequence(track.frames, &reason)) {
      if (why) *why = "sprite " + std::to_string(s) + ": " + reason;
      return false;
    }
    if (sprites_[s].max_frames > 0 && track.size() > sprites_[s].max_frames) {
      if (why) *why = "sprite " + std::to_string(s) + ": longer than max_frames";
      return false;
    }
    if (track.positions_m.size() != track.frames.size() ||
        track.velocities_m.size() != track.frames.size()) {
      if (why) *why = "sprite " + std::to_string(s) + ": states out of step with frames";
      return false;
    }
  }
  return true;
}

std::vector<const Track*> TrackPointers(const std::vector<Track>& tracks) {
  std::vector<const Track*> pointers;
  pointers.reserve(tracks.size());
  for (const Track& t : tracks) pointers.push_back(&t);
  return pointers;
}

}  // namespace ss
