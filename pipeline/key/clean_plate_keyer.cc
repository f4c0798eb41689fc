#include "pipeline/key/clean_plate_keyer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/options_binder.h"
#include "core/target_clones.h"
#include "pipeline/key/keyer_registry.h"
#include "pipeline/key/keying_config.h"

namespace ss {
namespace {

// The clean-plate key of one pixel p against plate colour mu (docs/keying.md).
// No branches and no floating-point min/max, so that loops of it vectorize.
inline PixelKey PlatePixel(int b, int g, int r, int mu_b, int mu_g, int mu_r, float tolerance,
                           float gain, float dark_floor, int shadow_min) {
  const float pb = static_cast<float>(b), pg = static_cast<float>(g), pr = static_cast<float>(r);
  const float ub = static_cast<float>(mu_b), ug = static_cast<float>(mu_g),
              ur = static_cast<float>(mu_r);
  const float mu2 = ub * ub + ug * ug + ur * ur + 1.f;
  const float ratio = (pb * ub + pg * ug + pr * ur) / mu2;  // brightness relative to the plate
  const float eb = pb - ratio * ub, eg = pg - ratio * ug, er = pr - ratio * ur;
  // levels off the plate's colour line
  const float chroma = std::sqrt(eb * eb + eg * eg + er * er);
  const float mu_norm = std::sqrt(mu2);
  // Distance from "the plate, possibly in shadow", in quarter levels.
  const int brighter = static_cast<int>((ratio - 1.f) * mu_norm * 4.f);
  const int too_dark = static_cast<int>((dark_floor - ratio) * mu_norm * 4.f);
  const int distance4 = std::max(static_cast<int>(chroma * 4.f), std::max(brighter, too_dark));
  // Rounded by + 0.5 and truncation, not std::lround (a call, and no vectorizing): the values
  // below 0, where truncation rounds the wrong way, all end as 0 (the clamp, the shade test).
  // NOLINTBEGIN(bugprone-incorrect-roundings)
  const int alpha = std::clamp(
      static_cast<int>((static_cast<float>(distance4) * 0.25f - tolerance) * gain + 0.5f), 0, 255);
  const int dark = static_cast<int>(255.f - ratio * 255.f + 0.5f);
  // NOLINTEND(bugprone-incorrect-roundings)
  const int shade = dark >= shadow_min ? dark : 0;
  return {alpha, ((shade * (255 - alpha) + 128) * 257) >> 16};
}

// The fine pass over one row span; kRgb: the input is R G B (the plate and
// the colour output are B G R either way).
template <bool kRgb>
__attribute__((always_inline)) inline void PlateRowImpl(
    const uint8_t* __restrict in, const uint8_t* __restrict plate,
    const float* __restrict tolerance, int x0, int x1, float gain, float dark_floor, int shadow_min,
    uint8_t* __restrict alpha, uint8_t* __restrict shadow, uint8_t* __restrict colour) {
  constexpr int kB = kRgb ? 2 : 0, kR = kRgb ? 0 : 2;
  for (int x = x0; x < x1; ++x) {
    const int b = in[3 * x + kB], g = in[3 * x + 1], r = in[3 * x + kR];
    const PixelKey k = PlatePixel(b, g, r, plate[3 * x], plate[3 * x + 1], plate[3 * x + 2],
                                  tolerance[x], gain, dark_floor, shadow_min);
    alpha[x] = static_cast<uint8_t>(k.alpha);
    shadow[x] = static_cast<uint8_t>(k.shadow);
    colour[3 * x] = static_cast<uint8_t>(b);  // no spill to remove on a non-green plate
    colour[3 * x + 1] = static_cast<uint8_t>(g);
    colour[3 * x + 2] = static_cast<uint8_t>(r);
  }
}

#define SS_PLATE_ROW(NAME, RGB)                                                                  \
  SS_TARGET_CLONES("avx2", "ssse3", "default")                                                   \
  void NAME(const uint8_t* __restrict in, const uint8_t* __restrict plate,                       \
            const float* __restrict tolerance, int x0, int x1, float gain, float dark_floor,     \
            int shadow_min, uint8_t* __restrict alpha, uint8_t* __restrict shadow,               \
            uint8_t* __restrict colour) {                                                        \
    PlateRowImpl<RGB>(in, plate, tolerance, x0, x1, gain, dark_floor, shadow_min, alpha, shadow, \
                      colour);                                                                   \
  }
SS_PLATE_ROW(PlateRowBgr, false)
SS_PLATE_ROW(PlateRowRgb, true)
#undef SS_PLATE_ROW

}  // namespace

bool CleanPlateKeyerOptions::IsValid(std::string* why) const {
  const CleanPlateKeyerOptions& o = *this;
  OptionProblems check(why);
  check.Within(o.low_sigma, AtLeast(0), "low_sigma", "a number >= 0");
  check.Within(o.min_sigma, Positive(), "min_sigma", "a number > 0");
  check.Within(o.ramp, Positive(), "ramp", "a number > 0");
  std::string part;
  check.Nested(o.shadow.IsValid(&part), "shadow.", part);
  check.Within(o.coarse_alpha, Inside(0, 1), "coarse_alpha", "a fraction > 0, < 1");
  check.Within(o.coarse_shadow, Inside(0, 1), "coarse_shadow", "a fraction > 0, < 1");
  check(o.high_sigma == 0 || o.high_sigma > o.low_sigma, "high_sigma",
        "must be 0 (ramp by levels) or above low_sigma (" + OptionProblems::Num(o.low_sigma) + ")");
  return check.ok();
}

CleanPlateKeyer::CleanPlateKeyer(CleanPlateKeyerOptions options)
    : Keyer(options.grid), options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("clean-plate keyer options", why);
}

int CleanPlateKeyer::ShadowMin() const {
  const ShadowOptions& shadow = options_.shadow;
  return shadow.enabled ? static_cast<int>(std::lround(255 * shadow.min_darkening)) : 256;
}

void CleanPlateKeyer::Train(const std::vector<cv::Mat>& empty_bgr) {
  StartTraining(empty_bgr, "clean-plate keyer");
  cv::Mat sum = cv::Mat::zeros(size_, CV_64FC3), sum_sq = cv::Mat::zeros(size_, CV_64FC3);
  cv::Mat f64;
  for (const cv::Mat& frame : empty_bgr) {
    frame.convertTo(f64, CV_64FC3);
    sum += f64;
    sum_sq += f64.mul(f64);
  }
  const double n = static_cast<double>(empty_bgr.size());
  cv::Mat mean = sum / n;
  cv::Mat var = sum_sq / n - mean.mul(mean);
  mean.convertTo(plate_, CV_8UC3);  // rounds
  // One noise std per pixel: the root mean of the channel variances, floored,
  // then the largest of each 3x3 neighbourhood (a camera shaking by a pixel
  // at a texture edge would otherwise look like a subject).
  cv::Mat var1;
  cv::transform(var, var1, cv::Matx13d(1.0 / 3, 1.0 / 3, 1.0 / 3));
  var1 = cv::max(var1, options_.min_sigma * options_.min_sigma);
  cv::Mat sigma;
  cv::sqrt(var1, sigma);
  cv::dilate(sigma, sigma, cv::Mat::ones(3, 3, CV_8U));
  // The distance a pixel is tested on is mostly the chromaticity distortion,
  // the length of a residual in the 2-D plane across the plate's colour line,
  // and the plate carries the noise of its own n frames: a tolerance of
  // low_sigma std in one dimension would let through exp(-z^2/2) of the pixels
  // instead of erfc(z/sqrt 2) (e.g. z = 4: 3e-4 instead of 6e-5, a speck per
  // frame). Match the one-dimensional rate: z2 = sqrt(-2 ln erfc(z/sqrt 2)),
  // on the std of (frame - plate), sigma * sqrt(1 + 1/n).
  const double tail = std::erfc(options_.low_sigma / std::sqrt(2.0));
  const double z2 = tail > 0 && tail < 1 ? std::sqrt(-2.0 * std::log(tail)) : options_.low_sigma;
  sigma.convertTo(tolerance_, CV_32F, z2 * std::sqrt(1.0 + 1.0 / n));
  ramp_ = options_.ramp;
  if (options_.high_sigma > 0) {
    const double ramp_sigma = options_.high_sigma - options_.low_sigma;
    ramp_ = std::max(1.0, ramp_sigma * cv::mean(sigma)[0] * std::sqrt(1.0 + 1.0 / n));
  }
  if (empty_bgr.size() < 2) {
    Log("pipeline.key")
        ->warn("clean-plate keyer trained on one frame: noise std is the floor {:.1f}",
               options_.min_sigma);
  }
  Log("pipeline.key")
      ->debug("clean-plate keyer trained on {} frames {}x{}, mean tolerance {:.1f} levels",
              empty_bgr.size(), size_.width, size_.height, cv::mean(tolerance_)[0]);
}

void CleanPlateKeyer::SampleRow(const uint8_t* row, ChannelOrder order, int cell_row,
                                uint8_t* foreground, uint8_t* shade) const {
  const int kb = order == ChannelOrder::kRgb ? 2 : 0;
  const int y = SampleY(cell_row);
  const uint8_t* plate = plate_.ptr<uint8_t>(y);
  const float* tolerance = tolerance_.ptr<float>(y);
  const float gain = static_cast<float>(255 / ramp_);
  const auto dark_floor = static_cast<float>(1 - options_.shadow.max_darkening);
  const int shadow_min = ShadowMin();
  const int coarse_alpha = static_cast<int>(std::lround(255 * options_.coarse_alpha));
  const int coarse_shadow = static_cast<int>(std::lround(255 * options_.coarse_shadow));
  for (int cx = 0; cx < cols_; ++cx) {
    const int x = SampleX(cx);
    const uint8_t* p = row + 3 * x;
    const uint8_t* u = plate + 3 * x;
    const PixelKey k = PlatePixel(p[kb], p[1], p[2 - kb], u[0], u[1], u[2], tolerance[x], gain,
                                  dark_floor, shadow_min);
    foreground[cx] = k.alpha > coarse_alpha;
    shade[cx] = k.shadow > coarse_shadow;
  }
}

void CleanPlateKeyer::FineRow(const uint8_t* row, ChannelOrder order, int y, int x0, int x1,
                              uint8_t* alpha, uint8_t* shadow, uint8_t* colour) const {
  const float gain = static_cast<float>(255 / ramp_);
  const auto dark_floor = static_cast<float>(1 - options_.shadow.max_darkening);
  const int shadow_min = ShadowMin();
  if (order == ChannelOrder::kRgb) {
    PlateRowRgb(row, plate_.ptr<uint8_t>(y), tolerance_.ptr<float>(y), x0, x1, gain, dark_floor,
                shadow_min, alpha, shadow, colour);
  } else {
    PlateRowBgr(row, plate_.ptr<uint8_t>(y), tolerance_.ptr<float>(y), x0, x1, gain, dark_floor,
                shadow_min, alpha, shadow, colour);
  }
}

CleanPlateKeyerOptions CleanPlateKeyerOptionsFrom(const KeyingConfig& k) {
  const auto& block = k.Block<CleanPlateKeyBlock>(CleanPlateKeyer::kMethod);
  CleanPlateKeyerOptions o;
  o.low_sigma = block.low_sigma;
  o.high_sigma = block.high_sigma;
  o.shadow = k.shadow;
  return o;
}

void RegisterCleanPlateKeyer() {
  // keying.clean_plate.*: the ramp in noise sigmas (CleanPlateKeyBlock's defaults are the
  // config's, 3 and 6).
  const auto keys = [](OptionsBinder& b, KeyingConfig& k) {
    auto& block = k.Block<CleanPlateKeyBlock>(CleanPlateKeyer::kMethod);
    b.Add("clean_plate.low_sigma", &block.low_sigma, "a number of noise sigmas >= 0",
          "difference from the plate, in multiples of the pixel's noise sigma, at which alpha "
          "starts to rise from 0")
        .Rule(AtLeast(0))
        .Add("clean_plate.high_sigma", &block.high_sigma, "a number of noise sigmas >= 0",
             "... and at which the pixel is pure subject (alpha 1); must be above `low_sigma`")
        .Rule(AtLeast(0));
  };
  const auto check = [](const KeyingConfig& k, std::string* why) {
    const auto& block = k.Block<CleanPlateKeyBlock>(CleanPlateKeyer::kMethod);
    OptionProblems problem(why);
    problem(!(block.low_sigma >= block.high_sigma), "clean_plate.high_sigma",
            "must be above low_sigma (" + OptionProblems::Num(block.low_sigma) + "), got " +
                OptionProblems::Num(block.high_sigma));
    return problem.ok();
  };
  RegisterKeyerType<CleanPlateKeyer>(
      CleanPlateKeyer::kMethod,
      "difference against a learned empty-enclosure plate, for backgrounds that are not green",
      CleanPlateKeyerOptionsFrom, AnyBlock::Of(CleanPlateKeyBlock{}), keys, check);
}

}  // namespace ss
