#pragma once
// Builds and keeps current the transitions of a sprite set (seed 000 §3):
//   kept pair {i, j}: stage 1 and stage 2 both accept; D(i,j) = stage-2 distance (>= 0)
//   transition i -> j: i has a successor i+1 and j a predecessor j-1 in their clips,
//     {i, j}, {i+1, j} and {i, j-1} are all kept pairs (a rejected pair is no longer
//     considered for transitions); C(i->j) = D(i+1, j) + D(i, j-1).
//   (j = i+1 is the clip itself and j = i would need D(i,i): neither is a transition.)
// A clip's last frame has no transitions out, its first frame none in. The transitions are
// a function of the kept pairs and the clip links, so a from-scratch build and any order
// of appends give the same set. See docs/transitions.md.
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/stage1_index.h"

namespace ss {

struct KeptPair {
  int64_t sprite_a = 0, sprite_b = 0;  // bank ids, sprite_a < sprite_b
  double distance = 0;                 // D(a, b) = D(b, a)
  bool operator==(const KeptPair&) const = default;
};

struct Transition {
  int64_t from = 0, to = 0;  // bank ids
  double distance = 0;       // D(from, to)
  double cost = 0;           // C(from -> to)
  bool operator==(const Transition&) const = default;
};

// What an Add made new: its kept pairs and every transition that did not exist before
// (those into the new sprites and those out of the clip ends they extended).
struct TransitionDelta {
  std::vector<KeptPair> pairs;
  std::vector<Transition> transitions;
};

// Keeps of `transitions` (those out of one sprite next to each other) the `keep` cheapest out of
// each sprite, by cost and then `to` (so any order of arrival keeps the same ones); each
// sprite's kept transitions end sorted by `to`. `keep` 0 keeps all.
void KeepCheapestPerSprite(std::vector<Transition>* transitions, int keep);

struct BuildOptions {
  int threads = 2;  // worker threads (>= 1)
  std::function<void(size_t done, size_t total)>
      progress;  // called from worker threads, serialized
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct BuildStats {
  int64_t sprites = 0;
  int64_t clips = 0;
  int64_t stage1_candidates = 0;   // unordered pairs stage 1 accepted (the k-d tree's answer)
  int64_t signature_rejected = 0;  // of those, rejected by SignatureRejects (no pixel read)
  int64_t stage2_evaluations = 0;  // the rest: stage 2 on the comparison images
  int64_t kept_pairs = 0;
  double seconds_images = 0;       // comparison images
  double seconds_index = 0;        // k-d tree build
  double seconds_pairs = 0;        // stage-1 queries + stage 2
  std::vector<std::string> notes;  // e.g. "one clip: every transition stays inside it"
};

class TransitionBuilder {
 public:
  // Throws InputError for invalid weights or px_per_m.
  TransitionBuilder(const TransitionWeights& weights, double px_per_m);

  // Replaces all state with the transitions of `sprites` (a clip's sprites in frame order).
  // Throws InputError("sprites", ...) for an empty set.
  void BuildFromScratch(std::span<const SpriteInput> sprites, const BuildOptions& options = {});
  // Appends sprites (one thread) and returns what became new.
  TransitionDelta Add(std::span<const SpriteInput> sprites);

  // For transition work shared by many workers (docs/scaling.md), one unit per bank clip:
  // AppendIndexOnly puts sprites in the store and the stage-1 index without finding any of
  // their pairs (their clips are other units'); returns the first new store index.
  int32_t AppendIndexOnly(std::span<const SpriteInput> sprites, int threads = 1);
  // Finds the kept pairs of the store range [first, end) (one bank clip's sprites) with every
  // sprite in the store, each pair once (pairs found before are not evaluated again), and
  // returns every transition with an end in the range. A transition's three pairs join the
  // same two clips, so the unit of the later of them finds it whole: the union over the units
  // is the table a single builder makes.
  TransitionDelta AddPairsOf(int32_t first, int32_t end);

  std::vector<KeptPair> KeptPairs() const;  // sorted by (sprite_a, sprite_b)
  // Sorted by (from, to); with `max_per_sprite` > 0 only that many out of each sprite, its
  // cheapest (KeepCheapestPerSprite).
  std::vector<Transition> Transitions(int max_per_sprite = 0) const;
  int64_t TransitionCount() const;

  const SpriteStore& store() const { return store_; }
  const TransitionClassifier& classifier() const { return classifier_; }
  const Stage1Index& index() const { return index_; }
  const BuildStats& stats() const { return stats_; }
  // D(i, j) for store indices, or a negative number when {i, j} is not kept.
  double KeptDistance(int32_t i, int32_t j) const;

 private:
  struct Neighbour {
    int32_t index;
    double distance;
  };
  // Appends the transitions out of store index i (C needs next(i)).
  void TransitionsFrom(int32_t i, std::vector<Transition>* out) const;
  // Appends the transitions into store index j (C needs prev(j)).
  void TransitionsInto(int32_t j, std::vector<Transition>* out) const;
  static const Neighbour* Find(const std::vector<Neighbour>& list, int32_t index);
  // The silhouette signature, then stage 2 on (i, j), counted in stats_: true with D(i, j) in `d`
  // when the pair is a candidate.
  bool Compare(int32_t i, int32_t j, double* d);
  void InsertNeighbour(int32_t at, int32_t index, double distance);

  TransitionClassifier classifier_;
  SpriteStore store_;
  Stage1Index index_;
  std::vector<std::vector<Neighbour>> neighbours_;  // kept pairs by store index, sorted by index
  BuildStats stats_;
};

}  // namespace ss
