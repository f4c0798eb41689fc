#pragma once
// The classifier's retrain as a job of its own (issue 36: long work is a controller the HTTP
// part owns, not code inside it): the labels exported as `transitions train` reads them, both
// stages trained and cross-validated, the weights written beside the bank under a name no other
// file has, the station restarted with them and the bank's transition table rebuilt (seed 000
// §3, docs/transitions.md). Its state is typed (RetrainState); the labelling page's part
// (station/console_labels.h) only starts it and turns the state into the status' JSON.
//
// Threads: Start, State, Wait and Stop on any thread; the job on a thread of its own, detached:
// a daemon told to stop while a long training runs does not wait for it (Stop waits only while
// the job uses the station host, i.e. restarts the station or follows its rebuild). While it
// follows the rebuild, its listeners run on the host's switching thread
// (StationHost::AddStationChangeListener) and the station's transitions worker
// (Station::AddTransitionsListener) and take only the job's mutex to wake it. Lock order: the
// host's and the station's listener locks -> the job's mutex. No lock of the job is held while
// it calls the host's switching methods (UseWeights) or removes a listener, nor while it calls
// `on_change`.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bank_records.h"
#include "pipeline/transitions/weights.h"
#include "station/api_part.h"

namespace ss {

// The labels CSV of `transitions train` (training.h ReadLabelsCsv): the header, then one
// row per yes / no label (skips are left out) in pair order (by the smaller, then the larger
// sprite id); a positive rate > 0 is written as the "# positive_rate=R" line first.
std::string TransitionLabelsCsv(const std::vector<TransitionLabelRecord>& labels,
                                double positive_rate);

// The positive rate the weights' stage 2 was calibrated for (training.stage2_calibration),
// or -1 when they were not.
double CalibratedPositiveRate(const TransitionWeights& weights);

enum class RetrainPhase { kIdle, kTraining, kRebuilding, kDone, kFailed, kCancelled };
const char* RetrainPhaseName(RetrainPhase phase);  // "idle", "training", ... as the status says

// What a retrain has done so far; each group is filled as its stage ends.
struct RetrainState {
  RetrainPhase phase = RetrainPhase::kIdle;
  double progress = 0;  // 0..1
  std::string stage;    // what it does now, in words
  // Cancel() is taken: from the start until the station gets the new weights.
  bool cancellable = false;
  // From the start.
  int64_t labels = 0, accepts = 0;  // yes + no labels, and the yes ones
  std::string started, previous_weights;
  // Once the labels are exported.
  std::string labels_file;
  double positive_rate = -1;  // the bank's, as calibrated (-1: none)
  // Once trained.
  bool trained = false;
  double precision = 0, recall = 0, stage1_precision = 0, stage1_recall = 0;  // cross-validated
  int folds = 0;
  std::string weights, fingerprint;  // the new file and its classifier's fingerprint
  double seconds_train = 0;
  bool calibrated = false;  // stage 2 set for the bank's positive rate; then:
  double accepts_per_sprite = 0, estimated_precision = 0, estimated_recall = 0;
  // Once done.
  int64_t transitions = 0;
  double seconds_rebuild = 0, seconds = 0;
  std::string finished;  // done, failed or cancelled
  std::string error;     // failed

  // The status' "transitions.retrain" member (docs/console.md): each group's keys once filled.
  nlohmann::json ToJson() const;
};

struct RetrainRequest {
  std::string bank;
  TransitionWeights current;  // the weights in use (their positive rate is the bank's)
  std::string current_path;   // "" : the shipped defaults
  int64_t labels = 0, accepts = 0;
};

class RetrainJob {
 public:
  // `context.host` (may be null) is the station host the new weights go to; without one the
  // job rebuilds the bank's table itself and keeps the weights (OwnWeights). `threads` >= 1 for
  // the training and that rebuild. `on_change` gets the state after each change (a new stage,
  // the end: then no retrain runs any more), with no lock held, on the job's thread or Start's;
  // it may be called after the job is destroyed (the thread is detached), so it must hold what
  // it uses.
  RetrainJob(api::Context context, int threads,
             std::function<void(const RetrainState&)> on_change = {});
  ~RetrainJob();  // Stop()
  RetrainJob(const RetrainJob&) = delete;
  RetrainJob& operator=(const RetrainJob&) = delete;

  // Starts the retrain; its state then. ConflictError while one runs or after Stop.
  RetrainState Start(RetrainRequest request);
  RetrainState State() const;
  bool Running() const;
  // Asks the running retrain to stop at its next stage (after the export, after the training,
  // before the station gets the new weights): it ends "cancelled", its weights file removed and
  // nothing else changed. ConflictError when none runs, or once the station has the new weights
  // (the rebuild then finishes). Its state then (the cancel pending until the next stage).
  RetrainState Cancel();
  // Blocks until no retrain runs.
  void Wait() const;
  // The server stops: a job following the station's rebuild stops at once, one restarting the
  // station when the restart is done, one still training is left to finish alone (it touches
  // only its own state and files). Idempotent.
  void Stop();
  // The weights the last retrain made, without a host (the host keeps them otherwise).
  std::optional<std::pair<TransitionWeights, std::string>> OwnWeights() const;

 private:
  struct Shared;
  static void Run(std::shared_ptr<Shared> shared, const RetrainRequest& request);
  std::shared_ptr<Shared> shared_;
};

}  // namespace ss
