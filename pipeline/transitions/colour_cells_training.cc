#include "pipeline/transitions/colour_cells_training.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numeric>
#include <random>
#include <thread>

#include "core/error.h"
#include "core/option_checks.h"
#include "pipeline/transitions/features.h"

namespace ss {

namespace {

// The thresholds tried. Alpha bounds are whole cells (so 255 * bound is exact); the last one
// (1e12) is "no alpha bound".
std::vector<double> VelocityGrid() {
  std::vector<double> g;
  for (int k = 1; k <= 48; ++k) g.push_back(0.0025 * k);  // up to 0.12 m/s
  return g;
}
const std::vector<double> kAlphaGrid = {20,  30,  40,  55,  75,  100, 135,
                                        180, 240, 320, 430, 580, 800, 1e12};
constexpr int kCellsGrid = 41;  // 0 ... 40 colour-different cells

// Counts of pairs at or below each grid point: H[v][a][c] then prefix sums on all three axes.
class GridCounts {
 public:
  GridCounts() : velocity_(VelocityGrid()) {
    counts_.assign(velocity_.size() * kAlphaGrid.size() * kCellsGrid, 0);
  }
  // False when the pair is above the grid's largest thresholds (never accepted).
  bool Bin(const ColourCellsMeasure& m, size_t* at) const {
    const auto v = std::lower_bound(velocity_.begin(), velocity_.end(), m.velocity_mps);
    if (v == velocity_.end()) return false;
    const auto a = std::lower_bound(kAlphaGrid.begin(), kAlphaGrid.end(), m.alpha_cells);
    if (a == kAlphaGrid.end() || m.colour_cells >= kCellsGrid) return false;
    *at = Index(v - velocity_.begin(), a - kAlphaGrid.begin(), m.colour_cells);
    return true;
  }
  void Add(size_t at, int64_t n = 1) { counts_[at] += n; }
  void Merge(const GridCounts& o) {
    for (size_t k = 0; k < counts_.size(); ++k) counts_[k] += o.counts_[k];
  }
  void PrefixSums() {
    const size_t nv = velocity_.size(), na = kAlphaGrid.size();
    for (size_t v = 0; v < nv; ++v)
      for (size_t a = 0; a < na; ++a)
        for (int c = 1; c < kCellsGrid; ++c) counts_[Index(v, a, c)] += counts_[Index(v, a, c - 1)];
    for (size_t v = 0; v < nv; ++v)
      for (size_t a = 1; a < na; ++a)
        for (int c = 0; c < kCellsGrid; ++c) counts_[Index(v, a, c)] += counts_[Index(v, a - 1, c)];
    for (size_t v = 1; v < nv; ++v)
      for (size_t a = 0; a < na; ++a)
        for (int c = 0; c < kCellsGrid; ++c) counts_[Index(v, a, c)] += counts_[Index(v - 1, a, c)];
  }
  int64_t At(size_t v, size_t a, int c) const { return counts_[Index(v, a, c)]; }
  const std::vector<double>& velocity() const { return velocity_; }

 private:
  size_t Index(size_t v, size_t a, int c) const {
    return (v * kAlphaGrid.size() + a) * kCellsGrid + static_cast<size_t>(c);
  }
  std::vector<double> velocity_;
  std::vector<int64_t> counts_;
};

void CheckOptions(const ColourCellsFitOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("training options", why);
}

// The best grid point for the positives' counts against the population's, and the weights.
ColourCellsFit Choose(GridCounts positives, int64_t positive_count, GridCounts population,
                      double population_pairs, double positive_rate,
                      const ColourCellsFitOptions& options, double sprites_per_row,
                      TransitionWeights* w, double min_precision = 0) {
  positives.PrefixSums();
  population.PrefixSums();
  struct Point {
    size_t v, a;
    int c;
    double precision, recall, f1;
    int64_t accepts;
  };
  std::vector<Point> points;
  double best = -1;
  for (size_t v = 0; v < positives.velocity().size(); ++v) {
    for (size_t a = 0; a < kAlphaGrid.size(); ++a) {
      for (int c = 0; c < kCellsGrid; ++c) {
        const int64_t accepts = population.At(v, a, c);
        if (accepts == 0) continue;
        const double recall = static_cast<double>(positives.At(v, a, c)) / positive_count;
        const double precision =
            std::min(1.0, positive_rate * population_pairs * recall / static_cast<double>(accepts));
        const double f1 =
            precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0.0;
        points.push_back({v, a, c, precision, recall, f1, accepts});
        best = std::max(best, f1);
      }
    }
  }
  if (points.empty()) throw InputError("labels", "no pair of the sample is within the grid");
  best = -1;
  for (const Point& p : points) {
    if (p.precision >= min_precision) best = std::max(best, p.f1);
  }
  if (best < 0) {  // no point that precise: the most precise ones
    for (const Point& p : points) best = std::max(best, p.precision);
    min_precision = best;
    best = -1;
    for (const Point& p : points) {
      if (p.precision >= min_precision) best = std::max(best, p.f1);
    }
  }
  // Near the best F1, the smallest alpha bound (fewest pixel reads), then the best F1.
  const Point* chosen = nullptr;
  for (const Point& p : points) {
    if (p.precision < min_precision || p.f1 < best - options.f1_tolerance) continue;
    if (!chosen || p.a < chosen->a || (p.a == chosen->a && p.f1 > chosen->f1)) chosen = &p;
  }
  ColourCellsFit fit;
  fit.max_velocity_mps = positives.velocity()[chosen->v];
  fit.max_alpha_cells = kAlphaGrid[chosen->a];
  fit.max_colour_cells = chosen->c;
  fit.precision = chosen->precision;
  fit.recall = chosen->recall;
  fit.f1 = chosen->f1;
  fit.accepts_per_sprite = static_cast<double>(chosen->accepts) / sprites_per_row;
  fit.positive_rate = positive_rate;
  fit.sampled_pairs = static_cast<int64_t>(population_pairs);
  fit.positives = positive_count;

  w->stage2_variant = Stage2Variant::kColourCells;
  w->colour_cells_max_velocity_mps = fit.max_velocity_mps;
  w->colour_cells_max_alpha_cells = fit.max_alpha_cells;
  w->colour_cells_max_cells = fit.max_colour_cells;
  // Stage 1: the velocity ball, u1 = 1 / scale_0 and T1 = (mean_0 - bias * scale_0) / scale_0
  // = the bound (a hair wider, so rounding never drops a pair the velocity test passes).
  w->stage1_weights = {1, 0, 0, 0};
  w->stage1_bias =
      (w->feature_mean[0] - fit.max_velocity_mps * (1 + 1e-9)) / w->feature_scale[0] - 1e-12;
  return fit;
}

}  // namespace

bool ColourCellsFitOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(rows, AtLeast(1), "rows", "at least 1 sprite");
  check.Within(threads, AtLeast(1), "threads", "at least 1 thread");
  check(std::isfinite(f1_tolerance) && f1_tolerance >= 0 && f1_tolerance <= 1, "f1_tolerance",
        "expected a number from 0 to 1, got " + OptionProblems::Num(f1_tolerance));
  return check.ok();
}

ColourCellsMeasure MeasureColourCells(const SpriteStore& store, int32_t i, int32_t j) {
  ColourCellsMeasure m;
  m.velocity_mps = CheapDiff(store.cheap(i), store.cheap(j))[0];
  const int stride = store.window().PlaneStride();
  m.alpha_cells =
      static_cast<double>(SumAlphaDifference(store.image(i), store.image(j), stride)) / 255.0;
  m.colour_cells = ColourCellCount(store.image(i), store.image(j), stride);
  return m;
}

ColourCellsFit FitColourCells(const SpriteStore& store,
                              std::span<const ColourCellsMeasure> positives, double positive_rate,
                              const ColourCellsFitOptions& options, TransitionWeights* weights) {
  CheckOptions(options);
  if (positives.empty()) throw InputError("labels", "no accepted pair: nothing to fit");
  if (!(positive_rate > 0 && positive_rate < 1)) {
    throw InputError("labels", "the positive rate must lie in (0, 1), got " +
                                   OptionProblems::Num(positive_rate));
  }
  GridCounts pos;
  for (const ColourCellsMeasure& m : positives) {
    if (size_t at; pos.Bin(m, &at)) pos.Add(at);
  }
  const int32_t n = store.size();
  if (n < 2) throw InputError("sprites", "at least two sprites are needed to fit");
  std::vector<int32_t> rows(n);
  std::iota(rows.begin(), rows.end(), 0);
  std::mt19937_64 rng(options.seed);
  std::shuffle(rows.begin(), rows.end(), rng);
  rows.resize(std::min<int32_t>(n, options.rows));
  GridCounts population;
  std::mutex merge;
  std::atomic<size_t> cursor{0};
  const double top_velocity = population.velocity().back();
  auto work = [&] {
    GridCounts local;
    for (size_t r; (r = cursor.fetch_add(1)) < rows.size();) {
      const int32_t i = rows[r];
      for (int32_t j = 0; j < n; ++j) {
        if (j == i) continue;
        if (CheapDiff(store.cheap(i), store.cheap(j))[0] > top_velocity) continue;
        if (size_t at; local.Bin(MeasureColourCells(store, i, j), &at)) local.Add(at);
      }
    }
    std::lock_guard<std::mutex> lock(merge);
    population.Merge(local);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < options.threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  const double pairs = static_cast<double>(rows.size()) * (n - 1);
  // accepts per sprite: each sampled row's accepts are its partners
  return Choose(std::move(pos), static_cast<int64_t>(positives.size()), std::move(population),
                pairs, positive_rate, options, static_cast<double>(rows.size()), weights);
}

ColourCellsFit FitColourCellsOnLabels(std::span<const ColourCellsMeasure> positives,
                                      std::span<const ColourCellsMeasure> negatives,
                                      const ColourCellsFitOptions& options,
                                      TransitionWeights* weights) {
  CheckOptions(options);
  if (positives.empty() || negatives.empty())
    throw InputError("labels", "both accepted and rejected pairs are needed to fit");
  GridCounts pos, all;
  for (const ColourCellsMeasure& m : positives) {
    if (size_t at; pos.Bin(m, &at)) {
      pos.Add(at);
      all.Add(at);
    }
  }
  for (const ColourCellsMeasure& m : negatives) {
    if (size_t at; all.Bin(m, &at)) all.Add(at);
  }
  const double total = static_cast<double>(positives.size() + negatives.size());
  const double rate = static_cast<double>(positives.size()) / total;
  ColourCellsFit fit = Choose(std::move(pos), static_cast<int64_t>(positives.size()),
                              std::move(all), total, rate, options, total, weights);
  fit.accepts_per_sprite = -1;  // not a population: no per-sprite figure
  return fit;
}

ColourCellsFit FitColourCellsOnTruth(std::span<const ColourCellsMeasure> units,
                                     std::span<const uint8_t> truth, int64_t true_total,
                                     double min_precision, const ColourCellsFitOptions& options,
                                     TransitionWeights* weights) {
  CheckOptions(options);
  if (units.size() != truth.size())
    throw InputError("truth", "the units and their truth differ in number");
  if (true_total <= 0) throw InputError("truth", "no true unit: nothing to fit");
  GridCounts pos, all;
  for (size_t k = 0; k < units.size(); ++k) {
    if (size_t at; all.Bin(units[k], &at)) {
      all.Add(at);
      if (truth[k]) pos.Add(at);
    }
  }
  // rate * pairs * recall = true accepts: rate = true_total / pairs, and pairs cancels.
  const double pairs = static_cast<double>(std::max<size_t>(units.size(), true_total));
  ColourCellsFit fit =
      Choose(std::move(pos), true_total, std::move(all), pairs,
             static_cast<double>(true_total) / pairs, options, 1.0, weights, min_precision);
  fit.accepts_per_sprite = -1;  // no population of sprites: the caller knows its rows
  return fit;
}

}  // namespace ss
