#pragma once
// Any video FFmpeg reads (MP4 from a phone, an OBS or camera recording, an AVI,
// an image sequence such as `shot%04d.png` or `left*.jpg`), decoded frame by frame to 8-bit
// BGR with its time from the container: the frame's presentation timestamp
// since the stream's start, so a variable frame rate stays as it was recorded.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "capture/recording/ffmpeg_util.h"

namespace ss {

struct SourceFrame {
  cv::Mat bgr;               // CV_8UC3, the video's size
  int64_t timestamp_ns = 0;  // presentation time since the stream's start
  int64_t index = 0;         // frames delivered before it since the open (or the seek)
};

class SourceVideo {
 public:
  // Opens PATH. `image_sequence_fps` is the frame rate of an image sequence (a
  // path holding `%` as printf has it, or `*`, `?`, `[` as a glob, in sorted order),
  // which carries no time of its own. InputError
  // naming the file when it is missing, not a video FFmpeg reads, or holds no
  // decodable video stream.
  explicit SourceVideo(const std::string& path, double image_sequence_fps = 25);
  SourceVideo(const SourceVideo&) = delete;
  SourceVideo& operator=(const SourceVideo&) = delete;

  const std::string& path() const { return path_; }
  // The size frames come in: as a player shows them, turned by the stream's display rotation.
  int width() const { return width_; }
  int height() const { return height_; }
  int rotation_deg() const { return rotation_deg_; }  // clockwise turn applied: 0, 90, 180, 270
  double fps() const { return fps_; }  // nominal (the container's average); 0 when unknown
  double duration_s() const { return duration_s_; }    // -1 when the container does not say
  const std::string& codec() const { return codec_; }  // FFmpeg's decoder name, e.g. "h264"

  // Jumps to the last keyframe at or before `time_s` (the caller drops the
  // frames before it); call it before the first Next() only. When the
  // container cannot seek, reading starts at the beginning instead.
  void SeekBefore(double time_s);
  // The next frame; false at the end. A frame the decoder reports damaged is
  // skipped, counted in corrupt_frames() and described in last_problem().
  bool Next(SourceFrame* frame);

  int64_t corrupt_frames() const { return corrupt_frames_; }
  const std::string& last_problem() const { return last_problem_; }

 private:
  bool Receive(SourceFrame* frame);

  std::string path_;
  int width_ = 0, height_ = 0;              // displayed
  int coded_width_ = 0, coded_height_ = 0;  // decoded
  int rotation_ = -1;                       // cv::RotateFlags, -1 for none
  int rotation_deg_ = 0;
  cv::Mat coded_;  // the decoded frame before turning
  double fps_ = 0;
  double duration_s_ = -1;
  std::string codec_;
  int stream_ = -1;
  AVRational time_base_{1, 1};
  int64_t start_pts_ = AV_NOPTS_VALUE;
  int64_t last_timestamp_ns_ = INT64_MIN;
  int64_t next_index_ = 0;
  bool draining_ = false;
  bool ended_ = false;
  int64_t corrupt_frames_ = 0;
  std::string last_problem_;
  av::InputPtr input_;
  av::CodecContextPtr decoder_;
  av::PacketPtr packet_;
  av::FramePtr frame_;
  av::SwsPtr sws_;
};

}  // namespace ss
