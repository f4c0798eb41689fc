#include "pipeline/key/chroma_keyer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/core/utility.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/options_binder.h"
#include "core/target_clones.h"
#include "pipeline/key/keyer_registry.h"
#include "pipeline/key/keying_config.h"

namespace ss {
namespace {

// Below this luma (of 255) the key of a training pixel is all noise.
constexpr double kMinTrainingLuma = 8.0;
// A cell is green (modelled and keyed) when at least this share of its training samples is.
constexpr double kMinGreenShare = 0.25;
// key_hi of a cell that is not green: no pixel there is ever keyed as subject
// (small enough, large enough to keep the kernel's float->int conversions in range).
constexpr float kNeverKey = -100.f;
// shadow_base of a cell that is not green: never a shadow.
constexpr float kNoShadow = -1000.f;
// A pixel whose mean alpha over the empty enclosure exceeds this is not green
// (the room behind a wall, a cable): it is never keyed.
constexpr int kUnkeyableAlpha = 16;

// The key of one pixel (docs/keying.md), in integer-friendly units: no
// branches and no floating-point min/max, so that loops of it vectorize.
inline PixelKey KeyPixel(int b, int g, int r, float key_hi, float gain, int32_t luma_floor,
                         float inv_luma, float shadow_base, int shadow_min) {
  const int luma4 = b + 2 * g + r;
  const float key4 =
      static_cast<float>(g - std::max(b, r)) / static_cast<float>(std::max(luma4, luma_floor));
  // Rounded by + 0.5 and truncation, not std::lround (a call, and no vectorizing): the values
  // below 0, where truncation rounds the wrong way, all end as 0 (the clamp, the shade test).
  // NOLINTBEGIN(bugprone-incorrect-roundings)
  const int alpha = std::clamp(static_cast<int>((key_hi - key4) * gain + 0.5f), 0, 255);
  const int dark = static_cast<int>(shadow_base - static_cast<float>(luma4) * inv_luma + 0.5f);
  // NOLINTEND(bugprone-incorrect-roundings)
  const int shade = dark >= shadow_min ? dark : 0;
  // shade * (255 - alpha) / 255, rounded: the shadow only shows where the subject does not.
  return {alpha, ((shade * (255 - alpha) + 128) * 257) >> 16};
}

// One row of an empty-enclosure frame, for the training statistics. Per pixel: its key added to
// `pixel_key`, and when it is green (key >= min_key, luma4 >= min_luma4) its luma4, key, key^2
// and a count added to the column accumulators (summed into cells per cell row, later). Written
// for the vectorizer: element-wise only, no reductions, no branches; cloned per instruction set
// as the keying rows are (the 3-byte de-interleave needs SSSE3).
SS_TARGET_CLONES("avx2", "ssse3", "default")
void TrainRow(const uint8_t* __restrict in, int width, float min_key, int min_luma4,
              float* __restrict pixel_key, int32_t* __restrict luma4_sum, float* __restrict key_sum,
              float* __restrict key2_sum, int32_t* __restrict count) {
  for (int x = 0; x < width; ++x) {
    const int b = in[3 * x], g = in[3 * x + 1], r = in[3 * x + 2];
    const int luma4 = b + 2 * g + r;
    // (G - max(R,B)) / max(luma, kMinTrainingLuma), luma = luma4 / 4
    const float key = 4.f * static_cast<float>(g - std::max(b, r)) /
                      static_cast<float>(std::max(luma4, min_luma4));
    pixel_key[x] += key;
    const bool green = (key >= min_key) & (luma4 >= min_luma4);  // & : no branch
    const int take = green ? 1 : 0;
    const auto weight = static_cast<float>(take);  // multiplied, not selected: no branch
    luma4_sum[x] += luma4 * take;
    key_sum[x] += key * weight;
    key2_sum[x] += key * key * weight;
    count[x] += take;
  }
}

// One row of an empty-enclosure frame keyed by the trained model: each pixel's alpha added to
// `alpha_sum` (a pixel the model keys on the empty enclosure is not green).
SS_TARGET_CLONES("avx2", "ssse3", "default")
void AlphaSumRow(const uint8_t* __restrict in, int width, const float* __restrict key_hi,
                 const float* __restrict gain, const int32_t* __restrict luma_floor,
                 const float* __restrict inv_luma, const float* __restrict shadow_base,
                 int shadow_min, uint32_t* __restrict alpha_sum) {
  for (int x = 0; x < width; ++x) {
    const PixelKey k = KeyPixel(in[3 * x], in[3 * x + 1], in[3 * x + 2], key_hi[x], gain[x],
                                luma_floor[x], inv_luma[x], shadow_base[x], shadow_min);
    alpha_sum[x] += static_cast<uint32_t>(k.alpha);
  }
}

}  // namespace

bool ChromaKeyerOptions::IsValid(std::string* why) const {
  const ChromaKeyerOptions& o = *this;
  OptionProblems check(why);
  check.Within(o.noise_z, AtLeast(0), "noise_z", "a number >= 0");
  check.Within(o.min_margin, FromUpTo(0, 1), "min_margin", "a fraction >= 0, < 1");
  check.Within(o.ramp, AboveUpTo(0, 2), "ramp", "a number > 0, <= 2");
  std::string part;
  check.Nested(o.shadow.IsValid(&part), "shadow.", part);
  check.Nested(o.despill.IsValid(&part), "despill.", part);
  check.Within(o.coarse_alpha, Inside(0, 1), "coarse_alpha", "a fraction > 0, < 1");
  check.Within(o.coarse_shadow, Inside(0, 1), "coarse_shadow", "a fraction > 0, < 1");
  check.Within(o.min_key, Positive(), "min_key", "a number > 0");
  check.Within(o.max_unkeyable, Between(0, 1), "max_unkeyable", "a fraction 0..1");
  check(o.key_low_levels < 0 || o.key_high_levels > o.key_low_levels, "key_high_levels",
        "must be above key_low_levels (" + OptionProblems::Num(o.key_low_levels) + ")");
  return check.ok();
}

ChromaKeyer::ChromaKeyer(ChromaKeyerOptions options) : Keyer(options.grid), options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("chroma keyer options", why);
}

void ChromaKeyer::Train(const std::vector<cv::Mat>& empty_bgr) {
  StartTraining(empty_bgr, "chroma keyer");
  const int s = grid_.step, cols = cols_, rows = rows_;
  const size_t cells = static_cast<size_t>(cols) * rows;

  // Per cell: mean luma, mean key and the key's spread over the green samples of all frames. A
  // cell that is part green, part something else (a wall's outside at the floor's edge) models
  // its green part: over all its pixels the spread would be so wide that nothing is ever keyed
  // there, not even on the green. Its other pixels are then found not keyable (below).
  std::vector<double> sum_y(cells, 0), sum_k(cells, 0), sum_kk(cells, 0), count(cells, 0),
      all(cells, 0);
  std::vector<float> pixel_key(static_cast<size_t>(size_.width) * size_.height, 0.f);
  const int min_luma4 = static_cast<int>(std::ceil(4 * kMinTrainingLuma));
  const auto min_key = static_cast<float>(options_.min_key);
  // Cell rows are independent (their cells, their pixel rows): one task each, all frames inside;
  // per column, sums over the cell row's pixel rows of every frame, then summed into its cells.
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    const size_t w = static_cast<size_t>(size_.width);
    std::vector<int32_t> luma4_sum(w), n(w);
    std::vector<float> key_sum(w), key2_sum(w);
    for (int cy = range.start; cy < range.end; ++cy) {
      std::fill(luma4_sum.begin(), luma4_sum.end(), 0);
      std::fill(n.begin(), n.end(), 0);
      std::fill(key_sum.begin(), key_sum.end(), 0.f);
      std::fill(key2_sum.begin(), key2_sum.end(), 0.f);
      const int y0 = cy * s, y1 = std::min(y0 + s, size_.height);
      for (const cv::Mat& frame : empty_bgr) {
        for (int y = y0; y < y1; ++y) {
          TrainRow(frame.ptr<uint8_t>(y), size_.width, min_key, min_luma4, &pixel_key[y * w],
                   luma4_sum.data(), key_sum.data(), key2_sum.data(), n.data());
        }
      }
      for (int cx = 0; cx < cols; ++cx) {
        const size_t c = static_cast<size_t>(cy) * cols + cx;
        const int x0 = cx * s, x1 = std::min(x0 + s, size_.width);
        all[c] = static_cast<double>(x1 - x0) * (y1 - y0) * static_cast<double>(empty_bgr.size());
        for (int x = x0; x < x1; ++x) {
          sum_y[c] += luma4_sum[x] / 4.0;
          sum_k[c] += key_sum[x];
          sum_kk[c] += key2_sum[x];
          count[c] += n[x];
        }
      }
    }
  });
  std::vector<double> luma(cells), key(cells), spread(cells);
  std::vector<uint8_t> green(cells);
  size_t n_green = 0;
  double luma_sum = 0, key_sum = 0, spread_sum = 0;
  for (size_t c = 0; c < cells; ++c) {
    const double n = std::max(count[c], 1.0);
    luma[c] = sum_y[c] / n;
    key[c] = sum_k[c] / n;
    spread[c] = std::sqrt(std::max(0.0, sum_kk[c] / n - key[c] * key[c]));
    green[c] = count[c] >= kMinGreenShare * all[c] && count[c] > 0;
    if (green[c]) {
      ++n_green;
      luma_sum += luma[c];
      key_sum += key[c];
      spread_sum += spread[c];
    }
  }
  unkeyable_fraction_ = 1.0 - static_cast<double>(n_green) / cells;
  if (n_green == 0 || unkeyable_fraction_ > options_.max_unkeyable) {
    size_ = {};
    throw InputError(
        "chroma keyer training",
        "only " + std::to_string(static_cast<int>(100 * (1 - unkeyable_fraction_))) +
            "% of the empty enclosure is green enough (key (G-max(R,B))/luma >= " +
            std::to_string(options_.min_key) +
            "); is it a green screen? the clean-plate keyer handles other backgrounds");
  }
  const double mean_luma = luma_sum / n_green, mean_key = key_sum / n_green,
               mean_spread = spread_sum / n_green;
  for (size_t c = 0; c < cells; ++c) {
    if (options_.global_model || !green[c]) {
      // Global model: one reference everywhere. Non-green cells: smooth filler for interpolation.
      luma[c] = mean_luma;
      key[c] = mean_key;
      spread[c] = mean_spread;
    }
  }
  if (unkeyable_fraction_ > 0) {
    Log("pipeline.key")
        ->warn("chroma keyer: {:.1f}% of the enclosure is not green and is never keyed",
               100 * unkeyable_fraction_);
  }

  // Kernel units: luma4 = B + 2G + R = 4 Y, key4 = (G - max(R,B)) / luma4 = k / 4,
  // alpha and shadow in 0..255.
  const auto& o = options_;
  auto params = [&o](double l, double k, double sd, bool is_green, float* f, int32_t* luma_floor) {
    double key_hi = k - std::max(o.min_margin * k, o.noise_z * sd), ramp = o.ramp * k;
    if (o.key_low_levels >= 0 &&
        o.key_high_levels > o.key_low_levels) {  // levels at the floor's luma l
      key_hi = std::min(key_hi, o.key_high_levels / l);
      ramp = std::max(key_hi - o.key_low_levels / l, 0.05 * k);
    }
    f[kKeyHi] = is_green ? static_cast<float>(key_hi / 4) : kNeverKey;
    f[kGain] = static_cast<float>(4 * 255 / ramp);
    f[kInvLuma] = is_green ? static_cast<float>(255 / (4 * l)) : 0.f;
    f[kShadowBase] = is_green && o.shadow.enabled ? 255.f : kNoShadow;
    const double dark_floor = 1 - o.shadow.max_darkening;  // darker than this: the subject
    *luma_floor = static_cast<int32_t>(std::lround(std::max(4 * dark_floor * l, 4.0)));
  };
  float f[kFloatParams];
  int32_t floor4 = 0;
  cell_f_.assign(cells * kFloatParams, 0.f);
  cell_floor_.assign(cells, 0);
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      const size_t c = static_cast<size_t>(cy) * cols + cx;
      params(luma[c], key[c], spread[c], green[c], f, &floor4);
      for (int p = 0; p < kFloatParams; ++p)
        cell_f_[(static_cast<size_t>(cy) * kFloatParams + p) * cols + cx] = f[p];
      cell_floor_[c] = floor4;
    }
  }

  // Bands: per cell row, the parameters at every x, interpolated linearly
  // between cell samples along x (nearest cell along y).
  const size_t w = static_cast<size_t>(size_.width);
  band_f_.assign(static_cast<size_t>(rows) * kFloatParams * w, 0.f);
  band_floor_.assign(static_cast<size_t>(rows) * w, 0);
  for (int cy = 0; cy < rows; ++cy) {
    for (int x = 0; x < size_.width; ++x) {
      const int from_centre = x - s / 2;  // cell centres lie at s / 2 + k s
      const double fx = std::clamp(from_centre / static_cast<double>(s), 0.0, cols - 1.0);
      const int c0 = static_cast<int>(fx), c1 = std::min(c0 + 1, cols - 1);
      const double t = fx - c0;
      const size_t i0 = static_cast<size_t>(cy) * cols + c0,
                   i1 = static_cast<size_t>(cy) * cols + c1;
      params(luma[i0] * (1 - t) + luma[i1] * t, key[i0] * (1 - t) + key[i1] * t,
             spread[i0] * (1 - t) + spread[i1] * t, green[t < 0.5 ? i0 : i1], f, &floor4);
      for (int p = 0; p < kFloatParams; ++p)
        band_f_[(static_cast<size_t>(cy) * kFloatParams + p) * w + x] = f[p];
      band_floor_[static_cast<size_t>(cy) * w + x] = floor4;
    }
  }
  // Pixels the model itself keys on the empty enclosure are not green (the
  // global model, kept naive for comparison, skips this).
  std::vector<uint32_t> alpha_sum(static_cast<size_t>(size_.width) * size_.height, 0);
  const int shadow_min = static_cast<int>(std::lround(255 * o.shadow.min_darkening));
  if (!o.global_model) {
    cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
      for (int cy = range.start; cy < range.end; ++cy) {
        const Params p = BandParams(cy);
        for (const cv::Mat& frame : empty_bgr) {
          for (int y = cy * s; y < std::min((cy + 1) * s, size_.height); ++y) {
            AlphaSumRow(frame.ptr<uint8_t>(y), size_.width, p.f[kKeyHi], p.f[kGain], p.luma_floor,
                        p.f[kInvLuma], p.f[kShadowBase], shadow_min, &alpha_sum[y * w]);
          }
        }
      }
    });
  }
  keyable_.resize(alpha_sum.size());
  green_px_.resize(alpha_sum.size());
  size_t masked = 0;
  // Mean alpha <= kUnkeyableAlpha and mean key >= min_key, without a division per pixel.
  const auto n_frames = static_cast<uint32_t>(empty_bgr.size());
  const uint32_t max_alpha_sum = kUnkeyableAlpha * n_frames;
  const auto min_key_sum = static_cast<float>(o.min_key * n_frames);
  for (size_t i = 0; i < alpha_sum.size(); ++i) {
    const bool keyable = alpha_sum[i] <= max_alpha_sum;
    keyable_[i] = keyable ? 0xFF : 0;
    green_px_[i] = keyable && pixel_key[i] >= min_key_sum ? 0xFF : 0;
    masked += !keyable;
  }
  if (masked > 0) {
    Log("pipeline.key")
        ->info(
            "chroma keyer: {} pixels ({:.2f}%) of the empty enclosure are not green, never keyed",
            masked, 100.0 * masked / alpha_sum.size());
  }
  Log("pipeline.key")
      ->debug("chroma keyer trained on {} frames {}x{}: key {:.3f}, luma {:.1f}, noise {:.4f}",
              empty_bgr.size(), size_.width, size_.height, mean_key, mean_luma, mean_spread);
}

cv::Mat ChromaKeyer::GreenMask() const {
  cv::Mat mask = cv::Mat::zeros(size_, CV_8U);
  for (int y = 0; y < size_.height; ++y) {
    // Green itself, and keyed: a cell mixing green with something else has so wide a key spread
    // that its threshold falls below 0 and nothing neutral (grey, brown) is keyed there.
    const float* key_hi = BandParams(std::min(y / grid_.step, rows_ - 1)).f[kKeyHi];
    const uint8_t* green = &green_px_[static_cast<size_t>(y) * size_.width];
    uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < size_.width; ++x) m[x] = key_hi[x] > 0.f ? green[x] : 0;
  }
  return mask;
}

ChromaKeyer::Params ChromaKeyer::BandParams(int cell_row) const {
  const size_t w = static_cast<size_t>(size_.width);
  Params p;
  for (int i = 0; i < kFloatParams; ++i)
    p.f[i] = &band_f_[(static_cast<size_t>(cell_row) * kFloatParams + i) * w];
  p.luma_floor = &band_floor_[static_cast<size_t>(cell_row) * w];
  return p;
}

ChromaKeyer::Params ChromaKeyer::CellParams(int cell_row) const {
  const size_t cols = static_cast<size_t>(cols_);
  Params p;
  for (int i = 0; i < kFloatParams; ++i)
    p.f[i] = &cell_f_[(static_cast<size_t>(cell_row) * kFloatParams + i) * cols];
  p.luma_floor = &cell_floor_[static_cast<size_t>(cell_row) * cols];
  return p;
}

namespace {

// The fine pass over one row span; kRgb: the input is R G B, the colour
// output B G R either way.
template <bool kRgb>
__attribute__((always_inline)) inline void ChromaRowImpl(
    const uint8_t* __restrict in, int x0, int x1, const float* __restrict key_hi,
    const float* __restrict gain, const int32_t* __restrict luma_floor,
    const float* __restrict inv_luma, const float* __restrict shadow_base, int shadow_min,
    int despill256, int strength256, const uint8_t* __restrict keyable, uint8_t* __restrict alpha,
    uint8_t* __restrict shadow, uint8_t* __restrict colour) {
  constexpr int kB = kRgb ? 2 : 0, kR = kRgb ? 0 : 2;
  for (int x = x0; x < x1; ++x) {
    const int b = in[3 * x + kB], g = in[3 * x + 1], r = in[3 * x + kR];
    const PixelKey k = KeyPixel(b, g, r, key_hi[x], gain[x], luma_floor[x], inv_luma[x],
                                shadow_base[x], shadow_min);
    alpha[x] = static_cast<uint8_t>(k.alpha) & keyable[x];
    shadow[x] = static_cast<uint8_t>(k.shadow) & keyable[x];
    colour[3 * x] = static_cast<uint8_t>(b);
    // Despill: the share `strength` of G above max(R, B) - bias * (max(R, B) - min(R, B)) is
    // removed.
    const int hi = std::max(b, r), lo = std::min(b, r);
    const int excess = std::max(g - (hi - (((hi - lo) * despill256 + 128) >> 8)), 0);
    colour[3 * x + 1] = static_cast<uint8_t>(g - ((excess * strength256 + 128) >> 8));
    colour[3 * x + 2] = static_cast<uint8_t>(r);
  }
}

// Cloned per instruction set: the de-interleave of 3-byte pixels needs SSSE3
// shuffles to vectorize; plain SSE2 runs it scalar.
#define SS_CHROMA_ROW(NAME, RGB)                                                                   \
  SS_TARGET_CLONES("avx2", "ssse3", "default")                                                     \
  void NAME(const uint8_t* __restrict in, int x0, int x1, const float* __restrict key_hi,          \
            const float* __restrict gain, const int32_t* __restrict luma_floor,                    \
            const float* __restrict inv_luma, const float* __restrict shadow_base, int shadow_min, \
            int despill256, int strength256, const uint8_t* __restrict keyable,                    \
            uint8_t* __restrict alpha, uint8_t* __restrict shadow, uint8_t* __restrict colour) {   \
    ChromaRowImpl<RGB>(in, x0, x1, key_hi, gain, luma_floor, inv_luma, shadow_base, shadow_min,    \
                       despill256, strength256, keyable, alpha, shadow, colour);                   \
  }
SS_CHROMA_ROW(ChromaRowBgr, false)
SS_CHROMA_ROW(ChromaRowRgb, true)
#undef SS_CHROMA_ROW

}  // namespace

void ChromaKeyer::SampleRow(const uint8_t* row, ChannelOrder /*order*/, int cell_row,
                            uint8_t* foreground, uint8_t* shade) const {
  const Params p = CellParams(cell_row);
  const int coarse_alpha = static_cast<int>(std::lround(255 * options_.coarse_alpha));
  const int coarse_shadow = static_cast<int>(std::lround(255 * options_.coarse_shadow));
  const int shadow_min = static_cast<int>(std::lround(255 * options_.shadow.min_darkening));
  const uint8_t* keyable = &keyable_[static_cast<size_t>(SampleY(cell_row)) * size_.width];
  for (int cx = 0; cx < cols_; ++cx) {
    // B and R may be swapped: the key is symmetric in them
    const uint8_t* px = row + 3 * SampleX(cx);
    const PixelKey k =
        KeyPixel(px[0], px[1], px[2], p.f[kKeyHi][cx], p.f[kGain][cx], p.luma_floor[cx],
                 p.f[kInvLuma][cx], p.f[kShadowBase][cx], shadow_min);
    const bool green = keyable[SampleX(cx)] != 0;
    foreground[cx] = green && k.alpha > coarse_alpha;
    shade[cx] = green && k.shadow > coarse_shadow;
  }
}

void ChromaKeyer::FineRow(const uint8_t* row, ChannelOrder order, int y, int x0, int x1,
                          uint8_t* alpha, uint8_t* shadow, uint8_t* colour) const {
  const Params p = BandParams(std::min(y / grid_.step, rows_ - 1));
  const int shadow_min = static_cast<int>(std::lround(255 * options_.shadow.min_darkening));
  const DespillOptions& despill = options_.despill;
  const int despill256 = static_cast<int>(std::lround(256 * despill.bias));
  const int strength256 =
      despill.enabled ? static_cast<int>(std::lround(256 * despill.strength)) : 0;
  const uint8_t* keyable = &keyable_[static_cast<size_t>(y) * size_.width];
  if (order == ChannelOrder::kRgb) {
    ChromaRowRgb(row, x0, x1, p.f[kKeyHi], p.f[kGain], p.luma_floor, p.f[kInvLuma],
                 p.f[kShadowBase], shadow_min, despill256, strength256, keyable, alpha, shadow,
                 colour);
  } else {
    ChromaRowBgr(row, x0, x1, p.f[kKeyHi], p.f[kGain], p.luma_floor, p.f[kInvLuma],
                 p.f[kShadowBase], shadow_min, despill256, strength256, keyable, alpha, shadow,
                 colour);
  }
}

ChromaKeyerOptions ChromaKeyerOptionsFrom(const KeyingConfig& k) {
  const auto& block = k.Block<ChromaKeyBlock>(ChromaKeyer::kMethod);
  ChromaKeyerOptions o;
  o.key_low_levels = block.low;
  o.key_high_levels = block.high;
  o.shadow = k.shadow;
  o.despill = k.despill;
  return o;
}

void RegisterChromaKeyer() {
  // keying.chroma.*: the key difference in 8-bit levels where alpha starts to fall, and where it
  // reaches 0 (ChromaKeyBlock's defaults are the config's, 20 and 60).
  const auto keys = [](OptionsBinder& b, KeyingConfig& k) {
    auto& block = k.Block<ChromaKeyBlock>(ChromaKeyer::kMethod);
    b.Add("chroma.low", &block.low, "a level from 0 to 255",
          "key difference (green minus the larger of red and blue, in 8-bit levels, after "
          "learning the screen) at which alpha starts to fall from 1")
        .Rule(Between(0, 255))
        .Add("chroma.high", &block.high, "a level from 0 to 255",
             "... and at which the pixel is pure background (alpha 0); must be above `low`")
        .Rule(Between(0, 255));
  };
  // The config's range; the keyer itself also takes < 0 (off: min_margin and ramp instead).
  const auto check = [](const KeyingConfig& k, std::string* why) {
    const auto& block = k.Block<ChromaKeyBlock>(ChromaKeyer::kMethod);
    OptionProblems problem(why);
    problem(!(block.low >= block.high), "chroma.high",
            "must be above low (" + OptionProblems::Num(block.low) + "), got " +
                OptionProblems::Num(block.high));
    return problem.ok();
  };
  RegisterKeyerType<ChromaKeyer>(ChromaKeyer::kMethod, "colour-difference keying for green screens",
                                 ChromaKeyerOptionsFrom, AnyBlock::Of(ChromaKeyBlock{}), keys,
                                 check);
}

}  // namespace ss
