#include "pipeline/transitions/visible_jump.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <utility>

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
  check.Within(max_pairs, AtLeast(1), "max_pairs", "at least 1");
  check.Within(min_step_px, Positive(), "min_step_px", "a positive number of px");
  return check.ok();
}

VisibleJumpMeter::VisibleJumpMeter(const Bank& bank, VisibleJumpOptions options)
    : options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("visible jump options", why);
  const std::vector<SpriteFeatures> features = bank.LoadFeatures();
  std::vector<JumpFrame> frames;
  frames.reserve(features.size());
  for (const SpriteFeatures& f : features) {
    JumpFrame frame{f.id, f.clip_id, f.mirrored, std::nullopt};
    if (f.next >= 0) frame.next = features[f.next].id;
    frames.push_back(frame);
  }
  Index(frames);
  load_ = [&bank](int64_t id) {
    const SpriteRecord record = bank.LoadSprite(id);
    return BillboardFromPixels(bank.LoadPixels(id), record.anchor_x_px, record.anchor_y_px,
                               record.kind == SpriteKind::kFloor);
  };
  cache_key_ = bank.path() + "\n" + std::to_string(features.size()) + "\n" +
               std::to_string(options_.max_pairs) + "\n" + std::to_string(options_.min_step_px);
}

VisibleJumpMeter::VisibleJumpMeter(const std::vector<JumpFrame>& frames, BillboardLoader load,
                                   const std::string& cache_key, VisibleJumpOptions options)
    : load_(std::move(load)), options_(options) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("visible jump options", why);
  Index(frames);
  if (!cache_key.empty()) {
    cache_key_ = cache_key + "\n" + std::to_string(frames.size()) + "\n" +
                 std::to_string(options_.max_pairs) + "\n" + std::to_string(options_.min_step_px);
  }
}

void VisibleJumpMeter::Index(const std::vector<JumpFrame>& frames) {
  for (const JumpFrame& f : frames) {
    clip_of_[f.id] = {f.clip, f.mirrored};
    if (!f.next) continue;
    next_[f.id] = *f.next;
    if (!f.mirrored) originals_with_next_.push_back(f.id);
  }
}

std::optional<int64_t> VisibleJumpMeter::NaturalSuccessor(int64_t id) const {
  const auto it = next_.find(id);
  if (it == next_.end()) return std::nullopt;
  return it->second;
}

std::optional<TransitionKind> VisibleJumpMeter::KindOf(int64_t from, int64_t to) const {
  const auto a = clip_of_.find(from), b = clip_of_.find(to);
  if (a == clip_of_.end() || b == clip_of_.end()) return std::nullopt;
  if (a->second.second != b->second.second) return TransitionKind::kOriginalMirror;
  return a->second.first == b->second.first ? TransitionKind::kWithinClip
                                            : TransitionKind::kJoiningClips;
}

const RgbaBillboard& VisibleJumpMeter::Billboard(int64_t id) {
  if (const auto it = billboards_.find(id); it != billboards_.end()) return it->second;
  return billboards_.emplace(id, load_(id)).first->second;
}

double VisibleJumpMeter::Difference_px(int64_t a, int64_t b) {
  if (a == b) return 0.0;
  // Room for both before either is loaded: the references stay valid.
  if (billboards_.size() + 2 > kKeptBillboards) billboards_.clear();
  const RgbaBillboard& first = Billboard(a);
  return ContactAlignedDifference_px(first, Billboard(b));
}

double VisibleJumpMeter::MedianStep_px() {
  if (median_step_px_) return *median_step_px_;
  if (!cache_key_.empty()) {
    const std::lock_guard<std::mutex> lock(CacheMutex());
    const auto it = MedianCache().find(cache_key_);
    if (it != MedianCache().end()) return *(median_step_px_ = it->second);
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
  median_step_px_ = median;
  if (cache_key_.empty()) return median;
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
