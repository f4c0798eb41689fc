#pragma once
// Reads one camera's Matroska video back frame by frame, in the camera's own
// pixel format (exact repacking for FFV1; swscale for the lossy codecs; an
// MJPEG camera's JPEGs as stored). Tolerates files cut short by a killed
// recorder (no index, no duration, a partial last cluster) and reports damaged
// frames instead of stopping: FFV1 slice CRCs, decoder errors, broken blocks.
//
// Decoding: with one decoder (decode_threads 1) the calling thread demuxes and
// decodes, and FFmpeg spreads each FFV1 frame's slices over its own threads.
// With more, the intra-only lossless codecs (ffv1, ffvhuff: every frame a
// keyframe) decode whole frames in parallel: the calling thread demuxes a few
// packets ahead and N decoder threads, each with its own FFmpeg decoder, check
// the slice CRCs, decode and repack them; frames come back in file order, each
// result (frame or damage) belonging to its own packet. The bytes are the same
// either way. Other codecs (mjpeg, h264) always use one decoder.
#include <cstdint>
#include <memory>
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
  // decode_threads: 1 = one decoder (FFmpeg's slice threads), 0 = one decoder
  // thread per core, N >= 2 = N decoder threads (intra-only codecs; see above).
  VideoReader(const std::string& path, PixelFormat format, int width, int height,
              int decode_threads = 1);
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;

  // Reads the next frame into `pixels`, resized to the frame's bytes (its
  // allocation is reused from call to call). Call from one thread at a time.
  Result Next(std::vector<uint8_t>& pixels);

  const std::string& path() const { return path_; }
  // Decoder threads reading in parallel; 1 when frames are decoded one after another.
  int decode_threads() const;

 private:
  struct Decoder;  // one FFmpeg decoder with its frame and converter (video_reader.cc)
  // One step of the demuxer: the next packet of the video stream, damage, or the end.
  struct Demuxed {
    enum class Kind { kPacket, kCorrupt, kEnd } kind = Kind::kEnd;
    int64_t pts_ms = -1;
    std::string problem;
  };
  struct Parallel;

  Demuxed ReadPacket();  // leaves a kPacket's data in packet_
  Result NextSequential(std::vector<uint8_t>& pixels);
  Result NextParallel(std::vector<uint8_t>& pixels);

  std::string path_;
  PixelFormat format_;
  int width_;
  int height_;
  bool passthrough_ = false;  // MJPEG camera: packets are the frames
  bool check_slice_crc_ = false;
  bool draining_ = false;
  int consecutive_read_errors_ = 0;
  int64_t last_sent_pts_ms_ = -1;
  av::InputPtr input_;
  int stream_index_ = -1;
  AVRational time_base_{1, 1000};
  std::unique_ptr<Decoder> decoder_;    // one decoder, on the calling thread
  std::unique_ptr<Parallel> parallel_;  // or decoder threads
  av::PacketPtr packet_;
};

// Checks every slice CRC of an FFV1 (level 3, slicecrc) packet; false with the reason when one
// fails.
bool Ffv1SlicesIntact(const uint8_t* data, size_t size, std::string* why);

}  // namespace ss
