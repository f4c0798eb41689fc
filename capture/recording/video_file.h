#pragma once
// Rendered animations as video files, through FFmpeg's libraries; the container follows the
// file's extension:
//   .mkv  Matroska: codec h264 (libx264), ffv1 (lossless) or mjpeg
//   .mp4  MP4: H.264 through libx264 when this FFmpeg has it, else MPEG-4 part 2 (mpeg4)
// Frames are timed at a constant rate (pts = frame index at 1/fps). H.264 and MPEG-4 are
// coded as yuv420p, which players expect; they need an even width and height.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ss {

// True when `path` ends in an extension VideoFileWriter writes (.mkv, .mp4).
bool IsVideoPath(const std::string& path);

class VideoFileWriter {
 public:
  // Creates `path`. InputError for an unknown extension, a codec the container does not
  // take, or an odd size for a 4:2:0 codec; WorkError when FFmpeg cannot open it.
  VideoFileWriter(const std::string& path, int width, int height, double fps,
                  const std::string& codec = "h264");
  ~VideoFileWriter();  // Close()s; never throws
  VideoFileWriter(const VideoFileWriter&) = delete;
  VideoFileWriter& operator=(const VideoFileWriter&) = delete;

  // One frame: 8-bit BGR, or BGRA (composited over black) of the writer's size.
  void Write(const cv::Mat& image);
  // Drains the encoder and writes the trailer. Idempotent.
  void Close();

  int frames_written() const;
  const std::string& encoder_name() const;  // "libx264", "mpeg4", "ffv1", "mjpeg"

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Every frame of a video file, decoded to 8-bit BGR (checks and tests). InputError when
// the file cannot be read.
std::vector<cv::Mat> ReadVideoFrames(const std::string& path);

}  // namespace ss
