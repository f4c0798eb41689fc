#include "animate/skeleton/cost_rows.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "core/float8.h"
#include "core/target_clones.h"

// GCC notes that 32-byte vector arguments change the ABI without AVX; these helpers are
// inline and never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace ss {

DenseCostRows::DenseCostRows(int targets, int sources, std::vector<float> values)
    : targets_(targets), sources_(sources), values_(std::move(values)) {
  if (targets < 0 || sources <= 0 || values_.size() != static_cast<size_t>(targets) * sources) {
    throw InputError("cost matrix", "expected " + std::to_string(targets) + " x " +
                                        std::to_string(sources) + " values, got " +
                                        std::to_string(values_.size()));
  }
}

float CostRows::At(int t, int s) const {
  std::vector<float> row(sources());
  Compute(t, 1, row.data());
  return row[s];
}

void DenseCostRows::Compute(int t0, int n, float* out) const {
  std::memcpy(out, values_.data() + static_cast<size_t>(t0) * sources_,
              sizeof(float) * n * sources_);
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kLanes = 8;   // floats per vector
constexpr int kChunk = 16;  // source frames per kernel step (two vectors)
constexpr int kTile = 6;    // complete target frames per kernel step

using float8::Load;
using float8::Store;
using float8::v8f;

inline v8f ClampPositive(v8f v) { return v > 0 ? v : v8f{}; }

// (The t loops are unrolled explicitly: at -O2 GCC otherwise keeps acc0/acc1 in memory.)
// out[t][s] = na[t] + nb[s] + sum_k a[t][k] * b[k][s] for TB targets and one chunk of
// kChunk sources starting at s (`b` the chunk's packed features [k][kChunk], `nb` offset by s).
template <int TB>
__attribute__((always_inline)) inline void DenseChunk(const float* b, int dim, const float* nb,
                                                      const float* a, const float* na,
                                                      float* const* out) {
  v8f acc0[TB], acc1[TB];
  const v8f nb0 = Load(nb), nb1 = Load(nb + kLanes);
#pragma GCC unroll 8
  for (int t = 0; t < TB; ++t) {
    acc0[t] = nb0 + na[t];
    acc1[t] = nb1 + na[t];
  }
  for (int k = 0; k < dim; ++k) {
    const v8f b0 = Load(b + k * kChunk), b1 = Load(b + k * kChunk + kLanes);
#pragma GCC unroll 8
    for (int t = 0; t < TB; ++t) {
      const float at = a[t * dim + k];
      acc0[t] += b0 * at;
      acc1[t] += b1 * at;
    }
  }
#pragma GCC unroll 8
  for (int t = 0; t < TB; ++t) {
    Store(out[t], ClampPositive(acc0[t]));
    Store(out[t] + kLanes, ClampPositive(acc1[t]));
  }
}

template <int TB>
__attribute__((always_inline)) inline void DenseRows(const float* b, int dim, const float* nb,
                                                     const float* a, const float* na,
                                                     float* const* rows, int count) {
  float* out[TB];
  alignas(32) float tail[TB][kChunk];
  for (int s = 0; s < count; s += kChunk) {
    const bool full = s + kChunk <= count;
    for (int t = 0; t < TB; ++t) out[t] = full ? rows[t] + s : tail[t];
    DenseChunk<TB>(b + static_cast<size_t>(s) * dim, dim, nb + s, a, na, out);
    if (!full) {
      for (int t = 0; t < TB; ++t) std::memcpy(rows[t] + s, tail[t], sizeof(float) * (count - s));
    }
  }
}

// Complete targets against every source: see DenseChunk. `b` is the packed block of the
// first source (a multiple of kChunk). 1 <= tb <= kTile.
SS_TARGET_CLONES("arch=x86-64-v3", "default")
void DenseKernel(const float* b, int dim, const float* nb, const float* a, const float* na, int tb,
                 float* const* rows, int count) {
  switch (tb) {
    case 1:
      DenseRows<1>(b, dim, nb, a, na, rows, count);
      break;
    case 2:
      DenseRows<2>(b, dim, nb, a, na, rows, count);
      break;
    case 3:
      DenseRows<3>(b, dim, nb, a, na, rows, count);
      break;
    case 4:
      DenseRows<4>(b, dim, nb, a, na, rows, count);
      break;
    case 5:
      DenseRows<5>(b, dim, nb, a, na, rows, count);
      break;
    default:
      DenseRows<kTile>(b, dim, nb, a, na, rows, count);
      break;
  }
}

// One target with missing terms: out[s] = sum over its features k of w[k] (a[k] - b[k][s])^2
// (`b` packed as for DenseKernel, `dim` features a source).
// The body of SparseKernel, inlined into each of its clones. (Its own function, as DenseRows is
// DenseKernel's: a clone built for AVX may not call Load or Store, built without, with a vector
// argument or result; clang refuses it as an ABI change, GCC let it pass.)
__attribute__((always_inline)) inline void SparseRow(const float* b, int dim, const int* features,
                                                     int nfeatures, const float* w, const float* a,
                                                     float* row, int count) {
  alignas(32) float tail[kLanes];
  // Up to `count` only: the last lanes of the padding may lie wholly past it (a negative
  // tail length here once overwrote the row).
  for (int s = 0; s < count; s += kLanes) {
    v8f acc{};
    const float* chunk = b + static_cast<size_t>(s / kChunk) * dim * kChunk + s % kChunk;
    for (int f = 0; f < nfeatures; ++f) {
      const v8f d = Load(chunk + features[f] * kChunk) - a[f];
      acc += d * d * w[f];
    }
    if (s + kLanes <= count) {
      Store(row + s, acc);
    } else {
      Store(tail, acc);
      std::memcpy(row + s, tail, sizeof(float) * (count - s));
    }
  }
}

SS_TARGET_CLONES("arch=x86-64-v3", "default")
void SparseKernel(const float* b, int dim, const int* features, int nfeatures, const float* w,
                  const float* a, float* row, int count) {
  SparseRow(b, dim, features, nfeatures, w, a, row, count);
}

}  // namespace

DescriptorCostRows::DescriptorCostRows(const PoseDescriptors& targets,
                                       const PoseDescriptors& sources, float min_source_coverage)
    : targets_(&targets), sources_(&sources) {
  if (targets.layout.dim != sources.layout.dim || targets.layout.groups != sources.layout.groups) {
    throw InputError(
        "skeletons",
        "targets and sources have different descriptors (skeletons or options differ)");
  }
  const DescriptorLayout& layout = sources.layout;
  const int count = sources.count;
  padded_ = (count + kChunk - 1) / kChunk * kChunk;
  source_features_.assign(static_cast<size_t>(layout.dim) * padded_, 0.0f);
  for (int k = 0; k < layout.dim; ++k) {
    for (int s = 0; s < count; ++s) {
      source_features_[(static_cast<size_t>(s / kChunk) * layout.dim + k) * kChunk + s % kChunk] =
          sources.feature(k, s);
    }
  }
  source_norm_.assign(padded_, 0.0f);
  for (int s = 0; s < count; ++s) {
    if (sources.coverage(s) < min_source_coverage || sources.present_weight[s] <= 0) {
      excluded_.push_back(s);
      continue;
    }
    if (!sources.complete(s)) incomplete_.push_back(s);
    double norm = 0;
    for (int k = 0; k < layout.dim; ++k) {
      const double v = sources.feature(k, s);
      norm += layout.feature_weight[k] * v * v;
    }
    source_norm_[s] = static_cast<float>(norm / layout.total_weight);
  }
}

void DescriptorCostRows::Compute(int t0, int n, float* out) const {
  const PoseDescriptors& tg = *targets_;
  const PoseDescriptors& src = *sources_;
  const DescriptorLayout& layout = tg.layout;
  const int count = src.count;
  const int dim = layout.dim;
  std::vector<int> dense;  // complete targets of this block
  for (int t = t0; t < t0 + n; ++t) {
    float* row = out + static_cast<size_t>(t - t0) * count;
    if (tg.complete(t)) {
      dense.push_back(t);  // below, a few targets at a time
      continue;
    }
    if (tg.present_weight[t] <= 0) {
      std::fill(row, row + count, 0.0f);  // nothing to match: every source is as good
    } else {
      std::vector<int> features;
      std::vector<float> w, a;
      for (int k = 0; k < dim; ++k) {
        if (!tg.has(layout.feature_group[k], t)) continue;
        features.push_back(k);
        w.push_back(layout.feature_weight[k] / tg.present_weight[t]);
        a.push_back(tg.feature(k, t));
      }
      SparseKernel(source_features_.data(), dim, features.data(), static_cast<int>(features.size()),
                   w.data(), a.data(), row, count);
    }
    for (int s : incomplete_) row[s] = PoseCost(tg, t, src, s);
    for (int s : excluded_) row[s] = kInf;
  }
  // Every dense target's weighted features first; then source blocks outer and target tiles
  // inner, so a block of source features (kSourceBlock x dim floats) is read from memory
  // once per call and stays in cache for all the tiles, instead of once per tile.
  const size_t nd = dense.size();
  std::vector<float> a(nd * dim), na(nd);
  std::vector<float*> all_rows(nd);
  for (size_t i = 0; i < nd; ++i) {
    const int t = dense[i];
    double norm = 0;
    for (int k = 0; k < dim; ++k) {
      const double v = tg.feature(k, t);
      norm += layout.feature_weight[k] * v * v;
      a[i * dim + k] =
          static_cast<float>(-2.0 * layout.feature_weight[k] * v / layout.total_weight);
    }
    na[i] = static_cast<float>(norm / layout.total_weight);
    all_rows[i] = out + static_cast<size_t>(t - t0) * count;
  }
  constexpr int kSourceBlock = 64 * kChunk;  // 1,024 sources: ~290 KiB of features for human14 (71)
  float* rows[kTile];
  for (int s0 = 0; s0 < count; s0 += kSourceBlock) {
    const int block = std::min(kSourceBlock, count - s0);
    for (size_t first = 0; first < nd; first += kTile) {
      const int tb = static_cast<int>(std::min<size_t>(kTile, nd - first));
      for (int i = 0; i < tb; ++i) rows[i] = all_rows[first + i] + s0;
      DenseKernel(source_features_.data() + static_cast<size_t>(s0) * dim, dim,
                  source_norm_.data() + s0, a.data() + first * dim, na.data() + first, tb, rows,
                  block);
    }
  }
  for (size_t i = 0; i < nd; ++i) {
    const int t = dense[i];
    for (int s : incomplete_) all_rows[i][s] = PoseCost(tg, t, src, s);
    for (int s : excluded_) all_rows[i][s] = kInf;
  }
}

float DescriptorCostRows::At(int t, int s) const {
  if (std::binary_search(excluded_.begin(), excluded_.end(), s)) return kInf;
  if (targets_->present_weight[t] <= 0) return 0.0f;
  return PoseCost(*targets_, t, *sources_, s);
}

}  // namespace ss
