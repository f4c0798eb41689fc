#include "pipeline/transitions/worker.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <unordered_set>

#include "core/bank.h"
#include "core/error.h"
#include "core/log.h"
#include "core/posix.h"
#include "core/sql_postgres.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/unit_worker.h"

namespace ss {

// Everything the thread owns (connections are used from the worker thread only).
struct TransitionWorker::State {
  TransitionWeights weights;
  int startup_threads = 1;
  TableChoice choice;
  std::optional<Bank> reader;
  std::optional<BankWriter> writer;
  std::unique_ptr<TransitionBuilder> builder;  // made when the bank scale is known
  SegmentKeys keys;
  TransitionBars bars;  // of the table's cap (choice.max_per_sprite), from the rounds' prunes
};

TransitionWorker::TransitionWorker(std::string bank_path, const TransitionWeights& weights,
                                   int startup_threads, TableChoice table,
                                   std::function<void()> on_startup_change)
    : bank_path_(std::move(bank_path)),
      state_(std::make_unique<State>()),
      on_startup_change_(std::move(on_startup_change)) {
  const TransitionClassifier check(
      weights);  // InputError for invalid weights, in the caller's thread
  state_->weights = weights;
  state_->startup_threads = std::max(1, startup_threads);
  state_->choice = table;
  thread_ = std::thread([this] { Run(); });
}

TransitionWorker::~TransitionWorker() { Stop(); }

void TransitionWorker::Submit(std::span<const int64_t> sprite_ids) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    queue_.insert(queue_.end(), sprite_ids.begin(), sprite_ids.end());
    stats_.queued = static_cast<int64_t>(queue_.size());
  }
  wake_.notify_one();
}

void TransitionWorker::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [&] { return stop_ || (!busy_ && queue_.empty()); });
}

bool TransitionWorker::WaitIdleFor(double seconds) {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, seconds)), [&] {
    return stop_ || (!busy_ && queue_.empty());
  }) && !stop_;
}

int64_t TransitionWorker::Stop() {
  int64_t dropped = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    dropped = static_cast<int64_t>(queue_.size());
    queue_.clear();
    stats_.queued = 0;
  }
  wake_.notify_all();
  idle_.notify_all();
  if (thread_.joinable()) thread_.join();
  return dropped;
}

TransitionWorkerStats TransitionWorker::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void TransitionWorker::Fail(const std::string& what) {
  Log("pipeline.transitions")->error("transition worker: {}", what);
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.failed_rounds;
  stats_.last_error = what;
}

void TransitionWorker::Run() {
  SetThisThreadNice(kNiceBackground);  // below capture and the console (core/posix.h)
  if (sql::IsPostgresAddress(bank_path_)) return RunUnits();
  auto log = Log("pipeline.transitions");
  State& s = *state_;
  auto fail = [&](const std::string& what) { Fail(what); };
  // Start-up: the connections, then the table of the complete clips.
  int64_t stored = 0, known = 0;
  try {
    s.reader.emplace(bank_path_);  // InputError when there is no bank: never create one here
    s.writer.emplace(bank_path_);
    const auto progress = [this](const char* stage) {
      return [this, stage](size_t done, size_t total) {
        {
          std::lock_guard<std::mutex> lock(mutex_);
          stats_.startup_stage = stage;
          stats_.startup_done = static_cast<int64_t>(done);
          stats_.startup_total = static_cast<int64_t>(total);
        }
        if (on_startup_change_) on_startup_change_();
      };
    };
    const BankSprites sprites = LoadBankSprites(*s.reader, &s.keys, progress("load"), s.choice);
    if (!sprites.inputs.empty() || !sprites.left_out.empty()) {
      std::vector<Transition> transitions;
      if (!sprites.inputs.empty()) {
        s.builder = std::make_unique<TransitionBuilder>(s.weights, sprites.px_per_m);
        s.builder->BuildFromScratch(sprites.inputs, BuildOptions{.threads = s.startup_threads,
                                                                 .progress = progress("pairs")});
        transitions = s.builder->Transitions(s.choice.max_per_sprite);
      }
      // Sprites left out are in the universe: transitions of theirs from before go.
      std::unordered_set<int64_t> universe(sprites.ids.begin(), sprites.ids.end());
      universe.insert(sprites.left_out.begin(), sprites.left_out.end());
      const StoreResult r =
          StoreTransitionTable(*s.writer, transitions, WeightsFingerprint(s.weights), universe);
      stored = r.replaced_all ? static_cast<int64_t>(transitions.size()) : r.added + r.changed;
      known = static_cast<int64_t>(sprites.inputs.size());
    } else {
      s.writer->SetMeta(kTransitionWeightsMetaKey, WeightsFingerprint(s.weights));
    }
    s.writer->SetMeta(TableChoice::kMetaKey, s.choice.MetaValue());
    s.writer->SetMeta(TableChoice::kCapMetaKey, s.choice.CapMetaValue());
    log->info("transition worker: {} sprites at start, {} transitions written", known, stored);
  } catch (const std::exception& e) {
    fail(std::string("start-up: ") + e.what());
    s.reader.reset();
    s.writer.reset();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.ready = true;
    stats_.startup_stage.clear();
    stats_.sprites = known;
    stats_.transitions_stored = stored;
    busy_ = false;
  }
  idle_.notify_all();
  if (on_startup_change_) on_startup_change_();

  std::vector<int64_t> round;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) break;
      round.assign(queue_.begin(), queue_.end());
      queue_.clear();
      busy_ = true;
    }
    const auto t0 = std::chrono::steady_clock::now();
    int64_t added_sprites = 0, added_transitions = 0;
    try {
      if (!s.writer) throw WorkError(bank_path_, "the bank could not be opened at start-up");
      // Skip ids already known (a clip completed before start-up and also submitted).
      std::vector<int64_t> fresh;
      std::unordered_set<int64_t> in_round;
      for (int64_t id : round) {
        if (s.builder && s.builder->store().IndexOf(id)) continue;
        if (in_round.insert(id).second) fresh.push_back(id);
      }
      if (!fresh.empty()) {
        const double scale = s.builder ? s.builder->store().px_per_m() : 0.0;
        // Merged sprites (unless the choice takes them) are left out here, never indexed.
        const BankSprites sprites =
            LoadBankSpritesById(*s.reader, fresh, &s.keys, scale, &s.choice);
        if (!s.builder && !sprites.inputs.empty())
          s.builder = std::make_unique<TransitionBuilder>(s.weights, sprites.px_per_m);
        const TransitionDelta delta =
            sprites.inputs.empty() ? TransitionDelta{} : s.builder->Add(sprites.inputs);
        const RoundResult stored =
            StoreTransitionRound(*s.writer, delta.transitions, s.choice.max_per_sprite, &s.bars);
        added_sprites = static_cast<int64_t>(sprites.inputs.size());  // those taken
        added_transitions = stored.written;
      }
    } catch (const std::exception& e) {
      fail(e.what());
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.rounds;
      stats_.sprites += added_sprites;
      stats_.transitions_stored += added_transitions;
      stats_.last_round_ms = ms;
      stats_.queued = static_cast<int64_t>(queue_.size());
      busy_ = false;
    }
    idle_.notify_all();
  }
}

// A PostgreSQL bank may have other writers (stations, ingests) and other workers at once: an
// incremental table kept by each would race (a start-up rebuild replaces rows another writer's
// sprites need). So this process does its share as units, claimed from the bank's work table
// like `spritestation transitions worker` does (unit_worker.h): together they make exactly the
// table a single build makes. Submit only wakes the loop; idle means no unit was free.
void TransitionWorker::RunUnits() {
  std::unique_ptr<UnitWorker> units;
  try {
    units = std::make_unique<UnitWorker>(bank_path_,
                                         UnitWorkerOptions{.weights = state_->weights,
                                                           .load_threads = state_->startup_threads,
                                                           .table = state_->choice});
  } catch (const std::exception& e) {
    Fail(std::string("start-up: ") + e.what());
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.ready = true;
    busy_ = units != nullptr;
  }
  idle_.notify_all();
  if (on_startup_change_) on_startup_change_();
  if (!units) {
    // Nothing can be done: drop what is submitted, as the incremental worker does.
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      queue_.clear();
      stats_.queued = 0;
      idle_.notify_all();
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    }
    return;
  }
  while (true) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) break;
      queue_.clear();  // their clips are units once complete (RunOne registers them)
      stats_.queued = 0;
      busy_ = true;
    }
    const auto t0 = std::chrono::steady_clock::now();
    bool did = false;
    try {
      did = units->RunOne();
    } catch (const std::exception& e) {
      Fail(e.what());
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::unique_lock<std::mutex> lock(mutex_);
    const UnitWorkerStats& u = units->stats();
    stats_.rounds = u.units;
    stats_.sprites = u.sprites_indexed;
    stats_.transitions_stored = u.transitions;
    if (did) {
      stats_.last_round_ms = ms;
      continue;
    }
    busy_ = !queue_.empty();
    if (!busy_) idle_.notify_all();
    // New clips of other writers are found by polling, as `transitions worker` does.
    wake_.wait_for(lock, std::chrono::milliseconds(200), [&] { return stop_ || !queue_.empty(); });
  }
}

}  // namespace ss
