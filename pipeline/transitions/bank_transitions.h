#pragma once
// A bank's transition table, built or brought up to date (`spritestation transitions
// BANK`), and the transitions stored as a diff: only what changed is written, in one
// transaction, so readers keep seeing a whole table. The bank's meta key
// "transitions.weights" records which weights made the table; other weights replace it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/bank.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/weights.h"

namespace ss {

inline constexpr const char* kTransitionWeightsMetaKey = "transitions.weights";
// Transitions written per bank transaction by the workers: short transactions keep the
// writer lock brief for the pipeline's sprite batches.
inline constexpr size_t kTransitionRowsPerTransaction = 2000;

// A stable fingerprint of weights (FNV-1a of their JSON), as stored in the meta key.
std::string WeightsFingerprint(const TransitionWeights& weights);

// What storing a transition set did.
struct StoreResult {
  int64_t added = 0, changed = 0, unchanged = 0;
  int64_t removed = 0;        // existing transitions the new set no longer has
  int64_t outside = 0;        // existing transitions touching sprites outside the set: left alone
  bool replaced_all = false;  // the table was cleared first (other weights, or removals)
};

// Stores `transitions` (sorted by (from, to)), all the transitions among `sprites`, made
// with weights `fingerprint`: writes only the differences when the table was made with
// the same weights and nothing must go; else clears the table and writes everything.
StoreResult StoreTransitionTable(BankWriter& bank, const std::vector<Transition>& transitions,
                                 const std::string& fingerprint,
                                 const std::unordered_set<int64_t>& sprites);

std::vector<TransitionRecord> ToRecords(const std::vector<Transition>& transitions);

// The worst transition kept out of each sprite that holds its TableChoice::max_per_sprite, as
// last seen in the bank: one after it (by cost, then `to`) can never be kept, because the table
// only grows while sprites arrive, so a sprite's bar only falls.
class TransitionBars {
 public:
  // True when `t` comes after its sprite's bar.
  bool Excludes(const Transition& t) const;
  // Learnt from each prune (BankWriter::PruneTransitions): a worker starts with none.
  void Set(const TransitionRecord& worst_kept);

 private:
  std::unordered_map<int64_t, std::pair<double, int64_t>> bars_;  // from -> (cost, to)
};

// What storing a round of new transitions did.
struct RoundResult {
  int64_t written = 0;  // rows upserted
  int64_t skipped = 0;  // new transitions after their sprite's bar, or past its cap in the round
  int64_t removed = 0;  // stored transitions pushed out of their sprite's cap
};

// Stores a worker's round of new transitions (TransitionDelta): upserted a few thousand rows a
// transaction, then, with `max_per_sprite` > 0, each sprite written to pruned to its cheapest
// (BankWriter::PruneTransitions) and `bars` brought up to date. Rounds of any order, by one
// worker or many at once, leave the table a batch build stores.
RoundResult StoreTransitionRound(BankWriter& bank, std::vector<Transition> transitions,
                                 int max_per_sprite, TransitionBars* bars);

struct BankUpdateOptions {
  TransitionWeights weights = DefaultWeights();  // the classifier (valid: weights.h IsValid)
  int threads = 2;                               // worker threads (>= 1)
  TableChoice table;  // which sprites take part (merged ones not, by default) and how many
                      // transitions leave each
  // stage: "load" (sprites read and decoded) or "pairs" (sprites searched); from any thread.
  std::function<void(const std::string& stage, size_t done, size_t total)> progress;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct BankUpdateSummary {
  std::string bank;
  int64_t sprites = 0, clips = 0;
  int64_t left_out = 0;  // sprites of complete clips the choice left out (tagged merged)
  BuildStats build;
  int64_t transitions = 0;
  StoreResult store;
  double seconds_load = 0, seconds_build = 0, seconds_store = 0;
  std::vector<std::string> notes;
  std::string ToJson() const;
  std::string ToText() const;
};

// Finds the transitions of every sprite of the complete clips of `bank_path` and stores
// them. InputError naming the bank when it is missing, not a bank, or holds no sprites.
BankUpdateSummary UpdateBankTransitions(const std::string& bank_path,
                                        const BankUpdateOptions& options);

}  // namespace ss
