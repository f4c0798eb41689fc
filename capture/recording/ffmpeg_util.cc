#include "capture/recording/ffmpeg_util.h"

#include <cstdarg>
#include <cstdio>
#include <mutex>

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include "core/error.h"
#include "core/log.h"

namespace ss::av {
namespace {

void LogCallback(void* avcl, int level, const char* fmt, va_list args) {
  if (level > AV_LOG_WARNING) return;
  // FFmpeg builds one line from several calls; keep the prefix state per thread.
  thread_local int print_prefix = 1;
  thread_local std::string pending;
  char line[1024];
  av_log_format_line2(avcl, level, fmt, args, line, sizeof(line), &print_prefix);
  pending += line;
  if (pending.empty() || pending.back() != '\n') return;
  pending.pop_back();
  // Debug level: the damage FFmpeg complains about (a slice CRC mismatch, a
  // truncated block) is reported by our readers with the file and frame named.
  Log("capture.ffmpeg")->debug("{}", pending);
  pending.clear();
}

}  // namespace

FramePtr NewFrame() {
  FramePtr f(av_frame_alloc());
  if (!f) throw WorkError("ffmpeg", "out of memory allocating a frame");
  return f;
}

PacketPtr NewPacket() {
  PacketPtr p(av_packet_alloc());
  if (!p) throw WorkError("ffmpeg", "out of memory allocating a packet");
  return p;
}

std::string ErrorText(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, text, sizeof(text));
  return text;
}

void Check(int ret, const std::string& path, const std::string& what) {
  if (ret < 0) throw WorkError(path, what + ": " + ErrorText(ret));
}

void InstallLogBridge() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_callback(LogCallback); });
}

}  // namespace ss::av
