#include "pipeline/transitions/bank_training.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "core/bank.h"
#include "core/csv_table.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/transitions/bank_sprites.h"

namespace ss {

namespace fs = std::filesystem;

bool BankTrainOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(train.IsValid(&part), "train.", part);
  check.Nested(window.IsValid(&part), "window.", part);
  check(std::isfinite(stage1_recall) && stage1_recall >= 0 && stage1_recall <= 1, "stage1_recall",
        "expected a share from 0 to 1, got " + OptionProblems::Num(stage1_recall));
  // Negative (any) reads the labels file's rate.
  check(!std::isnan(positive_rate) && positive_rate <= 1, "positive_rate",
        "expected a share from 0 to 1 (< 0: the labels file's), got " +
            OptionProblems::Num(positive_rate));
  check.Within(calibration_rows, AtLeast(1), "calibration_rows", "at least 1 sprite");
  check.Within(threads, AtLeast(1), "threads", "at least 1 thread");
  check(variant == Stage2Variant::kPaper || variant == Stage2Variant::kColourCells, "variant",
        "only \"paper\" and \"colour_cells\" are trained (linf and colour_blob files are "
        "written by hand)");
  return check.ok();
}

BankTrainResult TrainOnBank(const std::string& labels_path, const std::string& bank_path,
                            const BankTrainOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("training options", why);
  double file_rate = -1;
  const std::vector<Label> labels = ReadLabelsCsv(labels_path, &file_rate);
  const double positive_rate = options.positive_rate >= 0 ? options.positive_rate : file_rate;
  const Bank bank(bank_path);
  // The labelled sprites, each once.
  std::vector<int64_t> ids;
  std::set<int64_t> seen;
  for (const Label& l : labels) {
    for (int64_t id : {l.sprite_i, l.sprite_j}) {
      if (seen.insert(id).second) ids.push_back(id);
    }
  }
  SegmentKeys keys;
  BankSprites labelled;
  try {
    labelled = LoadBankSpritesById(bank, ids, &keys);
  } catch (const InputError& e) {
    throw InputError(labels_path, std::string("names a sprite the bank cannot give: ") + e.what());
  }
  SpriteStore store(options.window, labelled.px_per_m > 0 ? labelled.px_per_m : 1.0);
  store.Append(labelled.inputs, options.threads);
  std::vector<PairFeatures> x;
  std::vector<uint8_t> y;
  for (const Label& l : labels) {
    x.push_back(store.Features(*store.IndexOf(l.sprite_i), *store.IndexOf(l.sprite_j)));
    y.push_back(l.accept ? 1 : 0);
  }
  BankTrainResult result;
  try {
    result.weights = TrainWeights(x, y, options.window, options.train, &result.report);
  } catch (const InputError& e) {
    throw InputError(labels_path, e.what());
  }
  result.stage1_bias_from_labels = result.weights.stage1_bias;
  nlohmann::json training = nlohmann::json::parse(result.weights.training_json);
  training["source"] = "spritestation transitions train " + labels_path + " --bank " + bank_path;
  const bool calibrate_stage2 = positive_rate > 0;
  const bool cells = options.variant == Stage2Variant::kColourCells;
  // The colour_cells measurements of the labelled pairs.
  std::vector<ColourCellsMeasure> cells_positive, cells_negative;
  if (cells) {
    for (const Label& l : labels) {
      (l.accept ? cells_positive : cells_negative)
          .push_back(
              MeasureColourCells(store, *store.IndexOf(l.sprite_i), *store.IndexOf(l.sprite_j)));
    }
  }
  ColourCellsFitOptions cells_options;
  cells_options.rows = options.calibration_rows;
  cells_options.seed = options.train.seed;
  cells_options.threads = options.threads;
  auto record_cells = [&](const char* population) {
    const ColourCellsFit& f = result.cells;
    training["colour_cells_fit"] = {{"population", population},
                                    {"positive_rate", f.positive_rate},
                                    {"max_velocity_mps", f.max_velocity_mps},
                                    {"max_alpha_cells", f.max_alpha_cells},
                                    {"max_colour_cells", f.max_colour_cells},
                                    {"estimated_precision", f.precision},
                                    {"estimated_recall", f.recall},
                                    {"estimated_f1", f.f1},
                                    {"accepts_per_sprite", f.accepts_per_sprite},
                                    {"sampled_pairs", f.sampled_pairs},
                                    {"accept_labels", f.positives}};
  };
  if (calibrate_stage2 || options.stage1_recall > 0) {
    // Judge every pair of some sprites with stage 2 (brute force): the population.
    SegmentKeys all_keys;
    const BankSprites everything = LoadBankSprites(bank, &all_keys);
    if (!everything.inputs.empty()) {
      SpriteStore all(options.window, everything.px_per_m);
      all.Append(everything.inputs, options.threads);
      if (calibrate_stage2) {
        std::vector<double> positive_distances;
        const TransitionClassifier label_fit(result.weights);
        for (size_t k = 0; k < labels.size(); ++k) {
          if (y[k]) positive_distances.push_back(label_fit.Distance(x[k]));
        }
        const PopulationSample sample = SamplePopulation(all, label_fit, options.calibration_rows,
                                                         options.train.seed, options.threads);
        result.stage2 = CalibrateStage2(positive_distances, sample, positive_rate, &result.weights);
        result.stage2_calibrated = true;
        training["stage2_calibration"] = {{"positive_rate", positive_rate},
                                          {"sampled_rows", sample.rows.size()},
                                          {"threshold", result.stage2.threshold},
                                          {"accepts_per_sprite", result.stage2.accepts_per_sprite},
                                          {"estimated_precision", result.stage2.precision},
                                          {"estimated_recall", result.stage2.recall},
                                          {"bias", result.weights.stage2_bias}};
        if (cells) {
          // Stage 1 becomes the velocity ball of the variant (FitColourCells sets it).
          try {
            result.cells =
                FitColourCells(all, cells_positive, positive_rate, cells_options, &result.weights);
          } catch (const InputError& e) {
            throw InputError(labels_path, e.what());
          }
          result.colour_cells = true;
          record_cells("every pair of sampled sprites of the bank");
        } else if (options.stage1_recall > 0) {
          result.stage1 = FitStage1Filter(all, sample, options.stage1_recall, options.train.seed,
                                          &result.weights);
          result.calibration_accepts = result.stage1.stage2_accepts;
        }
      } else {
        const auto accepted =
            SampleStage2Accepted(all, TransitionClassifier(result.weights),
                                 options.calibration_rows, options.train.seed, options.threads);
        CalibrateStage1(accepted, options.stage1_recall, &result.weights);
        result.calibration_accepts = static_cast<int64_t>(accepted.size());
      }
    }
    if (options.stage1_recall > 0 && !cells) {
      training["stage1_calibration"] = {
          {"target_recall_of_stage2", options.stage1_recall},
          {"refitted_as_filter", result.stage2_calibrated},
          {"stage2_accepted_pairs_sampled", result.calibration_accepts},
          {"sampled_rows", options.calibration_rows},
          {"candidates_per_sprite", result.stage1.candidates_per_sprite},
          {"bias_from_labels", result.stage1_bias_from_labels},
          {"bias", result.weights.stage1_bias}};
    }
  }
  if (cells && !result.colour_cells) {
    try {
      result.cells =
          FitColourCellsOnLabels(cells_positive, cells_negative, cells_options, &result.weights);
    } catch (const InputError& e) {
      throw InputError(labels_path, e.what());
    }
    result.colour_cells = true;
    record_cells("the labelled pairs (no positive rate: a 50/50 world)");
  }
  result.weights.training_json = training.dump();
  return result;
}

namespace {

struct TruthRow {
  double x = 0, y = 0;
  SpriteTruth truth;
};

// truth/subjects.csv by timestamp.
std::unordered_map<int64_t, std::vector<TruthRow>> ReadSubjects(const std::string& path) {
  CsvTable csv(path, "cannot open the session truth (is this a synthetic session?)");
  const size_t c_ts = csv.Column("timestamp_ns"), c_x = csv.Column("x"), c_y = csv.Column("y"),
               c_heading = csv.Column("heading_rad"), c_phase = csv.Column("gait_phase"),
               c_pose = csv.Column("pose");
  std::unordered_map<int64_t, std::vector<TruthRow>> rows;
  while (csv.Next()) {
    try {
      TruthRow r;
      r.x = std::stod(csv[c_x]);
      r.y = std::stod(csv[c_y]);
      r.truth.heading_rad = std::stod(csv[c_heading]);
      r.truth.gait_phase = std::stod(csv[c_phase]);
      r.truth.pose = csv[c_pose];
      rows[std::stoll(csv[c_ts])].push_back(r);
    } catch (const std::logic_error&) {
      throw InputError(csv.Where(), "a number does not parse: '" + csv.line() + "'");
    }
  }
  return rows;
}

std::string Normal(const std::string& p) {
  std::error_code ec;
  const fs::path c = fs::weakly_canonical(fs::absolute(p), ec);
  return (ec ? fs::absolute(p).lexically_normal() : c).string();
}

}  // namespace

TruthLabelSummary LabelBankFromTruth(const std::string& session_dir, const std::string& bank_path,
                                     size_t count, const TruthLabelOptions& options,
                                     uint64_t seed) {
  const auto subjects = ReadSubjects((fs::path(session_dir) / "truth" / "subjects.csv").string());
  const Bank bank(bank_path);
  // The bank's record of this session: by its source directory, else the only session.
  const std::vector<SessionRecord> sessions = bank.ListSessions();
  int64_t session_id = 0;
  for (const SessionRecord& s : sessions) {
    if (Normal(s.source) == Normal(session_dir)) session_id = s.id;
  }
  if (session_id == 0 && sessions.size() == 1) {
    session_id = sessions[0].id;
    Log("pipeline.transitions")
        ->warn("{}: its one session came from '{}', not '{}'; matching by timestamps", bank_path,
               sessions[0].source, session_dir);
  }
  if (session_id == 0) {
    throw InputError(bank_path, "holds no session ingested from '" + session_dir + "' (" +
                                    std::to_string(sessions.size()) + " sessions)");
  }
  std::set<int64_t> cameras;
  for (const CameraRecord& c : bank.ListCameras()) {
    if (c.session_id == session_id) cameras.insert(c.id);
  }
  std::unordered_map<int64_t, int64_t> camera_of_clip;
  for (const ClipRecord& c : bank.ListClips()) camera_of_clip[c.id] = c.camera_id;

  TruthLabelSummary summary;
  std::vector<int64_t> ids;
  std::vector<SpriteTruth> truth;
  for (const SpriteFeatures& f : bank.LoadFeatures()) {
    if (!cameras.count(camera_of_clip[f.clip_id])) continue;
    if (f.mirrored) {
      ++summary.mirrored_skipped;
      continue;
    }
    const auto it = subjects.find(f.timestamp_ns);
    const TruthRow* best = nullptr;
    double best_m = 0.15;
    if (it != subjects.end()) {
      for (const TruthRow& r : it->second) {
        const double d = std::hypot(r.x - f.ground_x_m, r.y - f.ground_y_m);
        if (d <= best_m) {
          best_m = d;
          best = &r;
        }
      }
    }
    if (!best) {
      ++summary.sprites_unmatched;
      continue;
    }
    ++summary.sprites_matched;
    ids.push_back(f.id);
    truth.push_back(best->truth);
  }
  if (ids.size() < 2) {
    throw InputError(bank_path,
                     std::to_string(ids.size()) + " sprites of session '" + session_dir +
                         "' match its truth (by timestamp and ground position within 0.15 m; " +
                         std::to_string(summary.sprites_unmatched) +
                         " do not): at least two are needed to make labels");
  }
  summary.labels = LabelsFromTruth(ids, truth, count, options, seed);
  summary.positive_rate = TruthPositiveRate(truth, options, 2000, seed);
  return summary;
}

}  // namespace ss
