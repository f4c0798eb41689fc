#include "capture/aravis/pixel_formats.h"

#include <arv.h>

#include <cstdio>

namespace ss {
namespace {

struct Entry {
  PixelFormat format;
  uint32_t code;
  const char* name;
};

constexpr Entry kEntries[] = {
    {PixelFormat::kMono8, ARV_PIXEL_FORMAT_MONO_8, "Mono8"},
    {PixelFormat::kBayerRG8, ARV_PIXEL_FORMAT_BAYER_RG_8, "BayerRG8"},
    {PixelFormat::kBayerGR8, ARV_PIXEL_FORMAT_BAYER_GR_8, "BayerGR8"},
    {PixelFormat::kBayerGB8, ARV_PIXEL_FORMAT_BAYER_GB_8, "BayerGB8"},
    {PixelFormat::kBayerBG8, ARV_PIXEL_FORMAT_BAYER_BG_8, "BayerBG8"},
    {PixelFormat::kRGB8, ARV_PIXEL_FORMAT_RGB_8_PACKED, "RGB8"},
    {PixelFormat::kBGR8, ARV_PIXEL_FORMAT_BGR_8_PACKED, "BGR8"},
    {PixelFormat::kYUYV, ARV_PIXEL_FORMAT_YUV_422_YUYV_PACKED, "YUV422_8"},
};

}  // namespace

std::optional<uint32_t> GenicamPixelFormat(PixelFormat format) {
  for (const auto& e : kEntries) {
    if (e.format == format) return e.code;
  }
  return std::nullopt;
}

std::optional<PixelFormat> FromGenicamPixelFormat(uint32_t code) {
  for (const auto& e : kEntries) {
    if (e.code == code) return e.format;
  }
  return std::nullopt;
}

std::string GenicamPixelFormatName(uint32_t code) {
  for (const auto& e : kEntries) {
    if (e.code == code) return e.name;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%08x", code);
  return hex;
}

}  // namespace ss
