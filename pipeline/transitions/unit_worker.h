#pragma once
// One of any number of transition workers sharing a PostgreSQL bank (`spritestation
// transitions worker`, docs/scaling.md). Each keeps the stage-1 index and comparison images of
// every sprite of the bank's complete clips in memory, brings them up to date from the bank
// by complete_seq before each unit, and does units claimed from core/bank_work.h: one clip's
// pairs with every sprite it knows, and every transition with an end in that clip. The union
// of the units is the table a single `transitions BANK` builds, exactly (a transition's three
// pairs join the same two clips: TransitionBuilder::AddPairsOf), and so is its cap: each unit
// prunes the sprites it wrote to after its rows are committed (StoreTransitionRound).
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>

#include "core/bank.h"
#include "core/bank_work.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/weights.h"

namespace ss {

struct UnitWorkerOptions {
  TransitionWeights weights = DefaultWeights();  // the classifier (valid: weights.h IsValid)
  std::string name;                              // in the work table (host:pid when empty)
  // a unit not done by then may be taken by another worker, seconds (> 0)
  double lease_s = 60;
  int load_threads = 1;  // threads for the comparison images of newly indexed sprites (>= 1)
  TableChoice table;     // which sprites and transitions the table holds: every worker agrees
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct UnitWorkerStats {
  int64_t units = 0, transitions = 0;
  int64_t sprites_indexed = 0, clips_indexed = 0;
  int64_t stage2_evaluations = 0, kept_pairs = 0;
  double seconds_index = 0, seconds_pairs = 0, seconds_store = 0;
};

class UnitWorker {
 public:
  // InputError for a bank that is not PostgreSQL, or whose transitions are made with other
  // weights or another table choice (decided by the first worker, station or `transitions
  // BANK` to set them, on an empty table too; rebuild them with `transitions BANK` first).
  UnitWorker(const std::string& bank, UnitWorkerOptions options);

  // Registers new complete clips as units, claims one and does it. False when none was free.
  bool RunOne();
  WorkCounts Counts() const { return queue_.Counts(); }
  const UnitWorkerStats& stats() const { return stats_; }
  const std::string& name() const { return options_.name; }

 private:
  // Indexes the sprites of every complete clip not yet known.
  void CatchUp();

  UnitWorkerOptions options_;
  BankWorkQueue queue_;  // first: refuses a bank that is not PostgreSQL before anything opens it
  BankWriter writer_;    // then: a worker started before any station makes the (empty) bank
  Bank reader_;
  SegmentKeys keys_;
  TransitionBars bars_;  // of the table's cap, as this worker's prunes saw them
  std::unique_ptr<TransitionBuilder> builder_;
  std::map<int64_t, std::pair<int32_t, int32_t>> clip_range_;  // bank clip -> store [first, end)
  std::set<int64_t> seen_clips_;  // clips read (some may have no sprite taken: no range)
  int64_t loaded_seq_ = 0;
  UnitWorkerStats stats_;
};

}  // namespace ss
