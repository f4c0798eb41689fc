// The classifier's retrain as a job (station/retrain_job.h).
#include "station/retrain_job.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <tuple>

#include "core/bank.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/posix.h"
#include "core/utc_time.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "station/station.h"
#include "station/station_host.h"

namespace ss {

namespace fs = std::filesystem;

namespace {

constexpr int kFolds = 5;

// A file in `dir` named prefix-STAMP.ext that does not exist yet (never over an older one).
fs::path FreshName(const fs::path& dir, const std::string& prefix, const std::string& stamp,
                   const std::string& ext) {
  fs::path p = dir / (prefix + stamp + ext);
  for (int k = 2; fs::exists(p); ++k) p = dir / (prefix + stamp + "-" + std::to_string(k) + ext);
  return p;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc | std::ios::binary);
  if (!out) throw WorkError(path.string(), "cannot open for writing");
  out << text;
  out.close();
  if (!out) throw WorkError(path.string(), "write failed");
}

}  // namespace

std::string TransitionLabelsCsv(const std::vector<TransitionLabelRecord>& labels,
                                double positive_rate) {
  std::string out;
  if (positive_rate > 0 && positive_rate < 1) {
    char text[64];
    std::snprintf(text, sizeof(text), "# positive_rate=%.9g\n", positive_rate);
    out += text;
  }
  out += "sprite_i,sprite_j,accept\n";
  // In pair order, not labelling order: training's fold split follows the file's order, so
  // the same labels give the same cross-validated figures however they were asked.
  std::vector<const TransitionLabelRecord*> sorted;
  sorted.reserve(labels.size());
  for (const TransitionLabelRecord& l : labels) sorted.push_back(&l);
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto* x, const auto* y) {
    return std::make_tuple(std::min(x->from_sprite, x->to_sprite),
                           std::max(x->from_sprite, x->to_sprite), x->from_sprite) <
           std::make_tuple(std::min(y->from_sprite, y->to_sprite),
                           std::max(y->from_sprite, y->to_sprite), y->from_sprite);
  });
  for (const TransitionLabelRecord* p : sorted) {
    const TransitionLabelRecord& l = *p;
    if (l.label != "yes" && l.label != "no") continue;
    out += std::to_string(l.from_sprite) + "," + std::to_string(l.to_sprite) + "," +
           (l.label == "yes" ? "1" : "0") + "\n";
  }
  return out;
}

double CalibratedPositiveRate(const TransitionWeights& weights) {
  try {
    const nlohmann::json t = nlohmann::json::parse(weights.training_json);
    const double rate = t.at("stage2_calibration").at("positive_rate").get<double>();
    return rate > 0 && rate < 1 ? rate : -1;
  } catch (const std::exception&) {
    return -1;
  }
}

const char* RetrainPhaseName(RetrainPhase phase) {
  switch (phase) {
    case RetrainPhase::kIdle:
      return "idle";
    case RetrainPhase::kTraining:
      return "training";
    case RetrainPhase::kRebuilding:
      return "rebuilding";
    case RetrainPhase::kDone:
      return "done";
    case RetrainPhase::kFailed:
      return "failed";
    case RetrainPhase::kCancelled:
      return "cancelled";
  }
  return "idle";
}

nlohmann::json RetrainState::ToJson() const {
  nlohmann::json r = {{"state", RetrainPhaseName(phase)},
                      {"progress", progress},
                      {"stage", stage},
                      {"cancellable", cancellable}};
  if (phase == RetrainPhase::kIdle) return r;
  r["labels"] = labels;
  r["accepts"] = accepts;
  r["started"] = started;
  r["previous_weights"] = previous_weights;
  if (!labels_file.empty()) {
    r["labels_file"] = labels_file;
    r["positive_rate"] =
        positive_rate > 0 ? nlohmann::json(positive_rate) : nlohmann::json(nullptr);
  }
  if (trained) {
    r["precision"] = precision;
    r["recall"] = recall;
    r["stage1"] = {{"precision", stage1_precision}, {"recall", stage1_recall}};
    r["folds"] = folds;
    r["weights"] = weights;
    r["fingerprint"] = fingerprint;
    r["seconds_train"] = seconds_train;
    if (calibrated) {
      r["calibration"] = {{"accepts_per_sprite", accepts_per_sprite},
                          {"estimated_precision", estimated_precision},
                          {"estimated_recall", estimated_recall}};
    }
  }
  if (phase == RetrainPhase::kDone) {
    r["transitions"] = transitions;
    r["seconds_rebuild"] = seconds_rebuild;
    r["seconds"] = seconds;
  }
  if (phase == RetrainPhase::kFailed) r["error"] = error;
  if (!finished.empty()) r["finished"] = finished;
  return r;
}

// What the job's thread shares with the job's owner.
struct RetrainJob::Shared {
  api::Context context;
  int threads = 1;
  std::function<void(const RetrainState&)> on_change;

  mutable std::mutex mutex;  // guards what follows
  mutable std::condition_variable changed;
  RetrainState state;
  std::optional<std::pair<TransitionWeights, std::string>> own_weights;  // without a host
  bool running = false;                                                  // a job thread exists
  bool cancel = false;       // Cancel() asked: the job ends at its next stage
  bool handed_over = false;  // the station has the new weights: too late to cancel
  bool using_host = false;
  bool stop = false;
  // The host replaced its station or the station's transitions start-up moved on (set by the
  // job's listeners; the job waits on `changed` for it or `stop`).
  bool transitions_moved = false;
};

RetrainJob::RetrainJob(api::Context context, int threads,
                       std::function<void(const RetrainState&)> on_change)
    : shared_(std::make_shared<Shared>()) {
  shared_->context = std::move(context);
  shared_->threads = std::max(1, threads);
  shared_->on_change = std::move(on_change);
}

RetrainJob::~RetrainJob() { Stop(); }

void RetrainJob::Stop() {
  std::unique_lock lock(shared_->mutex);
  shared_->stop = true;
  shared_->changed.notify_all();
  shared_->changed.wait(lock, [&] { return !shared_->using_host; });
}

RetrainState RetrainJob::State() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->state;
}

bool RetrainJob::Running() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->running;
}

void RetrainJob::Wait() const {
  std::unique_lock lock(shared_->mutex);
  shared_->changed.wait(lock, [&] { return !shared_->running; });
}

RetrainState RetrainJob::Cancel() {
  std::lock_guard lock(shared_->mutex);
  if (!shared_->running) throw ConflictError("retrain", "no retrain is running");
  if (shared_->handed_over) {
    throw ConflictError("retrain",
                        "the station already uses the new weights; the transitions are being "
                        "rebuilt with them");
  }
  shared_->cancel = true;
  return shared_->state;
}

std::optional<std::pair<TransitionWeights, std::string>> RetrainJob::OwnWeights() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->own_weights;
}

RetrainState RetrainJob::Start(RetrainRequest request) {
  RetrainState started;
  {
    std::lock_guard lock(shared_->mutex);
    if (shared_->running || shared_->stop)
      throw ConflictError("retrain", "a retrain is running, or the server stops");
    shared_->running = true;
    shared_->cancel = false;
    shared_->handed_over = false;
    RetrainState& s = shared_->state;
    s = RetrainState{};
    s.phase = RetrainPhase::kTraining;
    s.cancellable = true;
    s.progress = 0.02;
    s.stage = "exporting the labels";
    s.labels = request.labels;
    s.accepts = request.accepts;
    s.started = UtcNowIso();
    s.previous_weights = request.current_path.empty() ? "shipped defaults" : request.current_path;
    started = s;
  }
  std::thread(Run, shared_, std::move(request)).detach();
  if (shared_->on_change) shared_->on_change(started);
  return started;
}

void RetrainJob::Run(std::shared_ptr<Shared> shared, const RetrainRequest& request) {
  const std::string& bank = request.bank;
  const TransitionWeights& current = request.current;
  const api::Context& context = shared->context;
  SetThisThreadNice(kNiceBackground);  // below capture and the console (core/posix.h)
  auto log = Log("station.labels");
  // Changes the state and tells it. `ends`: the job's last change, which also makes it no longer
  // cancellable and no longer running, under the same lock, so whoever is told "cancelled" or
  // "done" can start the next retrain at once.
  auto SetRetrain = [&](const std::function<void(RetrainState&)>& change, bool ends = false) {
    RetrainState now;
    {
      std::lock_guard lock(shared->mutex);
      change(shared->state);
      if (ends) {
        shared->state.cancellable = false;
        shared->running = false;
      }
      now = shared->state;
    }
    if (ends) shared->changed.notify_all();
    if (shared->on_change) shared->on_change(now);
  };
  const auto Finish = [&](const std::function<void(RetrainState&)>& change) {
    SetRetrain(change, true);
  };
  // Enters the part of the work that uses the station host: false when the server stops.
  auto enter_host = [&] {
    std::lock_guard lock(shared->mutex);
    if (shared->stop) return false;
    shared->using_host = true;
    return true;
  };
  // Ends the job here, "cancelled", when Cancel() asked (before the station has the weights).
  struct Cancelled {};
  auto cancel_point = [&] {
    std::lock_guard lock(shared->mutex);
    if (shared->cancel) throw Cancelled{};
  };
  std::string weights_written;  // removed again if the job is cancelled
  const auto t0 = std::chrono::steady_clock::now();
  auto seconds = [](auto since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
  };
  try {
    // 1. The labels as `transitions train` reads them, kept beside the weights they make.
    const fs::path dir = fs::absolute(bank).parent_path() / "weights";
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw WorkError(dir.string(), "cannot create the weights folder: " + ec.message());
    const std::string stamp = UtcNowStamp();
    const fs::path labels_path = FreshName(dir, "labels-", stamp, ".csv");
    const double positive_rate = CalibratedPositiveRate(current);
    WriteText(labels_path, TransitionLabelsCsv(Bank(bank).LoadTransitionLabels(), positive_rate));

    cancel_point();
    // 2. Train (both stages, cross-validated; stage 2 set for the positive rate on the bank).
    SetRetrain([&](RetrainState& r) {
      r.progress = 0.05;
      r.stage = "training on " + std::to_string(r.labels) + " labels (" + std::to_string(kFolds) +
                "-fold cross-validation), then calibrating on the bank";
      r.labels_file = labels_path.string();
      r.positive_rate = positive_rate > 0 ? positive_rate : -1;
    });
    // The shipped classifier (BankTrainOptions' defaults: DefaultWeights()' variant and window),
    // whatever the weights in use are.
    BankTrainOptions train;
    train.train.folds = kFolds;
    train.threads = shared->threads;
    const BankTrainResult result = TrainOnBank(labels_path.string(), bank, train);
    const double train_s = seconds(t0);

    cancel_point();
    // 3. The weights file, written whole under a name no other file has.
    const fs::path weights_path = FreshName(dir, "weights-", stamp, ".json");
    const fs::path partial = weights_path.string() + ".partial";
    SaveWeights(result.weights, partial.string());
    fs::rename(partial, weights_path);
    weights_written = weights_path.string();
    const std::string fingerprint = WeightsFingerprint(result.weights);
    log->info("retrained on {} labels: stage 2 precision {:.3f}, recall {:.3f}; weights {}",
              result.report.samples, result.report.stage2.precision(),
              result.report.stage2.recall(), weights_path.string());
    SetRetrain([&](RetrainState& r) {
      r.phase = RetrainPhase::kRebuilding;
      r.progress = 0.5;
      r.stage = "restarting the station with the new weights";
      r.trained = true;
      r.precision = result.report.stage2.precision();
      r.recall = result.report.stage2.recall();
      r.stage1_precision = result.report.stage1.precision();
      r.stage1_recall = result.report.stage1.recall();
      r.folds = result.report.folds;
      r.weights = weights_path.string();
      r.fingerprint = fingerprint;
      r.seconds_train = train_s;
      r.calibrated = result.stage2_calibrated;
      if (result.stage2_calibrated) {
        r.accepts_per_sprite = result.stage2.accepts_per_sprite;
        r.estimated_precision = result.stage2.precision;
        r.estimated_recall = result.stage2.recall;
      }
    });

    {
      // The last moment a cancel is honoured: from here the weights are used.
      std::lock_guard lock(shared->mutex);
      if (shared->cancel) throw Cancelled{};
      shared->handed_over = true;
      shared->state.cancellable = false;  // said with the rebuild's first progress, just below
    }
    // 4. The station uses them; the bank's table is rebuilt with them.
    const auto t_rebuild = std::chrono::steady_clock::now();
    auto stage_progress = [&](const std::string& stage, int64_t done, int64_t total) {
      const double f = total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 0.0;
      SetRetrain([&](RetrainState& r) {
        const bool load = stage == "load";
        r.progress = load ? 0.55 + 0.15 * f : 0.7 + 0.28 * f;
        r.stage = std::string(load ? "rebuilding transitions: reading sprites "
                                   : "rebuilding transitions: searching ") +
                  std::to_string(done) + " / " + std::to_string(total);
      });
    };
    bool rebuilt_by_station = false;
    if (context.host) {
      if (!enter_host())
        throw WorkError("retrain", "the server stopped before the station used the new weights");
      struct Leave {
        Shared& s;
        ~Leave() {
          {
            std::lock_guard lock(s.mutex);
            s.using_host = false;
          }
          s.changed.notify_all();
        }
      } leave{*shared};
      const std::shared_ptr<Station> before = context.host->current();
      const bool worker = before && before->Status().transitions_enabled;
      context.host->UseWeights(result.weights, weights_path.string());
      if (worker) {
        rebuilt_by_station = true;
        // The new station's transition worker rebuilds the table at its start. This thread
        // sleeps until that start-up moves on, the host replaces its station (the new one's
        // start-up is followed then) or the server stops: each of them wakes it.
        auto wake = [shared] {
          {
            std::lock_guard lock(shared->mutex);
            shared->transitions_moved = true;
          }
          shared->changed.notify_all();
        };
        struct Following {
          StationHost& host;
          int host_listener;
          std::shared_ptr<Station> station;  // whose start-up is followed
          int station_listener = 0;
          ~Following() {
            if (station) station->RemoveTransitionsListener(station_listener);
            host.RemoveStationChangeListener(host_listener);
          }
        } following{*context.host, context.host->AddStationChangeListener(wake)};
        for (;;) {
          {
            std::lock_guard lock(shared->mutex);
            if (shared->stop)
              throw WorkError("retrain", "the server stopped while the transitions were rebuilt");
            shared->transitions_moved = false;  // what moves from here on wakes the wait below
          }
          const std::shared_ptr<Station> station = context.host->current();
          if (station != following.station) {
            if (following.station)
              following.station->RemoveTransitionsListener(following.station_listener);
            following.station = station;
            following.station_listener = station ? station->AddTransitionsListener(wake) : 0;
          }
          if (station) {
            const StationStatus st = station->Status();
            if (st.transitions_ready) {
              if (!st.transitions_error.empty())
                throw WorkError("transitions", st.transitions_error);
              break;
            }
            if (!st.transitions_startup_stage.empty()) {
              stage_progress(st.transitions_startup_stage, st.transitions_startup_done,
                             st.transitions_startup_total);
            }
          }
          std::unique_lock lock(shared->mutex);
          shared->changed.wait(lock, [&] { return shared->stop || shared->transitions_moved; });
        }
      }
    } else {
      std::lock_guard lock(shared->mutex);
      shared->own_weights = std::make_pair(result.weights, weights_path.string());
    }
    if (!rebuilt_by_station) {
      BankUpdateOptions update;
      update.weights = result.weights;
      update.table = TableChoice::RecordedIn(Bank(bank));  // the sprites and cap it was made with
      update.threads = shared->threads;
      update.progress = [&](const std::string& stage, size_t done, size_t total) {
        stage_progress(stage, static_cast<int64_t>(done), static_cast<int64_t>(total));
      };
      UpdateBankTransitions(bank, update);
    }
    const Bank after(bank);
    const std::string table = after.GetMeta(kTransitionWeightsMetaKey).value_or("");
    if (table != fingerprint) {
      throw WorkError(bank, "the transition table was made by weights " + table + ", not the new " +
                                fingerprint);
    }
    const int64_t transitions = after.Counts().transitions;
    const double rebuild_s = seconds(t_rebuild);
    log->info("transitions rebuilt with {}: {} transitions in {:.1f} s", weights_path.string(),
              transitions, rebuild_s);
    Finish([&](RetrainState& r) {
      r.phase = RetrainPhase::kDone;
      r.progress = 1.0;
      r.stage = "done: " + std::to_string(transitions) + " transitions";
      r.transitions = transitions;
      r.seconds_rebuild = rebuild_s;
      r.seconds = seconds(t0);
      r.finished = UtcNowIso();
    });
  } catch (const Cancelled&) {
    std::error_code ec;
    if (!weights_written.empty()) fs::remove(weights_written, ec);
    log->info("retrain cancelled{}", weights_written.empty() ? "" : "; its weights file removed");
    Finish([&](RetrainState& r) {
      r.phase = RetrainPhase::kCancelled;
      r.stage = "cancelled";
      r.trained = false;
      r.weights.clear();
      r.finished = UtcNowIso();
    });
  } catch (const std::exception& e) {
    log->error("retrain failed: {}", e.what());
    Finish([&](RetrainState& r) {
      r.phase = RetrainPhase::kFailed;
      r.error = e.what();
      r.finished = UtcNowIso();
    });
  }
}

}  // namespace ss
