#pragma once
// Move-only RAII owners for FFmpeg's handles, FFmpeg error text, and the bridge
// that sends libav* log lines to spdlog ([capture.ffmpeg]).
#include <memory>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include "core/frame.h"

namespace ss::av {

struct CodecContextDeleter {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameDeleter {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketDeleter {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct SwsDeleter {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
// An input context (avformat_open_input).
struct InputDeleter {
  void operator()(AVFormatContext* f) const { avformat_close_input(&f); }
};
// An output context with its file (avformat_alloc_output_context2 + avio_open).
struct OutputDeleter {
  void operator()(AVFormatContext* f) const {
    if (f == nullptr) return;
    if (f->pb != nullptr && !(f->oformat->flags & AVFMT_NOFILE)) avio_closep(&f->pb);
    avformat_free_context(f);
  }
};

using CodecContextPtr = std::unique_ptr<AVCodecContext, CodecContextDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using SwsPtr = std::unique_ptr<SwsContext, SwsDeleter>;
using InputPtr = std::unique_ptr<AVFormatContext, InputDeleter>;
using OutputPtr = std::unique_ptr<AVFormatContext, OutputDeleter>;

// A new AVFrame / AVPacket; throws WorkError when out of memory.
FramePtr NewFrame();
PacketPtr NewPacket();

// FFmpeg's text for an AVERROR code.
std::string ErrorText(int code);
// Every FFmpeg failure (ret < 0) becomes a WorkError naming the file and the step.
void Check(int ret, const std::string& path, const std::string& what);

// Milliseconds: the time base of the recordings' video streams.
inline constexpr AVRational kMillis{1, 1000};

// Routes libav* log lines (warnings and errors) to spdlog's [capture.ffmpeg]; idempotent.
void InstallLogBridge();

}  // namespace ss::av
