#include "capture/recording/video_reader.h"

#include <cstring>
#include <filesystem>

extern "C" {
#include <libavutil/crc.h>
#include <libavutil/dict.h>
#include <libavutil/imgutils.h>
#include <libavutil/pixdesc.h>
}

#include "capture/recording/pixel_layout.h"
#include "core/error.h"

namespace ss {
namespace {

constexpr AVRational kMillis{1, 1000};
// Read errors in a row after which the rest of the file is given up as unreadable.
constexpr int kMaxConsecutiveReadErrors = 64;

}  // namespace

bool Ffv1SlicesIntact(const uint8_t* data, size_t size, std::string* why) {
  // FFV1 level 3 with slicecrc ends every slice with: slice size (24 bits, big
  // endian), error status (8 bits), CRC-32 parity (32 bits) chosen so that the
  // CRC of the whole slice is 0. Slices are walked from the end of the packet.
  constexpr size_t kTrailer = 8;
  const AVCRC* table = av_crc_get_table(AV_CRC_32_IEEE);
  size_t end = size;
  int slice = 0;
  while (end > 0) {
    if (end < kTrailer) {
      *why = "FFV1 slice chain broken (" + std::to_string(end) + " stray bytes)";
      return false;
    }
    const uint8_t* t = data + end - kTrailer;
    const size_t length = ((size_t{t[0]} << 16) | (size_t{t[1]} << 8) | size_t{t[2]}) + kTrailer;
    if (length > end) {
      *why = "FFV1 slice chain broken (slice " + std::to_string(slice) + " from the end claims " +
             std::to_string(length) + " bytes, " + std::to_string(end) + " left)";
      return false;
    }
    if (av_crc(table, 0, data + end - length, length) != 0) {
      *why = "FFV1 slice CRC mismatch (slice " + std::to_string(slice) + " from the end)";
      return false;
    }
    end -= length;
    ++slice;
  }
  if (slice == 0) {
    *why = "empty FFV1 packet";
    return false;
  }
  return true;
}

VideoReader::VideoReader(const std::string& path, PixelFormat format, int width, int height)
    : path_(path), format_(format), width_(width), height_(height) {
  av::InstallLogBridge();
  passthrough_ = format == PixelFormat::kMJPEG;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such video file");

  AVFormatContext* raw = nullptr;
  const int ret = avformat_open_input(&raw, path.c_str(), av_find_input_format("matroska"), nullptr);
  if (ret < 0) throw InputError(path, "not a readable Matroska file (" + av::ErrorText(ret) + ")");
  input_.reset(raw);
  // No avformat_find_stream_info: the Matroska header carries what we need,
  // and probing would read ahead into a possibly damaged file.
  for (unsigned i = 0; i < input_->nb_streams; ++i) {
    if (input_->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_VIDEO) {
      stream_index_ = static_cast<int>(i);
      break;
    }
  }
  if (stream_index_ < 0) throw InputError(path, "holds no video stream");
  AVStream* stream = input_->streams[stream_index_];
  time_base_ = stream->time_base;
  const AVCodecParameters* par = stream->codecpar;
  if (par->width != width || par->height != height) {
    throw InputError(path, "video is " + std::to_string(par->width) + "x" + std::to_string(par->height) +
                               ", session.json says " + std::to_string(width) + "x" + std::to_string(height));
  }
  if (passthrough_) {
    if (par->codec_id != AV_CODEC_ID_MJPEG) {
      throw InputError(path, std::string("an mjpeg camera's video must hold MJPEG, found ") +
                                 avcodec_get_name(par->codec_id));
    }
    packet_ = av::NewPacket();
    return;
  }
  const AVDictionaryEntry* crc = av_dict_get(stream->metadata, "SPRITESTATION_SLICECRC", nullptr, 0);
  check_slice_crc_ = par->codec_id == AV_CODEC_ID_FFV1 && crc != nullptr && std::strcmp(crc->value, "1") == 0;

  const AVCodec* codec = avcodec_find_decoder(par->codec_id);
  if (codec == nullptr) {
    throw InputError(path, std::string("no decoder for ") + avcodec_get_name(par->codec_id));
  }
  decoder_.reset(avcodec_alloc_context3(codec));
  if (!decoder_) throw WorkError(path, "out of memory allocating the decoder");
  if (avcodec_parameters_to_context(decoder_.get(), par) < 0) throw InputError(path, "bad codec parameters");
  decoder_->pkt_timebase = stream->time_base;
  decoder_->thread_count = 0;  // slice threads for FFV1, frame threads for H.264
  const int opened = avcodec_open2(decoder_.get(), codec, nullptr);
  if (opened < 0) {
    throw InputError(path, std::string("cannot open the ") + codec->name + " decoder (" + av::ErrorText(opened) + ")");
  }
  frame_ = av::NewFrame();
  packet_ = av::NewPacket();
}

VideoReader::Result VideoReader::Next(std::vector<uint8_t>& pixels) {
  while (true) {
    if (!passthrough_) {
      bool need_packet = false;
      Result r = Receive(pixels, &need_packet);
      if (!need_packet) return r;
    }
    if (draining_) return {};
    const int ret = av_read_frame(input_.get(), packet_.get());
    if (ret == AVERROR_EOF) {
      draining_ = true;
      if (passthrough_) return {};
      avcodec_send_packet(decoder_.get(), nullptr);
      continue;
    }
    if (ret < 0) {
      // A damaged or cut-off block. At the end of the file this is a truncation.
      const bool at_end = avio_feof(input_->pb) != 0;
      if (at_end || ++consecutive_read_errors_ >= kMaxConsecutiveReadErrors) {
        draining_ = true;
        if (!passthrough_) avcodec_send_packet(decoder_.get(), nullptr);
      }
      Result r;
      r.status = Status::kCorrupt;
      r.problem = at_end ? "the file ends inside a frame (truncated): " + av::ErrorText(ret)
                         : "damaged Matroska data: " + av::ErrorText(ret);
      return r;
    }
    if (packet_->stream_index != stream_index_) {
      av_packet_unref(packet_.get());
      continue;
    }
    consecutive_read_errors_ = 0;
    const int64_t ts = packet_->pts != AV_NOPTS_VALUE ? packet_->pts : packet_->dts;
    const int64_t pts_ms = ts == AV_NOPTS_VALUE ? -1 : av_rescale_q(ts, time_base_, kMillis);
    last_sent_pts_ms_ = pts_ms;
    Result bad;
    bad.status = Status::kCorrupt;
    bad.pts_ms = pts_ms;
    if (packet_->flags & AV_PKT_FLAG_CORRUPT) {
      av_packet_unref(packet_.get());
      bad.problem = "the container marks the frame as corrupt";
      return bad;
    }
    if (check_slice_crc_ && !Ffv1SlicesIntact(packet_->data, static_cast<size_t>(packet_->size), &bad.problem)) {
      av_packet_unref(packet_.get());
      return bad;
    }
    if (passthrough_) {
      pixels.assign(packet_->data, packet_->data + packet_->size);
      av_packet_unref(packet_.get());
      Result r;
      r.status = Status::kFrame;
      r.pts_ms = pts_ms;
      return r;
    }
    const int sent = avcodec_send_packet(decoder_.get(), packet_.get());
    av_packet_unref(packet_.get());
    if (sent < 0) {
      bad.problem = "cannot decode: " + av::ErrorText(sent);
      return bad;
    }
  }
}

VideoReader::Result VideoReader::Receive(std::vector<uint8_t>& pixels, bool* need_packet) {
  const int ret = avcodec_receive_frame(decoder_.get(), frame_.get());
  if (ret == AVERROR(EAGAIN)) {
    *need_packet = true;
    return {};
  }
  if (ret == AVERROR_EOF) return {};
  Result r;
  r.status = Status::kCorrupt;
  r.pts_ms = last_sent_pts_ms_;
  if (ret < 0) {
    r.problem = "cannot decode: " + av::ErrorText(ret);
    return r;
  }
  const int64_t ts = frame_->best_effort_timestamp;
  r.pts_ms = ts == AV_NOPTS_VALUE ? last_sent_pts_ms_ : av_rescale_q(ts, time_base_, kMillis);
  if (frame_->decode_error_flags != 0 || (frame_->flags & AV_FRAME_FLAG_CORRUPT)) {
    r.problem = "the decoder reports damage";
  } else if (frame_->width != width_ || frame_->height != height_) {
    r.problem = "frame is " + std::to_string(frame_->width) + "x" + std::to_string(frame_->height) +
                ", expected " + std::to_string(width_) + "x" + std::to_string(height_);
  } else {
    r = Convert(frame_.get(), pixels);
    r.pts_ms = ts == AV_NOPTS_VALUE ? last_sent_pts_ms_ : av_rescale_q(ts, time_base_, kMillis);
  }
  av_frame_unref(frame_.get());
  return r;
}

VideoReader::Result VideoReader::Convert(const AVFrame* frame, std::vector<uint8_t>& pixels) {
  pixels.resize(FrameBytes(format_, width_, height_));
  Result r;
  r.status = Status::kFrame;
  if (av::IsLosslessStorage(frame->format, format_)) {
    av::StorageToRaw(frame, format_, width_, height_, pixels.data());  // exact
    return r;
  }
  if (!sws_ || sws_source_format_ != frame->format) {
    sws_.reset(sws_getContext(width_, height_, static_cast<AVPixelFormat>(frame->format), width_, height_,
                              av::RawPixelFormat(format_), SWS_BICUBIC | SWS_ACCURATE_RND, nullptr, nullptr,
                              nullptr));
    sws_source_format_ = frame->format;
    if (!sws_) {
      r.status = Status::kCorrupt;
      r.problem = std::string("cannot convert ") + av_get_pix_fmt_name(static_cast<AVPixelFormat>(frame->format)) +
                  " to " + PixelFormatName(format_);
      return r;
    }
  }
  uint8_t* dst_data[4] = {nullptr};
  int dst_lines[4] = {0};
  av_image_fill_arrays(dst_data, dst_lines, pixels.data(), av::RawPixelFormat(format_), width_, height_, 1);
  sws_scale(sws_.get(), frame->data, frame->linesize, 0, height_, dst_data, dst_lines);
  return r;
}

}  // namespace ss
