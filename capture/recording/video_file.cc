#include "capture/recording/video_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libswscale/swscale.h>
}

#include <opencv2/imgproc.hpp>

#include "capture/recording/ffmpeg_util.h"
#include "core/error.h"

namespace ss {
namespace {

std::string Extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

bool IsVideoPath(const std::string& path) {
  const std::string ext = Extension(path);
  return ext == ".mkv" || ext == ".mp4";
}

struct VideoFileWriter::State {
  std::string path;
  int width = 0;
  int height = 0;
  std::string encoder_name;
  AVFormatContext* output = nullptr;  // freed in Close (with its pb)
  AVStream* stream = nullptr;
  std::unique_ptr<AVCodecContext, av::CodecContextDeleter> encoder;
  std::unique_ptr<AVFrame, av::FrameDeleter> frame;
  std::unique_ptr<AVPacket, av::PacketDeleter> packet;
  std::unique_ptr<SwsContext, av::SwsDeleter> sws;
  int frames = 0;
  bool header_written = false;
  bool closed = false;

  void Encode(AVFrame* f) {
    av::Check(avcodec_send_frame(encoder.get(), f), path, "encoding failed");
    for (;;) {
      const int ret = avcodec_receive_packet(encoder.get(), packet.get());
      if (ret == AVERROR(EAGAIN) || ret == AVERROR_EOF) return;
      av::Check(ret, path, "encoding failed");
      av_packet_rescale_ts(packet.get(), encoder->time_base, stream->time_base);
      packet->stream_index = stream->index;
      av::Check(av_interleaved_write_frame(output, packet.get()), path, "cannot write a packet");
    }
  }

  void Free() {
    if (output != nullptr) {
      if (output->pb != nullptr) avio_closep(&output->pb);
      avformat_free_context(output);
      output = nullptr;
    }
  }
};

VideoFileWriter::VideoFileWriter(const std::string& path, int width, int height, double fps,
                                 const std::string& codec)
    : state_(std::make_unique<State>()) {
  // libx264 reports its settings at info level on every open: keep FFmpeg to warnings.
  if (av_log_get_level() > AV_LOG_WARNING) av_log_set_level(AV_LOG_WARNING);
  State& s = *state_;
  s.path = path;
  s.width = width;
  s.height = height;
  const std::string ext = Extension(path);
  if (ext != ".mkv" && ext != ".mp4") {
    throw InputError(path, "expected a .mkv or .mp4 file (or a folder for PNG frames)");
  }
  if (codec != "h264" && codec != "ffv1" && codec != "mjpeg") {
    throw InputError("--codec", "expected h264, ffv1 or mjpeg, got " + codec);
  }
  if (ext == ".mp4" && codec != "h264") {
    throw InputError("--codec",
                     "an .mp4 file is written as h264 (or mpeg4 without libx264), not " + codec);
  }
  if (width < 2 || height < 2 || !(fps > 0) || !std::isfinite(fps)) {
    throw InputError(path, "needs a size of at least 2x2 and a frame rate > 0");
  }
  const AVCodec* encoder = nullptr;
  AVPixelFormat coded = AV_PIX_FMT_YUV420P;
  if (codec == "ffv1") {
    encoder = avcodec_find_encoder(AV_CODEC_ID_FFV1);
    coded = AV_PIX_FMT_BGR0;
  } else if (codec == "mjpeg") {
    encoder = avcodec_find_encoder(AV_CODEC_ID_MJPEG);
    coded = AV_PIX_FMT_YUVJ420P;
  } else {
    encoder = avcodec_find_encoder_by_name("libx264");
    if (encoder == nullptr && ext == ".mp4") encoder = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
  }
  if (encoder == nullptr) throw WorkError(path, "this FFmpeg build has no encoder for " + codec);
  s.encoder_name = encoder->name;
  if (coded != AV_PIX_FMT_BGR0 && (width % 2 != 0 || height % 2 != 0)) {
    throw InputError(path, "4:2:0 video needs an even size, the camera is " +
                               std::to_string(width) + "x" + std::to_string(height) +
                               " (use a folder for PNG frames)");
  }

  av::Check(avformat_alloc_output_context2(&s.output, nullptr, ext == ".mp4" ? "mp4" : "matroska",
                                           path.c_str()),
            path, "cannot create the muxer");
  s.stream = avformat_new_stream(s.output, nullptr);
  if (s.stream == nullptr) throw WorkError(path, "cannot add a video stream");

  s.encoder.reset(avcodec_alloc_context3(encoder));
  if (!s.encoder) throw WorkError(path, "out of memory allocating the encoder");
  AVCodecContext* c = s.encoder.get();
  const AVRational rate = av_d2q(fps, 100000);
  c->width = width;
  c->height = height;
  c->pix_fmt = coded;
  c->time_base = av_inv_q(rate);
  c->framerate = rate;
  c->gop_size = std::max(1, static_cast<int>(std::lround(fps)));
  c->max_b_frames = 0;
  c->thread_count = 0;
  if (codec == "ffv1") c->gop_size = 1;
  if (codec == "mjpeg") {
    c->color_range = AVCOL_RANGE_JPEG;
    c->flags |= AV_CODEC_FLAG_QSCALE;
    c->global_quality = FF_QP2LAMBDA * 2;
  }
  if (s.encoder_name == "mpeg4") {
    c->flags |= AV_CODEC_FLAG_QSCALE;
    c->global_quality = FF_QP2LAMBDA * 3;
  }
  if (s.output->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  AVDictionary* options = nullptr;
  if (s.encoder_name == "libx264") {
    av_dict_set(&options, "preset", "veryfast", 0);
    av_dict_set(&options, "crf", "18", 0);
  }
  const int opened = avcodec_open2(c, encoder, &options);
  av_dict_free(&options);
  av::Check(opened, path, "cannot open the " + s.encoder_name + " encoder");
  av::Check(avcodec_parameters_from_context(s.stream->codecpar, c), path,
            "cannot set stream parameters");
  s.stream->time_base = c->time_base;
  s.stream->avg_frame_rate = rate;

  s.frame.reset(av_frame_alloc());
  s.packet.reset(av_packet_alloc());
  if (!s.frame || !s.packet) throw WorkError(path, "out of memory");
  s.frame->format = coded;
  s.frame->width = width;
  s.frame->height = height;
  av::Check(av_frame_get_buffer(s.frame.get(), 0), path, "cannot allocate a frame");
  s.sws.reset(sws_getContext(width, height, AV_PIX_FMT_BGR24, width, height, coded,
                             SWS_BICUBIC | SWS_ACCURATE_RND, nullptr, nullptr, nullptr));
  if (!s.sws) throw WorkError(path, "cannot convert BGR for " + s.encoder_name);

  av::Check(avio_open(&s.output->pb, path.c_str(), AVIO_FLAG_WRITE), path, "cannot create");
  av::Check(avformat_write_header(s.output, nullptr), path, "cannot write the header");
  s.header_written = true;
}

VideoFileWriter::~VideoFileWriter() {
  try {
    Close();
  } catch (...) {
  }
  if (state_) state_->Free();
}

void VideoFileWriter::Write(const cv::Mat& image) {
  State& s = *state_;
  if (s.closed) throw WorkError(s.path, "write after close");
  if (image.cols != s.width || image.rows != s.height || image.depth() != CV_8U ||
      (image.channels() != 3 && image.channels() != 4)) {
    throw WorkError(s.path, "frames must be 8-bit BGR or BGRA of " + std::to_string(s.width) + "x" +
                                std::to_string(s.height));
  }
  cv::Mat bgr;
  if (image.channels() == 4) {
    // Straight alpha over black: what the transparent parts look like in a video.
    std::vector<cv::Mat> planes;
    cv::split(image, planes);
    cv::Mat colour;
    cv::merge(std::vector<cv::Mat>{planes[0], planes[1], planes[2]}, colour);
    cv::Mat alpha;
    cv::cvtColor(planes[3], alpha, cv::COLOR_GRAY2BGR);
    cv::multiply(colour, alpha, bgr, 1.0 / 255.0);
  } else {
    bgr = image.isContinuous() ? image : image.clone();
  }
  av::Check(av_frame_make_writable(s.frame.get()), s.path, "cannot reuse the frame buffer");
  const uint8_t* src[4] = {bgr.data, nullptr, nullptr, nullptr};
  const int src_lines[4] = {static_cast<int>(bgr.step[0]), 0, 0, 0};
  sws_scale(s.sws.get(), src, src_lines, 0, s.height, s.frame->data, s.frame->linesize);
  s.frame->pts = s.frames;
  s.Encode(s.frame.get());
  ++s.frames;
}

void VideoFileWriter::Close() {
  if (!state_) return;
  State& s = *state_;
  if (s.closed) return;
  s.closed = true;
  if (s.header_written) {
    s.Encode(nullptr);
    av::Check(av_write_trailer(s.output), s.path, "cannot write the trailer");
  }
  s.Free();
}

int VideoFileWriter::frames_written() const { return state_->frames; }
const std::string& VideoFileWriter::encoder_name() const { return state_->encoder_name; }

std::vector<cv::Mat> ReadVideoFrames(const std::string& path) {
  AVFormatContext* raw = nullptr;
  int ret = avformat_open_input(&raw, path.c_str(), nullptr, nullptr);
  if (ret < 0) throw InputError(path, "not a readable video (" + av::ErrorText(ret) + ")");
  std::unique_ptr<AVFormatContext, av::InputDeleter> input(raw);
  ret = avformat_find_stream_info(input.get(), nullptr);
  if (ret < 0) throw InputError(path, "no stream information (" + av::ErrorText(ret) + ")");
  const AVCodec* decoder = nullptr;
  const int index = av_find_best_stream(input.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (index < 0 || decoder == nullptr) throw InputError(path, "no decodable video stream");
  std::unique_ptr<AVCodecContext, av::CodecContextDeleter> context(avcodec_alloc_context3(decoder));
  if (!context) throw WorkError(path, "out of memory");
  av::Check(avcodec_parameters_to_context(context.get(), input->streams[index]->codecpar), path,
            "bad stream parameters");
  av::Check(avcodec_open2(context.get(), decoder, nullptr), path, "cannot open the decoder");
  std::unique_ptr<AVPacket, av::PacketDeleter> packet(av_packet_alloc());
  std::unique_ptr<AVFrame, av::FrameDeleter> frame(av_frame_alloc());
  std::unique_ptr<SwsContext, av::SwsDeleter> sws;
  std::vector<cv::Mat> frames;
  auto drain = [&] {
    for (;;) {
      const int r = avcodec_receive_frame(context.get(), frame.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      if (r < 0) throw InputError(path, "damaged video data (" + av::ErrorText(r) + ")");
      sws.reset(sws_getCachedContext(
          sws.release(), frame->width, frame->height, static_cast<AVPixelFormat>(frame->format),
          frame->width, frame->height, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr));
      if (!sws) throw WorkError(path, "cannot convert the decoded frames to BGR");
      cv::Mat bgr(frame->height, frame->width, CV_8UC3);
      uint8_t* dst[4] = {bgr.data, nullptr, nullptr, nullptr};
      const int dst_lines[4] = {static_cast<int>(bgr.step[0]), 0, 0, 0};
      sws_scale(sws.get(), frame->data, frame->linesize, 0, frame->height, dst, dst_lines);
      frames.push_back(bgr);
      av_frame_unref(frame.get());
    }
  };
  while (av_read_frame(input.get(), packet.get()) >= 0) {
    if (packet->stream_index == index) {
      ret = avcodec_send_packet(context.get(), packet.get());
      av_packet_unref(packet.get());
      if (ret < 0 && ret != AVERROR(EAGAIN))
        throw InputError(path, "damaged video data (" + av::ErrorText(ret) + ")");
      drain();
    } else {
      av_packet_unref(packet.get());
    }
  }
  avcodec_send_packet(context.get(), nullptr);
  drain();
  return frames;
}

}  // namespace ss
