#pragma once
// One camera's Matroska video, written through libavformat/libavcodec.
//   codec "ffv1":  lossless (FFV1 level 3, Golomb-Rice, every frame a keyframe, slice CRCs),
//                  bit-exact for every raw format (capture/recording/pixel_layout.h)
//   codec "ffvhuff": lossless, faster to decode, no checksums (core/recording_codecs.h)
//   codec "mjpeg": JPEG per frame (lossy); an MJPEG camera's JPEGs are stored as they came
//   codec "h264":  libx264, zero latency, no B-frames (lossy)
// Packet timestamps are milliseconds since the first frame (VideoPtsMs), so a
// player shows the recording at its true pace; the per-frame CSV stays authoritative.
#include <cstdint>
#include <string>
#include <vector>

#include "capture/recording/ffmpeg_util.h"
#include "core/frame.h"
#include "core/session.h"

namespace ss {

// The Matroska timestamp (ms) of a frame: its device time since the first frame,
// rounded, and forced strictly increasing. `previous_pts_ms` < 0 for the first frame.
int64_t VideoPtsMs(int64_t previous_pts_ms, int64_t first_timestamp_ns, int64_t timestamp_ns);
// VideoPtsMs over a whole CSV: the timestamp each row's frame carries in the video.
std::vector<int64_t> VideoPtsForRecords(const std::vector<FrameRecord>& records);

class VideoWriter {
 public:
  // Creates PATH; WorkError naming it when the codec or the file cannot be opened.
  VideoWriter(const std::string& path, PixelFormat format, int width, int height, double fps,
              const std::string& codec);
  ~VideoWriter();  // Close()s; never throws
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Encodes one frame (FrameBytes(format) bytes, or one JPEG for an MJPEG camera).
  void Write(const uint8_t* data, size_t size, int64_t pts_ms);
  // Ends the current Matroska cluster and hands every muxed byte to the OS, so
  // frames_muxed() frames survive a kill of the process.
  void Flush();
  // Drains the encoder, writes the index and closes the file. Idempotent.
  void Close();

  // Frames whose packets reached the muxer (in order; the encoders used have no reordering).
  int64_t frames_muxed() const { return frames_muxed_; }
  const std::string& path() const { return path_; }

 private:
  void Encode(AVFrame* frame);  // null drains
  void Mux(AVPacket* packet);

  std::string path_;
  PixelFormat format_;
  int width_;
  int height_;
  bool lossless_ = false;
  bool passthrough_ = false;  // MJPEG camera: packets are the camera's JPEGs
  bool closed_ = false;
  int64_t frames_muxed_ = 0;
  av::OutputPtr output_;
  AVStream* stream_ = nullptr;
  av::CodecContextPtr encoder_;
  av::FramePtr frame_;
  av::PacketPtr packet_;
  av::SwsPtr sws_;
};

}  // namespace ss
