#pragma once
// How the bank stores billboard pixels: the five 8-bit planes B, G, R, A, shadow
// (planar, row-major, width*height*5 bytes), compressed as one zstd frame that
// records its content size and a checksum of the content.
// The codec name is stored with each blob so that a later version can add others.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/bank_records.h"

struct ZSTD_CCtx_s;
struct ZSTD_DCtx_s;

namespace ss {

inline constexpr const char* kPixelCodec = "zstd-planar-bgras8";

class PixelCodec {
 public:
  PixelCodec();
  ~PixelCodec();
  PixelCodec(const PixelCodec&) = delete;
  PixelCodec& operator=(const PixelCodec&) = delete;

  // Compresses `pixels` (BGRA CV_8UC4, shadow CV_8UC1 of the same size or empty).
  // Throws WorkError naming the reason on a wrong type or size. The result is valid
  // until the next call.
  const std::vector<uint8_t>& Encode(const SpritePixels& pixels);
  // Decompresses a blob that should hold a width x height billboard. Throws WorkError
  // with the reason when the codec is unknown or the blob is not exactly that size.
  SpritePixels Decode(const void* data, size_t size, int width, int height,
                      const std::string& codec);

 private:
  ZSTD_CCtx_s* cctx_ = nullptr;
  ZSTD_DCtx_s* dctx_ = nullptr;
  std::vector<uint8_t> raw_;
  std::vector<uint8_t> compressed_;
};

}  // namespace ss
