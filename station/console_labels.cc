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

// The cross-validated figures of a weights file's training record (stage "stage2" or "stage1").
nlohmann::json CrossValidated(const nlohmann::json& training, const char* stage) {
  const std::string key = std::string(stage) + "_cross_validated";
  if (!training.is_object() || !training.contains(key) || !training[key].is_object())
    return nullptr;
  const nlohmann::json& cv = training[key];
  return {{"precision", cv.value("precision", 0.0)}, {"recall", cv.value("recall", 0.0)}};
}

}  // namespace

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
  check.Within(threads, AtLeast(1), "threads", "at least 1 thread");
  check.Within(candidate_rows, AtLeast(1), "candidate_rows", "at least 1 sprite");
  check.Within(min_labels, AtLeast(2), "min_labels", "at least 2 (a yes and a no)");
  return check.ok();
}

ConsoleLabels::ConsoleLabels(api::Context context, ConsoleLabelsOptions options)
    : context_(std::move(context)), options_(std::move(options)) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("labels options", why);
  // An ended retrain changed the weights (or tried to): the status reads them again.
  retrain_ = std::make_unique<RetrainJob>(
      context_, options_.threads,
      [dirty = dirty_, changed = context_.status_changed](const ss::RetrainState& state) {
        if (state.phase == RetrainPhase::kDone || state.phase == RetrainPhase::kFailed ||
            state.phase == RetrainPhase::kCancelled)
          *dirty = true;
        changed();
      });
}

ConsoleLabels::~ConsoleLabels() { Stop(); }

void ConsoleLabels::Stop() { retrain_->Stop(); }

std::string ConsoleLabels::BankPath() const {
  if (!options_.bank.empty()) return options_.bank;
  return context_.station()->bank_path();
}

std::pair<TransitionWeights, std::string> ConsoleLabels::WeightsInUse() const {
  if (context_.host) {
    StationHost::Weights w = context_.host->weights();
    return {std::move(w.weights), std::move(w.path)};
  }
  if (auto own = retrain_->OwnWeights()) return *std::move(own);
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
  *dirty_ = true;
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
  *dirty_ = true;
  return {{"removed", {{"from", from}, {"to", to}}}, {"labels", Counts()}};
}

std::string ConsoleLabels::ExportCsv() const {
  const std::string bank = BankPath();
  return TransitionLabelsCsv(Bank(bank).LoadTransitionLabels(),
                             CalibratedPositiveRate(WeightsInUse().first));
}

nlohmann::json ConsoleLabels::RetrainState() const { return retrain_->State().ToJson(); }

nlohmann::json ConsoleLabels::StartRetrain() {
  const std::string bank = BankPath();
  if (retrain_->Running())
    throw ConflictError("retrain", "a retrain is running (" + retrain_->State().stage + ")");
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
  return retrain_->Start({bank, std::move(weights), path, yes + no, yes}).ToJson();
}

nlohmann::json ConsoleLabels::CancelRetrain() { return retrain_->Cancel().ToJson(); }

void ConsoleLabels::WaitRetrain() { retrain_->Wait(); }

void ConsoleLabels::RefreshStatus() const {
  {
    std::lock_guard status_lock(status_mutex_);
    const bool dirty = dirty_->exchange(false);
    if (!dirty && MonotonicSeconds() - refreshed_at_ < 2.0) return;
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
      {"POST", "/api/labels/retrain/cancel",
       "POST /api/labels/retrain/cancel (ends the retrain at its next stage, before the station "
       "uses the new weights)",
       [this](const httplib::Request& req, httplib::Response& res) {
         ObjectBody(req, {});
         Reply(res, 200, {{"retrain", CancelRetrain()}});
       }},
  };
}

}  // namespace ss
