#include "animate/playback.h"

#include "core/error.h"

namespace ss {

namespace {
constexpr size_t kCacheSprites = 4096;
}

SequencePlayer::SequencePlayer(const std::vector<std::string>& bank_paths,
                               std::unique_ptr<SpriteRenderer> renderer)
    : renderer_(std::move(renderer)) {
  for (const std::string& path : bank_paths) banks_.push_back(std::make_unique<Bank>(path));
}

const SequencePlayer::Billboard& SequencePlayer::Load(const BankFrameRef& ref) {
  const auto key = std::make_pair(ref.bank, ref.sprite_id);
  if (const auto it = cache_.find(key); it != cache_.end()) return it->second;
  if (ref.bank < 0 || ref.bank >= static_cast<int>(banks_.size())) {
    throw InputError("sequences", "no bank " + std::to_string(ref.bank));
  }
  const Bank& bank = *banks_[ref.bank];
  const SpriteRecord record = bank.LoadSprite(ref.sprite_id);
  Billboard b;
  b.pixels = bank.LoadPixels(ref.sprite_id);
  b.anchor_px = Eigen::Vector2d(record.anchor_x_px, record.anchor_y_px);
  b.px_per_m = record.px_per_m;
  b.kind = record.kind;
  b.heading_rad = record.heading_rad;
  return cache_.emplace(key, std::move(b)).first->second;
}

cv::Mat SequencePlayer::RenderStep(const std::vector<SpriteSequence>& sprites, int t) {
  // Cleared only between steps: `placed` points into the cache.
  if (cache_.size() + sprites.size() > kCacheSprites) cache_.clear();
  std::vector<PlacedSprite> placed;
  for (const SpriteSequence& s : sprites) {
    if (s.frames.empty()) continue;
    const int step = std::min<int>(t, static_cast<int>(s.frames.size()) - 1);
    const Billboard& b = Load(s.frames[step]);
    placed.push_back({&b.pixels, b.anchor_px, b.px_per_m, s.positions_m[step], b.kind,
                      b.heading_rad + s.TurnAt(static_cast<size_t>(step))});
  }
  return renderer_->Render(placed);
}

}  // namespace ss
