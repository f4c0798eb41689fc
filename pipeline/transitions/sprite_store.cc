#include "pipeline/transitions/sprite_store.h"

#include <emmintrin.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
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
  // Cells per signature part, with ComputeSignature's partition.
  constexpr int kBlocks = kSignatureGrid * kSignatureGrid;
  const int cx = window_.cells_x, cy = window_.cells_y;
  for (int v = 0; v < cy; ++v) {
    for (int u = 0; u < cx; ++u) {
      ++coarse_cells_[(v * 4 / cy) * 4 + u * 4 / cx];
      ++signature_cells_[(v * kSignatureGrid / cy) * kSignatureGrid + u * kSignatureGrid / cx];
      ++signature_cells_[kBlocks + v * kSignatureBands / cy];
      ++signature_cells_[kBlocks + kSignatureBands + u * kSignatureBands / cx];
    }
  }
}

bool SpriteStore::SignatureLinfExceeds(int32_t i, int32_t j, int limit) const {
  for (int k = 0; k < kCoarseBlocks; ++k) {
    const int64_t d = std::abs(int64_t{coarse_[i][k]} - int64_t{coarse_[j][k]});
    if (d > int64_t{limit} * coarse_cells_[k]) return true;
  }
  for (int k = 0; k < kSignatureValues; ++k) {
    const int64_t d = std::abs(int64_t{signature_[i][k]} - int64_t{signature_[j][k]});
    if (d > int64_t{limit} * signature_cells_[k]) return true;
  }
  return false;
}

void SpriteStore::Clear() {
  ids_.clear();
  clips_.clear();
  prev_.clear();
  next_.clear();
  cheap_.clear();
  boxes_.clear();
  coarse_.clear();
  signature_.clear();
  chunks_.clear();
  index_of_.clear();
  clip_last_.clear();
}

std::optional<int32_t> SpriteStore::IndexOf(int64_t id) const {
  auto it = index_of_.find(id);
  if (it == index_of_.end()) return std::nullopt;
  return it->second;
}

void SpriteStore::ComputeSignature(int32_t i) {
  // Cell (u, v) lies in block (u * G / cells_x, v * G / cells_y) of a G x G grid, in row
  // band v * 32 / cells_y and column band u * 32 / cells_x (empty parts when a window has
  // fewer cells than parts: they add 0 to both sides of the bound).
  const uint8_t* alpha = image(i);
  std::array<uint32_t, kCoarseBlocks> coarse{};
  std::array<uint32_t, kSignatureValues> sig{};
  constexpr int kBlocks = kSignatureGrid * kSignatureGrid;
  const int cx = window_.cells_x, cy = window_.cells_y;
  for (int v = 0; v < cy; ++v) {
    const int block_row = v * kSignatureGrid / cy, coarse_row = v * 4 / cy,
              band = v * kSignatureBands / cy;
    for (int u = 0; u < cx; ++u) {
      const uint32_t a = alpha[v * cx + u];
      coarse[coarse_row * 4 + u * 4 / cx] += a;
      sig[block_row * kSignatureGrid + u * kSignatureGrid / cx] += a;
      sig[kBlocks + band] += a;
      sig[kBlocks + kSignatureBands + u * kSignatureBands / cx] += a;
    }
  }
  for (int k = 0; k < kCoarseBlocks; ++k)
    coarse_[i][k] = static_cast<uint16_t>(std::min(coarse[k], kSignatureMax));
  for (int k = 0; k < kSignatureValues; ++k)
    signature_[i][k] = static_cast<uint16_t>(std::min(sig[k], kSignatureMax));
}

namespace {

// sum |a_k - b_k| over `vectors` x 8 values in [0, 32767] (SSE2: the x86-64 baseline).
inline __m128i AbsDifferenceSums(const uint16_t* a, const uint16_t* b, int vectors) {
  const __m128i ones = _mm_set1_epi16(1);
  __m128i sum = _mm_setzero_si128();
  for (int k = 0; k < vectors; ++k) {
    const __m128i x = _mm_load_si128(reinterpret_cast<const __m128i*>(a) + k);
    const __m128i y = _mm_load_si128(reinterpret_cast<const __m128i*>(b) + k);
    // <= 32767: a valid int16
    const __m128i d = _mm_or_si128(_mm_subs_epu16(x, y), _mm_subs_epu16(y, x));
    sum = _mm_add_epi32(sum, _mm_madd_epi16(d, ones));
  }
  return sum;
}
inline uint64_t HorizontalSum(__m128i v) {
  alignas(16) int32_t lanes[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(lanes), v);
  return static_cast<uint64_t>(lanes[0]) + lanes[1] + lanes[2] + lanes[3];
}

}  // namespace

uint64_t SpriteStore::CoarseAlphaBound(int32_t i, int32_t j) const {
  return HorizontalSum(AbsDifferenceSums(coarse_[i].data(), coarse_[j].data(), kCoarseBlocks / 8));
}

uint64_t SpriteStore::SignatureAlphaBound(int32_t i, int32_t j) const {
  constexpr int kBlocks = kSignatureGrid * kSignatureGrid;
  const uint16_t* a = signature_[i].data();
  const uint16_t* b = signature_[j].data();
  const uint64_t blocks = HorizontalSum(AbsDifferenceSums(a, b, kBlocks / 8));
  const uint64_t rows =
      HorizontalSum(AbsDifferenceSums(a + kBlocks, b + kBlocks, kSignatureBands / 8));
  const uint64_t cols = HorizontalSum(AbsDifferenceSums(
      a + kBlocks + kSignatureBands, b + kBlocks + kSignatureBands, kSignatureBands / 8));
  return std::max({blocks, rows, cols});
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
  // Grow geometrically: reserve(n) alone would reallocate (and copy) every vector on each
  // one-sprite Add.
  const size_t capacity = n <= ids_.capacity() ? ids_.capacity() : std::max(n, 2 * ids_.capacity());
  ids_.reserve(capacity);
  clips_.reserve(capacity);
  prev_.reserve(capacity);
  next_.reserve(capacity);
  cheap_.reserve(capacity);
  boxes_.resize(n);
  coarse_.resize(n);
  signature_.resize(n);
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
          boxes_[i] =
              MakeComparisonImage(*sprites[k].billboard, px_per_m_, window_, mutable_image(i));
          ComputeSignature(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
      }
    }
  };
  const int workers =
      std::clamp(threads, 1, static_cast<int>(std::max<size_t>(1, sprites.size() / 256)));
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return first;
}

}  // namespace ss
