#include "pipeline/transitions/comparison.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

bool ComparisonWindow::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(width_m, Positive(), "width_m", "a positive number of metres");
  check.Within(height_m, Positive(), "height_m", "a positive number of metres");
  check.Within(cells_x, AtLeast(1), "cells_x", "at least 1 cell");
  check.Within(cells_y, AtLeast(1), "cells_y", "at least 1 cell");
  // A plane holds at most 4096 cells; the product is reported under cells_y.
  const int64_t cells = int64_t{cells_x} * cells_y;
  check(cells_x < 1 || cells_y < 1 || cells <= 4096, "cells_y",
        "expected cells_x * cells_y <= 4096 cells, got " + std::to_string(cells_x) + " x " +
            std::to_string(cells_y));
  return check.ok();
}

CellBox UnionBox(const CellBox& a, const CellBox& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

namespace {

// For each cell along one axis, the source pixels it overlaps and the overlap lengths.
struct Overlap {
  int pixel;
  double weight;  // overlap length in pixels
};
std::vector<std::vector<Overlap>> AxisOverlaps(double start_px, double cell_px, int cells,
                                               int pixels) {
  std::vector<std::vector<Overlap>> out(cells);
  for (int c = 0; c < cells; ++c) {
    const double lo = start_px + c * cell_px, hi = lo + cell_px;
    const int first = std::max(0, static_cast<int>(std::floor(lo)));
    const int last = std::min(pixels - 1, static_cast<int>(std::ceil(hi)) - 1);
    for (int p = first; p <= last; ++p) {
      const double w = std::min(hi, p + 1.0) - std::max(lo, static_cast<double>(p));
      if (w > 0) out[c].push_back({p, w});
    }
  }
  return out;
}

}  // namespace

CellBox MakeComparisonImage(const RgbaBillboard& b, double px_per_m, const ComparisonWindow& window,
                            uint8_t* image) {
  ValidateBillboard(b);
  std::string why;
  if (!window.IsValid(&why)) throw InputError("comparison_window", why);
  if (!(px_per_m > 0)) throw InputError("px_per_m", "must be positive");
  const int stride = window.PlaneStride();
  std::memset(image, 0, window.ImageBytes());

  // The window in pixel-edge coordinates (pixel (x, y) covers [x, x+1) x [y, y+1)): its
  // bottom edge at the contact point's height (anchor + 0.5), centred horizontally on the
  // alpha centroid or on the contact point. A floor sprite lies along the image's height,
  // centred on its anchor: its window is turned a quarter (width_m along the subject) and
  // centred on the anchor's height.
  const double across_m = b.floor ? window.height_m : window.width_m;
  const double along_m = b.floor ? window.width_m : window.height_m;
  const double cell_w = across_m * px_per_m / window.cells_x;
  const double cell_h = along_m * px_per_m / window.cells_y;
  double centre_x = b.anchor_x_px + 0.5;
  if (window.align == HorizontalAlignment::kAlphaCentroid) {
    double sum = 0, weight = 0;
    for (int y = 0; y < b.height; ++y) {
      for (int x = 0; x < b.width; ++x) {
        const uint8_t a = b.Pixel(x, y)[3];
        sum += a * (x + 0.5);
        weight += a;
      }
    }
    if (weight > 0) centre_x = sum / weight;
  }
  const double x0 = centre_x - 0.5 * across_m * px_per_m;
  const double y0 = b.anchor_y_px + 0.5 - (b.floor ? 0.5 : 1.0) * along_m * px_per_m;
  const auto cols = AxisOverlaps(x0, cell_w, window.cells_x, b.width);
  const auto rows = AxisOverlaps(y0, cell_h, window.cells_y, b.height);

  // Premultiplied sums per cell column for one source row, then per cell.
  std::vector<double> row_sums(static_cast<size_t>(window.cells_x) * 4);
  std::vector<double> cell_sums(static_cast<size_t>(window.Cells()) * 4, 0.0);
  for (int v = 0; v < window.cells_y; ++v) {
    for (const Overlap& ry : rows[v]) {
      std::fill(row_sums.begin(), row_sums.end(), 0.0);
      for (int u = 0; u < window.cells_x; ++u) {
        double* acc = &row_sums[u * 4];
        for (const Overlap& cx : cols[u]) {
          const uint8_t* p = b.Pixel(cx.pixel, ry.pixel);
          if (p[3] == 0) continue;
          const double wa = cx.weight * p[3];
          acc[0] += wa;
          acc[1] += wa * p[0];
          acc[2] += wa * p[1];
          acc[3] += wa * p[2];
        }
      }
      for (int u = 0; u < window.cells_x; ++u) {
        for (int k = 0; k < 4; ++k)
          cell_sums[(v * window.cells_x + u) * 4 + k] += ry.weight * row_sums[u * 4 + k];
      }
    }
  }

  CellBox box{static_cast<int16_t>(window.cells_x), static_cast<int16_t>(window.cells_y), 0, 0};
  const double cell_area = cell_w * cell_h;
  uint8_t* plane_a = image;
  uint8_t* plane_rgb[3] = {image + stride, image + 2 * stride, image + 3 * stride};
  for (int v = 0; v < window.cells_y; ++v) {
    for (int u = 0; u < window.cells_x; ++u) {
      const int cell = v * window.cells_x + u;
      const double* s = &cell_sums[cell * 4];
      const long alpha = std::lround(s[0] / cell_area);
      if (alpha <= 0) continue;
      plane_a[cell] = static_cast<uint8_t>(std::min(255L, alpha));
      for (int c = 0; c < 3; ++c) {
        plane_rgb[c][cell] =
            static_cast<uint8_t>(std::clamp(std::lround(s[1 + c] / s[0]), 0L, 255L));
      }
      box.x0 = std::min<int16_t>(box.x0, u);
      box.y0 = std::min<int16_t>(box.y0, v);
      box.x1 = std::max<int16_t>(box.x1, u + 1);
      box.y1 = std::max<int16_t>(box.y1, v + 1);
    }
  }
  if (box.empty()) box = CellBox{};
  return box;
}

PixelSums SumPixelDifferencesScalar(const uint8_t* a, const uint8_t* b, int stride) {
  PixelSums s;
  for (int k = 0; k < stride; ++k) {
    const int aa = a[k], ab = b[k];
    s.alpha_abs_diff += std::abs(aa - ab);
    const int w = std::min(aa, ab);
    s.weight += w;
    int d = 0;
    for (int c = 1; c <= 3; ++c) d += std::abs(int{a[c * stride + k]} - int{b[c * stride + k]});
    s.weighted_colour += static_cast<uint64_t>(w) * d;
  }
  return s;
}

namespace {

// SSE2 kernel, 16 cells per step. The weighted colour lanes are 32-bit: each madd lane
// adds at most 2 * 255 * 765 per step and a plane has at most 4096 / 16 steps.
PixelSums SumSse2(const uint8_t* a, const uint8_t* b, int stride) {
  const __m128i zero = _mm_setzero_si128();
  __m128i sad = zero, wsum = zero, wd = zero;
  for (int k = 0; k < stride; k += 16) {
    const __m128i aa = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k));
    const __m128i ab = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k));
    sad = _mm_add_epi64(sad, _mm_sad_epu8(aa, ab));
    const __m128i w = _mm_min_epu8(aa, ab);
    wsum = _mm_add_epi64(wsum, _mm_sad_epu8(w, zero));
    __m128i dlo = zero, dhi = zero;
    for (int c = 1; c <= 3; ++c) {
      const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + c * stride + k));
      const __m128i y = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + c * stride + k));
      const __m128i d = _mm_or_si128(_mm_subs_epu8(x, y), _mm_subs_epu8(y, x));
      dlo = _mm_add_epi16(dlo, _mm_unpacklo_epi8(d, zero));
      dhi = _mm_add_epi16(dhi, _mm_unpackhi_epi8(d, zero));
    }
    wd = _mm_add_epi32(wd, _mm_madd_epi16(_mm_unpacklo_epi8(w, zero), dlo));
    wd = _mm_add_epi32(wd, _mm_madd_epi16(_mm_unpackhi_epi8(w, zero), dhi));
  }
  alignas(16) uint32_t lanes[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(lanes), wd);
  alignas(16) uint64_t s64[2], w64[2];
  _mm_store_si128(reinterpret_cast<__m128i*>(s64), sad);
  _mm_store_si128(reinterpret_cast<__m128i*>(w64), wsum);
  PixelSums s;
  s.alpha_abs_diff = s64[0] + s64[1];
  s.weight = w64[0] + w64[1];
  s.weighted_colour = uint64_t{lanes[0]} + lanes[1] + lanes[2] + lanes[3];
  return s;
}

// AVX2 kernel, 32 cells per step; same arithmetic as SumSse2.
__attribute__((target("avx2"))) PixelSums SumAvx2(const uint8_t* a, const uint8_t* b, int stride) {
  const __m256i zero = _mm256_setzero_si256();
  __m256i sad = zero, wsum = zero, wd = zero;
  for (int k = 0; k < stride; k += 32) {
    const __m256i aa = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + k));
    const __m256i ab = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + k));
    sad = _mm256_add_epi64(sad, _mm256_sad_epu8(aa, ab));
    const __m256i w = _mm256_min_epu8(aa, ab);
    wsum = _mm256_add_epi64(wsum, _mm256_sad_epu8(w, zero));
    __m256i dlo = zero, dhi = zero;
    for (int c = 1; c <= 3; ++c) {
      const __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + c * stride + k));
      const __m256i y = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + c * stride + k));
      const __m256i d = _mm256_or_si256(_mm256_subs_epu8(x, y), _mm256_subs_epu8(y, x));
      dlo = _mm256_add_epi16(dlo, _mm256_unpacklo_epi8(d, zero));
      dhi = _mm256_add_epi16(dhi, _mm256_unpackhi_epi8(d, zero));
    }
    wd = _mm256_add_epi32(wd, _mm256_madd_epi16(_mm256_unpacklo_epi8(w, zero), dlo));
    wd = _mm256_add_epi32(wd, _mm256_madd_epi16(_mm256_unpackhi_epi8(w, zero), dhi));
  }
  alignas(32) uint32_t lanes[8];
  alignas(32) uint64_t s64[4], w64[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), wd);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s64), sad);
  _mm256_store_si256(reinterpret_cast<__m256i*>(w64), wsum);
  PixelSums s;
  for (int i = 0; i < 4; ++i) {
    s.alpha_abs_diff += s64[i];
    s.weight += w64[i];
  }
  for (int i = 0; i < 8; ++i) s.weighted_colour += lanes[i];
  return s;
}

using Kernel = PixelSums (*)(const uint8_t*, const uint8_t*, int);
Kernel ChooseKernel() { return __builtin_cpu_supports("avx2") ? &SumAvx2 : &SumSse2; }

// The alpha plane's SAD alone (the stride is a multiple of 64).
uint64_t AlphaSse2(const uint8_t* a, const uint8_t* b, int stride) {
  __m128i sad = _mm_setzero_si128();
  for (int k = 0; k < stride; k += 16) {
    sad =
        _mm_add_epi64(sad, _mm_sad_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k)),
                                        _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k))));
  }
  alignas(16) uint64_t s64[2];
  _mm_store_si128(reinterpret_cast<__m128i*>(s64), sad);
  return s64[0] + s64[1];
}
__attribute__((target("avx2"))) uint64_t AlphaAvx2(const uint8_t* a, const uint8_t* b, int stride) {
  __m256i sad = _mm256_setzero_si256();
  for (int k = 0; k < stride; k += 32) {
    sad = _mm256_add_epi64(
        sad, _mm256_sad_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + k)),
                             _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + k))));
  }
  alignas(32) uint64_t s64[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(s64), sad);
  return s64[0] + s64[1] + s64[2] + s64[3];
}
using AlphaKernel = uint64_t (*)(const uint8_t*, const uint8_t*, int);
AlphaKernel ChooseAlphaKernel() { return __builtin_cpu_supports("avx2") ? &AlphaAvx2 : &AlphaSse2; }

}  // namespace

uint64_t SumAlphaDifference(const uint8_t* a, const uint8_t* b, int stride) {
  static const AlphaKernel kernel = ChooseAlphaKernel();
  return kernel(a, b, stride);
}

int MaxAlphaDifference(const uint8_t* a, const uint8_t* b, int stride) {
  uint8_t worst = 0;  // a plain loop the compiler vectorizes (max of |a - b| on bytes)
  for (int k = 0; k < stride; ++k) {
    const uint8_t d =
        a[k] > b[k] ? static_cast<uint8_t>(a[k] - b[k]) : static_cast<uint8_t>(b[k] - a[k]);
    worst = std::max(worst, d);
  }
  return worst;
}

int LargestColourBlob(const uint8_t* a, const uint8_t* b, const ComparisonWindow& window) {
  const int w = window.cells_x, h = window.cells_y, n = window.Cells(),
            stride = window.PlaneStride();
  std::vector<uint8_t> mark(n, 0);
  int marked = 0;
  for (int k = 0; k < n; ++k) {
    if (a[k] < 128 || b[k] < 128) continue;
    int d = 0;
    for (int c = 1; c <= 3; ++c) d += std::abs(int{a[c * stride + k]} - int{b[c * stride + k]});
    mark[k] = d >= 90;
    marked += mark[k];
  }
  int best = 0;
  std::vector<int> stack;
  for (int k = 0; k < n && marked > best; ++k) {
    if (mark[k] != 1) continue;
    int size = 0;
    stack.assign(1, k);
    mark[k] = 2;
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      ++size;
      const int x = cell % w, y = cell / w;
      const int next[4] = {x > 0 ? cell - 1 : -1, x + 1 < w ? cell + 1 : -1, y > 0 ? cell - w : -1,
                           y + 1 < h ? cell + w : -1};
      for (int q : next) {
        if (q >= 0 && mark[q] == 1) {
          mark[q] = 2;
          stack.push_back(q);
        }
      }
    }
    best = std::max(best, size);
    marked -= size;
  }
  return best;
}

int ColourCellCountScalar(const uint8_t* a, const uint8_t* b, int stride) {
  int count = 0;
  for (int k = 0; k < stride; ++k) {
    if (a[k] < kOpaqueAlpha || b[k] < kOpaqueAlpha) continue;
    int d = 0;
    for (int c = 1; c <= 3; ++c) d += std::abs(int{a[c * stride + k]} - int{b[c * stride + k]});
    count += d >= kColourStep;
  }
  return count;
}

int ColourCellCount(const uint8_t* a, const uint8_t* b, int stride) {
  // 16 cells a step: opaque in both <=> the top bit of min(A_a, A_b) (kOpaqueAlpha = 128);
  // the three channel differences summed in 16-bit lanes (<= 765) and compared with 89.
  static_assert(kOpaqueAlpha == 128, "the opacity test is the top bit of the smaller alpha");
  const __m128i zero = _mm_setzero_si128();
  const __m128i step = _mm_set1_epi16(kColourStep - 1);
  int count = 0;
  for (int k = 0; k < stride; k += 16) {
    const __m128i aa = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k));
    const __m128i ab = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k));
    const int opaque = _mm_movemask_epi8(_mm_min_epu8(aa, ab));
    if (opaque == 0) continue;
    __m128i lo = zero, hi = zero;
    for (int c = 1; c <= 3; ++c) {
      const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + c * stride + k));
      const __m128i y = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + c * stride + k));
      const __m128i d = _mm_or_si128(_mm_subs_epu8(x, y), _mm_subs_epu8(y, x));
      lo = _mm_add_epi16(lo, _mm_unpacklo_epi8(d, zero));
      hi = _mm_add_epi16(hi, _mm_unpackhi_epi8(d, zero));
    }
    const __m128i differ = _mm_packs_epi16(_mm_cmpgt_epi16(lo, step), _mm_cmpgt_epi16(hi, step));
    count += __builtin_popcount(static_cast<unsigned>(_mm_movemask_epi8(differ) & opaque));
  }
  return count;
}

PixelSums SumPixelDifferences(const uint8_t* a, const uint8_t* b, int stride) {
  static const Kernel kernel = ChooseKernel();
  return kernel(a, b, stride);
}

PixelDifference PixelDifferenceFromSums(const PixelSums& s, const CellBox& box_a,
                                        const CellBox& box_b) {
  PixelDifference d;
  const int area = BoxArea(UnionBox(box_a, box_b));
  d.alpha = area > 0 ? static_cast<double>(s.alpha_abs_diff) / (255.0 * area) : 0.0;
  d.colour = s.weight > 0 ? static_cast<double>(s.weighted_colour) / (3.0 * s.weight) : 255.0;
  return d;
}

}  // namespace ss
