#include "station/console_labels.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include "core/bank.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"
#include "core/utc_time.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/sprite_store.h"
#include "pipeline/transitions/stage1_index.h"
#include "station/station.h"
#include "station/station_host.h"

// After every header that may include Eigen (api_part.h says why).
#include <httplib.h>

namespace ss {

namespace fs = std::filesystem;
using api::Json;
using api::ObjectBody;
using api::Reply;
using api::Route;

namespace {

constexpr int kFolds = 5;
// stage-2 evaluations a row at most (a random subset)
constexpr size_t kMaxCandidatesPerRow = 1000;

// NotFoundError naming the sprite when the bank has no such sprite.
void CheckSprite(const Bank& bank, int64_t id) {
  try {
    (void)bank.LoadSprite(id);
  } catch (const InputError&) {
    throw NotFoundError("sprite", "no sprite with id " + std::to_string(id) + " in the bank");
  }
}

bool SameWindow(const ComparisonWindow& a, const ComparisonWindow& b) {
  return a.width_m == b.width_m && a.height_m == b.height_m && a.cells_x == b.cells_x &&
         a.cells_y == b.cells_y && a.align == b.align;
}

std::string Basename(const std::string& path) { return fs::path(path).filename().string(); }

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

// The cross-validated figures of a weights file's training record (stage "stage2" or "stage1").
nlohmann::json CrossValidated(const nlohmann::json& training, const char* stage) {
  const std::string key = std::string(stage) + "_cross_validated";
  if (!training.is_object() || !training.contains(key) || !training[key].is_object())
    return nullptr;
  const nlohmann::json& cv = training[key];
  return {{"precision", cv.value("precision", 0.0)}, {"recall", cv.value("recall", 0.0)}};
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

// ---- the sprites the pair search runs on --------------------------------------------------
// The originals of the bank's complete clips with their comparison images, brought up to date
// with the clips completed since (SpriteStore::Append), so a search after new sprites arrive
// reads only those.

struct ConsoleLabels::Pool {
  struct Meta {
    int64_t clip = 0, frame = 0;
    int width = 0, height = 0;
    double anchor_x = 0, anchor_y = 0;
  };
  std::string bank;
  ComparisonWindow window;
  int64_t last_seq = 0;
  SegmentKeys keys;
  std::unique_ptr<SpriteStore> store;
  std::vector<Meta> meta;  // by store index

  void Update(int threads) {
    const Bank b(bank);
    const std::vector<ClipRecord> clips = b.ListClips(last_seq);
    if (clips.empty()) return;
    std::set<int64_t> clip_ids;
    int64_t max_seq = last_seq;
    for (const ClipRecord& c : clips) {
      clip_ids.insert(c.id);
      max_seq = std::max(max_seq, c.complete_seq);
    }
    std::vector<int64_t> ids;
    std::vector<const SpriteFeatures*> features;
    const std::vector<SpriteFeatures> all = b.LoadFeatures(last_seq);  // by (clip, mirrored, frame)
    for (const SpriteFeatures& f : all) {
      if (f.mirrored || !clip_ids.count(f.clip_id)) continue;
      ids.push_back(f.id);
      features.push_back(&f);
    }
    if (!ids.empty()) {
      const BankSprites loaded = LoadBankSpritesById(b, ids, &keys, store ? store->px_per_m() : 0);
      if (!store) store = std::make_unique<SpriteStore>(window, loaded.px_per_m);
      store->Append(loaded.inputs, threads);
      for (size_t k = 0; k < ids.size(); ++k) {
        const RgbaBillboard& bb = loaded.billboards[k];
        meta.push_back({features[k]->clip_id, features[k]->frame, bb.width, bb.height,
                        bb.anchor_x_px, bb.anchor_y_px});
      }
    }
    last_seq = max_seq;
  }

  // A pair of store indices as the page takes it (docs/console.md).
  nlohmann::json PairJson(int32_t i, int32_t j, double d,
                          const TransitionClassifier& classifier) const {
    const SpriteStore& s = *store;
    auto sprite_json = [&](int32_t k) {
      return nlohmann::json{{"id", s.id(k)},
                            {"prev", s.id(s.prev(k))},
                            {"next", s.id(s.next(k))},
                            {"clip", meta[k].clip},
                            {"frame", meta[k].frame}};
    };
    nlohmann::json billboards = nlohmann::json::object();
    for (int32_t k : {i, j}) {
      for (int32_t m : {s.prev(k), k, s.next(k)}) {
        billboards[std::to_string(s.id(m))] = {{"width", meta[m].width},
                                               {"height", meta[m].height},
                                               {"anchor", {meta[m].anchor_x, meta[m].anchor_y}}};
      }
    }
    const double margin = d - classifier.stage2_threshold();
    return {{"from", s.id(i)},
            {"to", s.id(j)},
            {"d", d},
            {"margin", margin},
            {"p_accept", 1.0 / (1.0 + std::exp(std::clamp(margin, -50.0, 50.0)))},
            {"decision", classifier.Stage2Accepts(d) ? "accept" : "reject"},
            {"a", sprite_json(i)},
            {"b", sprite_json(j)},
            {"frames", {s.id(s.prev(i)), s.id(i), s.id(j), s.id(s.next(j))}},
            {"billboards", billboards}};
  }
};

bool ConsoleLabelsOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(threads >= 1, "threads", "expected at least 1 thread, got " + std::to_string(threads));
  check(candidate_rows >= 1, "candidate_rows",
        "expected at least 1 sprite, got " + std::to_string(candidate_rows));
  check(min_labels >= 2, "min_labels",
        "expected at least 2 (a yes and a no), got " + std::to_string(min_labels));
  return check.ok();
}

ConsoleLabels::ConsoleLabels(api::Context context, ConsoleLabelsOptions options)
    : context_(std::move(context)),
      options_(std::move(options)),
      shared_(std::make_shared<Shared>()) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("labels options", why);
  shared_->retrain = {{"state", "idle"}, {"progress", 0}, {"stage", ""}};
}

ConsoleLabels::~ConsoleLabels() { Stop(); }

void ConsoleLabels::Stop() {
  std::unique_lock lock(shared_->mutex);
  shared_->stop = true;
  // A thread following the station's rebuild wakes and stops at once; one restarting the
  // station stops when the restart is done; one still training is left to finish alone (it
  // touches only `shared_` and files).
  shared_->changed.notify_all();
  shared_->changed.wait(lock, [&] { return !shared_->using_host; });
}

std::string ConsoleLabels::BankPath() const {
  if (!options_.bank.empty()) return options_.bank;
  return context_.station()->bank_path();
}

std::pair<TransitionWeights, std::string> ConsoleLabels::WeightsInUse() const {
  if (context_.host) {
    StationHost::Weights w = context_.host->weights();
    return {std::move(w.weights), std::move(w.path)};
  }
  std::lock_guard lock(shared_->mutex);
  if (shared_->own_weights) return *shared_->own_weights;
  return {DefaultWeights(), ""};
}

nlohmann::json ConsoleLabels::Counts() const {
  const std::map<std::string, int64_t> n = Bank(BankPath()).CountTransitionLabels();
  const int64_t yes = n.at("yes"), no = n.at("no"), skip = n.at("skip");
  return {{"yes", yes},
          {"no", no},
          {"skip", skip},
          {"total", yes + no + skip},
          {"exportable", yes + no}};
}

void ConsoleLabels::UpdatePool(const std::string& bank, const TransitionWeights& weights) {
  if (!pool_ || pool_->bank != bank || !SameWindow(pool_->window, weights.window)) {
    pool_ = std::make_unique<Pool>();
    pool_->bank = bank;
    pool_->window = weights.window;
  }
  pool_->Update(options_.threads);
}

nlohmann::json ConsoleLabels::Pairs(int count) {
  const std::string bank = BankPath();
  const auto [weights, weights_path] = WeightsInUse();
  std::lock_guard lock(pool_mutex_);
  UpdatePool(bank, weights);
  const TransitionClassifier classifier(weights);
  const double threshold = classifier.stage2_threshold();
  nlohmann::json out = {
      {"weights", weights_path.empty() ? "shipped defaults" : Basename(weights_path)},
      {"threshold", threshold},
      {"sprites", 0},
      {"searched", 0},
      {"candidates", 0},
      {"pairs", nlohmann::json::array()}};
  if (!pool_->store || pool_->store->size() == 0) return out;
  const SpriteStore& store = *pool_->store;
  const int32_t n = store.size();

  // Labelled pairs, in either order, are not asked again.
  std::set<std::pair<int64_t, int64_t>> labelled;
  for (const TransitionLabelRecord& l : Bank(bank).LoadTransitionLabels()) {
    labelled.insert({std::min(l.from_sprite, l.to_sprite), std::max(l.from_sprite, l.to_sprite)});
  }
  auto eligible = [&](int32_t i) { return store.prev(i) >= 0 && store.next(i) >= 0; };
  std::vector<int32_t> rows;
  for (int32_t i = 0; i < n; ++i) {
    if (eligible(i)) rows.push_back(i);
  }
  std::mt19937_64 rng(options_.seed);
  std::shuffle(rows.begin(), rows.end(), rng);
  if (rows.size() > static_cast<size_t>(options_.candidate_rows))
    rows.resize(options_.candidate_rows);

  Stage1Index index(classifier);
  index.Build(store.all_cheap());
  struct Candidate {
    int32_t i, j;
    double d;
  };
  std::vector<Candidate> candidates;
  std::set<std::pair<int32_t, int32_t>> seen;
  std::vector<int32_t> found;
  for (int32_t i : rows) {
    found.clear();
    index.Query(store.cheap(i), &found);
    std::shuffle(found.begin(), found.end(), rng);
    size_t evaluated = 0;
    for (int32_t j : found) {
      if (j == i || !eligible(j)) continue;
      // Near frames of one clip are the clip itself, not a transition worth asking about.
      if (store.clip(i) == store.clip(j) &&
          std::abs(pool_->meta[i].frame - pool_->meta[j].frame) <= 2)
        continue;
      const int64_t a = store.id(i), b = store.id(j);
      if (labelled.count({std::min(a, b), std::max(a, b)})) continue;
      if (!seen.insert({std::min(i, j), std::max(i, j)}).second) continue;
      candidates.push_back({i, j, classifier.Distance(store.Features(i, j))});
      if (++evaluated >= kMaxCandidatesPerRow) break;
    }
  }
  out["sprites"] = n;
  out["searched"] = rows.size();
  out["candidates"] = candidates.size();
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](const Candidate& x, const Candidate& y) {
                     return std::abs(x.d - threshold) < std::abs(y.d - threshold);
                   });
  // Each sprite (and its neighbours in the clip) in at most one pair of the answer, so the
  // questions are not the same pair shifted by a frame.
  std::unordered_set<int32_t> used;
  for (const Candidate& c : candidates) {
    if (static_cast<int>(out["pairs"].size()) >= count) break;
    if (used.count(c.i) || used.count(c.j)) continue;
    for (int32_t k : {c.i, c.j}) {
      used.insert(k);
      used.insert(store.prev(k));
      used.insert(store.next(k));
    }
    out["pairs"].push_back(pool_->PairJson(c.i, c.j, c.d, classifier));
  }
  return out;
}

nlohmann::json ConsoleLabels::Pair(int64_t from, int64_t to) {
  if (from == to)
    throw InputError("to", "the same sprite as \"from\" (" + std::to_string(from) + ")");
  const std::string bank = BankPath();
  {
    const Bank reader(bank);
    CheckSprite(reader, from);
    CheckSprite(reader, to);
  }
  const auto [weights, weights_path] = WeightsInUse();
  std::lock_guard lock(pool_mutex_);
  UpdatePool(bank, weights);
  auto index = [&](int64_t id, const char* field) {
    const std::optional<int32_t> i = pool_->store ? pool_->store->IndexOf(id) : std::nullopt;
    if (!i) {
      throw InputError(
          field,
          "sprite " + std::to_string(id) +
              " is a mirrored copy or in a clip still being written: only originals of complete "
              "clips are labelled");
    }
    if (pool_->store->prev(*i) < 0 || pool_->store->next(*i) < 0) {
      throw InputError(
          field, "sprite " + std::to_string(id) +
                     " is the first or last frame of its clip: the transition cannot be played");
    }
    return *i;
  };
  const int32_t i = index(from, "from"), j = index(to, "to");
  const TransitionClassifier classifier(weights);
  return pool_->PairJson(i, j, classifier.Distance(pool_->store->Features(i, j)), classifier);
}

nlohmann::json ConsoleLabels::Store(const nlohmann::json& body) {
  const api::LabelRequest r = api::ParseLabel(body);
  const int64_t from = r.from, to = r.to;
  const std::string& label = r.label;
  const std::string bank = BankPath();
  {
    const Bank reader(bank);
    CheckSprite(reader, from);
    CheckSprite(reader, to);
  }
  TransitionLabelRecord record{from, to, label, UtcNowIso(), "console"};
  BankWriter(bank).SetTransitionLabel(record);
  {
    std::lock_guard lock(shared_->mutex);
    shared_->dirty = true;
  }
  return {{"stored",
           {{"from", from}, {"to", to}, {"label", label}, {"labelled_at", record.labelled_at}}},
          {"labels", Counts()}};
}

nlohmann::json ConsoleLabels::Undo(const nlohmann::json& body) {
  const api::LabelRequest r = api::ParseLabelUndo(body);
  const int64_t from = r.from, to = r.to;
  const std::string bank = BankPath();
  if (!BankWriter(bank).RemoveTransitionLabel(from, to)) {
    throw NotFoundError(
        "label", "no label for the pair " + std::to_string(from) + " -> " + std::to_string(to));
  }
  {
    std::lock_guard lock(shared_->mutex);
    shared_->dirty = true;
  }
  return {{"removed", {{"from", from}, {"to", to}}}, {"labels", Counts()}};
}

std::string ConsoleLabels::ExportCsv() const {
  const std::string bank = BankPath();
  return TransitionLabelsCsv(Bank(bank).LoadTransitionLabels(),
                             CalibratedPositiveRate(WeightsInUse().first));
}

nlohmann::json ConsoleLabels::RetrainState() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->retrain;
}

nlohmann::json ConsoleLabels::StartRetrain() {
  const std::string bank = BankPath();
  {
    std::lock_guard lock(shared_->mutex);
    if (shared_->running) {
      throw ConflictError("retrain", "a retrain is running (" +
                                         shared_->retrain.value("stage", std::string()) + ")");
    }
  }
  if (context_.host) {
    const std::shared_ptr<Station> station = context_.host->current();
    if (station && station->SessionActive()) {
      throw ConflictError("session",
                          "a capture session is running; stop it before retraining (the station "
                          "restarts with the new weights, which would end the session)");
    }
  }
  const nlohmann::json n = Counts();
  const int64_t yes = n["yes"], no = n["no"];
  if (yes + no < options_.min_labels || yes == 0 || no == 0) {
    throw InputError("labels", std::to_string(yes) + " yes and " + std::to_string(no) +
                                   " no: retraining needs at least " +
                                   std::to_string(options_.min_labels) +
                                   " labels, some of each (skips do not count)");
  }
  auto [weights, path] = WeightsInUse();
  {
    std::lock_guard lock(shared_->mutex);
    if (shared_->running || shared_->stop)
      throw ConflictError("retrain", "a retrain is running, or the server stops");
    shared_->running = true;
    shared_->retrain = {{"state", "training"},
                        {"progress", 0.02},
                        {"stage", "exporting the labels"},
                        {"labels", yes + no},
                        {"accepts", yes},
                        {"started", UtcNowIso()},
                        {"previous_weights", path.empty() ? "shipped defaults" : path}};
  }
  std::thread(RunRetrain, shared_, context_, options_, bank, std::move(weights)).detach();
  return RetrainState();
}

void ConsoleLabels::WaitRetrain() {
  std::unique_lock lock(shared_->mutex);
  shared_->changed.wait(lock, [&] { return !shared_->running; });
}

void ConsoleLabels::RunRetrain(std::shared_ptr<Shared> shared, api::Context context,
                               const ConsoleLabelsOptions& options, const std::string& bank,
                               const TransitionWeights& current) {
  SetThisThreadNice(kNiceBackground);  // below capture and the console (core/posix.h)
  auto log = Log("station.labels");
  auto SetRetrain = [&](const std::function<void(nlohmann::json&)>& change) {
    std::lock_guard lock(shared->mutex);
    change(shared->retrain);
  };
  // Enters the part of the work that uses the station host: false when the server stops.
  auto enter_host = [&] {
    std::lock_guard lock(shared->mutex);
    if (shared->stop) return false;
    shared->using_host = true;
    return true;
  };
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

    // 2. Train (both stages, cross-validated; stage 2 set for the positive rate on the bank).
    SetRetrain([&](nlohmann::json& r) {
      r["progress"] = 0.05;
      r["stage"] = "training on " + r["labels"].dump() + " labels (" + std::to_string(kFolds) +
                   "-fold cross-validation), then calibrating on the bank";
      r["labels_file"] = labels_path.string();
      r["positive_rate"] =
          positive_rate > 0 ? nlohmann::json(positive_rate) : nlohmann::json(nullptr);
    });
    // The shipped classifier (BankTrainOptions' defaults: DefaultWeights()' variant and window),
    // whatever the weights in use are.
    BankTrainOptions train;
    train.train.folds = kFolds;
    train.threads = options.threads;
    const BankTrainResult result = TrainOnBank(labels_path.string(), bank, train);
    const double train_s = seconds(t0);

    // 3. The weights file, written whole under a name no other file has.
    const fs::path weights_path = FreshName(dir, "weights-", stamp, ".json");
    const fs::path partial = weights_path.string() + ".partial";
    SaveWeights(result.weights, partial.string());
    fs::rename(partial, weights_path);
    const std::string fingerprint = WeightsFingerprint(result.weights);
    log->info("retrained on {} labels: stage 2 precision {:.3f}, recall {:.3f}; weights {}",
              result.report.samples, result.report.stage2.precision(),
              result.report.stage2.recall(), weights_path.string());
    SetRetrain([&](nlohmann::json& r) {
      r["state"] = "rebuilding";
      r["progress"] = 0.5;
      r["stage"] = "restarting the station with the new weights";
      r["precision"] = result.report.stage2.precision();
      r["recall"] = result.report.stage2.recall();
      r["stage1"] = {{"precision", result.report.stage1.precision()},
                     {"recall", result.report.stage1.recall()}};
      r["folds"] = result.report.folds;
      r["weights"] = weights_path.string();
      r["fingerprint"] = fingerprint;
      r["seconds_train"] = train_s;
      if (result.stage2_calibrated) {
        r["calibration"] = {{"accepts_per_sprite", result.stage2.accepts_per_sprite},
                            {"estimated_precision", result.stage2.precision},
                            {"estimated_recall", result.stage2.recall}};
      }
    });

    // 4. The station uses them; the bank's table is rebuilt with them.
    const auto t_rebuild = std::chrono::steady_clock::now();
    auto stage_progress = [&](const std::string& stage, int64_t done, int64_t total) {
      const double f = total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 0.0;
      SetRetrain([&](nlohmann::json& r) {
        const bool load = stage == "load";
        r["progress"] = load ? 0.55 + 0.15 * f : 0.7 + 0.28 * f;
        r["stage"] = std::string(load ? "rebuilding transitions: reading sprites "
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
      update.threads = options.threads;
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
    SetRetrain([&](nlohmann::json& r) {
      r["state"] = "done";
      r["progress"] = 1.0;
      r["stage"] = "done: " + std::to_string(transitions) + " transitions";
      r["transitions"] = transitions;
      r["seconds_rebuild"] = rebuild_s;
      r["seconds"] = seconds(t0);
      r["finished"] = UtcNowIso();
    });
  } catch (const std::exception& e) {
    log->error("retrain failed: {}", e.what());
    SetRetrain([&](nlohmann::json& r) {
      r["state"] = "failed";
      r["error"] = e.what();
      r["finished"] = UtcNowIso();
    });
  }
  {
    std::lock_guard lock(shared->mutex);
    shared->dirty = true;
    shared->running = false;
  }
  shared->changed.notify_all();
}

void ConsoleLabels::RefreshStatus() const {
  {
    std::lock_guard lock(shared_->mutex);
    std::lock_guard status_lock(status_mutex_);
    if (!shared_->dirty && MonotonicSeconds() - refreshed_at_ < 2.0) return;
    shared_->dirty = false;
    refreshed_at_ = MonotonicSeconds();
  }
  nlohmann::json labels, weights;
  const auto [w, path] = WeightsInUse();
  std::string table;
  try {
    const std::string bank = BankPath();
    const Bank b(bank);
    const std::map<std::string, int64_t> n = b.CountTransitionLabels();
    labels = {{"yes", n.at("yes")},
              {"no", n.at("no")},
              {"skip", n.at("skip")},
              {"total", n.at("yes") + n.at("no") + n.at("skip")},
              {"exportable", n.at("yes") + n.at("no")}};
    table = b.GetMeta(kTransitionWeightsMetaKey).value_or("");
  } catch (const std::exception& e) {
    labels = {{"error", e.what()}};
  }
  std::string fingerprint;
  nlohmann::json training;
  {
    std::lock_guard lock(status_mutex_);
    if (weights_status_path_ == path && weights_status_.contains("fingerprint")) {
      fingerprint = weights_status_["fingerprint"];
    }
  }
  if (fingerprint.empty()) fingerprint = WeightsFingerprint(w);
  try {
    training = nlohmann::json::parse(w.training_json);
  } catch (const std::exception&) {
    training = nullptr;
  }
  weights = {{"name", path.empty() ? "shipped defaults" : Basename(path)},
             {"path", path},
             {"fingerprint", fingerprint},
             {"table", table},
             {"cross_validated", CrossValidated(training, "stage2")},
             {"positive_rate",
              CalibratedPositiveRate(w) > 0 ? nlohmann::json(CalibratedPositiveRate(w)) : nullptr}};
  std::lock_guard lock(status_mutex_);
  labels_status_ = std::move(labels);
  weights_status_ = std::move(weights);
  weights_status_path_ = path;
}

void ConsoleLabels::AddStatus(nlohmann::json& status) const {
  try {
    RefreshStatus();
  } catch (const std::exception& e) {
    Log("station.labels")->warn("labels status: {}", e.what());
  }
  nlohmann::json retrain = RetrainState();
  std::lock_guard lock(status_mutex_);
  status["labels"] = labels_status_;
  nlohmann::json& t = status["transitions"];
  if (!t.is_object()) t = nlohmann::json::object();
  t["weights"] = weights_status_;
  t["retrain"] = std::move(retrain);
}

std::vector<Route> ConsoleLabels::Routes() {
  return {
      {"GET", "/api/labels", "GET /api/labels (counts)",
       Json([this](const httplib::Request&) { return Counts(); })},
      {"GET", "/api/labels/pairs", "GET /api/labels/pairs?count=N (least sure first)",
       Json([this](const httplib::Request& req) {
         return Pairs(static_cast<int>(api::IntParam(req, "count", 10, 1, 100)));
       })},
      {"GET", "/api/labels/pair",
       "GET /api/labels/pair?from=ID&to=ID (one pair, as pairs gives it)",
       Json([this](const httplib::Request& req) {
         for (const char* field : {"from", "to"}) {
           if (!req.has_param(field)) throw InputError(field, "missing (?from=ID&to=ID)");
         }
         return Pair(api::IntParam(req, "from", 0, 1, INT64_MAX),
                     api::IntParam(req, "to", 0, 1, INT64_MAX));
       })},
      {"POST", "/api/labels",
       "POST /api/labels {\"from\": ID, \"to\": ID, \"label\": \"yes\" | \"no\" | \"skip\"}",
       Json([this](const httplib::Request& req) {
         return Store(ObjectBody(req, api::kLabelFields));
       })},
      {"POST", "/api/labels/undo", "POST /api/labels/undo {\"from\": ID, \"to\": ID}",
       Json([this](const httplib::Request& req) {
         return Undo(ObjectBody(req, api::kLabelUndoFields));
       })},
      {"GET", R"(/api/labels/export\.csv)",
       "GET /api/labels/export.csv (transitions train's labels CSV)",
       [this](const httplib::Request&, httplib::Response& res) {
         res.set_header("Content-Disposition", "attachment; filename=\"labels.csv\"");
         res.set_content(ExportCsv(), "text/csv; charset=utf-8");
       }},
      {"POST", "/api/labels/retrain",
       "POST /api/labels/retrain (202; progress in the status' transitions.retrain)",
       [this](const httplib::Request& req, httplib::Response& res) {
         ObjectBody(req, {});
         Reply(res, 202, {{"retrain", StartRetrain()}});
       }},
  };
}

}  // namespace ss
