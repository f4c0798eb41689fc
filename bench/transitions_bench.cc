// spritestation bench transitions: the two-stage transition search on a synthetic
// hamster bank (seed 000 §3), against brute force measured in the same run, for the default
// classifier (colour_cells) and the paper's six side by side.
//   weights fitted on seed 1 only (--train-out refits both); every figure on other seeds:
//   full build of N sprites of seed 2 on T threads; stage-2 evaluations (pixel reads) vs all
//   N(N-1)/2 pairs; recall of the pairs brute force accepts (exact on sampled rows); quality
//   against the synthetic truth (visible key points, feet unordered); for the paper's six the
//   candidate cascade with and without the level-2 silhouette signature (one core, same
//   candidates); incremental add of one sprite to a 60,000-sprite set of seed 3 (default).
// The JSON's "seeds" says which seeds were which. The judge without a truth: the visible jump
// (pipeline/transitions/visible_jump.h) of the kept transitions of the sampled rows, at most
// 2000 of them spread evenly: full_build.jump_ratio_median / _p95 and full_build.jumps.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_set>

#include <nlohmann/json.hpp>

#include "bench/bench_registry.h"
#include "core/error.h"
#include "core/log.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/colour_cells_training.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/transition_jumps.h"
#include "pipeline/transitions/truth_labels.h"

namespace ss::bench::transitions_bench {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
// CPU seconds of the whole process (all threads): with other jobs on the machine, wall
// time alone would hide whether the build itself or the contention is slow.
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
double LoadAverage() {
  double load[1] = {0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

struct Args {
  int sprites = 30000;
  int incremental_base = 60000;
  int adds = 300;
  int rows = 300;
  int threads = 2;
  int labels = 3000;
  double stage1_recall = 0.999;
  double stage2_bias_shift = 0;
  // --train-out: the least transitions precision (on the training set) the default is fitted
  // for; 0.85 is the lower bar (F1 >= 0.80 at P >= 0.85).
  double min_precision = 0.85;
  // The seed the weights are fitted on. Anything but 1 is for measuring a family's ceiling
  // (--train-seed=2 fits on the test set itself: an upper bound, not a held-out figure).
  uint64_t train_seed = 1;  // added to the stage-2 bias (> 0 lowers the threshold T2)
  double near_miss = TruthLabelOptions{}.near_miss_fraction;
  std::string weights_path, train_out, paper_weights_path, paper_train_out;
  bool incremental = true, micro = false, json = false, sweep = false;
};

Args Parse(const std::vector<std::string>& argv) {
  Args a;
  // `--name=value` and `--name value` both work; a lone `--` is skipped (the bench command
  // passes options it does not know through as extras, which may reorder separate values).
  std::vector<std::string> tokens;
  for (const std::string& t : argv) {
    if (t == "--") continue;
    const auto eq = t.find('=');
    if (t.rfind("--", 0) == 0 && eq != std::string::npos) {
      tokens.push_back(t.substr(0, eq));
      tokens.push_back(t.substr(eq + 1));
    } else {
      tokens.push_back(t);
    }
  }
  for (size_t k = 0; k < tokens.size(); ++k) {
    const std::string& s = tokens[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= tokens.size()) throw InputError("bench transitions", s + " needs a value");
      return tokens[++k];
    };
    if (s == "--sprites")
      a.sprites = std::stoi(value());
    else if (s == "--incremental-base")
      a.incremental_base = std::stoi(value());
    else if (s == "--adds")
      a.adds = std::stoi(value());
    else if (s == "--rows")
      a.rows = std::stoi(value());
    else if (s == "--threads")
      a.threads = std::stoi(value());
    else if (s == "--labels")
      a.labels = std::stoi(value());
    else if (s == "--near-miss")
      a.near_miss = std::stod(value());
    else if (s == "--stage1-recall")
      a.stage1_recall = std::stod(value());
    else if (s == "--stage2-bias-shift")
      a.stage2_bias_shift = std::stod(value());
    else if (s == "--weights")
      a.weights_path = value();
    else if (s == "--train-out")
      a.train_out = value();
    else if (s == "--train-seed")
      a.train_seed = std::stoull(value());
    else if (s == "--min-precision")
      a.min_precision = std::stod(value());
    else if (s == "--paper-weights")
      a.paper_weights_path = value();
    else if (s == "--paper-train-out")
      a.paper_train_out = value();
    else if (s == "--skip-incremental")
      a.incremental = false;
    else if (s == "--micro")
      a.micro = true;
    else if (s == "--json")
      a.json = true;
    else if (s == "--sweep-stage2")
      a.sweep = true;
    else
      throw InputError("bench transitions",
                       "unknown argument '" + s + "' (see bench/transitions_bench.cc)");
  }
  if (a.sprites < 100 || a.rows < 1 || a.threads < 1)
    throw InputError("bench transitions", "bad sizes");
  return a;
}

// A synthetic set in live order (each original followed by its mirror).
std::vector<SyntheticSprite> LiveSet(int sprites, uint64_t seed) {
  SyntheticSpriteOptions o;
  o.frames = (sprites + 1) / 2;
  o.seed = seed;
  auto all = MakeSyntheticSprites(o);
  const size_t half = all.size() / 2;
  std::vector<SyntheticSprite> live;
  live.reserve(all.size());
  for (size_t k = 0; k < half; ++k) {
    live.push_back(std::move(all[k]));
    live.push_back(std::move(all[half + k]));
  }
  live.resize(sprites);
  return live;
}

std::vector<int64_t> Ids(const std::vector<SyntheticSprite>& s) {
  std::vector<int64_t> ids;
  ids.reserve(s.size());
  for (const auto& x : s) ids.push_back(x.id);
  return ids;
}
std::vector<SpriteTruth> Truths(const std::vector<SyntheticSprite>& s) {
  std::vector<SpriteTruth> t;
  t.reserve(s.size());
  for (const auto& x : s) t.push_back(x.truth);
  return t;
}

// The seeds of the synthetic sets: weights and thresholds are fitted on the training set only,
// every figure is reported on the others.
constexpr uint64_t kTestSeed = 2, kIncrementalSeed = 3;

struct Trained {
  TransitionWeights paper, cells;
};

// Trains on a separate synthetic set (seed kTrainSeed): labels from truth, then (1) the paper's
// six as shipped before (label fit on the 32 x 32 window, stage 2 set for the real positive
// rate, stage 1 refitted as its filter) and (2) the colour_cells default (the paper fit on the
// default's 1 px window for the labelling page's ordering, then the three thresholds by
// FitColourCells: what `transitions train` does). Writes them when asked.
Trained Train(const Args& a, nlohmann::json* out) {
  const auto t0 = Clock::now();
  const auto sprites = LiveSet(a.sprites, a.train_seed);
  SpriteStore store(ComparisonWindow{}, SyntheticSpriteOptions{}.px_per_m);
  store.Append(AsSpriteInputs(sprites), a.threads);
  const auto ids = Ids(sprites);
  const auto truth = Truths(sprites);
  TruthLabelOptions label_options;
  label_options.near_miss_fraction = a.near_miss;
  const auto labels = LabelsFromTruth(ids, truth, a.labels, label_options, 1);
  std::vector<PairFeatures> x;
  std::vector<uint8_t> y;
  for (const Label& l : labels) {
    x.push_back(store.Features(*store.IndexOf(l.sprite_i), *store.IndexOf(l.sprite_j)));
    y.push_back(l.accept);
  }
  TrainReport report;
  TransitionWeights w = TrainWeights(x, y, ComparisonWindow{}, TrainOptions{}, &report);
  const double label_stage1_bias = w.stage1_bias;
  // Stage 2 for the real prior: true transitions are rare among all pairs.
  const double positive_rate = TruthPositiveRate(truth, label_options, 2000, 1);
  std::vector<double> positive_distances;
  {
    const TransitionClassifier label_fit(w);
    for (size_t k = 0; k < labels.size(); ++k) {
      if (y[k]) positive_distances.push_back(label_fit.Distance(x[k]));
    }
  }
  const PopulationSample sample =
      SamplePopulation(store, TransitionClassifier(w), a.rows, 7, a.threads);
  const Stage2Calibration s2 = CalibrateStage2(positive_distances, sample, positive_rate, &w);
  const Stage1Calibration s1 = FitStage1Filter(store, sample, a.stage1_recall, 7, &w);
  const std::string source =
      "spritestation bench transitions --train-out: synthetic hamster set, seed " +
      std::to_string(a.train_seed) + ", " + std::to_string(a.sprites) +
      " sprites (pipeline/transitions/synthetic.cc), labels from truth";
  nlohmann::json training = nlohmann::json::parse(w.training_json);
  training["source"] = source;
  training["stage2_calibration"] = {{"positive_rate", positive_rate},
                                    {"sampled_rows", sample.rows.size()},
                                    {"threshold", s2.threshold},
                                    {"accepts_per_sprite", s2.accepts_per_sprite},
                                    {"estimated_precision", s2.precision},
                                    {"estimated_recall", s2.recall},
                                    {"bias", w.stage2_bias}};
  training["stage1_calibration"] = {{"target_recall_of_stage2", a.stage1_recall},
                                    {"refitted_as_filter", true},
                                    {"stage2_accepted_pairs_sampled", s1.stage2_accepts},
                                    {"sampled_rows", a.rows},
                                    {"candidates_per_sprite", s1.candidates_per_sprite},
                                    {"bias_from_labels", label_stage1_bias},
                                    {"bias", w.stage1_bias}};
  w.training_json = training.dump();
  Trained trained;
  trained.paper = w;
  (*out)["training"]["paper_six"] = training;
  std::printf(
      "trained on %zu labels of seed %llu (%lld accepts): paper six stage 1 CV precision %.3f "
      "recall %.3f, stage 2 CV precision %.3f recall %.3f\n",
      labels.size(), static_cast<unsigned long long>(a.train_seed),
      static_cast<long long>(report.accepts), report.stage1.precision(), report.stage1.recall(),
      report.stage2.precision(), report.stage2.recall());
  std::printf(
      "  paper six: stage 2 set for the truth's positive rate %.3g (%.1f true partners per "
      "sprite): %.1f accepts per sprite, estimated precision %.3f recall %.3f; stage 1 refitted "
      "to pass %.3f of them: %.1f candidates per sprite\n",
      positive_rate, positive_rate * (a.sprites - 1), s2.accepts_per_sprite, s2.precision,
      s2.recall, a.stage1_recall, s1.candidates_per_sprite);

  // The colour_cells default, on its own window.
  const ComparisonWindow window = DefaultWeights().window;
  SpriteStore fine(window, SyntheticSpriteOptions{}.px_per_m);
  fine.Append(AsSpriteInputs(sprites), a.threads);
  std::vector<PairFeatures> xf;
  for (const Label& l : labels) {
    const int32_t i = *fine.IndexOf(l.sprite_i), j = *fine.IndexOf(l.sprite_j);
    xf.push_back(fine.Features(i, j));
  }
  TrainReport fine_report;
  TransitionWeights c = TrainWeights(xf, y, window, TrainOptions{}, &fine_report);
  // The three thresholds, fitted on the training set's truth for what the goal counts:
  // transitions i -> j (all of {i, j}, {i+1, j}, {i, j-1} kept) of a.rows random sprites
  // against every sprite, each measured as the componentwise largest of its three pairs'.
  const TruthLabelOptions truth_options;
  std::vector<int32_t> order(fine.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 row_rng(7);
  std::shuffle(order.begin(), order.end(), row_rng);
  std::vector<int32_t> fit_rows;
  for (int32_t i : order) {
    if (static_cast<int>(fit_rows.size()) >= a.rows) break;
    if (fine.next(i) >= 0) fit_rows.push_back(i);
  }
  constexpr double kFar = 0.12;  // the fit's largest velocity bound
  std::vector<ColourCellsMeasure> units;
  std::vector<uint8_t> unit_truth;
  std::atomic<int64_t> true_total{0}, true_far{0}, true_colourful{0};
  {
    std::mutex merge;
    std::atomic<size_t> cursor{0};
    const int32_t m = fine.size();
    auto work = [&] {
      std::vector<ColourCellsMeasure> mi(m), ms(m), local_units;
      std::vector<uint8_t> ti(m), ts(m), near_i(m), near_s(m), local_truth;
      int64_t local_true = 0, local_true_far = 0, local_true_colourful = 0;
      for (size_t r; (r = cursor.fetch_add(1)) < fit_rows.size();) {
        const int32_t i = fit_rows[r], s = fine.next(i);
        for (int32_t j = 0; j < m; ++j) {
          ti[j] = TruthAccepts(sprites[i].truth, sprites[j].truth, truth_options);
          ts[j] = TruthAccepts(sprites[s].truth, sprites[j].truth, truth_options);
          near_i[j] = CheapDiff(fine.cheap(i), fine.cheap(j))[0] <= kFar;
          near_s[j] = CheapDiff(fine.cheap(s), fine.cheap(j))[0] <= kFar;
          if (near_i[j]) mi[j] = MeasureColourCells(fine, i, j);
          if (near_s[j]) ms[j] = MeasureColourCells(fine, s, j);
        }
        for (int32_t j = 0; j < m; ++j) {
          const int32_t q = fine.prev(j);
          if (q < 0 || j == i || j == s) continue;
          const bool truth = ti[j] && ts[j] && ti[q];
          local_true += truth;
          if (!near_i[j] || !near_s[j] || !near_i[q]) {
            local_true_far += truth;
            continue;
          }
          ColourCellsMeasure u;
          u.velocity_mps = std::max({mi[j].velocity_mps, ms[j].velocity_mps, mi[q].velocity_mps});
          u.alpha_cells = std::max({mi[j].alpha_cells, ms[j].alpha_cells, mi[q].alpha_cells});
          u.colour_cells = std::max({mi[j].colour_cells, ms[j].colour_cells, mi[q].colour_cells});
          if (u.colour_cells > 40) {  // beyond the grid: never accepted
            local_true_colourful += truth;
            continue;
          }
          local_units.push_back(u);
          local_truth.push_back(truth);
        }
      }
      std::lock_guard<std::mutex> lock(merge);
      units.insert(units.end(), local_units.begin(), local_units.end());
      unit_truth.insert(unit_truth.end(), local_truth.begin(), local_truth.end());
      true_total += local_true;
      true_far += local_true_far;
      true_colourful += local_true_colourful;
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < a.threads; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
  }
  ColourCellsFitOptions fit_options;
  fit_options.threads = a.threads;
  const ColourCellsFit fit =
      FitColourCellsOnTruth(units, unit_truth, true_total.load(), a.min_precision, fit_options, &c);
  // What the chosen point loses of the true transitions, bound by bound (a transition fails a
  // bound when the largest of its three pairs' measurements exceeds it; beyond 0.12 m/s or 40
  // colour cells it was not measured).
  int64_t lose_velocity = 0, lose_alpha = 0, lose_cells = 0, lose_only_cells = 0;
  for (size_t k = 0; k < units.size(); ++k) {
    if (!unit_truth[k]) continue;
    const bool v = units[k].velocity_mps > fit.max_velocity_mps;
    const bool al = units[k].alpha_cells > fit.max_alpha_cells;
    const bool ce = units[k].colour_cells > fit.max_colour_cells;
    lose_velocity += v;
    lose_alpha += al;
    lose_cells += ce;
    lose_only_cells += ce && !v && !al;
  }
  std::printf(
      "  default on the training set: of %lld true transitions, %lld beyond 0.12 m/s and %lld "
      "beyond 40 colour cells (no grid point keeps them); over the chosen velocity bound %lld, "
      "alpha bound %lld, colour bound %lld (only it %lld)\n",
      static_cast<long long>(true_total.load()), static_cast<long long>(true_far.load()),
      static_cast<long long>(true_colourful.load()), static_cast<long long>(lose_velocity),
      static_cast<long long>(lose_alpha), static_cast<long long>(lose_cells),
      static_cast<long long>(lose_only_cells));
  nlohmann::json cells_training = nlohmann::json::parse(c.training_json);
  cells_training["source"] = source;
  // The labelling page reads the positive rate the weights were calibrated for here.
  cells_training["stage2_calibration"] = {{"positive_rate", positive_rate}};
  cells_training["colour_cells_fit"] = {{"population",
                                         "transitions of sampled sprites against every sprite, "
                                         "truth known (bench transitions --train-out)"},
                                        {"min_precision", a.min_precision},
                                        {"true_transitions_sampled", true_total.load()},
                                        {"true_beyond_velocity_grid", true_far.load()},
                                        {"true_beyond_colour_grid", true_colourful.load()},
                                        {"true_over_velocity_bound", lose_velocity},
                                        {"true_over_alpha_bound", lose_alpha},
                                        {"true_over_colour_bound", lose_cells},
                                        {"positive_rate", positive_rate},
                                        {"sampled_rows", a.rows},
                                        {"max_velocity_mps", fit.max_velocity_mps},
                                        {"max_alpha_cells", fit.max_alpha_cells},
                                        {"max_colour_cells", fit.max_colour_cells},
                                        {"estimated_precision", fit.precision},
                                        {"estimated_recall", fit.recall},
                                        {"estimated_f1", fit.f1},
                                        {"accepts_per_sprite", fit.accepts_per_sprite}};
  c.training_json = cells_training.dump();
  trained.cells = c;
  (*out)["training"]["default"] = cells_training;
  (*out)["training"]["seconds"] = Since(t0);
  std::printf(
      "  default (colour_cells): velocity <= %.4g m/s AND alpha difference <= %.4g cells AND "
      "colour-different cells <= %d; estimated on the training set: precision %.3f recall %.3f "
      "F1 %.3f (transitions of %zu rows, chosen at precision >= %.2f)\n",
      fit.max_velocity_mps, fit.max_alpha_cells, fit.max_colour_cells, fit.precision, fit.recall,
      fit.f1, fit_rows.size(), a.min_precision);
  if (!a.train_out.empty()) SaveWeights(trained.cells, a.train_out);
  if (!a.paper_train_out.empty()) SaveWeights(trained.paper, a.paper_train_out);
  return trained;
}

// The candidates of every 10th sprite (j > i), from the built index.
std::vector<std::pair<int32_t, int32_t>> SampledCandidates(const TransitionBuilder& builder) {
  std::vector<std::pair<int32_t, int32_t>> out;
  std::vector<int32_t> hits;
  for (int32_t i = 0; i < builder.store().size(); i += 10) {
    hits.clear();
    builder.index().Query(builder.store().cheap(i), &hits);
    for (int32_t j : hits) {
      if (j > i) out.push_back({i, j});
    }
  }
  return out;
}

// One thread's CPU time per candidate for deciding the sampled candidates two ways:
// "coarse only" = the cheap terms, the 4 x 4 bound, then the pixels (the cascade before the
// level-2 signature); "signature" = SignatureRejects (both levels), then the pixels.
// Both make the same decisions; the accept counts are compared to be sure.
void CompareCascades(const TransitionBuilder& builder, nlohmann::json* out) {
  const SpriteStore& store = builder.store();
  const TransitionClassifier& c = builder.classifier();
  const auto pairs = SampledCandidates(builder);
  const auto& u2 = c.stage2_unit_weights();
  auto coarse_rejects = [&](int32_t i, int32_t j) {
    const CheapDifference cheap = CheapDiff(store.cheap(i), store.cheap(j));
    double d = 0;
    for (int k = 0; k < kCheapFeatureCount; ++k) d += u2[k] * cheap[k];
    if (d > c.stage2_threshold()) return true;
    PixelSums bound;
    bound.alpha_abs_diff = store.CoarseAlphaBound(i, j);
    bound.weight = 1;
    return d + u2[4] * PixelDifferenceFromSums(bound, store.box(i), store.box(j)).alpha >
           c.stage2_threshold();
  };
  double ns[2] = {0, 0};
  int64_t accepts[2] = {0, 0}, pixel_reads[2] = {0, 0};
  for (int rep = 0; rep < 2; ++rep) {  // twice, alternating, to even out the machine's load
    for (int way = 0; way < 2; ++way) {
      const double c0 = ThreadCpuSeconds();
      int64_t acc = 0, reads = 0;
      for (size_t k = 0; k < pairs.size(); ++k) {
        if (k + 8 < pairs.size()) store.PrefetchCoarse(pairs[k + 8].second);
        const auto [i, j] = pairs[k];
        if (way == 0 ? coarse_rejects(i, j) : c.SignatureRejects(store, i, j)) continue;
        ++reads;
        double d;
        acc += c.Stage2(store, i, j, &d);
      }
      ns[way] += (ThreadCpuSeconds() - c0) * 1e9 / std::max<size_t>(1, pairs.size()) / 2;
      accepts[way] = acc;
      pixel_reads[way] = reads;
    }
  }
  if (accepts[0] != accepts[1]) throw std::logic_error("the two cascades decided differently");
  std::printf(
      "  deciding %zu sampled stage-1 candidates on one core (CPU): 4x4 bound then pixels %.1f ns "
      "a candidate "
      "(%.1f%% read pixels); with the level-2 signature %.1f ns (%.1f%% read pixels)\n",
      pairs.size(), ns[0], 100.0 * pixel_reads[0] / pairs.size(), ns[1],
      100.0 * pixel_reads[1] / pairs.size());
  (*out)["cascade_ab"] = {{"sampled_candidates", pairs.size()},
                          {"coarse_only_ns_per_candidate", ns[0]},
                          {"coarse_only_pixel_reads", pixel_reads[0]},
                          {"signature_ns_per_candidate", ns[1]},
                          {"signature_pixel_reads", pixel_reads[1]}};
}

// --sweep-stage2: per stage-2 bias shift, on the sampled candidates of the shipped stage 1,
// the stage-2 evaluations (signature survivors) and accepts per sprite.
void SweepStage2(const TransitionBuilder& builder, const TransitionWeights& weights) {
  const auto pairs = SampledCandidates(builder);
  const int32_t n = builder.store().size();
  const int32_t whole_rows = (n + 9) / 10;  // rows of ten
  const double rows = whole_rows;
  for (double shift : {0.0, 0.5, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0}) {
    TransitionWeights w = weights;
    w.stage2_bias += shift;
    const TransitionClassifier c(w);
    int64_t survive = 0, accept = 0;
    for (const auto& [i, j] : pairs) {
      if (c.SignatureRejects(builder.store(), i, j)) continue;
      ++survive;
      double d;
      accept += c.Stage2(builder.store(), i, j, &d);
    }
    // Each sampled row's candidates j > i: about half of its partners; per sprite = x 2.
    std::printf(
        "  stage-2 bias %+.2f (T2 %.3f): per sprite %.1f stage-2 evaluations, %.1f accepts -> "
        "~%.0fx fewer "
        "evaluations than brute force\n",
        shift, c.stage2_threshold(), 2 * survive / rows, 2 * accept / rows,
        (n - 1) / (2 * survive / rows));
  }
}

// One classifier's full build of the test set, brute force on sampled rows in the same run,
// and its agreement with the truth. Returns the "full_build" object.
nlohmann::json FullBuild(const Args& a, const TransitionWeights& weights, const std::string& name,
                         const std::vector<SyntheticSprite>& sprites, double seconds_generate,
                         bool paper_extras, nlohmann::json* result) {
  const double px_per_m = SyntheticSpriteOptions{}.px_per_m;
  auto t = Clock::now();
  const auto inputs = AsSpriteInputs(sprites);
  TransitionBuilder builder(weights, px_per_m);
  const double load_before = LoadAverage();
  const double cpu_before = ProcessCpuSeconds();
  t = Clock::now();
  builder.BuildFromScratch(inputs, BuildOptions{.threads = a.threads});
  const double seconds_pairs = Since(t);
  t = Clock::now();
  const auto transitions = builder.Transitions();
  const double seconds_transitions = Since(t);
  const double seconds_build = seconds_pairs + seconds_transitions;
  const double cpu_build = ProcessCpuSeconds() - cpu_before;
  const BuildStats& stats = builder.stats();
  const int32_t n = builder.store().size();
  const double all_pairs = 0.5 * n * (n - 1.0);

  // ---- brute force on sampled rows: stage 2 against every sprite ----
  const auto& store = builder.store();
  const TransitionClassifier& classifier = builder.classifier();
  std::vector<int32_t> rows(n);
  std::iota(rows.begin(), rows.end(), 0);
  std::mt19937_64 rng(3);
  std::shuffle(rows.begin(), rows.end(), rng);
  rows.resize(std::min<int32_t>(n, a.rows));
  std::atomic<size_t> cursor{0};
  std::atomic<int64_t> brute_accepted{0}, brute_kept{0}, truth_pos{0}, kept_total{0}, kept_true{0},
      brute_true{0};
  t = Clock::now();
  auto work = [&] {
    const TruthLabelOptions truth_options;
    int64_t ba = 0, bk = 0, tp = 0, kt = 0, ktt = 0, btt = 0;
    for (size_t r; (r = cursor.fetch_add(1)) < rows.size();) {
      const int32_t i = rows[r];
      for (int32_t j = 0; j < n; ++j) {
        if (j == i) continue;
        double d;
        const bool brute = classifier.Stage2(store, i, j, &d);  // the full evaluation
        const bool kept = builder.KeptDistance(i, j) >= 0;
        const bool truth = TruthAccepts(sprites[i].truth, sprites[j].truth, truth_options);
        ba += brute;
        bk += brute && kept;
        tp += truth;
        kt += kept;
        ktt += kept && truth;
        btt += brute && truth;
      }
    }
    brute_accepted += ba;
    brute_kept += bk;
    truth_pos += tp;
    kept_total += kt;
    kept_true += ktt;
    brute_true += btt;
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < a.threads; ++k) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  const double seconds_sample = Since(t);
  const double evaluations = static_cast<double>(rows.size()) * (n - 1);
  // Brute force proper: stage 2 alone (no truth check, no lookups) on the first sampled
  // rows, one thread, CPU time, so that the extrapolation is the classifier's cost.
  const size_t plain_rows = std::min<size_t>(rows.size(), 40);
  double sink = 0;
  const double plain_cpu0 = ThreadCpuSeconds();
  for (size_t r = 0; r < plain_rows; ++r) {
    for (int32_t j = 0; j < n; ++j) {
      double d;
      if (j != rows[r]) sink += classifier.Stage2(store, rows[r], j, &d);
    }
  }
  benchmark::DoNotOptimize(sink);
  const double seconds_per_eval_core =
      (ThreadCpuSeconds() - plain_cpu0) / (static_cast<double>(plain_rows) * (n - 1));
  const double brute_seconds_core = all_pairs * seconds_per_eval_core;
  const double ratio = all_pairs / std::max<int64_t>(1, stats.stage2_evaluations);
  const double ratio_stage1 = all_pairs / std::max<int64_t>(1, stats.stage1_candidates);
  const double recall_vs_brute =
      brute_accepted > 0 ? static_cast<double>(brute_kept) / brute_accepted : 1.0;
  const double precision_truth = kept_total > 0 ? static_cast<double>(kept_true) / kept_total : 0.0;
  const double recall_truth = truth_pos > 0 ? static_cast<double>(kept_true) / truth_pos : 0.0;

  // Transition-level quality against truth: i -> j is right when the truth accepts {i,j}, {i+1,j},
  // {i,j-1}.
  const TruthLabelOptions truth_options;
  std::unordered_set<int32_t> row_set(rows.begin(), rows.end());
  int64_t t_found = 0, t_true = 0, t_truth_total = 0;
  for (const Transition& tr : transitions) {
    const int32_t i = *store.IndexOf(tr.from);
    if (!row_set.count(i)) continue;
    const int32_t j = *store.IndexOf(tr.to);
    ++t_found;
    t_true += TruthAccepts(sprites[i].truth, sprites[j].truth, truth_options) &&
              TruthAccepts(sprites[store.next(i)].truth, sprites[j].truth, truth_options) &&
              TruthAccepts(sprites[i].truth, sprites[store.prev(j)].truth, truth_options);
  }
  for (int32_t i : rows) {
    const int32_t s = store.next(i);
    if (s < 0) continue;
    for (int32_t j = 0; j < n; ++j) {
      const int32_t q = store.prev(j);
      if (q < 0 || j == i || j == s) continue;
      t_truth_total += TruthAccepts(sprites[i].truth, sprites[j].truth, truth_options) &&
                       TruthAccepts(sprites[s].truth, sprites[j].truth, truth_options) &&
                       TruthAccepts(sprites[i].truth, sprites[q].truth, truth_options);
    }
  }

  // The visible jump of the kept transitions of the sampled rows, from the same billboards the
  // build read (LiveSet: originals are the first (sprites + 1) / 2 ids, mirrors the rest).
  const int64_t originals = (static_cast<int64_t>(sprites.size()) + 1) / 2;
  std::vector<JumpFrame> frames;
  frames.reserve(n);
  for (int32_t i = 0; i < n; ++i) {
    JumpFrame f{store.id(i), store.clip(i), store.id(i) > originals, std::nullopt};
    if (store.next(i) >= 0) f.next = store.id(store.next(i));
    frames.push_back(f);
  }
  VisibleJumpMeter meter(
      frames,
      [&](int64_t id) {
        const std::optional<int32_t> i = store.IndexOf(id);
        if (!i) throw InputError("bench transitions", "no sprite " + std::to_string(id));
        return sprites[*i].billboard;
      },
      "");
  std::vector<std::pair<int64_t, int64_t>> row_transitions;
  for (const Transition& tr : transitions) {
    if (row_set.count(*store.IndexOf(tr.from))) row_transitions.emplace_back(tr.from, tr.to);
  }
  t = Clock::now();
  const TransitionJumpSummary jumps = MeasureTransitionJumps(meter, row_transitions);
  const double seconds_jumps = Since(t);

  std::printf(
      "\n== transitions, %s: full build, %d synthetic sprites of seed %llu (%lld clips, mirrors "
      "included), %d threads ==\n",
      name.c_str(), n, static_cast<unsigned long long>(kTestSeed),
      static_cast<long long>(stats.clips), a.threads);
  std::printf(
      "  build: %.2f s (images %.2f s, index %.3f s, stage 1 + stage 2 %.2f s, transitions %.2f s)"
      "   goal <= 60 s: %s\n",
      seconds_build, stats.seconds_images, stats.seconds_index, stats.seconds_pairs,
      seconds_transitions, seconds_build <= 60 ? "met" : "MISSED");
  std::printf(
      "  CPU time of the build %.2f s over %d threads (machine load average %.1f before it)\n",
      cpu_build, a.threads, load_before);
  std::printf(
      "  stage 1 (k-d tree): %lld candidates of %.0f pairs (%.0fx fewer); silhouette signature "
      "rejects %lld "
      "of them without reading a pixel\n",
      static_cast<long long>(stats.stage1_candidates), all_pairs, ratio_stage1,
      static_cast<long long>(stats.signature_rejected));
  std::printf(
      "  stage-2 evaluations (pairs whose pixels are read): %lld of %.0f pairs -> %.0fx fewer "
      "than brute force   goal >= 600x: %s\n",
      static_cast<long long>(stats.stage2_evaluations), all_pairs, ratio,
      ratio >= 600 ? "met" : "MISSED");
  std::printf(
      "  accepts per sprite (kept pairs x 2 / sprites): %.1f; at most all_pairs / 600 = %.0f "
      "evaluations for 600x\n",
      2.0 * stats.kept_pairs / n, all_pairs / 600);
  std::printf(
      "  brute force (extrapolated: the full stage 2 timed on %zu rows x %d pairs, %.0f ns each, "
      "CPU time of one core): %.0f s on one core, %.0f s on %d; the two-stage build (%.2f s CPU) "
      "needs %.0fx less "
      "CPU\n",
      plain_rows, n - 1, seconds_per_eval_core * 1e9, brute_seconds_core,
      brute_seconds_core / a.threads, a.threads, cpu_build, brute_seconds_core / cpu_build);
  std::printf(
      "  (recall and quality below: all %zu sampled rows x %d = %.3g pairs judged by brute force, "
      "%.1f s)\n",
      rows.size(), n - 1, evaluations, seconds_sample);
  std::printf(
      "  kept %lld pairs, %zu transitions; of the %lld pairs brute force accepts in the sampled "
      "rows, kept "
      "%.4f   goal >= 0.99: %s\n",
      static_cast<long long>(stats.kept_pairs), transitions.size(),
      static_cast<long long>(brute_accepted.load()), recall_vs_brute,
      recall_vs_brute >= 0.99 ? "met" : "MISSED");
  std::printf(
      "  against synthetic truth (sampled rows; same pose, every visible key point within %.1f "
      "mm, feet unordered; %.1f true partners per sprite): pairs precision %.3f recall %.3f; "
      "transitions precision "
      "%.3f recall %.3f\n",
      truth_options.max_keypoint_displacement_m * 1e3, static_cast<double>(truth_pos) / rows.size(),
      precision_truth, recall_truth, t_found ? static_cast<double>(t_true) / t_found : 0.0,
      t_truth_total ? static_cast<double>(t_true) / t_truth_total : 0.0);
  if (paper_extras) {
    CompareCascades(builder, result);
    if (a.sweep) SweepStage2(builder, weights);
  }
  std::printf("  %s  (%.1f s)   goal median <= 1.0, p95 <= 2.0: %s\n",
              jumps.ToText().substr(0, jumps.ToText().size() - 1).c_str(), seconds_jumps,
              jumps.all.median && *jumps.all.median <= 1.0 && jumps.all.p95 && *jumps.all.p95 <= 2.0
                  ? "met"
                  : "MISSED");
  const double precision_transitions = t_found ? static_cast<double>(t_true) / t_found : 0.0;
  const double recall_transitions =
      t_truth_total ? static_cast<double>(t_true) / t_truth_total : 0.0;
  const double f1_transitions = precision_transitions + recall_transitions > 0
                                    ? 2 * precision_transitions * recall_transitions /
                                          (precision_transitions + recall_transitions)
                                    : 0.0;
  std::printf("  transitions F1 %.3f at precision %.3f   goal >= 0.85 at P >= 0.90: %s\n",
              f1_transitions, precision_transitions,
              f1_transitions >= 0.85 && precision_transitions >= 0.9 ? "met" : "MISSED");
  return {{"sprites", n},
          {"clips", stats.clips},
          {"threads", a.threads},
          {"seconds", seconds_build},
          {"cpu_seconds", cpu_build},
          {"load_average_before", load_before},
          {"seconds_generate_synthetic", seconds_generate},
          {"stage1_candidates", stats.stage1_candidates},
          {"signature_rejected", stats.signature_rejected},
          {"stage2_evaluations", stats.stage2_evaluations},
          {"fewer_stage1_candidates_ratio", ratio_stage1},
          {"all_pairs", all_pairs},
          {"fewer_evaluations_ratio", ratio},
          {"kept_pairs", stats.kept_pairs},
          {"transitions", transitions.size()},
          {"brute_force_sampled_rows", rows.size()},
          {"brute_force_ns_per_evaluation_one_core", seconds_per_eval_core * 1e9},
          {"brute_force_timed_rows", plain_rows},
          {"cpu_ratio_brute_force_vs_build", brute_seconds_core / cpu_build},
          {"brute_force_seconds_extrapolated_one_core", brute_seconds_core},
          {"recall_of_brute_force_accepts", recall_vs_brute},
          {"brute_force_accepts_sampled", brute_accepted.load()},
          {"truth_pair_precision", precision_truth},
          {"truth_pair_recall", recall_truth},
          {"truth_transition_precision", t_found ? static_cast<double>(t_true) / t_found : 0.0},
          {"truth_transition_recall", recall_transitions},
          {"truth_transition_f1", f1_transitions},
          {"truth_partners_per_sprite", static_cast<double>(truth_pos) / rows.size()},
          {"jump_ratio_median", jumps.ToJson()["median"]},
          {"jump_ratio_p95", jumps.ToJson()["p95"]},
          {"jumps", jumps.ToJson()},
          {"seconds_jumps", seconds_jumps},
          {"classifier", name}};
}

int Run(const std::vector<std::string>& argv) {
  const Args a = Parse(argv);
  SetLogLevel("warn");
  nlohmann::json result;
  TransitionWeights weights =
      a.weights_path.empty() ? DefaultWeights() : LoadWeights(a.weights_path);
  TransitionWeights paper =
      a.paper_weights_path.empty() ? PaperWeights() : LoadWeights(a.paper_weights_path);
  if (!a.train_out.empty() || !a.paper_train_out.empty()) {
    const Trained trained = Train(a, &result);
    weights = trained.cells;
    paper = trained.paper;
  }
  if (a.stage2_bias_shift != 0) {
    paper.stage2_bias += a.stage2_bias_shift;
    std::printf(
        "paper six: stage-2 bias shifted by %+g (threshold T2 %.4f): NOT the shipped operating "
        "point\n",
        a.stage2_bias_shift, TransitionClassifier(paper).stage2_threshold());
    result["stage2_bias_shift"] = a.stage2_bias_shift;
  }
  result["seeds"] = {
      {"train", a.train_seed}, {"test", kTestSeed}, {"incremental", kIncrementalSeed}};
  std::printf(
      "seeds: weights and thresholds fitted on seed %llu (--train-out, or the shipped files, "
      "trained the same way on seed 1); every figure below on seed %llu (full build) and %llu "
      "(incremental)\n",
      static_cast<unsigned long long>(a.train_seed), static_cast<unsigned long long>(kTestSeed),
      static_cast<unsigned long long>(kIncrementalSeed));
  if (a.train_seed == kTestSeed || a.train_seed == kIncrementalSeed) {
    std::printf(
        "WARNING: fitted on a seed the figures are reported on: an upper bound of the "
        "classifiers' family, not a held-out figure\n");
  }
  const double px_per_m = SyntheticSpriteOptions{}.px_per_m;

  // ---- full builds of the test set: the default, then the paper's six ----
  auto t = Clock::now();
  const auto sprites = LiveSet(a.sprites, kTestSeed);
  const double seconds_generate = Since(t);
  result["full_build"] = FullBuild(a, weights, "default", sprites, seconds_generate,
                                   !TransitionClassifier(weights).colour_cells(), &result);
  nlohmann::json paper_result;
  result["paper_six"]["full_build"] =
      FullBuild(a, paper, "paper six", sprites, seconds_generate, true, &paper_result);
  if (paper_result.contains("cascade_ab"))
    result["paper_six"]["cascade_ab"] = paper_result["cascade_ab"];

  // ---- incremental ----
  if (a.incremental) {
    auto live = LiveSet(a.incremental_base + a.adds, kIncrementalSeed);
    const auto live_inputs = AsSpriteInputs(live);
    TransitionBuilder inc(weights, px_per_m);
    t = Clock::now();
    inc.BuildFromScratch(std::span(live_inputs).first(a.incremental_base),
                         BuildOptions{.threads = a.threads});
    const double seconds_base = Since(t);
    for (int k = 0; k < a.incremental_base; ++k)
      std::vector<uint8_t>().swap(live[k].billboard.rgba);
    std::vector<double> ms, cpu_ms;
    int64_t new_transitions = 0, appended = 0;
    const int64_t candidates_before = inc.stats().stage1_candidates;
    const int64_t evaluations_before = inc.stats().stage2_evaluations;
    for (int k = 0; k < a.adds; ++k) {
      const SpriteInput& s = live_inputs[a.incremental_base + k];
      const auto t0 = Clock::now();
      const double c0 = ThreadCpuSeconds();
      const TransitionDelta d = inc.Add(std::span(&s, 1));
      cpu_ms.push_back((ThreadCpuSeconds() - c0) * 1e3);
      ms.push_back(Since(t0) * 1e3);
      new_transitions += static_cast<int64_t>(d.transitions.size());
      appended += inc.store().prev(inc.store().size() - 1) >= 0;
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2], p90 = sorted[sorted.size() * 9 / 10],
                 worst = sorted.back();
    std::sort(cpu_ms.begin(), cpu_ms.end());
    const double median_cpu = cpu_ms[cpu_ms.size() / 2];
    std::printf(
        "\n== transitions: incremental, one sprite at a time onto %d sprites (one core) ==\n",
        a.incremental_base);
    std::printf(
        "  base build %.1f s; %d adds (%lld appended to an existing clip): median %.3f ms, p90 "
        "%.3f ms, max "
        "%.3f ms (the max includes a k-d tree rebuild)   goal median <= 2 ms: %s\n",
        seconds_base, a.adds, static_cast<long long>(appended), median, p90, worst,
        median <= 2 ? "met" : "MISSED");
    std::printf("  median CPU time of one add (this thread): %.3f ms\n", median_cpu);
    std::printf(
        "  per add: %.1f stage-1 candidates, %.1f stage-2 evaluations, %.2f new transitions\n",
        static_cast<double>(inc.stats().stage1_candidates - candidates_before) / a.adds,
        static_cast<double>(inc.stats().stage2_evaluations - evaluations_before) / a.adds,
        static_cast<double>(new_transitions) / a.adds);
    result["incremental"] = {
        {"base_sprites", a.incremental_base},
        {"adds", a.adds},
        {"median_ms", median},
        {"median_cpu_ms", median_cpu},
        {"p90_ms", p90},
        {"max_ms", worst},
        {"base_build_seconds", seconds_base},
        {"appended_to_clip", appended},
        {"stage1_candidates_per_add",
         static_cast<double>(inc.stats().stage1_candidates - candidates_before) / a.adds},
        {"stage2_evaluations_per_add",
         static_cast<double>(inc.stats().stage2_evaluations - evaluations_before) / a.adds}};
  }
  if (a.json) std::printf("%s\n", result.dump(2).c_str());
  if (a.micro) return RunGoogleBenchmarks("BM_Transitions", {"--benchmark_min_time=0.2"});
  return 0;
}

// The stage-2 pixel kernel on one pair of 32x32 comparison images: SIMD vs the plain loop.
void Images(std::vector<uint8_t>* a, std::vector<uint8_t>* b, int* stride) {
  const ComparisonWindow w;
  *stride = w.PlaneStride();
  std::mt19937 rng(1);
  a->resize(w.ImageBytes());
  b->resize(w.ImageBytes());
  for (auto& v : *a) v = rng() % 256;
  for (auto& v : *b) v = rng() % 256;
}
void BM_TransitionsPixelKernelSimd(benchmark::State& state) {
  std::vector<uint8_t> a, b;
  int stride;
  Images(&a, &b, &stride);
  for (auto _ : state) benchmark::DoNotOptimize(SumPixelDifferences(a.data(), b.data(), stride));
  state.SetItemsProcessed(state.iterations());
}
void BM_TransitionsPixelKernelScalar(benchmark::State& state) {
  std::vector<uint8_t> a, b;
  int stride;
  Images(&a, &b, &stride);
  for (auto _ : state)
    benchmark::DoNotOptimize(SumPixelDifferencesScalar(a.data(), b.data(), stride));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TransitionsPixelKernelSimd);
BENCHMARK(BM_TransitionsPixelKernelScalar);

}  // namespace

}  // namespace ss::bench::transitions_bench

namespace ss::bench {
int RunTransitionWorkers(const std::vector<std::string>& args);  // transition_workers_bench.cc
}  // namespace ss::bench

namespace ss::bench::transitions_bench {

namespace {

int RunOrWorkers(const std::vector<std::string>& args) {
  if (!args.empty() && args.front() == "--workers")
    return RunTransitionWorkers({args.begin() + 1, args.end()});
  return Run(args);
}

const bool registered = RegisterSuite(
    {"transitions",
     "two-stage transition search on a synthetic 30k-sprite bank vs brute force, default and "
     "paper six; incremental add at 60k "
     "[--sprites N --threads T --rows R --weights F --paper-weights F --train-out F "
     "--paper-train-out F --min-precision P --train-seed S --stage2-bias-shift X "
     "--sweep-stage2 --skip-incremental --micro --json]; --workers: PostgreSQL transition workers "
     "(scripts/bench-postgres.sh BUILD transitions)",
     &RunOrWorkers});

}  // namespace
}  // namespace ss::bench::transitions_bench
