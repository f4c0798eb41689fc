#pragma once
// The incremental transition worker: a background thread that keeps a bank's transition
// table current while the pipeline appends sprites. The pipeline hands it the ids of
// newly stored sprites (AppendResult::sprite_ids, originals and mirrors, in the order
// stored); Submit only queues them, so the writer never waits for transition finding.
// The worker reads the sprites through its own connection, finds their transitions
// against the whole bank in both directions (into the new sprites, and out of the clip
// ends they extend; TransitionBuilder::Add), and stores each round as one short
// transaction through its own writer connection.
// On start it loads every sprite of the bank's complete clips and brings their table up
// to date (UpdateBankTransitions' rules). Sprites of clips that were incomplete at start
// and are never submitted are not seen (run `spritestation transitions BANK` later).
// Errors never stop the thread: a round that fails is counted, logged and skipped.
// On a PostgreSQL bank (other writers, other workers) the thread does units of the bank's
// shared work table instead (unit_worker.h, docs/scaling.md): the same table, exactly.
// Threads: the owner's (the station's bank writer) Submit; any thread stats() and the waits;
// the owner Stop. The worker's thread (and the start-up build's) take mutex_, a leaf: it is
// held for a copy or a count, never while calling out (on_startup_change runs without it).
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/weights.h"

namespace ss {

struct TransitionWorkerStats {
  bool ready = false;              // the start-up build is done
  int64_t sprites = 0;             // sprites the worker knows (start-up + submitted, not left out)
  int64_t queued = 0;              // submitted, not yet processed
  int64_t rounds = 0;              // rounds of submitted sprites processed
  int64_t transitions_stored = 0;  // written since start (start-up table included)
  int64_t failed_rounds = 0;
  std::string last_error;    // of the last failed round (or start-up)
  double last_round_ms = 0;  // find + store time of the last round
  // While the start-up build runs: "load" (sprites read) or "pairs" (sprites searched), with
  // sprites done of total; "" once it is done.
  std::string startup_stage;
  int64_t startup_done = 0, startup_total = 0;
};

class TransitionWorker {
 public:
  // Starts the thread. Invalid weights throw InputError here; a bank that cannot be
  // opened shows up as stats().last_error (the thread then drops what is submitted).
  // `sprites`: which sprites take part (merged ones not, by default), at start and in rounds.
  // `on_startup_change`, when set, is called each time stats().ready or the start-up progress
  // (startup_stage, startup_done, startup_total) changed, so a caller waiting for the start-up
  // build can wait on its own condition variable instead of polling stats(). It runs on the
  // worker's thread (the "pairs" stage: on one of the start-up build's threads, one call at a
  // time) with none of the worker's locks held; keep it short and do not call Stop from it.
  TransitionWorker(std::string bank_path, const TransitionWeights& weights, int startup_threads = 1,
                   TableChoice table = {}, std::function<void()> on_startup_change = {});
  ~TransitionWorker();  // Stop()
  TransitionWorker(const TransitionWorker&) = delete;
  TransitionWorker& operator=(const TransitionWorker&) = delete;

  // Queues newly stored sprites; returns at once. Ids the worker already knows are skipped.
  void Submit(std::span<const int64_t> sprite_ids);
  // Blocks until everything submitted before the call is processed (tests, shutdown).
  void WaitIdle();
  // The same for at most `seconds`; true when idle.
  bool WaitIdleFor(double seconds);
  // Finishes the round in progress and joins the thread; queued ids are dropped (their
  // complete clips are brought up to date at the next start). Returns how many were dropped.
  int64_t Stop();
  TransitionWorkerStats stats() const;

 private:
  struct State;
  void Run();
  void RunUnits();  // on a PostgreSQL bank
  void Fail(const std::string& what);

  std::string bank_path_;
  std::unique_ptr<State> state_;
  std::function<void()> on_startup_change_;  // set before the thread starts, never changed
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<int64_t> queue_;
  bool stop_ = false;
  bool busy_ = true;  // until the start-up build is done
  TransitionWorkerStats stats_;
  std::thread thread_;
};

}  // namespace ss
