#include "core/bank_pixels.h"

#include <zstd.h>

#include <cstring>

#include "core/error.h"

namespace ss {
namespace {

// zstd level: 3 (zstd's default) compresses a 64x64 billboard in tens of microseconds.
constexpr int kZstdLevel = 3;
constexpr int kPlanes = 5;

}  // namespace

PixelCodec::PixelCodec() : cctx_(ZSTD_createCCtx()), dctx_(ZSTD_createDCtx()) {
  if (!cctx_ || !dctx_) throw WorkError("pixel codec", "out of memory creating zstd contexts");
  // A content checksum in every frame lets `bank verify` catch damaged pixels.
  ZSTD_CCtx_setParameter(cctx_, ZSTD_c_compressionLevel, kZstdLevel);
  ZSTD_CCtx_setParameter(cctx_, ZSTD_c_checksumFlag, 1);
}

PixelCodec::~PixelCodec() {
  ZSTD_freeCCtx(cctx_);
  ZSTD_freeDCtx(dctx_);
}

const std::vector<uint8_t>& PixelCodec::Encode(const SpritePixels& pixels) {
  const cv::Mat& bgra = pixels.bgra;
  if (bgra.empty() || bgra.type() != CV_8UC4) {
    throw WorkError("billboard pixels", "bgra must be a non-empty CV_8UC4 image");
  }
  if (!pixels.shadow.empty() &&
      (pixels.shadow.type() != CV_8UC1 || pixels.shadow.size() != bgra.size())) {
    throw WorkError("billboard pixels", "shadow must be CV_8UC1 of the billboard's size (" +
                                            std::to_string(bgra.cols) + "x" +
                                            std::to_string(bgra.rows) + ")");
  }
  const size_t n = static_cast<size_t>(bgra.cols) * static_cast<size_t>(bgra.rows);
  raw_.resize(n * kPlanes);
  uint8_t* planes[kPlanes];
  for (int p = 0; p < kPlanes; ++p) planes[p] = raw_.data() + n * static_cast<size_t>(p);
  size_t i = 0;
  for (int y = 0; y < bgra.rows; ++y) {
    const uint8_t* row = bgra.ptr<uint8_t>(y);
    for (int x = 0; x < bgra.cols; ++x, ++i) {
      planes[0][i] = row[4 * x];
      planes[1][i] = row[4 * x + 1];
      planes[2][i] = row[4 * x + 2];
      planes[3][i] = row[4 * x + 3];
    }
    if (!pixels.shadow.empty()) {
      std::memcpy(planes[4] + static_cast<size_t>(y) * bgra.cols, pixels.shadow.ptr<uint8_t>(y),
                  bgra.cols);
    }
  }
  if (pixels.shadow.empty()) std::memset(planes[4], 0, n);
  compressed_.resize(ZSTD_compressBound(raw_.size()));
  const size_t size =
      ZSTD_compress2(cctx_, compressed_.data(), compressed_.size(), raw_.data(), raw_.size());
  if (ZSTD_isError(size))
    throw WorkError("billboard pixels", std::string("zstd: ") + ZSTD_getErrorName(size));
  compressed_.resize(size);
  return compressed_;
}

SpritePixels PixelCodec::Decode(const void* data, size_t size, int width, int height,
                                const std::string& codec) {
  if (codec != kPixelCodec)
    throw WorkError("billboard pixels", "unknown pixel codec '" + codec + "'");
  if (width <= 0 || height <= 0) {
    throw WorkError("billboard pixels",
                    "bad size " + std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  const unsigned long long stated = ZSTD_getFrameContentSize(data, size);
  if (stated == ZSTD_CONTENTSIZE_ERROR) throw WorkError("billboard pixels", "not a zstd frame");
  if (stated == ZSTD_CONTENTSIZE_UNKNOWN) {  // every blob we write states it: a damaged header
    throw WorkError("billboard pixels",
                    "its zstd frame states no size (a damaged header), expected " +
                        std::to_string(n * kPlanes) + " bytes");
  }
  if (stated != n * kPlanes) {
    throw WorkError("billboard pixels", "holds " + std::to_string(stated) + " bytes, expected " +
                                            std::to_string(n * kPlanes) + " (" +
                                            std::to_string(width) + "x" + std::to_string(height) +
                                            "x5)");
  }
  raw_.resize(n * kPlanes);
  const size_t got = ZSTD_decompressDCtx(dctx_, raw_.data(), raw_.size(), data, size);
  if (ZSTD_isError(got))
    throw WorkError("billboard pixels", std::string("zstd: ") + ZSTD_getErrorName(got));
  if (got != n * kPlanes) {
    throw WorkError("billboard pixels", "decompressed to " + std::to_string(got) +
                                            " bytes, expected " + std::to_string(n * kPlanes));
  }
  SpritePixels pixels;
  pixels.bgra.create(height, width, CV_8UC4);
  pixels.shadow.create(height, width, CV_8UC1);
  const uint8_t* planes[kPlanes];
  for (int p = 0; p < kPlanes; ++p) planes[p] = raw_.data() + n * static_cast<size_t>(p);
  size_t i = 0;
  for (int y = 0; y < height; ++y) {
    uint8_t* row = pixels.bgra.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x, ++i) {
      row[4 * x] = planes[0][i];
      row[4 * x + 1] = planes[1][i];
      row[4 * x + 2] = planes[2][i];
      row[4 * x + 3] = planes[3][i];
    }
  }
  std::memcpy(pixels.shadow.data, planes[4], n);
  return pixels;
}

}  // namespace ss
