#pragma once
// The labelling page's part of the control API (`/api/labels...`, docs/console.md):
// a person judges transitions the classifier is least sure of, the judgements are
// kept in the bank (table transition_labels), exported as the labels CSV that
// `spritestation transitions train` reads, and the classifier is retrained from them
// in the background (a RetrainJob, station/retrain_job.h), with the progress in the
// status every console receives (seed 000 §3, docs/transitions.md).
// Threads: the API's threads call the routes, the server's Stop; pool_mutex_ (one pair search
// at a time) and status_mutex_ are never held together.
//
// A pair (i, j) is the classifier's pair: the page plays it as the transition i -> j
// would look (i-1, i, then j, j+1) and the label says whether that jump looks smooth.
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bank_records.h"
#include "pipeline/transitions/weights.h"
#include "station/api_part.h"
#include "station/retrain_job.h"

namespace ss {

struct ConsoleLabelsOptions {
  std::string bank;  // "" : the running station's bank (tests name one)
  int threads = 2;   // threads for training and, without a station, the rebuild (>= 1)
  // sprites whose stage-1 candidates are searched for uncertain pairs (>= 1)
  int candidate_rows = 400;
  uint64_t seed = 1;    // of the row sample
  int min_labels = 10;  // yes + no labels a retrain needs (>= 2: both kinds are needed)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

class ConsoleLabels : public api::Part {
 public:
  explicit ConsoleLabels(api::Context context, ConsoleLabelsOptions options = {});
  ~ConsoleLabels() override;  // Stop()

  std::vector<api::Route> Routes() override;
  void AddStatus(nlohmann::json& status) const override;
  void Stop() override;

  // GET /api/labels: {"yes", "no", "skip", "total", "exportable"}.
  nlohmann::json Counts() const;
  // GET /api/labels/pairs?count=N: the N unlabelled pairs of originals whose stage-2
  // decision is nearest its threshold (least sure first; each sprite in at most one pair),
  // among the stage-1 candidates of up to `candidate_rows` sprites. Every sprite of a pair
  // has a predecessor and a successor in its clip, so either side can be played first.
  nlohmann::json Pairs(int count);
  // GET /api/labels/pair?from=ID&to=ID: one pair as Pairs gives it (a link to a transition).
  // NotFoundError naming an unknown sprite; InputError naming the field for a mirrored
  // sprite, one of a clip still being written, or a first or last frame.
  nlohmann::json Pair(int64_t from, int64_t to);
  // POST /api/labels {"from", "to", "label": "yes" | "no" | "skip"}: stores (or replaces)
  // a label. InputError naming the field; NotFoundError naming an unknown sprite.
  nlohmann::json Store(const nlohmann::json& body);
  // POST /api/labels/undo {"from", "to"}: removes a label (NotFoundError when there is none).
  nlohmann::json Undo(const nlohmann::json& body);
  // GET /api/labels/export.csv
  std::string ExportCsv() const;
  // POST /api/labels/retrain: starts the background retrain; returns its state.
  // ConflictError while one runs or a capture session is active; InputError("labels", ...)
  // when the labels cannot train a classifier (too few, or one kind only).
  nlohmann::json StartRetrain();
  // POST /api/labels/retrain/cancel: RetrainJob::Cancel; its state.
  nlohmann::json CancelRetrain();
  // Blocks until no retrain runs (tests).
  void WaitRetrain();
  // The "retrain" member of the status.
  nlohmann::json RetrainState() const;

 private:
  struct Pool;
  std::string BankPath() const;
  // The weights in use: the host's (its stations run them), else this part's own.
  std::pair<TransitionWeights, std::string> WeightsInUse() const;
  void RefreshStatus() const;  // labels and weights from the bank (at most every 2 s)
  // pool_ made anew for another bank or comparison window, then brought up to the bank's sprites;
  // pool_mutex_ held.
  void UpdatePool(const std::string& bank, const TransitionWeights& weights);

  api::Context context_;
  ConsoleLabelsOptions options_;
  // The labels or weights changed: refresh the status. Shared with the retrain's callback, which
  // may outlive this part (the job's thread is detached).
  std::shared_ptr<std::atomic<bool>> dirty_ = std::make_shared<std::atomic<bool>>(true);
  std::unique_ptr<RetrainJob> retrain_;

  std::mutex pool_mutex_;  // one pair search at a time
  std::unique_ptr<Pool> pool_;

  mutable std::mutex status_mutex_;  // guards what follows
  mutable nlohmann::json labels_status_, weights_status_;
  mutable std::string weights_status_path_;
  mutable double refreshed_at_ = -1e9;
};

}  // namespace ss
