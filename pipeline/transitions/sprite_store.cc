#include "pipeline/transitions/sprite_store.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

#include "core/error.h"

namespace ss {

SpriteStore::SpriteStore(const ComparisonWindow& window, double px_per_m)
    : window_(window), px_per_m_(px_per_m), image_bytes_(window.ImageBytes()) {
  std::string why;
  if (!window.IsValid(&why)) throw InputError("comparison_window", why);
  if (!(px_per_m > 0)) throw InputError("px_per_m", "must be positive");
}

void SpriteStore::Clear() {
  ids_.clear();
  clips_.clear();
  prev_.clear();
  next_.clear();
  cheap_.clear();
  boxes_.clear();
  alpha_blocks_.clear();
  chunks_.clear();
  index_of_.clear();
  clip_last_.clear();
}

std::optional<int32_t> SpriteStore::IndexOf(int64_t id) const {
  auto it = index_of_.find(id);
  if (it == index_of_.end()) return std::nullopt;
  return it->second;
}

int32_t SpriteStore::Append(std::span<const SpriteInput> sprites, int threads) {
  const int32_t first = size();
  // Validate everything before changing anything.
  std::unordered_map<int64_t, int32_t> batch_ids;
  for (size_t k = 0; k < sprites.size(); ++k) {
    const SpriteInput& s = sprites[k];
    const std::string name = "sprite " + std::to_string(s.id);
    if (index_of_.count(s.id) || !batch_ids.emplace(s.id, 0).second) {
      throw InputError(name, "appears twice (sprite ids must be unique)");
    }
    if (!s.billboard) throw InputError(name, "has no billboard");
    try {
      ValidateBillboard(*s.billboard);
    } catch (const InputError& e) {
      throw InputError(name, e.what());
    }
  }
  const size_t n = static_cast<size_t>(first) + sprites.size();
  if (n > static_cast<size_t>(INT32_MAX)) throw InputError("sprites", "more than 2^31 sprites");
  ids_.reserve(n);
  clips_.reserve(n);
  prev_.reserve(n);
  next_.reserve(n);
  cheap_.reserve(n);
  boxes_.resize(n);
  alpha_blocks_.resize(n);
  while (chunks_.size() * kChunkSize < n) {
    chunks_.emplace_back(new uint8_t[static_cast<size_t>(kChunkSize) * image_bytes_]);
  }
  for (const SpriteInput& s : sprites) {
    const int32_t i = static_cast<int32_t>(ids_.size());
    ids_.push_back(s.id);
    clips_.push_back(s.clip);
    cheap_.push_back(s.cheap);
    next_.push_back(-1);
    auto [it, inserted] = clip_last_.try_emplace(s.clip, i);
    if (inserted) {
      prev_.push_back(-1);
    } else {
      prev_.push_back(it->second);
      next_[it->second] = i;
      it->second = i;
    }
    index_of_.emplace(s.id, i);
  }
  // Comparison images, in parallel over blocks.
  std::atomic<size_t> cursor{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    constexpr size_t kBlock = 64;
    for (size_t begin; (begin = cursor.fetch_add(kBlock)) < sprites.size();) {
      const size_t end = std::min(sprites.size(), begin + kBlock);
      for (size_t k = begin; k < end; ++k) {
        const int32_t i = first + static_cast<int32_t>(k);
        try {
          boxes_[i] = MakeComparisonImage(*sprites[k].billboard, px_per_m_, window_, mutable_image(i));
          const uint8_t* alpha = image(i);
          auto& blocks = alpha_blocks_[i];
          blocks.fill(0);
          for (int v = 0; v < window_.cells_y; ++v) {
            for (int u = 0; u < window_.cells_x; ++u) {
              blocks[(v * 4 / window_.cells_y) * 4 + u * 4 / window_.cells_x] += alpha[v * window_.cells_x + u];
            }
          }
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
      }
    }
  };
  const int workers = std::clamp(threads, 1, static_cast<int>(std::max<size_t>(1, sprites.size() / 256)));
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return first;
}

}  // namespace ss
