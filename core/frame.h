#pragma once
// A Frame is one image as a camera delivered it: who took it, when, in which
// pixel format, and the bytes. Pixels are either owned by the frame or borrowed
// from a driver buffer that is given back when the last copy of the frame dies.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

enum class PixelFormat {
  kMono8,
  kBayerRG8,
  kBayerGR8,
  kBayerGB8,
  kBayerBG8,
  kRGB8,
  kBGR8,
  kYUYV,   // packed 4:2:2, Y0 U Y1 V
  kNV12,   // planar Y then interleaved UV at half resolution
  kMJPEG,  // one JPEG image per frame, size varies
};

// "mono8", "bayer_rg8", "rgb8", "bgr8", "yuyv", "nv12", "mjpeg".
std::string PixelFormatName(PixelFormat format);
// Inverse of PixelFormatName; std::nullopt for an unknown name.
std::optional<PixelFormat> ParsePixelFormat(const std::string& name);
// Bytes of one frame of that format and size; 0 for compressed formats.
size_t FrameBytes(PixelFormat format, int width, int height);

struct Frame {
  int camera = 0;            // index of the camera within its session or station
  uint64_t sequence = 0;     // device sequence number (gaps mean drops)
  int64_t timestamp_ns = 0;  // device timestamp
  PixelFormat format = PixelFormat::kBGR8;
  int width = 0;
  int height = 0;
  const uint8_t* data = nullptr;        // first byte of the pixels
  size_t size = 0;                      // bytes at data
  std::shared_ptr<const void> storage;  // keeps data alive (owned vector or borrowed buffer)

  // A frame owning a copy of its pixels.
  static Frame Owned(PixelFormat format, int width, int height, std::vector<uint8_t> pixels);
  // A frame borrowing `data`; `release` runs when the last copy of the frame is destroyed.
  static Frame Borrowed(PixelFormat format, int width, int height, const uint8_t* data, size_t size,
                        std::function<void()> release);
};

// Converts any frame to 8-bit BGR (OpenCV's order). Throws InputError naming the
// format and the reason when the frame is malformed (wrong size, bad JPEG).
cv::Mat ToBgr(const Frame& frame);
// Into a caller-owned buffer, reusing its allocation when the size matches.
void ToBgr(const Frame& frame, cv::Mat& bgr);

}  // namespace ss
