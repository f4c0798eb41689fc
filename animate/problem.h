#pragma once
// An animation problem on a transition graph: the sprites (their anchors and length limits)
// and the cost terms over them. The total cost C = sum of all terms (seed 000 eq. 3).
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "animate/cost_term.h"
#include "animate/track.h"
#include "animate/transition_graph.h"

namespace ss {

struct SpriteSpec {
  std::string name;
  Anchor anchor = Anchor::kStart;
  // p_0 (kStart; kFree: first guess) or p_{n-1}
  Eigen::Vector2d anchor_m = Eigen::Vector2d::Zero();
  // Floor sprites: the ground direction the anchored step faces (IntegrateTrack); none: as filmed.
  std::optional<double> anchor_facing_rad;
  double smoothness = 1.0;            // α, strength of Cs for this sprite (its SmoothnessTerm)
  int initial_frames = 60;            // length of a random initial sequence
  int max_frames = 0;                 // longer sequences are cut at the end; 0 = no limit
  std::vector<int> initial_sequence;  // optional starting sequence (must follow real edges)
};

// Total cost with its parts by term kind ("smoothness", "location", ...).
struct CostBreakdown {
  double total = 0.0;
  std::map<std::string, double> by_kind;
  std::map<std::string, int> violations;  // CountViolations summed by kind
  std::string ToString() const;           // "total 12.3 (smoothness 4.1, path 8.2)"
};

class Problem {
 public:
  explicit Problem(const TransitionGraph& graph) : graph_(graph) {}
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  // Adds a sprite and its smoothness term; returns its id. Throws InputError for a bad spec.
  int AddSprite(SpriteSpec spec);
  // Adds a term; throws InputError when it reads a sprite that does not exist.
  void AddTerm(std::unique_ptr<CostTerm> term);

  const TransitionGraph& graph() const { return graph_; }
  int num_sprites() const { return static_cast<int>(sprites_.size()); }
  const SpriteSpec& sprite(int s) const { return sprites_[s]; }
  int num_terms() const { return static_cast<int>(terms_.size()); }
  const CostTerm& term(int k) const { return *terms_[k]; }
  // Indices of the terms that read sprite s.
  const std::vector<int>& TermsOf(int s) const { return terms_of_[s]; }

  // C for one track per sprite, with its breakdown.
  CostBreakdown Evaluate(const std::vector<Track>& tracks) const;
  double TotalCost(const std::vector<Track>& tracks) const { return Evaluate(tracks).total; }
  // A sprite's track for `frames`, positioned from its anchor (`anchor_m` overrides a free start).
  Track MakeSpriteTrack(int s, std::vector<int> frames) const;
  // Checks one track per sprite: real edges only, length limits. Says what is wrong.
  bool IsValid(const std::vector<Track>& tracks, std::string* why = nullptr) const;

 private:
  const TransitionGraph& graph_;
  std::vector<SpriteSpec> sprites_;
  std::vector<std::unique_ptr<CostTerm>> terms_;
  std::vector<std::vector<int>> terms_of_;
};

// Pointers to each track, the form terms read.
std::vector<const Track*> TrackPointers(const std::vector<Track>& tracks);

}  // namespace ss
