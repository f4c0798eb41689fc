#include "pipeline/key/chroma_keyer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/log.h"

namespace ss {
namespace {

// Below this luma (of 255) the key of a training pixel is all noise.
constexpr double kMinTrainingLuma = 8.0;
// key_hi of a cell that is not green: no pixel there is ever keyed as subject
// (small enough, large enough to keep the kernel's float->int conversions in range).
constexpr float kNeverKey = -100.f;
// shadow_base of a cell that is not green: never a shadow.
constexpr float kNoShadow = -1000.f;

}  // namespace

ChromaKeyer::ChromaKeyer(ChromaKeyerOptions options) : Keyer(options.grid), options_(options) {
  const auto& o = options_;
  auto check = [](bool ok, const char* field, const char* reason) {
    if (!ok) throw InputError(std::string("keying.chroma.") + field, reason);
  };
  check(o.noise_z >= 0, "noise_z", "must not be negative");
  check(o.min_margin >= 0 && o.min_margin < 1, "min_margin", "must be within [0, 1)");
  check(o.ramp > 0 && o.ramp <= 2, "ramp", "must be within (0, 2]");
  check(o.dark_floor >= 0 && o.dark_floor < 1, "dark_floor", "must be within [0, 1)");
  check(o.shadow_min >= 0 && o.shadow_min < 1, "shadow_min", "must be within [0, 1)");
  check(o.coarse_alpha > 0 && o.coarse_alpha < 1, "coarse_alpha", "must be within (0, 1)");
  check(o.coarse_shadow > 0 && o.coarse_shadow < 1, "coarse_shadow", "must be within (0, 1)");
  check(o.min_key > 0, "min_key", "must be positive");
  check(o.max_unkeyable >= 0 && o.max_unkeyable <= 1, "max_unkeyable", "must be within [0, 1]");
}

void ChromaKeyer::Train(const std::vector<cv::Mat>& empty_bgr) {
  StartTraining(empty_bgr, "chroma keyer");
  const int s = grid_.step, cols = cols_, rows = rows_;
  const size_t cells = static_cast<size_t>(cols) * rows;

  // Per cell: mean luma, mean key and the key's spread over all pixels of all frames.
  std::vector<double> sum_y(cells, 0), sum_k(cells, 0), sum_kk(cells, 0), count(cells, 0);
  for (const cv::Mat& frame : empty_bgr) {
    for (int y = 0; y < size_.height; ++y) {
      const uint8_t* p = frame.ptr<uint8_t>(y);
      const size_t row = static_cast<size_t>(y / s) * cols;
      for (int x = 0; x < size_.width; ++x, p += 3) {
        const double luma = (p[0] + 2.0 * p[1] + p[2]) / 4.0;
        const double key = (p[1] - std::max(p[0], p[2])) / std::max(luma, kMinTrainingLuma);
        const size_t c = row + x / s;
        sum_y[c] += luma;
        sum_k[c] += key;
        sum_kk[c] += key * key;
        count[c] += 1;
      }
    }
  }
  std::vector<double> luma(cells), key(cells), spread(cells);
  std::vector<uint8_t> green(cells);
  size_t n_green = 0;
  double luma_sum = 0, key_sum = 0, spread_sum = 0;
  for (size_t c = 0; c < cells; ++c) {
    luma[c] = sum_y[c] / count[c];
    key[c] = sum_k[c] / count[c];
    spread[c] = std::sqrt(std::max(0.0, sum_kk[c] / count[c] - key[c] * key[c]));
    green[c] = key[c] >= options_.min_key && luma[c] >= kMinTrainingLuma;
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
    throw InputError("chroma keyer training",
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
    Log("pipeline.key")->warn("chroma keyer: {:.1f}% of the enclosure is not green and is never keyed",
                              100 * unkeyable_fraction_);
  }

  // Kernel units: luma4 = B + 2G + R = 4 Y, key4 = (G - max(R,B)) / luma4 = k / 4,
  // alpha and shadow in 0..255.
  const auto& o = options_;
  auto params = [&o](double l, double k, double sd, bool is_green, float* f, int32_t* luma_floor) {
    f[kKeyHi] = is_green ? static_cast<float>((k - std::max(o.min_margin * k, o.noise_z * sd)) / 4) : kNeverKey;
    f[kGain] = static_cast<float>(4 * 255 / (o.ramp * k));
    f[kInvLuma] = is_green ? static_cast<float>(255 / (4 * l)) : 0.f;
    f[kShadowBase] = is_green ? 255.f : kNoShadow;
    *luma_floor = static_cast<int32_t>(std::lround(std::max(4 * o.dark_floor * l, 4.0)));
  };
  float f[kFloatParams];
  int32_t floor4 = 0;
  cell_f_.assign(cells * kFloatParams, 0.f);
  cell_floor_.assign(cells, 0);
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      const size_t c = static_cast<size_t>(cy) * cols + cx;
      params(luma[c], key[c], spread[c], green[c], f, &floor4);
      for (int p = 0; p < kFloatParams; ++p) cell_f_[(static_cast<size_t>(cy) * kFloatParams + p) * cols + cx] = f[p];
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
      const double fx = std::clamp((x - s / 2) / static_cast<double>(s), 0.0, cols - 1.0);
      const int c0 = static_cast<int>(fx), c1 = std::min(c0 + 1, cols - 1);
      const double t = fx - c0;
      const size_t i0 = static_cast<size_t>(cy) * cols + c0, i1 = static_cast<size_t>(cy) * cols + c1;
      params(luma[i0] * (1 - t) + luma[i1] * t, key[i0] * (1 - t) + key[i1] * t,
             spread[i0] * (1 - t) + spread[i1] * t, green[t < 0.5 ? i0 : i1], f, &floor4);
      for (int p = 0; p < kFloatParams; ++p) band_f_[(static_cast<size_t>(cy) * kFloatParams + p) * w + x] = f[p];
      band_floor_[static_cast<size_t>(cy) * w + x] = floor4;
    }
  }
  Log("pipeline.key")->debug("chroma keyer trained on {} frames {}x{}: key {:.3f}, luma {:.1f}, noise {:.4f}",
                             empty_bgr.size(), size_.width, size_.height, mean_key, mean_luma, mean_spread);
}

ChromaKeyer::Params ChromaKeyer::BandParams(int cell_row) const {
  const size_t w = static_cast<size_t>(size_.width);
  Params p;
  for (int i = 0; i < kFloatParams; ++i) p.f[i] = &band_f_[(static_cast<size_t>(cell_row) * kFloatParams + i) * w];
  p.luma_floor = &band_floor_[static_cast<size_t>(cell_row) * w];
  return p;
}

ChromaKeyer::Params ChromaKeyer::CellParams(int cell_row) const {
  const size_t cols = static_cast<size_t>(cols_);
  Params p;
  for (int i = 0; i < kFloatParams; ++i) p.f[i] = &cell_f_[(static_cast<size_t>(cell_row) * kFloatParams + i) * cols];
  p.luma_floor = &cell_floor_[static_cast<size_t>(cell_row) * cols];
  return p;
}

namespace {

struct PixelKey {
  int alpha;   // 0..255
  int shadow;  // 0..255
};

// The key of one pixel (docs/keying.md), in integer-friendly units: no
// branches and no floating-point min/max, so that loops of it vectorize.
inline PixelKey KeyPixel(int b, int g, int r, float key_hi, float gain, int32_t luma_floor,
                         float inv_luma, float shadow_base, int shadow_min) {
  const int luma4 = b + 2 * g + r;
  const float key4 = static_cast<float>(g - std::max(b, r)) / static_cast<float>(std::max(luma4, luma_floor));
  const int alpha = std::clamp(static_cast<int>((key_hi - key4) * gain + 0.5f), 0, 255);
  const int dark = static_cast<int>(shadow_base - static_cast<float>(luma4) * inv_luma + 0.5f);
  const int shade = dark >= shadow_min ? dark : 0;
  // shade * (255 - alpha) / 255, rounded: the shadow only shows where the subject does not.
  return {alpha, ((shade * (255 - alpha) + 128) * 257) >> 16};
}

// The fine pass over one row span. Cloned per instruction set: the de-interleave
// of BGR bytes needs SSSE3 shuffles to vectorize; plain SSE2 runs it scalar.
__attribute__((target_clones("avx2", "ssse3", "default")))
void ChromaRow(const uint8_t* __restrict in, int x0, int x1, const float* __restrict key_hi,
               const float* __restrict gain, const int32_t* __restrict luma_floor,
               const float* __restrict inv_luma, const float* __restrict shadow_base, int shadow_min,
               uint8_t* __restrict alpha, uint8_t* __restrict shadow, uint8_t* __restrict colour) {
  for (int x = x0; x < x1; ++x) {
    const int b = in[3 * x], g = in[3 * x + 1], r = in[3 * x + 2];
    const PixelKey k =
        KeyPixel(b, g, r, key_hi[x], gain[x], luma_floor[x], inv_luma[x], shadow_base[x], shadow_min);
    alpha[x] = static_cast<uint8_t>(k.alpha);
    shadow[x] = static_cast<uint8_t>(k.shadow);
    colour[3 * x] = static_cast<uint8_t>(b);
    colour[3 * x + 1] = static_cast<uint8_t>(std::min(g, std::max(b, r)));  // despill: G <= max(R, B)
    colour[3 * x + 2] = static_cast<uint8_t>(r);
  }
}

}  // namespace

void ChromaKeyer::SampleRow(const uint8_t* bgr_row, int cell_row, uint8_t* foreground,
                            uint8_t* shade) const {
  const Params p = CellParams(cell_row);
  const int coarse_alpha = static_cast<int>(std::lround(255 * options_.coarse_alpha));
  const int coarse_shadow = static_cast<int>(std::lround(255 * options_.coarse_shadow));
  const int shadow_min = static_cast<int>(std::lround(255 * options_.shadow_min));
  for (int cx = 0; cx < cols_; ++cx) {
    const uint8_t* px = bgr_row + 3 * SampleX(cx);
    const PixelKey k = KeyPixel(px[0], px[1], px[2], p.f[kKeyHi][cx], p.f[kGain][cx], p.luma_floor[cx],
                                p.f[kInvLuma][cx], p.f[kShadowBase][cx], shadow_min);
    foreground[cx] = k.alpha > coarse_alpha;
    shade[cx] = k.shadow > coarse_shadow;
  }
}

void ChromaKeyer::FineRow(const uint8_t* bgr_row, int y, int x0, int x1, uint8_t* alpha,
                          uint8_t* shadow, uint8_t* colour) const {
  const Params p = BandParams(std::min(y / grid_.step, rows_ - 1));
  ChromaRow(bgr_row, x0, x1, p.f[kKeyHi], p.f[kGain], p.luma_floor, p.f[kInvLuma], p.f[kShadowBase],
            static_cast<int>(std::lround(255 * options_.shadow_min)), alpha, shadow, colour);
}

}  // namespace ss
