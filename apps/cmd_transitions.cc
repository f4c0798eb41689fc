// spritestation transitions BANK | train LABELS --bank BANK --out WEIGHTS |
//                label --from-truth SESSION --bank BANK --out LABELS | worker --bank
//                postgresql://...
// The transition table of a sprite bank (seed 000 §3; docs/transitions.md).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/bank.h"
#include "core/error.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/transition_jumps.h"
#include "pipeline/transitions/unit_worker.h"

namespace ss::apps {
namespace {

struct Args {
  std::string bank, weights, labels, out, session, name;
  double lease_s = 60;
  bool exit_when_idle = false;
  int threads = 2, folds = 5, count = 1000;
  uint64_t seed = 1;
  double stage1_recall = 0.999;
  double positive_rate = -1;
  std::string variant;  // train: "paper" | "colour_cells"; "": the default weights' variant
  bool json = false, quiet = false;
  bool include_merged = false;
  int max_per_sprite = TableChoice::kDefaultMaxPerSprite;
  int jump_sample = TransitionJumpOptions{}.max_transitions;
};

TransitionWeights WeightsOf(const Args& a) {
  return a.weights.empty() ? DefaultWeights() : LoadWeights(a.weights);
}

// Progress on stderr, at most a few lines a second, always the last one of a stage.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet) {}
  void operator()(const std::string& stage, size_t done, size_t total) {
    if (quiet_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (done < total && stage == stage_ && now - last_ < std::chrono::milliseconds(250)) return;
    stage_ = stage;
    last_ = now;
    const char* what = stage == "load" ? "reading sprites" : "finding transitions";
    std::fprintf(stderr, "%s: %zu / %zu sprites (%.0f%%)\n", what, done, total,
                 total ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0);
  }

 private:
  bool quiet_;
  std::mutex mutex_;
  std::string stage_;
  std::chrono::steady_clock::time_point last_{};
};

void Build(const Args& a) {
  if (a.bank.empty())
    throw InputError("transitions", "a sprite bank is needed: spritestation transitions BANK");
  BankUpdateOptions options;
  options.weights = WeightsOf(a);
  options.threads = a.threads;
  options.table = {.include_merged = a.include_merged, .max_per_sprite = a.max_per_sprite};
  auto progress = std::make_shared<Progress>(a.quiet || a.json);
  options.progress = [progress](const std::string& stage, size_t done, size_t total) {
    (*progress)(stage, done, total);
  };
  const BankUpdateSummary s = UpdateBankTransitions(a.bank, options);
  // The judge without a truth: how visible the kept transitions are (issue 34).
  std::optional<TransitionJumpSummary> jumps;
  if (a.jump_sample > 0) {
    const Bank bank(a.bank);
    std::vector<std::pair<int64_t, int64_t>> pairs;
    for (const TransitionRecord& t : bank.LoadTransitions())
      pairs.emplace_back(t.from_sprite, t.to_sprite);
    VisibleJumpMeter meter(bank);
    jumps = MeasureTransitionJumps(meter, pairs, {.max_transitions = a.jump_sample});
  }
  if (!a.json) {
    std::printf("%s%s", s.ToText().c_str(), jumps ? jumps->ToText().c_str() : "");
    return;
  }
  nlohmann::json j = nlohmann::json::parse(s.ToJson());
  if (jumps) {
    j["jumps"] = jumps->ToJson();
    j["transitions_per_sprite"] =
        s.sprites > 0 ? static_cast<double>(s.transitions) / static_cast<double>(s.sprites) : 0.0;
  }
  std::printf("%s\n", j.dump(2).c_str());
}

void Train(const Args& a) {
  BankTrainOptions options;
  options.train.folds = a.folds;
  options.train.seed = a.seed;
  options.window = DefaultWeights().window;
  if (a.variant == "colour_cells") {
    options.variant = Stage2Variant::kColourCells;
    options.window = ColourCellsWeights().window;  // its 1 px window on the contact point
  } else if (a.variant == "paper") {
    options.variant = Stage2Variant::kPaper;
    options.window = PaperWeights().window;
  }
  options.stage1_recall = a.stage1_recall;
  options.positive_rate = a.positive_rate;
  options.threads = a.threads;
  const BankTrainResult r = TrainOnBank(a.labels, a.bank, options);
  SaveWeights(r.weights, a.out);
  if (a.json) {
    nlohmann::json j = nlohmann::json::parse(r.weights.training_json);
    j["out"] = a.out;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  const TrainReport& t = r.report;
  std::printf("trained on %lld labelled pairs (%lld accepts), %d-fold cross-validated:\n",
              static_cast<long long>(t.samples), static_cast<long long>(t.accepts), t.folds);
  std::printf("  stage 1 (4 cheap features): precision %.3f, recall %.3f\n", t.stage1.precision(),
              t.stage1.recall());
  std::printf("  stage 2 (all 6 features):   precision %.3f, recall %.3f\n", t.stage2.precision(),
              t.stage2.recall());
  if (r.stage2_calibrated) {
    std::printf(
        "  stage 2 then set for the positive rate %.3g on the bank: %.1f accepts per sprite, "
        "estimated "
        "precision %.3f, recall %.3f (threshold D <= %.4f)\n",
        r.stage2.positive_rate, r.stage2.accepts_per_sprite, r.stage2.precision, r.stage2.recall,
        r.stage2.threshold);
  } else {
    std::printf(
        "  stage 2 keeps the labels' 50/50 operating point (no positive rate: give --positive-rate "
        "or make "
        "labels with 'label --from-truth')\n");
  }
  if (r.colour_cells) {
    // stage 1 is the colour_cells variant's velocity ball (below)
  } else if (a.stage1_recall > 0 && r.stage2_calibrated) {
    std::printf(
        "  stage 1 refitted as its filter to pass %.3f of %lld stage-2 accepts on the bank: %.1f "
        "candidates "
        "per sprite (%.0fx fewer than all pairs)\n",
        a.stage1_recall, static_cast<long long>(r.calibration_accepts),
        r.stage1.candidates_per_sprite, r.stage1.fewer_than_all);
  } else if (a.stage1_recall > 0) {
    std::printf(
        "  stage 1 then set to pass %.3f of %lld stage-2 accepts on the bank (bias %.4f -> %.4f)\n",
        a.stage1_recall, static_cast<long long>(r.calibration_accepts), r.stage1_bias_from_labels,
        r.weights.stage1_bias);
  }
  if (r.colour_cells) {
    std::printf(
        "  stage 2 (colour_cells) fitted on %s: velocity <= %.4g m/s AND alpha "
        "difference <= %.4g cells AND <= %d colour-different cells; estimated precision %.3f, "
        "recall %.3f (stage 1: the velocity ball)\n",
        r.stage2_calibrated ? "the bank for the positive rate" : "the labels alone (50/50)",
        r.cells.max_velocity_mps, r.cells.max_alpha_cells, r.cells.max_colour_cells,
        r.cells.precision, r.cells.recall);
  }
  std::printf("weights written to %s\n", a.out.c_str());
}

void Label(const Args& a) {
  const TruthLabelSummary s = LabelBankFromTruth(a.session, a.bank, static_cast<size_t>(a.count),
                                                 TruthLabelOptions{}, a.seed);
  WriteLabelsCsv(s.labels, a.out, s.positive_rate > 0 ? s.positive_rate : -1);
  size_t accepts = 0;
  for (const auto& l : s.labels) accepts += l.accept ? 1 : 0;
  if (a.json) {
    std::printf("%s\n", nlohmann::json({{"out", a.out},
                                        {"labels", s.labels.size()},
                                        {"accepts", accepts},
                                        {"positive_rate", s.positive_rate},
                                        {"sprites_matched", s.sprites_matched},
                                        {"sprites_unmatched", s.sprites_unmatched},
                                        {"mirrored_skipped", s.mirrored_skipped}})
                            .dump(2)
                            .c_str());
  } else {
    std::printf(
        "%zu labels (%zu accepts) from the truth of %lld sprites (%lld unmatched, %lld mirrors "
        "left out; "
        "%.3g of their pairs are true transitions) written to %s\n",
        s.labels.size(), accepts, static_cast<long long>(s.sprites_matched),
        static_cast<long long>(s.sprites_unmatched), static_cast<long long>(s.mirrored_skipped),
        s.positive_rate, a.out.c_str());
  }
}

volatile std::sig_atomic_t g_worker_stop = 0;

// One of any number of workers sharing a PostgreSQL bank's transition work (docs/scaling.md).
// SIGTERM or SIGINT: the unit in progress is finished and stored, then the summary, exit 0.
void Worker(const Args& a) {
  std::signal(SIGTERM, [](int) { g_worker_stop = 1; });
  std::signal(SIGINT, [](int) { g_worker_stop = 1; });
  UnitWorkerOptions options;
  options.weights = WeightsOf(a);
  options.name = a.name;
  options.lease_s = a.lease_s;
  options.load_threads = a.threads;
  options.table = {.include_merged = a.include_merged, .max_per_sprite = a.max_per_sprite};
  UnitWorker worker(a.bank, options);
  const auto t0 = std::chrono::steady_clock::now();
  while (!g_worker_stop) {
    if (worker.RunOne()) continue;
    if (a.exit_when_idle) {
      const WorkCounts c = worker.Counts();
      if (c.pending == 0 && c.leased == 0) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // polls the bank for new clips
  }
  const UnitWorkerStats& s = worker.stats();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (a.json) {
    std::printf("%s\n", nlohmann::json({{"worker", worker.name()},
                                        {"units", s.units},
                                        {"transitions", s.transitions},
                                        {"sprites_indexed", s.sprites_indexed},
                                        {"clips_indexed", s.clips_indexed},
                                        {"stage2_evaluations", s.stage2_evaluations},
                                        {"kept_pairs", s.kept_pairs},
                                        {"seconds", seconds},
                                        {"seconds_index", s.seconds_index},
                                        {"seconds_pairs", s.seconds_pairs},
                                        {"seconds_store", s.seconds_store}})
                            .dump(2)
                            .c_str());
  } else {
    std::printf(
        "%s: %lld units, %lld transitions stored; %lld sprites indexed; %.1f s (index %.1f, pairs "
        "%.1f, "
        "store %.1f)\n",
        worker.name().c_str(), static_cast<long long>(s.units),
        static_cast<long long>(s.transitions), static_cast<long long>(s.sprites_indexed), seconds,
        s.seconds_index, s.seconds_pairs, s.seconds_store);
  }
}

}  // namespace

void AddTransitionsCommand(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "transitions",
      "Build or bring up to date a bank's transitions; 'label' and 'train' the classifier");
  cmd->add_option("bank", args->bank,
                  "Sprite bank, file or postgresql://... (build or update its transitions)");
  cmd->add_option("--weights", args->weights,
                  "Classifier weights file (default: the shipped weights)");
  cmd->add_option("--threads", args->threads, "Worker threads")->check(CLI::Range(1, 64));
  cmd->add_flag("--quiet", args->quiet, "No progress lines");
  cmd->add_flag("--include-merged", args->include_merged,
                "Sprites tagged merged (two subjects in one blob) take part too");
  cmd->add_option("--max-per-sprite", args->max_per_sprite,
                  "At most this many transitions out of a sprite, its cheapest (0: all)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--jump-sample", args->jump_sample,
                  "Judge at most this many kept transitions by their visible jump (0: none)")
      ->check(CLI::Range(0, 10000000));
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([cmd, args] {
    if (cmd->get_subcommands().empty()) Build(*args);
  });

  auto* train =
      cmd->add_subcommand("train",
                          "Train both classifiers on labelled pairs; prints cross-validated "
                          "precision/recall");
  train->add_option("labels", args->labels, "Labels CSV: sprite_i,sprite_j,accept")->required();
  train->add_option("--bank", args->bank, "The bank the sprite ids belong to")->required();
  train->add_option("--out", args->out, "Weights file to write")->required();
  train->add_option("--folds", args->folds, "Cross-validation folds")->check(CLI::Range(2, 50));
  train->add_option("--seed", args->seed, "Seed of the fold split and the calibration sample");
  train
      ->add_option("--stage1-recall", args->stage1_recall,
                   "Share of stage-2 accepts stage 1 must pass on the bank (0: keep the label fit)")
      ->check(CLI::Range(0.0, 1.0));
  train
      ->add_option(
          "--positive-rate", args->positive_rate,
          "Share of all sprite pairs that are true transitions, to set stage 2's threshold for "
          "(default: the labels file's '# positive_rate=' line)")
      ->check(CLI::Range(0.0, 1.0));
  train->add_option("--threads", args->threads, "Worker threads")->check(CLI::Range(1, 64));
  train
      ->add_option("--variant", args->variant,
                   "Stage 2 to fit: paper (the default's) or colour_cells (docs/transitions.md)")
      ->check(CLI::IsMember({"paper", "colour_cells"}));
  train->add_flag("--json", args->json, "Print JSON");
  train->callback([args] { Train(*args); });

  auto* label = cmd->add_subcommand("label", "Make labels from a synthetic session's truth");
  label->add_option("--from-truth", args->session, "Synthetic session directory (with truth/)")
      ->required();
  label->add_option("--bank", args->bank, "The bank the session was ingested into")->required();
  label->add_option("--out", args->out, "Labels CSV to write")->required();
  label->add_option("--count", args->count, "About this many labels, half accepts")
      ->check(CLI::Range(10, 1000000));
  label->add_option("--seed", args->seed, "Seed of the pair sampling");
  label->add_flag("--json", args->json, "Print JSON");
  label->callback([args] { Label(*args); });

  auto* worker = cmd->add_subcommand(
      "worker",
      "Share a PostgreSQL bank's transition work with any number of workers on any hosts");
  worker->add_option("--bank", args->bank, "The PostgreSQL bank (postgresql://...)")->required();
  worker->add_option("--weights", args->weights,
                     "Classifier weights file (default: the shipped weights)");
  worker->add_option("--name", args->name,
                     "This worker's name in the work table (default host:pid)");
  worker
      ->add_option("--lease", args->lease_s,
                   "Seconds a claimed unit is this worker's; then any worker's")
      ->check(CLI::Range(1.0, 86400.0));
  worker->add_option("--threads", args->threads, "Threads for the comparison images of new sprites")
      ->check(CLI::Range(1, 64));
  worker->add_flag("--include-merged", args->include_merged,
                   "Sprites tagged merged take part too (every worker of a bank alike)");
  worker
      ->add_option("--max-per-sprite", args->max_per_sprite,
                   "At most this many transitions out of a sprite (every worker alike; 0: all)")
      ->check(CLI::Range(0, 1000000));
  worker->add_flag("--exit-when-idle", args->exit_when_idle,
                   "Exit when no unit is pending or leased");
  worker->add_flag("--json", args->json, "Print JSON");
  worker->callback([args] { Worker(*args); });
}

}  // namespace ss::apps
