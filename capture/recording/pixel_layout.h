#pragma once
// How each raw camera format is stored losslessly in FFV1, and the exact
// repacking both ways (no colour conversion, no rounding: bit-exact):
//   bgr8, rgb8               <-> bgr0     (packed B G R X; rgb8 swaps on the way), or gbrp
//                                          (planes G, B, R) for ffvhuff, which decodes planes
//                                          about twice as fast as packed pixels
//   mono8, bayer_*8          <-> gray     (the Bayer pattern lives in session.json)
//   yuyv (Y0 U Y1 V)         <-> yuv422p
//   nv12 (Y, then UV pairs)  <-> yuv420p
#include <cstdint>

extern "C" {
#include <libavutil/frame.h>
#include <libavutil/pixfmt.h>
}

#include "core/frame.h"

namespace ss::av {

// The FFmpeg pixel format that holds a camera format's bytes as they are
// (bgr24, rgb24, gray, yuyv422, nv12); AV_PIX_FMT_NONE for MJPEG.
AVPixelFormat RawPixelFormat(PixelFormat format);
// The FFV1 storage format for a raw camera format; AV_PIX_FMT_NONE for MJPEG.
AVPixelFormat LosslessStorageFormat(PixelFormat format);
// Whether a decoded frame of `av_format` holds `format`'s bytes exactly (StorageToRaw takes it).
bool IsLosslessStorage(int av_format, PixelFormat format);

// Repacks `width` x `height` raw pixels into `dst` (allocated, writable, of
// LosslessStorageFormat(format), or gbrp for colour, and that size).
void RawToStorage(const uint8_t* src, PixelFormat format, int width, int height, AVFrame* dst);

// Repacks a decoded frame of LosslessStorageFormat(format) into raw bytes at
// `dst` (FrameBytes(format, width, height) of room).
void StorageToRaw(const AVFrame* src, PixelFormat format, int width, int height, uint8_t* dst);

}  // namespace ss::av
