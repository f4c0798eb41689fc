// spritestation bench transitions-explore: which pair features can agree with the synthetic
// truth (same pose, every key point visible in either sprite within 4 mm = 1 px at 250
// px/m)? On a few thousand
// synthetic sprites (training set seed 1, test set seed 2), for every pair of sampled rows:
// candidate features at several comparison resolutions and alignments, then the best
// achievable pair-level and transition-level F1 (precision >= 0.85 and unconstrained) per
// feature and per feature set (non-negative logistic direction fitted on the training set,
// threshold swept on the test set: an optimistic upper bound of what a shipped threshold gets),
// AND-combinations of two thresholds, what the truth rejects among pairs whose silhouettes
// agree to the pixel, and the same figures against a truth with the feet unordered.
// Results and their reading: bench/RESULTS.md "transitions: what can agree with the truth".
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_registry.h"
#include "core/error.h"
#include "core/log.h"
#include "pipeline/transitions/classifier.h"
#include "pipeline/transitions/synthetic.h"
#include "pipeline/transitions/training.h"
#include "pipeline/transitions/truth_labels.h"

namespace ss::bench::transitions_explore_bench {
namespace {

struct Config {
  std::string name;
  ComparisonWindow window;
  bool body_frame = false;  // oracle: the window centred on the synthetic body centre
};

struct Image {
  int w = 0, h = 0;
  std::vector<uint8_t> a, r, g, b;
  // per alpha threshold (64, 128, 192): distance (quarter cells, capped 255) to the set, and
  // the set's boundary cells (inside, with a 4-neighbour outside)
  std::array<std::vector<uint8_t>, 3> dt;
  std::array<std::vector<uint16_t>, 3> boundary;
  CellBox box;
};

constexpr int kLevels[3] = {64, 128, 192};

// Exact squared Euclidean distance transform (Felzenszwalb & Huttenlocher), 1-D pass.
void Edt1d(const std::vector<double>& f, std::vector<double>& d, int n) {
  std::vector<int> v(n);
  std::vector<double> z(n + 1);
  int k = 0;
  v[0] = 0;
  z[0] = -1e30;
  z[1] = 1e30;
  for (int q = 1; q < n; ++q) {
    double s;
    while (true) {
      s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * q - 2.0 * v[k]);
      if (s <= z[k] && k > 0) {
        --k;
        continue;
      }
      break;
    }
    if (s <= z[k]) {  // k == 0
      v[0] = q;
      z[0] = -1e30;
      z[1] = 1e30;
      continue;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = 1e30;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = (q - v[k]) * (q - v[k]) + f[v[k]];
  }
}

// Distance (in cells, Euclidean) from every cell to the nearest cell with inside = 1.
std::vector<double> Distance(const std::vector<uint8_t>& inside, int w, int h) {
  const double inf = 1e20;
  std::vector<double> grid(static_cast<size_t>(w) * h);
  for (size_t k = 0; k < grid.size(); ++k) grid[k] = inside[k] ? 0 : inf;
  std::vector<double> f(std::max(w, h)), d(std::max(w, h));
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) f[y] = grid[y * w + x];
    Edt1d(f, d, h);
    for (int y = 0; y < h; ++y) grid[y * w + x] = d[y];
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) f[x] = grid[y * w + x];
    Edt1d(f, d, w);
    for (int x = 0; x < w; ++x) grid[y * w + x] = std::sqrt(d[x]);
  }
  return grid;
}

Image MakeImage(const SyntheticSprite& s, const Config& c, double px_per_m) {
  RgbaBillboard b = s.billboard;
  ComparisonWindow window = c.window;
  if (c.body_frame) {
    b.anchor_x_px = (b.width - 1) / 2.0;
    window.align = HorizontalAlignment::kContactPoint;
  }
  std::vector<uint8_t> img(window.ImageBytes());
  Image out;
  out.box = MakeComparisonImage(b, px_per_m, window, img.data());
  out.w = window.cells_x;
  out.h = window.cells_y;
  const int n = window.Cells(), stride = window.PlaneStride();
  out.a.assign(img.begin(), img.begin() + n);
  out.r.assign(img.begin() + stride, img.begin() + stride + n);
  out.g.assign(img.begin() + 2 * stride, img.begin() + 2 * stride + n);
  out.b.assign(img.begin() + 3 * stride, img.begin() + 3 * stride + n);
  for (int l = 0; l < 3; ++l) {
    std::vector<uint8_t> inside(n);
    for (int k = 0; k < n; ++k) inside[k] = out.a[k] >= kLevels[l];
    const auto dist = Distance(inside, out.w, out.h);
    out.dt[l].resize(n);
    for (int k = 0; k < n; ++k)
      out.dt[l][k] = static_cast<uint8_t>(std::min(255.0, std::round(4 * dist[k])));
    for (int y = 0; y < out.h; ++y) {
      for (int x = 0; x < out.w; ++x) {
        const int k = y * out.w + x;
        if (!inside[k]) continue;
        const bool edge = x == 0 || y == 0 || x == out.w - 1 || y == out.h - 1 || !inside[k - 1] ||
                          !inside[k + 1] || !inside[k - out.w] || !inside[k + out.w];
        if (edge) out.boundary[l].push_back(static_cast<uint16_t>(k));
      }
    }
  }
  return out;
}

// Features of one pair at one config (cell units converted to pixels with cell_px).
enum Feat {
  kL1,
  kSad,
  kLinf,
  kHaus64,
  kHaus128,
  kHaus192,
  kHausMean,
  kHausP90,
  kCount128,
  kColour,
  kBlob,
  kColBlob,
  kColCount,
  kNumFeat
};
const char* kFeatNames[kNumFeat] = {
    "alpha_l1", "alpha_sad_px2",   "alpha_linf",      "haus64",      "haus128",
    "haus192",  "haus_mean",       "haus128_p90",     "outliers1px", "colour_l1",
    "blob_px2", "colour_blob_px2", "colour_cells_px2"};

std::array<double, kNumFeat> PairFeats(const Image& i, const Image& j, double cell_w_px,
                                       double cell_h_px) {
  std::array<double, kNumFeat> f{};
  const int n = i.w * i.h;
  uint64_t sad = 0, weight = 0, wcol = 0;
  int linf = 0;
  for (int k = 0; k < n; ++k) {
    const int d = std::abs(int{i.a[k]} - int{j.a[k]});
    sad += d;
    linf = std::max(linf, d);
    const int w = std::min(i.a[k], j.a[k]);
    weight += w;
    wcol += static_cast<uint64_t>(w) *
            (std::abs(int{i.r[k]} - int{j.r[k]}) + std::abs(int{i.g[k]} - int{j.g[k]}) +
             std::abs(int{i.b[k]} - int{j.b[k]}));
  }
  const int area = BoxArea(UnionBox(i.box, j.box));
  f[kL1] = area ? sad / (255.0 * area) : 0;
  f[kSad] = sad / 255.0 * cell_w_px * cell_h_px;
  f[kLinf] = linf / 255.0;
  f[kColour] = weight ? wcol / (3.0 * weight) : 255;
  const double cell_px = std::sqrt(cell_w_px * cell_h_px);
  std::vector<int> hist(256, 0);
  for (int l = 0; l < 3; ++l) {
    int worst = 0, outliers = 0;
    for (uint16_t k : i.boundary[l]) {
      const int d = j.dt[l][k];
      worst = std::max(worst, d);
      if (l == 1) {
        ++hist[d];
        outliers += d * cell_px > 4 * 1.01;
      }
    }
    for (uint16_t k : j.boundary[l]) {
      const int d = i.dt[l][k];
      worst = std::max(worst, d);
      if (l == 1) {
        ++hist[d];
        outliers += d * cell_px > 4 * 1.01;
      }
    }
    f[kHaus64 + l] = worst / 4.0 * cell_px;
    if (l == 1) {
      f[kCount128] = outliers;
      const int total = static_cast<int>(i.boundary[1].size() + j.boundary[1].size());
      int acc = 0, q = 0;
      for (; q < 256; ++q) {
        acc += hist[q];
        if (acc >= 0.9 * total) break;
      }
      f[kHausP90] = q / 4.0 * cell_px;
    }
  }
  f[kHausMean] = (f[kHaus64] + f[kHaus128] + f[kHaus192]) / 3;
  // Largest 4-connected blob of cells with |dA| >= 96, in px^2 (only for small mismatches).
  if (f[kSad] < 400) {
    std::vector<uint8_t> mark(n, 0);
    std::vector<int> stack;
    double best = 0;
    for (int k = 0; k < n; ++k) mark[k] = std::abs(int{i.a[k]} - int{j.a[k]}) >= 96;
    for (int k = 0; k < n; ++k) {
      if (mark[k] != 1) continue;
      double sum = 0;
      stack.assign(1, k);
      mark[k] = 2;
      while (!stack.empty()) {
        const int c = stack.back();
        stack.pop_back();
        sum += std::abs(int{i.a[c]} - int{j.a[c]}) / 255.0;
        const int x = c % i.w, y = c / i.w;
        const int nb[4] = {x > 0 ? c - 1 : -1, x + 1 < i.w ? c + 1 : -1, y > 0 ? c - i.w : -1,
                           y + 1 < i.h ? c + i.w : -1};
        for (int q : nb) {
          if (q >= 0 && mark[q] == 1) {
            mark[q] = 2;
            stack.push_back(q);
          }
        }
      }
      best = std::max(best, sum);
    }
    f[kBlob] = best * cell_w_px * cell_h_px;
  } else {
    f[kBlob] = f[kSad];
  }
  {
    // Cells opaque in both whose colours differ by >= 90 (L1 over R, G, B): count and largest blob.
    std::vector<uint8_t> mark(n, 0);
    int count = 0;
    for (int k = 0; k < n; ++k) {
      mark[k] = i.a[k] >= 128 && j.a[k] >= 128 &&
                std::abs(int{i.r[k]} - int{j.r[k]}) + std::abs(int{i.g[k]} - int{j.g[k]}) +
                        std::abs(int{i.b[k]} - int{j.b[k]}) >=
                    90;
      count += mark[k];
    }
    std::vector<int> stack;
    int best = 0;
    for (int k = 0; k < n && count > best; ++k) {
      if (mark[k] != 1) continue;
      int sum = 0;
      stack.assign(1, k);
      mark[k] = 2;
      while (!stack.empty()) {
        const int c = stack.back();
        stack.pop_back();
        ++sum;
        const int x = c % i.w, y = c / i.w;
        const int nb[4] = {x > 0 ? c - 1 : -1, x + 1 < i.w ? c + 1 : -1, y > 0 ? c - i.w : -1,
                           y + 1 < i.h ? c + i.w : -1};
        for (int q : nb) {
          if (q >= 0 && mark[q] == 1) {
            mark[q] = 2;
            stack.push_back(q);
          }
        }
      }
      best = std::max(best, sum);
    }
    f[kColBlob] = best * cell_w_px * cell_h_px;
    f[kColCount] = count * cell_w_px * cell_h_px;
  }
  return f;
}

// Whether point k of a matched with point l of b is compared: visible in at least one.
bool Seen(const SpriteTruth& a, size_t k, const SpriteTruth& b, size_t l) {
  const auto& va = a.keypoint_visible;
  const auto& vb = b.keypoint_visible;
  return va.empty() || vb.empty() || va[k] || vb[l];
}

// KeypointDisplacement with the feet (points 4.. of the list) matched as an unordered set.
double PermDisplacement(const SpriteTruth& a, const SpriteTruth& b) {
  const auto& p = a.keypoints_m;
  const auto& q = b.keypoints_m;
  if (p.size() != q.size() || p.size() < 8) return INFINITY;
  double fixed = 0;
  for (size_t k = 0; k < 8; k += 2) {
    if (Seen(a, k / 2, b, k / 2))
      fixed = std::max(fixed, std::hypot(p[k] - q[k], p[k + 1] - q[k + 1]));
  }
  const int legs = static_cast<int>(p.size() - 8) / 2;
  std::vector<int> perm(legs);
  std::iota(perm.begin(), perm.end(), 0);
  double best = INFINITY;
  do {
    double worst = 0;
    for (int l = 0; l < legs; ++l) {
      if (!Seen(a, 4 + l, b, 4 + perm[l])) continue;
      worst = std::max(
          worst, std::hypot(p[8 + 2 * l] - q[8 + 2 * perm[l]], p[9 + 2 * l] - q[9 + 2 * perm[l]]));
    }
    best = std::min(best, worst);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return std::max(fixed, best);
}

struct Sweep {
  double f1 = 0, precision = 0, recall = 0, threshold = 0;  // best F1 with precision >= 0.85
  double f1_any = 0, p_any = 0, r_any = 0;                  // best F1 at any precision
};
// scores: lower = more alike; +inf never accepted. positives: total true (incl. never scored).
Sweep BestF1(std::vector<std::pair<double, uint8_t>> scored, int64_t positives) {
  std::sort(scored.begin(), scored.end());
  Sweep s;
  int64_t tp = 0, fp = 0;
  for (size_t k = 0; k < scored.size(); ++k) {
    if (!std::isfinite(scored[k].first)) break;
    tp += scored[k].second;
    fp += !scored[k].second;
    if (k + 1 < scored.size() && scored[k + 1].first == scored[k].first) continue;
    const double p = static_cast<double>(tp) / (tp + fp),
                 r = static_cast<double>(tp) / std::max<int64_t>(1, positives);
    const double f1 = p + r > 0 ? 2 * p * r / (p + r) : 0;
    if (f1 > s.f1_any) s.f1_any = f1, s.p_any = p, s.r_any = r;
    if (p >= 0.85 && f1 > s.f1)
      s.f1 = f1, s.precision = p, s.recall = r, s.threshold = scored[k].first;
  }
  return s;
}

// One data set: sprites, per-config images, and sampled rows with their successors.
struct Set {
  std::vector<SyntheticSprite> sprites;
  std::vector<std::vector<Image>> images;  // [config][sprite]
  std::vector<int32_t> prev, next;
};

Set MakeSet(int n, uint64_t seed, const std::vector<Config>& configs, double px_per_m,
            int threads) {
  Set s;
  SyntheticSpriteOptions o;
  o.frames = n / 2;
  o.seed = seed;
  s.sprites = MakeSyntheticSprites(o);
  const int m = static_cast<int>(s.sprites.size());
  s.prev.assign(m, -1);
  s.next.assign(m, -1);
  for (int k = 1; k < m; ++k) {
    if (s.sprites[k].clip == s.sprites[k - 1].clip) {
      s.prev[k] = k - 1;
      s.next[k - 1] = k;
    }
  }
  s.images.resize(configs.size());
  for (size_t c = 0; c < configs.size(); ++c) {
    s.images[c].resize(m);
    std::atomic<int> cursor{0};
    auto work = [&] {
      for (int k; (k = cursor.fetch_add(1)) < m;)
        s.images[c][k] = MakeImage(s.sprites[k], configs[c], px_per_m);
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
  }
  return s;
}

// Per pair row: every feature of every config + cheap diffs + paper six D.
struct Rows {
  std::vector<int32_t> rows;   // sampled i
  std::vector<int32_t> slot;   // sprite -> row slot or -1
  std::vector<int64_t> index;  // slot * m + j -> record or -1
  int m = 0;
  int64_t Find(int32_t i, int32_t j) const {
    const int32_t s = slot[i];
    return s < 0 ? -1 : index[static_cast<size_t>(s) * m + j];
  }
  std::vector<float> x;  // records x dims
  std::vector<uint8_t> truth;
  std::vector<float> displacement_mm;
  std::vector<uint8_t> truth_perm;  // legs matched as an unordered set
  int dims = 0;
};

int Run(const std::vector<std::string>& argv) {
  SetLogLevel("warn");
  int n = 6000, nrows = 150, threads = 2;
  bool all_resolutions = false;
  for (const std::string& t : argv) {
    if (t == "--") continue;
    if (t == "--all-resolutions") {
      all_resolutions = true;
      continue;
    }
    const auto eq = t.find('=');
    if (eq == std::string::npos)
      throw InputError("bench transitions-explore", "unknown argument '" + t + "'");
    const std::string key = t.substr(0, eq), value = t.substr(eq + 1);
    if (key == "--sprites")
      n = std::stoi(value);
    else if (key == "--rows")
      nrows = std::stoi(value);
    else if (key == "--threads")
      threads = std::stoi(value);
    else
      throw InputError("bench transitions-explore", "unknown argument '" + t + "'");
  }
  const double px_per_m = SyntheticSpriteOptions{}.px_per_m;
  std::vector<Config> configs;
  auto window = [](double cell_px_x, double cell_px_y, double wm, double hm) {
    ComparisonWindow w;
    w.width_m = wm;
    w.height_m = hm;
    w.cells_x = static_cast<int>(std::lround(wm * 250 / cell_px_x));
    w.cells_y = static_cast<int>(std::lround(hm * 250 / cell_px_y));
    return w;
  };
  configs.push_back({"shipped32x32", ComparisonWindow{}, false});
  if (all_resolutions) {
    configs.push_back({"4px", window(4, 4, 0.24, 0.18), false});
    configs.push_back({"2px", window(2, 2, 0.24, 0.18), false});
  }
  configs.push_back({"1px", window(1, 1, 0.24, 0.18), false});
  configs.push_back({"1px_contact", window(1, 1, 0.24, 0.18), false});
  configs.back().window.align = HorizontalAlignment::kContactPoint;
  configs.push_back({"1px_bodyframe(oracle)", window(1, 1, 0.24, 0.18), true});
  const int nc = static_cast<int>(configs.size());
  const TransitionClassifier paper(PaperWeights());  // the paper six as shipped before
  const TruthLabelOptions truth_options;

  auto collect = [&](const Set& s, uint64_t seed) {
    Rows r;
    const int m = static_cast<int>(s.sprites.size());
    std::mt19937_64 rng(seed);
    std::vector<int32_t> order(m);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<int32_t> want;
    for (int32_t i : order) {
      if (static_cast<int>(r.rows.size()) >= nrows) break;
      if (s.next[i] < 0) continue;
      r.rows.push_back(i);
      want.push_back(i);
      want.push_back(s.next[i]);
    }
    std::sort(want.begin(), want.end());
    want.erase(std::unique(want.begin(), want.end()), want.end());
    r.dims = 5 + nc * kNumFeat;  // 4 cheap + paper D, then per config
    // Prefilter: the shipped 32x32 alpha L1 <= 0.2 and cheap stage-2 part small (printed recall).
    std::vector<std::pair<int32_t, int32_t>> pairs;
    for (int32_t i : want) {
      for (int32_t j = 0; j < m; ++j) {
        if (j == i) continue;
        const Image& a = s.images[0][i];
        const Image& b = s.images[0][j];
        uint64_t sad = 0;
        for (size_t k = 0; k < a.a.size(); ++k) sad += std::abs(int{a.a[k]} - int{b.a[k]});
        const double l1 = sad / (255.0 * std::max(1, BoxArea(UnionBox(a.box, b.box))));
        const bool truth = TruthAccepts(s.sprites[i].truth, s.sprites[j].truth, truth_options);
        if (l1 <= 0.12 || truth) pairs.push_back({i, j});
      }
    }
    r.x.assign(pairs.size() * r.dims, 0);
    r.truth.resize(pairs.size());
    r.displacement_mm.resize(pairs.size());
    r.truth_perm.resize(pairs.size());
    std::atomic<size_t> cursor{0};
    auto work = [&] {
      for (size_t p; (p = cursor.fetch_add(1)) < pairs.size();) {
        const auto [i, j] = pairs[p];
        float* x = &r.x[p * r.dims];
        const CheapDifference cd = CheapDiff(s.sprites[i].cheap, s.sprites[j].cheap);
        for (int k = 0; k < 4; ++k) x[k] = cd[k];
        // paper six on the shipped window
        {
          const Image& a = s.images[0][i];
          const Image& b = s.images[0][j];
          const auto f = PairFeats(a, b, 1.875, 1.25);
          PixelDifference pd{f[kL1], f[kColour]};
          x[4] = paper.Distance(MakePairFeatures(cd, pd));
        }
        for (int c = 0; c < nc; ++c) {
          const ComparisonWindow& w = configs[c].window;
          const auto f = PairFeats(s.images[c][i], s.images[c][j], w.width_m * 250 / w.cells_x,
                                   w.height_m * 250 / w.cells_y);
          for (int k = 0; k < kNumFeat; ++k) x[5 + c * kNumFeat + k] = static_cast<float>(f[k]);
        }
        r.truth[p] = TruthAccepts(s.sprites[i].truth, s.sprites[j].truth, truth_options);
        r.displacement_mm[p] =
            s.sprites[i].truth.pose == s.sprites[j].truth.pose
                ? static_cast<float>(1e3 *
                                     KeypointDisplacement(s.sprites[i].truth, s.sprites[j].truth))
                : 1e6f;
        r.truth_perm[p] = s.sprites[i].truth.pose == s.sprites[j].truth.pose &&
                          PermDisplacement(s.sprites[i].truth, s.sprites[j].truth) <=
                              truth_options.max_keypoint_displacement_m;
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    r.m = m;
    r.slot.assign(m, -1);
    for (size_t k = 0; k < want.size(); ++k) r.slot[want[k]] = static_cast<int32_t>(k);
    r.index.assign(want.size() * m, -1);
    for (size_t p = 0; p < pairs.size(); ++p)
      r.index[static_cast<size_t>(r.slot[pairs[p].first]) * m + pairs[p].second] =
          static_cast<int64_t>(p);
    return r;
  };

  const auto t0 = std::chrono::steady_clock::now();
  const Set train = MakeSet(n, 1, configs, px_per_m, threads);
  const Set test = MakeSet(n, 2, configs, px_per_m, threads);
  const Rows rtrain = collect(train, 11);
  const Rows rtest = collect(test, 12);
  std::printf(
      "explore: %d sprites a set (train seed 1, test seed 2), %d rows (+ successors); %zu / %zu "
      "prefiltered "
      "pairs; %.1f s\n",
      n, nrows, rtrain.truth.size(), rtest.truth.size(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());

  // Truth totals over all pairs of the sampled rows (pairs outside the prefilter are false).
  auto positives_pairs = [&](const Set& s, const Rows& r) {
    int64_t pos = 0, kept = 0;
    for (int32_t i : r.rows) {
      for (int32_t j = 0; j < static_cast<int32_t>(s.sprites.size()); ++j) {
        if (j != i && TruthAccepts(s.sprites[i].truth, s.sprites[j].truth, truth_options)) ++pos;
      }
    }
    for (int32_t i : r.rows) {
      for (int32_t j = 0; j < static_cast<int32_t>(s.sprites.size()); ++j) {
        const int64_t p = r.Find(i, j);
        kept += p >= 0 && r.truth[p];
      }
    }
    return std::pair<int64_t, int64_t>(pos, kept);
  };
  const auto [test_pos, test_pos_kept] = positives_pairs(test, rtest);
  std::printf("test rows: %lld true pairs (%.1f partners a row), the prefilter keeps %lld\n",
              static_cast<long long>(test_pos), static_cast<double>(test_pos) / rtest.rows.size(),
              static_cast<long long>(test_pos_kept));

  // Evaluation of a score function over the test rows: pair level and transition level.
  bool use_perm = false;
  auto truth_of = [&](int32_t i, int32_t j) {
    if (!use_perm) return TruthAccepts(test.sprites[i].truth, test.sprites[j].truth, truth_options);
    return test.sprites[i].truth.pose == test.sprites[j].truth.pose &&
           PermDisplacement(test.sprites[i].truth, test.sprites[j].truth) <=
               truth_options.max_keypoint_displacement_m;
  };
  auto evaluate = [&](const std::function<double(const float*)>& score) {
    int64_t pair_pos = 0;
    const auto& rtruth = use_perm ? rtest.truth_perm : rtest.truth;
    std::vector<std::pair<double, uint8_t>> pair_scores, trans_scores;
    int64_t trans_pos = 0;
    const int m = static_cast<int>(test.sprites.size());
    auto sc = [&](int32_t i, int32_t j) -> std::pair<double, bool> {
      const int64_t p = rtest.Find(i, j);
      if (p < 0) return {INFINITY, truth_of(i, j)};
      return {score(&rtest.x[p * rtest.dims]), rtruth[p] != 0};
    };
    for (int32_t i : rtest.rows) {
      for (int32_t j = 0; j < m; ++j) {
        if (j == i) continue;
        const int64_t p = rtest.Find(i, j);
        if (p >= 0) pair_scores.push_back({score(&rtest.x[p * rtest.dims]), rtruth[p]});
        pair_pos += p >= 0 ? rtruth[p] : truth_of(i, j);
      }
      const int32_t s = test.next[i];
      for (int32_t j = 0; j < m; ++j) {
        const int32_t q = test.prev[j];
        if (q < 0 || j == i || j == s) continue;
        const auto a = sc(i, j);
        if (!std::isfinite(a.first) && !a.second) continue;
        const auto b = sc(s, j);
        const auto c = sc(i, q);
        const bool truth = a.second && b.second && c.second;
        trans_pos += truth;
        const double v = std::max({a.first, b.first, c.first});
        if (std::isfinite(v)) trans_scores.push_back({v, truth});
      }
    }
    return std::pair<Sweep, Sweep>(BestF1(pair_scores, pair_pos), BestF1(trans_scores, trans_pos));
  };
  auto print = [&](const std::string& name, const std::pair<Sweep, Sweep>& r) {
    std::printf(
        "  %-46s pairs F1 %.3f (P %.3f R %.3f) [any P: %.3f]   transitions F1 %.3f (P %.3f R %.3f) "
        "[any P: %.3f]\n",
        name.c_str(), r.first.f1, r.first.precision, r.first.recall, r.first.f1_any, r.second.f1,
        r.second.precision, r.second.recall, r.second.f1_any);
  };

  std::printf("\n== single features (threshold swept on test) ==\n");
  print("paper six, shipped weights (D)",
        evaluate([](const float* x) { return static_cast<double>(x[4]); }));
  for (int c = 0; c < nc; ++c) {
    for (int k = 0; k < kNumFeat; ++k) {
      const int col = 5 + c * kNumFeat + k;
      print(configs[c].name + " " + kFeatNames[k],
            evaluate([col](const float* x) { return static_cast<double>(x[col]); }));
    }
  }

  // Feature sets: non-negative balanced logistic on train (prefiltered pairs), standardized.
  auto fit = [&](const std::vector<int>& cols) {
    const size_t np = rtrain.truth.size();
    const int d = static_cast<int>(cols.size());
    std::vector<double> mean(d, 0), sd(d, 0);
    for (size_t p = 0; p < np; ++p) {
      for (int k = 0; k < d; ++k) mean[k] += rtrain.x[p * rtrain.dims + cols[k]];
    }
    for (int k = 0; k < d; ++k) mean[k] /= np;
    for (size_t p = 0; p < np; ++p) {
      for (int k = 0; k < d; ++k)
        sd[k] += std::pow(rtrain.x[p * rtrain.dims + cols[k]] - mean[k], 2);
    }
    for (int k = 0; k < d; ++k) sd[k] = std::sqrt(sd[k] / np) + 1e-12;
    std::vector<double> z(np * d);
    for (size_t p = 0; p < np; ++p) {
      for (int k = 0; k < d; ++k)
        z[p * d + k] = (rtrain.x[p * rtrain.dims + cols[k]] - mean[k]) / sd[k];
    }
    LogisticOptions lo;
    lo.max_iterations = 3000;
    const LinearModel model = FitLogistic(z, d, rtrain.truth, lo);
    std::vector<double> u(d);
    for (int k = 0; k < d; ++k) u[k] = model.weights[k] / sd[k];
    return [u, cols](const float* x) {
      double s = 0;
      for (size_t k = 0; k < cols.size(); ++k) s += u[k] * x[cols[k]];
      return s;
    };
  };
  auto col = [&](int c, int k) { return 5 + c * kNumFeat + k; };
  std::printf(
      "\n== feature sets (non-negative logistic direction from train, threshold swept on test) "
      "==\n");
  print("paper six refit (cheap4 + 32x32 alpha_l1, colour)",
        evaluate(fit({0, 1, 2, 3, col(0, kL1), col(0, kColour)})));
  for (int c = 0; c < nc; ++c) {
    print(configs[c].name + ": cheap4 + l1 + colour",
          evaluate(fit({0, 1, 2, 3, col(c, kL1), col(c, kColour)})));
    print(configs[c].name + ": cheap4 + haus128 + haus_mean",
          evaluate(fit({0, 1, 2, 3, col(c, kHaus128), col(c, kHausMean)})));
    print(configs[c].name + ": cheap4 + hausmean + l1 + colour + blob",
          evaluate(
              fit({0, 1, 2, 3, col(c, kHausMean), col(c, kL1), col(c, kColour), col(c, kBlob)})));
    std::vector<int> all = {0, 1, 2, 3};
    for (int k = 0; k < kNumFeat; ++k) all.push_back(col(c, k));
    print(configs[c].name + ": cheap4 + all", evaluate(fit(all)));
  }
  // AND of thresholds (score = max_k x_k / t_k): a max-type combination like the truth's.
  auto and_of = [&](const std::vector<int>& cols, const std::vector<double>& scales) {
    return [cols, scales](const float* x) {
      double s = 0;
      for (size_t k = 0; k < cols.size(); ++k) s = std::max(s, x[cols[k]] / scales[k]);
      return s;
    };
  };
  const int cc = nc - 2;  // 1px_contact
  const int cf = nc - 3;  // 1px centroid
  struct Named {
    std::string name;
    int col;
    double unit;  // a typical threshold
  };
  const std::vector<Named> cands = {{"velocity", 0, 0.05},
                                    {"contact alpha_linf", col(cc, kLinf), 0.5},
                                    {"contact haus_mean", col(cc, kHausMean), 1.0},
                                    {"contact blob", col(cc, kBlob), 2.0},
                                    {"contact colour_blob", col(cc, kColBlob), 2.0},
                                    {"contact colour_cells", col(cc, kColCount), 4.0},
                                    {"centroid colour_blob", col(cf, kColBlob), 2.0},
                                    {"contact alpha_l1", col(cc, kL1), 0.03}};
  {
    // What the truth rejects among pairs whose silhouettes agree to the pixel (1px contact-aligned
    // haus_mean <= 0.5 px, alpha_linf <= 0.5) and whose velocities agree (<= 0.05 m/s).
    int64_t total = 0, pos = 0, pose = 0, legs = 0;
    std::array<int64_t, 10> worst_point{};
    std::vector<double> disp;
    for (size_t p = 0; p < rtest.truth.size(); ++p) {
      const float* x = &rtest.x[p * rtest.dims];
      if (!(x[col(nc - 2, kHausMean)] <= 1.0 && x[col(nc - 2, kLinf)] <= 0.8 && x[0] <= 0.05))
        continue;
      ++total;
      if (rtest.truth[p]) {
        ++pos;
        continue;
      }
      if (rtest.displacement_mm[p] >= 1e5f) {
        ++pose;
        continue;
      }
      if (rtest.truth_perm[p]) {
        ++legs;
        continue;
      }
      disp.push_back(rtest.displacement_mm[p]);
    }
    // which key point is worst, for the rest (recomputed from the sprites of the rows)
    for (int32_t i : rtest.rows) {
      for (int32_t j = 0; j < static_cast<int32_t>(test.sprites.size()); ++j) {
        const int64_t p = rtest.Find(i, j);
        if (p < 0 || rtest.truth[p] || rtest.truth_perm[p] || rtest.displacement_mm[p] >= 1e5f)
          continue;
        const float* x = &rtest.x[p * rtest.dims];
        if (!(x[col(nc - 2, kHausMean)] <= 1.0 && x[col(nc - 2, kLinf)] <= 0.8 && x[0] <= 0.05))
          continue;
        const auto& a = test.sprites[i].truth.keypoints_m;
        const auto& b = test.sprites[j].truth.keypoints_m;
        size_t arg = 0;
        double w = -1;
        for (size_t k = 0; k < a.size(); k += 2) {
          if (!Seen(test.sprites[i].truth, k / 2, test.sprites[j].truth, k / 2)) continue;
          const double d = std::hypot(a[k] - b[k], a[k + 1] - b[k + 1]);
          if (d > w) w = d, arg = k / 2;
        }
        ++worst_point[std::min<size_t>(arg, 9)];
      }
    }
    std::sort(disp.begin(), disp.end());
    std::printf(
        "\n== pairs whose silhouettes agree to the pixel (contact haus_mean <= 1 px, alpha_linf <= "
        "0.8, "
        "velocity <= 0.05 m/s), sampled test rows ==\n");
    std::printf(
        "  %lld pairs: %lld true; false because: pose label differs %lld, only the feet's "
        "identities differ "
        "%lld, key points moved %zu (median %.1f mm, p90 %.1f mm); worst point of those: head "
        "%lld, right %lld, "
        "left %lld, top %lld, feet %lld/%lld/%lld/%lld\n",
        static_cast<long long>(total), static_cast<long long>(pos), static_cast<long long>(pose),
        static_cast<long long>(legs), disp.size(), disp.empty() ? 0.0 : disp[disp.size() / 2],
        disp.empty() ? 0.0 : disp[disp.size() * 9 / 10], static_cast<long long>(worst_point[0]),
        static_cast<long long>(worst_point[1]), static_cast<long long>(worst_point[2]),
        static_cast<long long>(worst_point[3]), static_cast<long long>(worst_point[4]),
        static_cast<long long>(worst_point[5]), static_cast<long long>(worst_point[6]),
        static_cast<long long>(worst_point[7]));
  }
  std::printf("\n== AND of two thresholds (best ratio on test) ==\n");
  for (size_t a = 0; a < cands.size(); ++a) {
    for (size_t b = a + 1; b < cands.size(); ++b) {
      std::pair<Sweep, Sweep> best;
      double best_ratio = 0;
      for (double ratio : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0}) {
        const auto r =
            evaluate(and_of({cands[a].col, cands[b].col}, {cands[a].unit, cands[b].unit * ratio}));
        if (r.second.f1 > best.second.f1) best = r, best_ratio = ratio;
      }
      print(cands[a].name + " & " + cands[b].name + " x" + std::to_string(best_ratio).substr(0, 4),
            best);
      // The thresholds of the best transitions F1: x_a <= t * unit_a AND x_b <= t * unit_b * ratio.
      std::printf(
          "    thresholds (transitions' best): %s <= %.4g, %s <= %.4g; (pairs' best): %.4g, %.4g\n",
          cands[a].name.c_str(), best.second.threshold * cands[a].unit, cands[b].name.c_str(),
          best.second.threshold * cands[b].unit * best_ratio, best.first.threshold * cands[a].unit,
          best.first.threshold * cands[b].unit * best_ratio);
    }
  }
  std::printf(
      "\n== against a truth with the feet matched as an unordered set (legs' identities are not "
      "visible) ==\n");
  use_perm = true;
  print("original truth as a classifier", evaluate([&](const float* x) {
          const size_t p = (x - rtest.x.data()) / rtest.dims;
          return rtest.truth[p] ? 0.0 : INFINITY;
        }));
  print("paper six, shipped weights (D)",
        evaluate([](const float* x) { return static_cast<double>(x[4]); }));
  for (const Named& c : cands) {
    const int cl = c.col;
    print(c.name, evaluate([cl](const float* x) { return static_cast<double>(x[cl]); }));
  }
  std::vector<int> all = {0, 1, 2, 3};
  for (int k = 0; k < kNumFeat; ++k) all.push_back(col(cc, k));
  print("1px_contact: cheap4 + all (fit on original truth)", evaluate(fit(all)));
  return 0;
}

const bool registered = RegisterSuite({"transitions-explore",
                                       "which pair features agree with the synthetic truth: best "
                                       "F1 per feature, resolution and alignment "
                                       "[--sprites=N --rows=R --threads=T --all-resolutions]",
                                       &Run});

}  // namespace
}  // namespace ss::bench::transitions_explore_bench
