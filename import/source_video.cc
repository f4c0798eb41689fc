#include "import/source_video.h"

#include <cmath>
#include <filesystem>

extern "C" {
#include <libavutil/dict.h>
#include <libavutil/display.h>
}

#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/log.h"

namespace ss {
namespace {

constexpr AVRational kNanos{1, 1000000000};
// Read errors in a row after which the rest of the file is given up as unreadable.
constexpr int kMaxConsecutiveReadErrors = 64;

// A printf pattern (img%04d.png) or a glob (left*.jpg): image2 reads the files as frames.
bool IsImageSequence(const std::string& path) {
  return path.find_first_of("%*?[") != std::string::npos;
}
bool IsGlob(const std::string& path) { return path.find_first_of("*?[") != std::string::npos; }

}  // namespace

SourceVideo::SourceVideo(const std::string& path, double image_sequence_fps) : path_(path) {
  av::InstallLogBridge();
  if (!IsImageSequence(path)) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path, "no such file");
    if (std::filesystem::is_directory(path, ec)) {
      throw InputError(
          path, "is a folder; for an image sequence give a pattern such as " + path + "/%04d.png");
    }
  }
  AVDictionary* options = nullptr;
  const AVInputFormat* format = nullptr;
  if (IsImageSequence(path)) {
    format = av_find_input_format("image2");
    av_dict_set(&options, "framerate", std::to_string(image_sequence_fps).c_str(), 0);
    if (IsGlob(path)) av_dict_set(&options, "pattern_type", "glob", 0);
  }
  AVFormatContext* raw = nullptr;
  const int opened = avformat_open_input(&raw, path.c_str(), format, &options);
  av_dict_free(&options);
  if (opened < 0)
    throw InputError(path, "FFmpeg cannot open it as a video (" + av::ErrorText(opened) + ")");
  input_.reset(raw);
  if (const int r = avformat_find_stream_info(input_.get(), nullptr); r < 0) {
    throw InputError(path, "FFmpeg cannot read its streams (" + av::ErrorText(r) + ")");
  }
  const AVCodec* codec = nullptr;
  stream_ = av_find_best_stream(input_.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
  if (stream_ < 0 || codec == nullptr) {
    throw InputError(path, stream_ == AVERROR_DECODER_NOT_FOUND
                               ? "its video is in a codec this FFmpeg cannot decode"
                               : "holds no video stream");
  }
  const AVStream* stream = input_->streams[stream_];
  time_base_ = stream->time_base;
  start_pts_ = stream->start_time;
  codec_ = codec->name;
  decoder_.reset(avcodec_alloc_context3(codec));
  if (!decoder_) throw WorkError(path, "out of memory for the decoder");
  if (const int r = avcodec_parameters_to_context(decoder_.get(), stream->codecpar); r < 0) {
    throw InputError(path, "bad codec parameters (" + av::ErrorText(r) + ")");
  }
  decoder_->thread_count = 0;
  decoder_->pkt_timebase = time_base_;
  if (const int r = avcodec_open2(decoder_.get(), codec, nullptr); r < 0) {
    throw InputError(path, "cannot open its " + codec_ + " decoder (" + av::ErrorText(r) + ")");
  }
  coded_width_ = decoder_->width;
  coded_height_ = decoder_->height;
  if (coded_width_ <= 0 || coded_height_ <= 0)
    throw InputError(path, "its video has no frame size");
  // A phone stores a portrait video as landscape frames and a display matrix that turns them;
  // players (and the ffmpeg CLI) show them turned, and so does the import.
  width_ = coded_width_;
  height_ = coded_height_;
  if (const uint8_t* matrix = av_stream_get_side_data(stream, AV_PKT_DATA_DISPLAYMATRIX, nullptr)) {
    const double ccw = av_display_rotation_get(reinterpret_cast<const int32_t*>(matrix));
    // Clockwise degrees, as the ffmpeg CLI's autorotation reads them.
    const int clockwise = ((static_cast<int>(std::lround(-ccw)) % 360) + 360) % 360;
    if (clockwise == 90) rotation_ = cv::ROTATE_90_CLOCKWISE;
    if (clockwise == 180) rotation_ = cv::ROTATE_180;
    if (clockwise == 270) rotation_ = cv::ROTATE_90_COUNTERCLOCKWISE;
    if (clockwise == 90 || clockwise == 270) std::swap(width_, height_);
    if (clockwise % 90 != 0 || std::isnan(ccw)) {
      Log("import")->warn("{}: a display rotation of {} degrees is not applied", path, -ccw);
    }
    rotation_deg_ = clockwise % 90 == 0 ? clockwise : 0;
  }
  const AVRational rate =
      stream->avg_frame_rate.num > 0 ? stream->avg_frame_rate : stream->r_frame_rate;
  if (rate.num > 0 && rate.den > 0) fps_ = av_q2d(rate);
  if (stream->duration != AV_NOPTS_VALUE && stream->duration > 0) {
    duration_s_ = stream->duration * av_q2d(time_base_);
  } else if (input_->duration != AV_NOPTS_VALUE && input_->duration > 0) {
    duration_s_ = static_cast<double>(input_->duration) / AV_TIME_BASE;
  }
  packet_ = av::NewPacket();
  frame_ = av::NewFrame();
}

void SourceVideo::SeekBefore(double time_s) {
  if (time_s <= 0) return;
  const int64_t base = start_pts_ == AV_NOPTS_VALUE ? 0 : start_pts_;
  const int64_t target =
      base + av_rescale_q(static_cast<int64_t>(std::llround(time_s * 1e9)), kNanos, time_base_);
  const int r = avformat_seek_file(input_.get(), stream_, INT64_MIN, target, target, 0);
  if (r < 0) {
    Log("import")->info("{}: the container cannot seek ({}); reading from the start", path_,
                        av::ErrorText(r));
    return;
  }
  avcodec_flush_buffers(decoder_.get());
}

bool SourceVideo::Receive(SourceFrame* out) {
  const int r = avcodec_receive_frame(decoder_.get(), frame_.get());
  if (r == AVERROR(EAGAIN)) {
    if (draining_) ended_ = true;  // a drained decoder owes nothing more
    return false;
  }
  if (r == AVERROR_EOF) {
    ended_ = true;
    return false;
  }
  if (r < 0) {
    ++corrupt_frames_;
    last_problem_ = "decoder error (" + av::ErrorText(r) + ")";
    return false;
  }
  int64_t pts = frame_->best_effort_timestamp;
  if (pts == AV_NOPTS_VALUE) pts = frame_->pts;
  int64_t timestamp_ns;
  if (pts == AV_NOPTS_VALUE) {
    // No time at all: one nominal frame after the last one.
    const int64_t step = static_cast<int64_t>(1e9 / (fps_ > 0 ? fps_ : 25.0));
    timestamp_ns = last_timestamp_ns_ == INT64_MIN ? 0 : last_timestamp_ns_ + step;
  } else {
    if (start_pts_ == AV_NOPTS_VALUE) start_pts_ = pts;  // the stream's start is its first frame
    timestamp_ns = av_rescale_q(pts - start_pts_, time_base_, kNanos);
  }
  if (frame_->flags & AV_FRAME_FLAG_CORRUPT || frame_->decode_error_flags != 0) {
    ++corrupt_frames_;
    last_problem_ =
        "the decoder reports the frame at " + std::to_string(timestamp_ns / 1e9) + " s damaged";
    av_frame_unref(frame_.get());
    return false;
  }
  if (frame_->width != coded_width_ || frame_->height != coded_height_) {
    ++corrupt_frames_;
    last_problem_ = "a frame of " + std::to_string(frame_->width) + "x" +
                    std::to_string(frame_->height) + " in a video of " +
                    std::to_string(coded_width_) + "x" + std::to_string(coded_height_) +
                    " (a size change mid-stream is not imported)";
    av_frame_unref(frame_.get());
    return false;
  }
  sws_.reset(sws_getCachedContext(
      sws_.release(), coded_width_, coded_height_, static_cast<AVPixelFormat>(frame_->format),
      coded_width_, coded_height_, AV_PIX_FMT_BGR24, SWS_BILINEAR, nullptr, nullptr, nullptr));
  if (!sws_) throw WorkError(path_, "cannot convert its pixel format to BGR");
  cv::Mat& coded = rotation_ < 0 ? out->bgr : coded_;
  coded.create(coded_height_, coded_width_, CV_8UC3);
  uint8_t* dst[4] = {coded.data, nullptr, nullptr, nullptr};
  int dst_lines[4] = {static_cast<int>(coded.step), 0, 0, 0};
  sws_scale(sws_.get(), frame_->data, frame_->linesize, 0, coded_height_, dst, dst_lines);
  av_frame_unref(frame_.get());
  if (rotation_ >= 0) cv::rotate(coded_, out->bgr, rotation_);
  out->timestamp_ns = timestamp_ns;
  out->index = next_index_++;
  last_timestamp_ns_ = timestamp_ns;
  return true;
}

bool SourceVideo::Next(SourceFrame* out) {
  int read_errors = 0;
  while (!ended_) {
    if (Receive(out)) return true;
    if (ended_) break;
    if (draining_) continue;  // a damaged frame: the next one
    const int r = av_read_frame(input_.get(), packet_.get());
    if (r == AVERROR_EOF) {
      draining_ = true;
      avcodec_send_packet(decoder_.get(), nullptr);
      continue;
    }
    if (r < 0) {
      ++corrupt_frames_;
      last_problem_ = "cannot read the container (" + av::ErrorText(r) + ")";
      if (++read_errors >= kMaxConsecutiveReadErrors) {
        Log("import")->warn("{}: {} read errors in a row; the rest of the file is unreadable",
                            path_, read_errors);
        draining_ = true;
        avcodec_send_packet(decoder_.get(), nullptr);
      }
      continue;
    }
    read_errors = 0;
    if (packet_->stream_index == stream_) {
      const int sent = avcodec_send_packet(decoder_.get(), packet_.get());
      if (sent < 0 && sent != AVERROR(EAGAIN)) {
        ++corrupt_frames_;
        last_problem_ = "the decoder refuses a packet (" + av::ErrorText(sent) + ")";
      }
    }
    av_packet_unref(packet_.get());
  }
  return false;
}

}  // namespace ss
