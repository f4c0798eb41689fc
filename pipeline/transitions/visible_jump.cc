#include "pipeline/transitions/visible_jump.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "core/error.h"
#include "core/option_checks.h"
#include "pipeline/transitions/bank_sprites.h"

namespace ss {
namespace {

constexpr size_t kKeptBillboards = 512;

// Premultiplied colour and alpha of pixel (x, y) of `b`, or zeros outside it.
inline void Premultiplied(const RgbaBillboard& b, int x, int y, int out[4]) {
  if (x < 0 || y < 0 || x >= b.width || y >= b.height) {
    out[0] = out[1] = out[2] = out[3] = 0;
    return;
  }
  const uint8_t* p = b.Pixel(x, y);
  const int a = p[3];
  // Scaled by 255: c * a (0..65025) against a * 255 for alpha.
  out[0] = p[0] * a;
  out[1] = p[1] * a;
  out[2] = p[2] * a;
  out[3] = a * 255;
}

// The process-wide cache of MedianStep_px, by bank and options.
std::mutex& CacheMutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, double>& MedianCache() {
  static std::map<std::string, double> cache;
  return cache;
}

}  // namespace

double ContactAlignedDifference_px(const RgbaBillboard& a, const RgbaBillboard& b) {
  ValidateBillboard(a);
  ValidateBillboard(b);
  // b's pixel (x, y) lies on a's pixel (x + ox, y + oy): the contact points coincide.
  const int ox = static_cast<int>(std::lround(a.anchor_x_px - b.anchor_x_px));
  const int oy = static_cast<int>(std::lround(a.anchor_y_px - b.anchor_y_px));
  const int x0 = std::min(0, ox), x1 = std::max(a.width, ox + b.width);
  const int y0 = std::min(0, oy), y1 = std::max(a.height, oy + b.height);
  int64_t sum = 0;  // in units of 1/255 of a channel level
  int pa[4], pb[4];
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      Premultiplied(a, x, y, pa);
      Premultiplied(b, x - ox, y - oy, pb);
      for (int c = 0; c < 4; ++c) sum += std::abs(pa[c] - pb[c]);
    }
  }
  return static_cast<double>(sum) / (255.0 * 4.0 * 255.0);
}

bool VisibleJumpOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(max_pairs >= 1, "max_pairs", "must be >= 1, got " + std::to_string(max_pairs));
  check(min_step_px > 0 && std::isfinite(min_step_px), "min_step_px",
        "must be a positive number of px, got " + OptionProblems::Num(min_step_px));
  return check.ok();
}

VisibleJumpMeter::VisibleJumpMeter(const Bank& bank, VisibleJumpOptions options)
    : bank_(bank), options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("visible jump options", why);
  const std::vector<SpriteFeatures> features = bank_.LoadFeatures();
  for (const SpriteFeatures& f : features) {
    if (f.next < 0) continue;
    next_[f.id] = features[f.next].id;
    if (!f.mirrored) originals_with_next_.push_back(f.id);
  }
  cache_key_ = bank_.path() + "\n" + std::to_string(features.size()) + "\n" +
               std::to_string(options_.max_pairs) + "\n" + std::to_string(options_.min_step_px);
}

std::optional<int64_t> VisibleJumpMeter::NaturalSuccessor(int64_t id) const {
  const auto it = next_.find(id);
  if (it == next_.end()) return std::nullopt;
  return it->second;
}

const RgbaBillboard& VisibleJumpMeter::Billboard(int64_t id) {
  if (const auto it = billboards_.find(id); it != billboards_.end()) return it->second;
  const SpriteRecord record = bank_.LoadSprite(id);
  return billboards_
      .emplace(id,
               BillboardFromPixels(bank_.LoadPixels(id), record.anchor_x_px, record.anchor_y_px))
      .first->second;
}

double VisibleJumpMeter::Difference_px(int64_t a, int64_t b) {
  if (a == b) return 0.0;
  // Room for both before either is loaded: the references stay valid.
  if (billboards_.size() + 2 > kKeptBillboards) billboards_.clear();
  const RgbaBillboard& first = Billboard(a);
  return ContactAlignedDifference_px(first, Billboard(b));
}

double VisibleJumpMeter::MedianStep_px() {
  {
    const std::lock_guard<std::mutex> lock(CacheMutex());
    const auto it = MedianCache().find(cache_key_);
    if (it != MedianCache().end()) return it->second;
  }
  const size_t n = originals_with_next_.size();
  const size_t pairs = std::min(n, static_cast<size_t>(options_.max_pairs));
  std::vector<double> steps;
  steps.reserve(pairs);
  for (size_t k = 0; k < pairs; ++k) {
    // Evenly spread: pair k of `pairs` is the (k * n / pairs)-th of the bank.
    const int64_t id = originals_with_next_[k * n / pairs];
    steps.push_back(Difference_px(id, next_.at(id)));
  }
  double median = 0.0;
  if (!steps.empty()) {
    std::sort(steps.begin(), steps.end());
    const size_t m = steps.size() / 2;
    median = steps.size() % 2 == 1 ? steps[m] : 0.5 * (steps[m - 1] + steps[m]);
  }
  median = std::max(median, options_.min_step_px);
  const std::lock_guard<std::mutex> lock(CacheMutex());
  MedianCache()[cache_key_] = median;
  return median;
}

double VisibleJumpMeter::JumpBetween(int64_t shown, int64_t natural) {
  return Difference_px(shown, natural) / MedianStep_px();
}

std::optional<double> VisibleJumpMeter::Jump(int64_t from, int64_t to) {
  const std::optional<int64_t> natural = NaturalSuccessor(from);
  if (!natural) return std::nullopt;
  return JumpBetween(to, *natural);
}

}  // namespace ss
