#include "capture/recording/video_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

extern "C" {
#include <libavutil/dict.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
}

#include "capture/recording/pixel_layout.h"
#include "core/error.h"
#include "core/log.h"
#include "core/recording_codecs.h"

namespace ss {
namespace {

// An AVDictionary of options, freed on scope exit (what the callee left unused).
struct Dict {
  AVDictionary* d = nullptr;
  Dict() = default;
  Dict(const Dict&) = delete;
  Dict& operator=(const Dict&) = delete;
  ~Dict() { av_dict_free(&d); }
  void Set(const char* key, const char* value) { av_dict_set(&d, key, value, 0); }
};

}  // namespace

int64_t VideoPtsMs(int64_t previous_pts_ms, int64_t first_timestamp_ns, int64_t timestamp_ns) {
  if (previous_pts_ms < 0) return 0;
  const double ms = std::round(static_cast<double>(timestamp_ns - first_timestamp_ns) / 1e6);
  const int64_t pts = static_cast<int64_t>(ms);
  return std::max(pts, previous_pts_ms + 1);
}

std::vector<int64_t> VideoPtsForRecords(const std::vector<FrameRecord>& records) {
  std::vector<int64_t> pts;
  pts.reserve(records.size());
  int64_t previous = -1;
  for (const auto& r : records) {
    previous = VideoPtsMs(previous, records.front().timestamp_ns, r.timestamp_ns);
    pts.push_back(previous);
  }
  return pts;
}

VideoWriter::VideoWriter(const std::string& path, PixelFormat format, int width, int height,
                         double fps, const std::string& codec)
    : path_(path), format_(format), width_(width), height_(height) {
  av::InstallLogBridge();
  passthrough_ = format == PixelFormat::kMJPEG;
  const RecordingCodec* known = FindRecordingCodec(codec);
  lossless_ = known != nullptr && known->lossless;
  if (passthrough_ && codec != "mjpeg") {
    throw WorkError(path, "an MJPEG camera is recorded as codec 'mjpeg', not '" + codec + "'");
  }
  if (known == nullptr) {
    throw WorkError(path, "unknown codec '" + codec + "' (expected " + RecordingCodecNames() + ")");
  }

  AVFormatContext* raw_output = nullptr;
  av::Check(avformat_alloc_output_context2(&raw_output, nullptr, "matroska", path.c_str()), path,
            "cannot create a Matroska muxer");
  output_.reset(raw_output);
  stream_ = avformat_new_stream(output_.get(), nullptr);
  if (stream_ == nullptr) throw WorkError(path, "cannot add a video stream");
  stream_->time_base = av::kMillis;

  if (passthrough_) {
    stream_->codecpar->codec_type = AVMEDIA_TYPE_VIDEO;
    stream_->codecpar->codec_id = AV_CODEC_ID_MJPEG;
    stream_->codecpar->width = width;
    stream_->codecpar->height = height;
  } else {
    const AVCodec* encoder = nullptr;
    AVPixelFormat coded_format = AV_PIX_FMT_NONE;
    Dict options;
    if (codec == "ffv1") {
      encoder = avcodec_find_encoder(AV_CODEC_ID_FFV1);
      coded_format = av::LosslessStorageFormat(format);
      options.Set("level", "3");
      options.Set("slicecrc", "1");  // lets the reader detect a damaged frame
      options.Set("slices", width * height >= 1280 * 720 ? "16" : "4");
    } else if (codec == "ffvhuff") {
      encoder = avcodec_find_encoder(AV_CODEC_ID_FFVHUFF);
      coded_format = av::LosslessStorageFormat(format);
      // Colour as planes: ffvhuff decodes them about twice as fast as packed bgra.
      if (coded_format == AV_PIX_FMT_BGR0) coded_format = AV_PIX_FMT_GBRP;
    } else if (codec == "mjpeg") {
      encoder = avcodec_find_encoder(AV_CODEC_ID_MJPEG);
      coded_format = AV_PIX_FMT_YUVJ420P;
    } else {
      encoder = avcodec_find_encoder_by_name("libx264");
      if (encoder == nullptr) encoder = avcodec_find_encoder(AV_CODEC_ID_H264);
      coded_format = AV_PIX_FMT_YUV420P;
      options.Set("preset", "veryfast");
      options.Set("tune", "zerolatency");  // no lookahead: a frame is muxed when written
      options.Set("crf", "18");
    }
    if (encoder == nullptr) throw WorkError(path, "this FFmpeg build has no " + codec + " encoder");

    encoder_.reset(avcodec_alloc_context3(encoder));
    if (!encoder_) throw WorkError(path, "out of memory allocating the encoder");
    AVCodecContext* c = encoder_.get();
    c->width = width;
    c->height = height;
    c->pix_fmt = coded_format;
    c->time_base = av::kMillis;
    c->framerate = av_d2q(fps, 100000);
    c->max_b_frames = 0;
    c->thread_count = 0;
    c->thread_type = FF_THREAD_SLICE;
    if (lossless_) {
      c->gop_size = 1;  // every frame decodes on its own: damage stays in its frame
    } else {
      c->gop_size = std::max(1, static_cast<int>(std::lround(fps)));
    }
    if (codec == "mjpeg") {
      c->color_range = AVCOL_RANGE_JPEG;
      c->flags |= AV_CODEC_FLAG_QSCALE;
      c->global_quality = FF_QP2LAMBDA * 2;
    }
    if (output_->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    av::Check(avcodec_open2(c, encoder, &options.d), path,
              std::string("cannot open the ") + encoder->name + " encoder");
    av::Check(avcodec_parameters_from_context(stream_->codecpar, c), path,
              "cannot set stream parameters");

    frame_ = av::NewFrame();
    frame_->format = coded_format;
    frame_->width = width;
    frame_->height = height;
    av::Check(av_frame_get_buffer(frame_.get(), 0), path, "cannot allocate a frame");
    if (!lossless_) {
      sws_.reset(sws_getContext(width, height, av::RawPixelFormat(format), width, height,
                                coded_format, SWS_BICUBIC | SWS_ACCURATE_RND, nullptr, nullptr,
                                nullptr));
      if (!sws_)
        throw WorkError(path, "cannot convert " + PixelFormatName(format) + " for " + codec);
    }
  }
  // The reader checks FFV1 slice CRCs only on files that say they carry them.
  av_dict_set(&stream_->metadata, "SPRITESTATION_SLICECRC", codec == "ffv1" ? "1" : "0", 0);
  av_dict_set(&stream_->metadata, "SPRITESTATION_PIXEL_FORMAT", PixelFormatName(format).c_str(), 0);

  av::Check(avio_open(&output_->pb, path.c_str(), AVIO_FLAG_WRITE), path, "cannot create");
  Dict mux_options;
  // The muxer closes a cluster after at most a second of video on its own; Flush() does it sooner.
  mux_options.Set("cluster_time_limit", "1000");
  av::Check(avformat_write_header(output_.get(), &mux_options.d), path,
            "cannot write the Matroska header");
  avio_flush(output_->pb);
  packet_ = av::NewPacket();
}

VideoWriter::~VideoWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    Log("capture.recording")->error("{}", e.what());
  }
}

void VideoWriter::Write(const uint8_t* data, size_t size, int64_t pts_ms) {
  if (closed_) throw WorkError(path_, "write after close");
  if (passthrough_) {
    av_packet_unref(packet_.get());
    av::Check(av_new_packet(packet_.get(), static_cast<int>(size)), path_,
              "cannot allocate a packet");
    std::memcpy(packet_->data, data, size);
    packet_->pts = packet_->dts = pts_ms;
    packet_->flags |= AV_PKT_FLAG_KEY;
    Mux(packet_.get());
    return;
  }
  av::Check(av_frame_make_writable(frame_.get()), path_, "cannot reuse the frame buffer");
  if (lossless_) {
    av::RawToStorage(data, format_, width_, height_, frame_.get());
  } else {
    uint8_t* src_data[4] = {nullptr};
    int src_lines[4] = {0};
    av::Check(av_image_fill_arrays(src_data, src_lines, data, av::RawPixelFormat(format_), width_,
                                   height_, 1),
              path_, "bad source frame");
    sws_scale(sws_.get(), src_data, src_lines, 0, height_, frame_->data, frame_->linesize);
  }
  frame_->pts = pts_ms;
  Encode(frame_.get());
}

void VideoWriter::Encode(AVFrame* frame) {
  av::Check(avcodec_send_frame(encoder_.get(), frame), path_, "encoding failed");
  while (true) {
    const int ret = avcodec_receive_packet(encoder_.get(), packet_.get());
    if (ret == AVERROR(EAGAIN) || ret == AVERROR_EOF) return;
    av::Check(ret, path_, "encoding failed");
    av_packet_rescale_ts(packet_.get(), encoder_->time_base, stream_->time_base);
    Mux(packet_.get());
  }
}

void VideoWriter::Mux(AVPacket* packet) {
  packet->stream_index = stream_->index;
  // av_write_frame: one stream needs no interleaving queue, so the packet goes straight to the
  // cluster.
  av::Check(av_write_frame(output_.get(), packet), path_, "cannot write a frame (disk full?)");
  ++frames_muxed_;
}

void VideoWriter::Flush() {
  if (closed_) return;
  av::Check(av_write_frame(output_.get(), nullptr), path_, "cannot flush");
  avio_flush(output_->pb);
  if (output_->pb->error < 0) av::Check(output_->pb->error, path_, "cannot write (disk full?)");
}

void VideoWriter::Close() {
  if (closed_) return;
  closed_ = true;
  if (encoder_) Encode(nullptr);
  av::Check(av_write_trailer(output_.get()), path_, "cannot finish the file");
  const int ret = avio_closep(&output_->pb);
  av::Check(ret, path_, "cannot close");
}

}  // namespace ss
