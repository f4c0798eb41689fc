// The labelling page's backend (station/console_labels.h) on a bank of synthetic
// sprites whose truth is known: labels stored, counted and exported as the CSV that
// `transitions train` reads, the pairs asked least sure first, bad input named, and a
// retrain that writes new weights and rebuilds the bank's transitions with them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "core/error_kinds.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/bank_training.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/truth_labels.h"
#include "station/console_labels.h"
#include "tests/pipeline/transitions_bank_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using ss::testing::ScratchDir;

// A bank of synthetic clips (originals and mirrors) with each original's truth.
struct SyntheticBank {
  std::string path;
  std::vector<int64_t> originals;  // bank ids
  std::vector<SpriteTruth> truth;  // of originals[k]
};

SyntheticBank MakeBank(const std::string& path, int frames) {
  SyntheticSpriteOptions o;
  o.frames = frames;
  o.min_clip_frames = 10;
  o.max_clip_frames = 60;
  o.seed = 3;
  const std::vector<SyntheticSprite> sprites = MakeSyntheticSprites(o);
  const size_t half = sprites.size() / 2;  // originals, then their mirrors in the same order
  SyntheticBank out;
  out.path = path;
  BankWriter w(path);
  const int64_t session = w.AddSession({0, "synthetic@labels", "synthetic", "", "test"});
  const int64_t camera = w.AddCamera(session, {0, 0, "cam0", "", 640, 480});
  int64_t frame = 100;
  for (size_t begin = 0; begin < half;) {
    size_t end = begin;
    while (end < half && sprites[end].clip == sprites[begin].clip) ++end;
    ClipRecord clip;
    clip.camera_id = camera;
    clip.track_id = sprites[begin].clip;
    clip.first_frame = frame;
    clip.last_frame = frame + static_cast<int64_t>(end - begin) - 1;
    clip.complete = true;
    std::vector<SpriteRecord> records;
    for (size_t k = begin; k < end; ++k) {
      const int64_t f = frame + static_cast<int64_t>(k - begin);
      records.push_back(testing::Record(sprites[k], f, false));
      records.push_back(testing::Record(sprites[half + k], f, true));
    }
    const AppendResult r = w.AppendClipBatch(clip, records);
    for (size_t k = begin; k < end; ++k) {
      out.originals.push_back(r.sprite_ids[2 * (k - begin)]);
      out.truth.push_back(sprites[k].truth);
    }
    frame += static_cast<int64_t>(end - begin) + 10;
    begin = end;
  }
  return out;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

ConsoleLabels Labels(const SyntheticBank& bank, api::Context context = {}) {
  ConsoleLabelsOptions options;
  options.bank = bank.path;
  options.candidate_rows = 100000;  // every sprite: the search is exhaustive
  return ConsoleLabels(std::move(context), options);
}

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ConsoleLabels, StoresCountsExportsAndNamesBadInput) {
  ScratchDir dir;
  const SyntheticBank bank = MakeBank(dir / "bank.db", 200);
  ConsoleLabels labels = Labels(bank);
  const int64_t a = bank.originals[3], b = bank.originals[40], c = bank.originals[90];
  labels.Store({{"from", a}, {"to", b}, {"label", "yes"}});
  labels.Store({{"from", b}, {"to", c}, {"label", "no"}});
  const nlohmann::json last = labels.Store({{"from", a}, {"to", c}, {"label", "skip"}});
  EXPECT_EQ(last["labels"],
            (nlohmann::json{{"yes", 1}, {"no", 1}, {"skip", 1}, {"total", 3}, {"exportable", 2}}));
  // Stored in the bank, as it was said.
  const auto rows = Bank(bank.path).LoadTransitionLabels();
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].source, "console");
  // The CSV: skips left out; the shipped weights were calibrated for a positive rate, which
  // the export carries so that `transitions train` on it does what the page's retrain does.
  const double rate = CalibratedPositiveRate(DefaultWeights());
  ASSERT_GT(rate, 0);
  const std::string csv = labels.ExportCsv();
  char rate_line[64];
  std::snprintf(rate_line, sizeof(rate_line), "# positive_rate=%.9g\n", rate);
  EXPECT_EQ(csv, std::string(rate_line) + "sprite_i,sprite_j,accept\n" + std::to_string(a) + "," +
                     std::to_string(b) + ",1\n" + std::to_string(b) + "," + std::to_string(c) +
                     ",0\n");

  // Bad input names what is wrong.
  std::string e = MessageOf([&] { labels.Store({{"from", a}, {"to", 999999}, {"label", "yes"}}); });
  EXPECT_EQ(e.rfind("sprite:", 0), 0u) << e;
  EXPECT_NE(e.find("999999"), std::string::npos) << e;
  EXPECT_THROW(labels.Store({{"from", a}, {"to", 999999}, {"label", "yes"}}), NotFoundError);
  e = MessageOf([&] { labels.Store({{"from", a}, {"to", b}, {"label", "maybe"}}); });
  EXPECT_EQ(e.rfind("label:", 0), 0u) << e;
  EXPECT_NE(e.find("maybe"), std::string::npos) << e;
  EXPECT_EQ(MessageOf([&] { labels.Store({{"from", a}, {"to", b}}); }).rfind("label:", 0), 0u);
  EXPECT_EQ(MessageOf([&] {
              labels.Store({{"from", a}, {"to", b}, {"label", 1}});
            }).rfind("label:", 0),
            0u);
  EXPECT_EQ(MessageOf([&] {
              labels.Store({{"from", "x"}, {"to", b}, {"label", "yes"}});
            }).rfind("from:", 0),
            0u);
  EXPECT_EQ(MessageOf([&] { labels.Store({{"from", a}, {"label", "yes"}}); }).rfind("to:", 0), 0u);
  EXPECT_EQ(MessageOf([&] {
              labels.Store({{"from", a}, {"to", a}, {"label", "yes"}});
            }).rfind("to:", 0),
            0u);
  EXPECT_EQ(Bank(bank.path).LoadTransitionLabels().size(), 3u) << "nothing stored by bad input";
  // Undo removes one; a second undo of it is a 404.
  EXPECT_EQ(labels.Undo({{"from", a}, {"to", c}})["labels"]["skip"], 0);
  EXPECT_THROW(labels.Undo({{"from", a}, {"to", c}}), NotFoundError);
  // A retrain needs labels of both kinds, enough of them.
  e = MessageOf([&] { labels.StartRetrain(); });
  EXPECT_EQ(e.rfind("labels:", 0), 0u) << e;
  EXPECT_EQ(labels.RetrainState()["state"], "idle");
}

TEST(ConsoleLabels, AsksTheLeastSurePairsFirstAndNeverAgain) {
  ScratchDir dir;
  const SyntheticBank bank = MakeBank(dir / "bank.db", 300);
  ConsoleLabels labels = Labels(bank);
  const nlohmann::json first = labels.Pairs(8);
  const auto& pairs = first["pairs"];
  ASSERT_EQ(pairs.size(), 8u) << first.dump(1);
  const double t2 = first["threshold"];
  EXPECT_EQ(t2, TransitionClassifier(DefaultWeights()).stage2_threshold());
  // Least sure first: |D - T2| grows down the list, and p_accept is the logistic of the margin.
  for (size_t k = 0; k < pairs.size(); ++k) {
    const double margin = pairs[k]["margin"];
    EXPECT_NEAR(margin, pairs[k]["d"].get<double>() - t2, 1e-9);
    EXPECT_NEAR(pairs[k]["p_accept"].get<double>(), 1 / (1 + std::exp(margin)), 1e-9);
    EXPECT_EQ(pairs[k]["decision"], margin <= 0 ? "accept" : "reject");
    if (k > 0) {
      EXPECT_GE(std::abs(margin), std::abs(pairs[k - 1]["margin"].get<double>()));
    }
  }
  // The first pair asked is the one nearest the threshold among every pair of the bank's
  // originals that stage 1 passes (the search is exhaustive here).
  {
    const TransitionClassifier classifier(DefaultWeights());
    SegmentKeys keys;
    const Bank b(bank.path);
    std::vector<int64_t> ids = bank.originals;
    const BankSprites loaded = LoadBankSpritesById(b, ids, &keys);
    SpriteStore store(DefaultWeights().window, loaded.px_per_m);
    store.Append(loaded.inputs, 2);
    double best = 1e9;
    for (int32_t i = 0; i < store.size(); ++i) {
      if (store.prev(i) < 0 || store.next(i) < 0) continue;
      for (int32_t j = 0; j < store.size(); ++j) {
        if (j == i || store.prev(j) < 0 || store.next(j) < 0) continue;
        if (store.clip(i) == store.clip(j) && std::abs(i - j) <= 2) continue;
        if (!classifier.Stage1Accepts(store.cheap(i), store.cheap(j))) continue;
        best = std::min(best, std::abs(classifier.Distance(store.Features(i, j)) -
                                       classifier.stage2_threshold()));
      }
    }
    EXPECT_NEAR(std::abs(pairs[0]["margin"].get<double>()), best, 1e-9);
  }
  // The frames to play: i-1, i, then j, j+1, each a sprite of the bank with its billboard's size.
  std::set<int64_t> sprites;
  for (const auto& p : pairs) {
    const auto& f = p["frames"];
    EXPECT_EQ(f, (nlohmann::json{p["a"]["prev"], p["from"], p["to"], p["b"]["next"]}));
    for (const char* side : {"a", "b"}) {
      const SpriteRecord s = Bank(bank.path).LoadSprite(p[side]["id"]);
      EXPECT_EQ(Bank(bank.path).LoadSprite(p[side]["prev"]).frame, s.frame - 1);
      EXPECT_EQ(Bank(bank.path).LoadSprite(p[side]["next"]).frame, s.frame + 1);
      EXPECT_EQ(p["billboards"][std::to_string(s.id)]["width"], s.billboard_width_px);
      EXPECT_FALSE(s.mirrored);
      EXPECT_TRUE(sprites.insert(s.id).second) << "each sprite in one pair of an answer";
    }
  }
  // One pair asked by its ids (a link) is the pair as the list gives it.
  EXPECT_EQ(labels.Pair(pairs[1]["from"], pairs[1]["to"]), pairs[1]);
  std::string e = MessageOf([&] { labels.Pair(pairs[1]["from"], 999999); });
  EXPECT_EQ(e, "sprite: no sprite with id 999999 in the bank");
  e = MessageOf([&] { labels.Pair(bank.originals[0], pairs[1]["to"]); });  // a clip's first frame
  EXPECT_EQ(
      e.rfind("from: sprite " + std::to_string(bank.originals[0]) + " is the first or last frame",
              0),
      0u)
      << e;
  // A labelled pair (in either order) is not asked again.
  labels.Store({{"from", pairs[0]["to"]}, {"to", pairs[0]["from"]}, {"label", "skip"}});
  const nlohmann::json again = labels.Pairs(8);
  for (const auto& p : again["pairs"]) {
    EXPECT_FALSE(p["from"] == pairs[0]["from"] && p["to"] == pairs[0]["to"]);
    EXPECT_FALSE(p["from"] == pairs[0]["to"] && p["to"] == pairs[0]["from"]);
  }
  EXPECT_GE(std::abs(again["pairs"][0]["margin"].get<double>()),
            std::abs(pairs[0]["margin"].get<double>()));
}

TEST(ConsoleLabels, TheExportTrainsAndARetrainRebuildsTheTable) {
  ScratchDir dir;
  const SyntheticBank bank = MakeBank(dir / "bank.db", 600);
  // What the console's event stream would send: the retrain's state read each time it is told.
  std::mutex told_mutex;
  std::condition_variable told_more;
  std::vector<nlohmann::json> told;
  const ConsoleLabels* reader = nullptr;
  api::Context context;
  context.status_changed = [&] {
    {
      std::lock_guard lock(told_mutex);
      if (reader) told.push_back(reader->RetrainState());
    }
    told_more.notify_all();
  };
  ConsoleLabels labels = Labels(bank, context);
  {
    std::lock_guard lock(told_mutex);
    reader = &labels;
  }
  // A told end is whole: a viewer told "done" or "cancelled" is offered no cancel, and can
  // start the next retrain (the console's test clicks it at once). The end `state` is told just
  // after WaitRetrain returns: waited for, up to 30 s. How many ends were told.
  const auto told_ends = [&](const std::string& state) {
    std::unique_lock lock(told_mutex);
    told_more.wait_for(lock, std::chrono::seconds(30), [&] {
      return std::any_of(told.begin(), told.end(),
                         [&](const nlohmann::json& r) { return r["state"] == state; });
    });
    int ends = 0;
    for (const nlohmann::json& r : told) {
      if (r["state"] == "training" || r["state"] == "rebuilding") continue;
      ++ends;
      EXPECT_EQ(r["cancellable"], false) << r.dump(1);
    }
    told.clear();
    return ends;
  };
  // A person who judges as the truth does: labels of the bank's originals, half accepts.
  const std::vector<Label> truth =
      LabelsFromTruth(bank.originals, bank.truth, 240, TruthLabelOptions{}, 7);
  ASSERT_GT(truth.size(), 200u);
  for (const Label& l : truth) {
    labels.Store({{"from", l.sprite_i}, {"to", l.sprite_j}, {"label", l.accept ? "yes" : "no"}});
  }
  // The export is the labels CSV `transitions train` reads, with every label as it was given.
  const std::string csv_path = dir / "labels.csv";
  std::ofstream(csv_path) << labels.ExportCsv();
  double rate = -1;
  const std::vector<Label> read = ReadLabelsCsv(csv_path, &rate);
  ASSERT_EQ(read.size(), truth.size());
  std::map<std::pair<int64_t, int64_t>, bool> want;
  for (const Label& l : truth) want[{l.sprite_i, l.sprite_j}] = l.accept;
  for (const Label& l : read) EXPECT_EQ(want.at({l.sprite_i, l.sprite_j}), l.accept);
  EXPECT_NEAR(rate, CalibratedPositiveRate(DefaultWeights()), 1e-8 * rate);
  BankTrainOptions train;
  train.threads = 2;
  const BankTrainResult trained = TrainOnBank(csv_path, bank.path, train);
  EXPECT_EQ(trained.report.samples, static_cast<int64_t>(truth.size()));
  EXPECT_GT(trained.report.stage2.precision(), 0.7);
  EXPECT_GT(trained.report.stage2.recall(), 0.7);

  // The page's retrain: the same training in the background, weights beside the bank, the
  // table rebuilt with them (no station here: the part rebuilds it itself).
  const nlohmann::json started = labels.StartRetrain();
  EXPECT_EQ(started["state"], "training");
  EXPECT_EQ(started["cancellable"], true) << "a cancel is taken from the start";
  EXPECT_THROW(labels.StartRetrain(), ConflictError);
  labels.WaitRetrain();
  const nlohmann::json r = labels.RetrainState();
  ASSERT_EQ(r["state"], "done") << r.dump(1);
  EXPECT_GE(told_ends("done"), 1) << "the end is told";
  EXPECT_EQ(r["progress"], 1.0);
  EXPECT_EQ(r["cancellable"], false) << "not once it is over";
  EXPECT_NEAR(r["precision"].get<double>(), trained.report.stage2.precision(), 1e-12)
      << "the same folds";
  EXPECT_NEAR(r["recall"].get<double>(), trained.report.stage2.recall(), 1e-12);
  const std::string weights_path = r["weights"];
  EXPECT_EQ(fs::path(weights_path).parent_path(), fs::path(dir / "weights"));
  const TransitionWeights written = LoadWeights(weights_path);
  // It fits the shipped classifier, as `transitions train` does.
  EXPECT_EQ(written.stage2_variant, DefaultWeights().stage2_variant);
  EXPECT_EQ(written.stage2_variant, trained.weights.stage2_variant);
  EXPECT_EQ(r["fingerprint"], WeightsFingerprint(written));
  EXPECT_EQ(Bank(bank.path).GetMeta(kTransitionWeightsMetaKey), WeightsFingerprint(written));
  EXPECT_EQ(r["transitions"], Bank(bank.path).Counts().transitions);
  EXPECT_GT(r["transitions"].get<int64_t>(), 0);
  // The labels file it trained on sits beside the weights and reads back the same.
  EXPECT_EQ(ReadFile(r["labels_file"]), labels.ExportCsv());
  // The status names the new weights; a second retrain never overwrites the first file.
  nlohmann::json status = {{"transitions", {{"enabled", false}}}};
  labels.AddStatus(status);
  EXPECT_EQ(status["transitions"]["enabled"], false) << "the station's members stay";
  EXPECT_EQ(status["transitions"]["weights"]["path"], weights_path);
  EXPECT_EQ(status["transitions"]["weights"]["table"], WeightsFingerprint(written));
  EXPECT_EQ(status["transitions"]["retrain"]["state"], "done");
  EXPECT_EQ(status["labels"]["exportable"], static_cast<int64_t>(truth.size()));
  labels.StartRetrain();
  labels.WaitRetrain();
  EXPECT_EQ(labels.RetrainState()["state"], "done");
  const std::string second = labels.RetrainState()["weights"];
  EXPECT_NE(second, weights_path);
  EXPECT_TRUE(fs::exists(weights_path));

  // A cancel ends a retrain at its next stage, before the bank's table or weights change: the
  // training takes seconds, the cancel lands before it ends.
  EXPECT_THROW(labels.CancelRetrain(), ConflictError) << "none runs";
  const std::string table = Bank(bank.path).GetMeta(kTransitionWeightsMetaKey).value_or("");
  const auto files = [&] {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir / "weights"))
      names.insert(e.path().filename().string());
    return names;
  };
  const std::set<std::string> before = files();
  labels.StartRetrain();
  EXPECT_EQ(labels.CancelRetrain()["state"], "training");
  labels.WaitRetrain();
  const nlohmann::json cancelled = labels.RetrainState();
  EXPECT_EQ(cancelled["state"], "cancelled") << cancelled.dump(1);
  EXPECT_EQ(cancelled["cancellable"], false);
  EXPECT_GE(told_ends("cancelled"), 1) << "the cancel is told";
  EXPECT_FALSE(cancelled.contains("weights")) << cancelled.dump(1);
  EXPECT_TRUE(cancelled.contains("finished"));
  EXPECT_EQ(Bank(bank.path).GetMeta(kTransitionWeightsMetaKey).value_or(""), table);
  std::set<std::string> added;
  for (const std::string& f : files())
    if (!before.count(f)) added.insert(f);
  ASSERT_EQ(added.size(), 1u) << "only its labels file";
  EXPECT_EQ(added.begin()->rfind("labels-", 0), 0u) << *added.begin();
  // The weights in use are still the second retrain's.
  labels.AddStatus(status);
  EXPECT_EQ(status["transitions"]["weights"]["path"], second);
  EXPECT_EQ(status["transitions"]["retrain"]["state"], "cancelled");
}

}  // namespace
}  // namespace ss
