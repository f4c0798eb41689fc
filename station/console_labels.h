#pragma once
// The labelling page's part of the control API (`/api/labels...`, docs/console.md):
// a person judges transitions the classifier is least sure of, the judgements are
// kept in the bank (table transition_labels), exported as the labels CSV that
// `spritestation transitions train` reads, and the classifier is retrained from them
// in the background: new weights written beside the bank (never over an older file),
// the station restarted with them and the bank's transition table rebuilt, with the
// progress in the status every console receives (seed 000 §3, docs/transitions.md).
//
// A pair (i, j) is the classifier's pair: the page plays it as the transition i -> j
// would look (i-1, i, then j, j+1) and the label says whether that jump looks smooth.
#include <condition_variable>
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

// The labels CSV of `transitions train` (training.h ReadLabelsCsv): the header, then one
// row per yes / no label (skips are left out) in pair order (by the smaller, then the larger
// sprite id); a positive rate > 0 is written as the "# positive_rate=R" line first.
std::string TransitionLabelsCsv(const std::vector<TransitionLabelRecord>& labels,
                                double positive_rate);

// The positive rate the weights' stage 2 was calibrated for (training.stage2_calibration),
// or -1 when they were not.
double CalibratedPositiveRate(const TransitionWeights& weights);

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
  // Blocks until no retrain runs (tests).
  void WaitRetrain();
  // The "retrain" member of the status.
  nlohmann::json RetrainState() const;

 private:
  struct Pool;
  // What the retrain thread shares with the part. The thread is detached: a daemon told to
  // stop while a long training runs does not wait for it (Stop waits only while the thread
  // uses the station host, i.e. restarts the station or follows its rebuild).
  // Threads: the API's threads call the routes and StartRetrain, the server's Stop; the
  // retrain thread runs RunRetrain. While it follows the station's rebuild, its listeners run
  // on the host's switching thread (StationHost::AddStationChangeListener) and on the
  // station's transitions worker thread (Station::AddTransitionsListener) and take only
  // `mutex` to wake it. Lock order: the host's and the station's listener locks -> `mutex`
  // -> status_mutex_ (RefreshStatus); pool_mutex_ is taken with neither held. No lock of this
  // part is held while calling the host's switching methods (UseWeights) or removing a
  // listener.
  struct Shared {
    std::mutex mutex;  // guards every member
    std::condition_variable changed;
    nlohmann::json retrain;  // the status' "retrain" member
    std::optional<std::pair<TransitionWeights, std::string>> own_weights;  // without a host
    bool running = false;  // a retrain thread exists
    bool using_host = false;
    bool stop = false;
    bool dirty = true;  // the labels or weights changed: refresh the status
    // The host replaced its station or the station's transitions start-up moved on (set by
    // the retrain's listeners; the retrain thread waits on `changed` for it or `stop`).
    bool transitions_moved = false;
  };
  std::string BankPath() const;
  // The weights in use: the host's (its stations run them), else this part's own.
  std::pair<TransitionWeights, std::string> WeightsInUse() const;
  static void RunRetrain(std::shared_ptr<Shared> shared, api::Context context,
                         const ConsoleLabelsOptions& options, const std::string& bank,
                         const TransitionWeights& current);
  void RefreshStatus() const;  // labels and weights from the bank (at most every 2 s)
  // pool_ made anew for another bank or comparison window, then brought up to the bank's sprites;
  // pool_mutex_ held.
  void UpdatePool(const std::string& bank, const TransitionWeights& weights);

  api::Context context_;
  ConsoleLabelsOptions options_;
  std::shared_ptr<Shared> shared_;

  std::mutex pool_mutex_;  // one pair search at a time
  std::unique_ptr<Pool> pool_;

  mutable std::mutex status_mutex_;  // guards what follows
  mutable nlohmann::json labels_status_, weights_status_;
  mutable std::string weights_status_path_;
  mutable double refreshed_at_ = -1e9;
};

}  // namespace ss
