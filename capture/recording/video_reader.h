#pragma once
// Reads one camera's Matroska video back frame by frame, in the camera's own
// pixel format (exact repacking for FFV1; swscale for the lossy codecs; an
// MJPEG camera's JPEGs as stored). Tolerates files cut short by a killed
// recorder (no index, no duration, a partial last cluster) and reports damaged
// frames instead of stopping: FFV1 slice CRCs, decoder errors, broken blocks.
#include <cstdint>
#include <string>
#include <vector>

#include "capture/recording/ffmpeg_util.h"
#include "core/frame.h"

namespace ss {

class VideoReader {
 public:
  enum class Status {
    kFrame,    // pixels hold the next frame
    kCorrupt,  // one frame (or a stretch of the container) could not be read; reading goes on
    kEnd,      // no more frames
  };
  struct Result {
    Status status = Status::kEnd;
    int64_t pts_ms = -1;  // the frame's Matroska timestamp; -1 when unknown (container damage)
    std::string problem;  // for kCorrupt: what was wrong
  };

  // Opens PATH holding a `format` camera of width x height. InputError naming
  // the file when it is missing, not Matroska, or holds no decodable video.
  VideoReader(const std::string& path, PixelFormat format, int width, int height);
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;

  // Reads the next frame into `pixels`, resized to the frame's bytes (its
  // allocation is reused from call to call).
  Result Next(std::vector<uint8_t>& pixels);

  const std::string& path() const { return path_; }

 private:
  Result Receive(std::vector<uint8_t>& pixels, bool* need_packet);
  Result Convert(const AVFrame* frame, std::vector<uint8_t>& pixels);

  std::string path_;
  PixelFormat format_;
  int width_;
  int height_;
  bool passthrough_ = false;   // MJPEG camera: packets are the frames
  bool check_slice_crc_ = false;
  bool draining_ = false;
  int consecutive_read_errors_ = 0;
  int64_t last_sent_pts_ms_ = -1;
  av::InputPtr input_;
  int stream_index_ = -1;
  AVRational time_base_{1, 1000};
  av::CodecContextPtr decoder_;
  av::FramePtr frame_;
  av::PacketPtr packet_;
  av::SwsPtr sws_;
  int sws_source_format_ = AV_PIX_FMT_NONE;
};

// Checks every slice CRC of an FFV1 (level 3, slicecrc) packet; false with the reason when one fails.
bool Ffv1SlicesIntact(const uint8_t* data, size_t size, std::string* why);

}  // namespace ss
