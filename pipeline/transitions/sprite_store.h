#pragma once
// What the transition finder keeps per sprite: bank id, clip links, the cheap
// features and the comparison image (stored once, contiguous, in chunks so that
// appending never moves existing images). The bank fills it (SpriteInput).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "pipeline/transitions/billboard.h"
#include "pipeline/transitions/comparison.h"
#include "pipeline/transitions/features.h"

namespace ss {

// One sprite handed to the transition finder; sprites of a clip arrive in frame order.
struct SpriteInput {
  int64_t id = 0;    // bank sprite id, unique
  int64_t clip = 0;  // bank clip id
  CheapFeatures cheap;
  const RgbaBillboard* billboard = nullptr;  // borrowed for the call
};

class SpriteStore {
 public:
  SpriteStore(const ComparisonWindow& window, double px_per_m);

  int32_t size() const { return static_cast<int32_t>(ids_.size()); }
  // Appends sprites after the last sprite of their clips (or as new clips), building
  // their comparison images on up to `threads` threads. Throws InputError naming the
  // sprite for a duplicate id, a missing or malformed billboard. Returns the first new index.
  int32_t Append(std::span<const SpriteInput> sprites, int threads = 1);
  void Clear();

  int64_t id(int32_t i) const { return ids_[i]; }
  int64_t clip(int32_t i) const { return clips_[i]; }
  int32_t prev(int32_t i) const {
    return prev_[i];
  }  // predecessor in its clip, -1 for a first frame
  int32_t next(int32_t i) const { return next_[i]; }  // successor in its clip, -1 for a last frame
  const CheapFeatures& cheap(int32_t i) const { return cheap_[i]; }
  const std::vector<CheapFeatures>& all_cheap() const { return cheap_; }
  const uint8_t* image(int32_t i) const {
    return chunks_[i >> kChunkShift].get() +
           static_cast<size_t>(i & (kChunkSize - 1)) * image_bytes_;
  }
  const CellBox& box(int32_t i) const { return boxes_[i]; }
  // The silhouette signature (docs/transitions.md "Silhouette signature"): the alpha plane
  // of the comparison image summed over fixed partitions of its cells, each sum clamped to
  // kSignatureMax (x -> min(x, M) moves no two values further apart, so clamping keeps the
  // bound). For any partition P, sum_{p in P} |S_i,p - S_j,p| <= sum_cells |A_i - A_j|
  // (triangle inequality), so each bound below is an exact lower bound of the alpha
  // feature's numerator, computed without reading a pixel. Level 1: a 4 x 4 grid of cell
  // blocks (32 bytes a sprite). Level 2: an 8 x 8 grid, 32 row bands and 32 column bands
  // (256 bytes); its bound is the largest of the three partitions' (the 8 x 8 grid refines
  // the 4 x 4 one, so level 2 >= level 1).
  static constexpr int kCoarseBlocks = 16;
  static constexpr int kSignatureGrid = 8;    // 8 x 8 blocks
  static constexpr int kSignatureBands = 32;  // row bands, and column bands
  static constexpr int kSignatureValues = kSignatureGrid * kSignatureGrid + 2 * kSignatureBands;
  static constexpr uint32_t kSignatureMax = 32767;  // 16-bit lanes, differences summed as int16
  uint64_t CoarseAlphaBound(int32_t i, int32_t j) const;
  uint64_t SignatureAlphaBound(int32_t i, int32_t j) const;
  // Proves without reading a pixel that max_cells |A_i - A_j| > limit (0..255): true when
  // some part p of the level-1 or level-2 signature has |S_i,p - S_j,p| > limit * cells(p),
  // since |S_i,p - S_j,p| <= sum_{cells in p} |A_i - A_j| <= cells(p) * max |A_i - A_j|
  // (clamping keeps it: x -> min(x, M) moves no two values further apart). False decides nothing.
  bool SignatureLinfExceeds(int32_t i, int32_t j, int limit) const;
  void PrefetchCoarse(int32_t i) const { __builtin_prefetch(coarse_[i].data()); }
  std::optional<int32_t> IndexOf(int64_t id) const;
  size_t clip_count() const { return clip_last_.size(); }
  const ComparisonWindow& window() const { return window_; }
  double px_per_m() const { return px_per_m_; }

  PixelDifference Pixels(int32_t i, int32_t j) const {
    return PixelDifferenceFromSums(SumPixelDifferences(image(i), image(j), window_.PlaneStride()),
                                   box(i), box(j));
  }
  PairFeatures Features(int32_t i, int32_t j) const {
    return MakePairFeatures(CheapDiff(cheap(i), cheap(j)), Pixels(i, j));
  }

 private:
  static constexpr int kChunkShift = 12;
  static constexpr int32_t kChunkSize = 1 << kChunkShift;
  // Fills coarse_[i] and signature_[i] from the alpha plane of image(i).
  void ComputeSignature(int32_t i);
  uint8_t* mutable_image(int32_t i) {
    return chunks_[i >> kChunkShift].get() +
           static_cast<size_t>(i & (kChunkSize - 1)) * image_bytes_;
  }

  ComparisonWindow window_;
  double px_per_m_;
  size_t image_bytes_;
  std::vector<int64_t> ids_, clips_;
  std::vector<int32_t> prev_, next_;
  std::vector<CheapFeatures> cheap_;
  std::vector<CellBox> boxes_;
  struct alignas(32) Coarse : std::array<uint16_t, kCoarseBlocks> {};
  struct alignas(64) Signature : std::array<uint16_t, kSignatureValues> {};
  std::vector<Coarse> coarse_;
  std::vector<Signature> signature_;
  std::array<uint32_t, kCoarseBlocks> coarse_cells_{};        // cells in each level-1 part
  std::array<uint32_t, kSignatureValues> signature_cells_{};  // cells in each level-2 part
  std::vector<std::unique_ptr<uint8_t[]>> chunks_;
  std::unordered_map<int64_t, int32_t> index_of_;
  std::unordered_map<int64_t, int32_t> clip_last_;
};

}  // namespace ss
