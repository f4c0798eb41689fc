#pragma once
// GenICam pixel formats (Aravis's ArvPixelFormat codes) the backend and the
// emulated camera understand, mapped to SpriteStation's PixelFormat.
#include <cstdint>
#include <optional>
#include <string>

#include "core/frame.h"

namespace ss {

// The GenICam code of a format; std::nullopt for formats GigE Vision does not carry (NV12, MJPEG).
std::optional<uint32_t> GenicamPixelFormat(PixelFormat format);
// The PixelFormat of a GenICam code; std::nullopt for any other code (Mono16, packed 12-bit, ...).
std::optional<PixelFormat> FromGenicamPixelFormat(uint32_t code);
// "Mono8", "BayerRG8", "RGB8", ... (the GenICam name), or the code in hex.
std::string GenicamPixelFormatName(uint32_t code);

}  // namespace ss
