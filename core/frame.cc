#include "core/frame.h"

#include <array>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ss {
namespace {

struct FormatName {
  PixelFormat format;
  const char* name;
};
constexpr std::array<FormatName, 10> kNames{{
    {PixelFormat::kMono8, "mono8"},
    {PixelFormat::kBayerRG8, "bayer_rg8"},
    {PixelFormat::kBayerGR8, "bayer_gr8"},
    {PixelFormat::kBayerGB8, "bayer_gb8"},
    {PixelFormat::kBayerBG8, "bayer_bg8"},
    {PixelFormat::kRGB8, "rgb8"},
    {PixelFormat::kBGR8, "bgr8"},
    {PixelFormat::kYUYV, "yuyv"},
    {PixelFormat::kNV12, "nv12"},
    {PixelFormat::kMJPEG, "mjpeg"},
}};

}  // namespace

std::string PixelFormatName(PixelFormat format) {
  for (const auto& n : kNames) {
    if (n.format == format) return n.name;
  }
  return "unknown";
}

std::optional<PixelFormat> ParsePixelFormat(const std::string& name) {
  for (const auto& n : kNames) {
    if (name == n.name) return n.format;
  }
  return std::nullopt;
}

size_t FrameBytes(PixelFormat format, int width, int height) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  switch (format) {
    case PixelFormat::kMono8:
    case PixelFormat::kBayerRG8:
    case PixelFormat::kBayerGR8:
    case PixelFormat::kBayerGB8:
    case PixelFormat::kBayerBG8:
      return pixels;
    case PixelFormat::kRGB8:
    case PixelFormat::kBGR8:
      return pixels * 3;
    case PixelFormat::kYUYV:
      return pixels * 2;
    case PixelFormat::kNV12:
      return pixels * 3 / 2;
    case PixelFormat::kMJPEG:
      return 0;
  }
  return 0;
}

Frame Frame::Owned(PixelFormat format, int width, int height, std::vector<uint8_t> pixels) {
  auto owned = std::make_shared<std::vector<uint8_t>>(std::move(pixels));
  Frame f;
  f.format = format;
  f.width = width;
  f.height = height;
  f.data = owned->data();
  f.size = owned->size();
  f.storage = std::move(owned);
  return f;
}

Frame Frame::Borrowed(PixelFormat format, int width, int height, const uint8_t* data, size_t size,
                      std::function<void()> release) {
  Frame f;
  f.format = format;
  f.width = width;
  f.height = height;
  f.data = data;
  f.size = size;
  f.storage = std::shared_ptr<const void>(data, [release = std::move(release)](const void*) {
    if (release) release();
  });
  return f;
}

void ToBgr(const Frame& frame, cv::Mat& bgr) {
  const std::string fmt = PixelFormatName(frame.format);
  if (frame.width <= 0 || frame.height <= 0 || frame.data == nullptr) {
    throw InputError("frame " + std::to_string(frame.sequence),
                     "empty " + fmt + " frame (" + std::to_string(frame.width) + "x" +
                         std::to_string(frame.height) + ")");
  }
  const size_t expected = FrameBytes(frame.format, frame.width, frame.height);
  if (expected != 0 && frame.size < expected) {
    throw InputError("frame " + std::to_string(frame.sequence),
                     fmt + " frame holds " + std::to_string(frame.size) + " bytes, expected " +
                         std::to_string(expected));
  }
  auto* data = const_cast<uint8_t*>(frame.data);  // cv::Mat header only; never written
  const int w = frame.width;
  const int h = frame.height;
  switch (frame.format) {
    case PixelFormat::kBGR8:
      cv::Mat(h, w, CV_8UC3, data).copyTo(bgr);
      return;
    case PixelFormat::kRGB8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC3, data), bgr, cv::COLOR_RGB2BGR);
      return;
    case PixelFormat::kMono8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC1, data), bgr, cv::COLOR_GRAY2BGR);
      return;
    // OpenCV names Bayer patterns by the second row's first two pixels:
    // an RGGB sensor (R at 0,0) is COLOR_BayerBG2BGR.
    case PixelFormat::kBayerRG8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC1, data), bgr, cv::COLOR_BayerBG2BGR);
      return;
    case PixelFormat::kBayerGR8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC1, data), bgr, cv::COLOR_BayerGB2BGR);
      return;
    case PixelFormat::kBayerGB8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC1, data), bgr, cv::COLOR_BayerGR2BGR);
      return;
    case PixelFormat::kBayerBG8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC1, data), bgr, cv::COLOR_BayerRG2BGR);
      return;
    case PixelFormat::kYUYV:
      cv::cvtColor(cv::Mat(h, w, CV_8UC2, data), bgr, cv::COLOR_YUV2BGR_YUYV);
      return;
    case PixelFormat::kNV12:
      cv::cvtColor(cv::Mat(h * 3 / 2, w, CV_8UC1, data), bgr, cv::COLOR_YUV2BGR_NV12);
      return;
    case PixelFormat::kMJPEG: {
      cv::Mat decoded =
          cv::imdecode(cv::Mat(1, static_cast<int>(frame.size), CV_8UC1, data), cv::IMREAD_COLOR);
      if (decoded.empty() || decoded.cols != w || decoded.rows != h) {
        throw InputError(
            "frame " + std::to_string(frame.sequence),
            "MJPEG frame does not decode to " + std::to_string(w) + "x" + std::to_string(h));
      }
      bgr = std::move(decoded);
      return;
    }
  }
  throw InputError("frame " + std::to_string(frame.sequence), "unknown pixel format");
}

cv::Mat ToBgr(const Frame& frame) {
  cv::Mat bgr;
  ToBgr(frame, bgr);
  return bgr;
}

}  // namespace ss
