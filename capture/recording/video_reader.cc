#include "capture/recording/video_reader.h"

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>

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

// Read errors in a row after which the rest of the file is given up as unreadable.
constexpr int kMaxConsecutiveReadErrors = 64;
// Packets demuxed ahead per decoder thread: one being decoded, one waiting.
constexpr size_t kPacketsAheadPerThread = 2;

// Whether every frame of the stream decodes on its own, so frames can be decoded in parallel.
// FFV1: a frame that is not a keyframe is sent to the decoder that decoded the frame before it
// (NextParallel), so FFV1 always qualifies. Huffyuv with adaptive tables ("context") does not.
bool DecodesFramesIndependently(const AVCodecParameters* par) {
  if (par->codec_id == AV_CODEC_ID_FFV1) return true;
  if (par->codec_id == AV_CODEC_ID_FFVHUFF || par->codec_id == AV_CODEC_ID_HUFFYUV) {
    return !(par->extradata_size >= 3 && (par->extradata[2] & 0x40) != 0);
  }
  return false;
}

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

// One FFmpeg decoder with its frame and the converter to the camera's bytes.
struct VideoReader::Decoder {
  av::CodecContextPtr context;
  av::FramePtr frame = av::NewFrame();
  av::SwsPtr sws;
  int sws_source_format = AV_PIX_FMT_NONE;

  // thread_count 0: FFmpeg's own threads (slices for FFV1, frames for H.264); 1: none.
  Decoder(const std::string& path, const AVStream* stream, int thread_count) {
    const AVCodecParameters* par = stream->codecpar;
    const AVCodec* codec = avcodec_find_decoder(par->codec_id);
    if (codec == nullptr) {
      throw InputError(path, std::string("no decoder for ") + avcodec_get_name(par->codec_id));
    }
    context.reset(avcodec_alloc_context3(codec));
    if (!context) throw WorkError(path, "out of memory allocating the decoder");
    if (avcodec_parameters_to_context(context.get(), par) < 0)
      throw InputError(path, "bad codec parameters");
    context->pkt_timebase = stream->time_base;
    context->thread_count = thread_count;
    const int opened = avcodec_open2(context.get(), codec, nullptr);
    if (opened < 0) {
      throw InputError(path, std::string("cannot open the ") + codec->name + " decoder (" +
                                 av::ErrorText(opened) + ")");
    }
  }

  // The decoded `frame` as the camera's bytes in `pixels`, or what is wrong with it; unrefs it.
  Result Take(PixelFormat format, int width, int height, std::vector<uint8_t>& pixels) {
    Result r;
    r.status = Status::kCorrupt;
    if (frame->decode_error_flags != 0 || (frame->flags & AV_FRAME_FLAG_CORRUPT)) {
      r.problem = "the decoder reports damage";
    } else if (frame->width != width || frame->height != height) {
      r.problem = "frame is " + std::to_string(frame->width) + "x" + std::to_string(frame->height) +
                  ", expected " + std::to_string(width) + "x" + std::to_string(height);
    } else {
      r = Convert(format, width, height, pixels);
    }
    av_frame_unref(frame.get());
    return r;
  }

  Result Convert(PixelFormat format, int width, int height, std::vector<uint8_t>& pixels) {
    pixels.resize(FrameBytes(format, width, height));
    Result r;
    r.status = Status::kFrame;
    if (av::IsLosslessStorage(frame->format, format)) {
      av::StorageToRaw(frame.get(), format, width, height, pixels.data());  // exact
      return r;
    }
    if (!sws || sws_source_format != frame->format) {
      sws.reset(sws_getContext(width, height, static_cast<AVPixelFormat>(frame->format), width,
                               height, av::RawPixelFormat(format), SWS_BICUBIC | SWS_ACCURATE_RND,
                               nullptr, nullptr, nullptr));
      sws_source_format = frame->format;
      if (!sws) {
        r.status = Status::kCorrupt;
        r.problem = std::string("cannot convert ") +
                    av_get_pix_fmt_name(static_cast<AVPixelFormat>(frame->format)) + " to " +
                    PixelFormatName(format);
        return r;
      }
    }
    uint8_t* dst_data[4] = {nullptr};
    int dst_lines[4] = {0};
    av_image_fill_arrays(dst_data, dst_lines, pixels.data(), av::RawPixelFormat(format), width,
                         height, 1);
    sws_scale(sws.get(), frame->data, frame->linesize, 0, height, dst_data, dst_lines);
    return r;
  }
};

// Decoder threads for the intra-only codecs. The reader's thread demuxes and queues each
// packet as a Job with one decoder thread; results are handed out in file order.
struct VideoReader::Parallel {
  struct Job {
    av::PacketPtr packet;         // null for damage found while demuxing
    Result result;                // set by the decoder thread (or by the demuxer)
    std::vector<uint8_t> pixels;  // the decoded frame
    bool done = false;            // guarded by mutex
  };
  struct Worker {
    std::unique_ptr<Decoder> decoder;
    std::deque<Job*> queue;  // guarded by mutex
    std::thread thread;
  };

  const VideoReader* reader;
  std::vector<Worker> workers;
  std::deque<std::unique_ptr<Job>> jobs;  // in file order; the reader's thread only
  std::vector<std::vector<uint8_t>> spare_pixels;
  size_t next_worker = 0;
  size_t last_worker = 0;
  std::mutex mutex;
  std::condition_variable work;
  std::condition_variable finished;
  bool stopping = false;

  Parallel(const VideoReader* r, const AVStream* stream, int threads)
      : reader(r), workers(threads) {
    for (Worker& w : workers) w.decoder = std::make_unique<Decoder>(r->path_, stream, 1);
    for (size_t i = 0; i < workers.size(); ++i)
      workers[i].thread = std::thread([this, i] { Run(workers[i]); });
  }

  ~Parallel() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stopping = true;
    }
    work.notify_all();
    for (Worker& w : workers) w.thread.join();
  }

  // Queues a packet with a decoder: a keyframe with the next in turn, any other frame with the
  // decoder of the frame before it (which holds the state it depends on).
  void Submit(std::unique_ptr<Job> job) {
    if (job->packet->flags & AV_PKT_FLAG_KEY) last_worker = next_worker++ % workers.size();
    if (!spare_pixels.empty()) {
      job->pixels = std::move(spare_pixels.back());
      spare_pixels.pop_back();
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      workers[last_worker].queue.push_back(job.get());
    }
    work.notify_all();
    jobs.push_back(std::move(job));
  }

  void Run(Worker& w) {
    while (true) {
      Job* job = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex);
        work.wait(lock, [&] { return stopping || !w.queue.empty(); });
        if (stopping) return;
        job = w.queue.front();
        w.queue.pop_front();
      }
      Result r = Decode(*w.decoder, job->packet.get(), job->result.pts_ms, job->pixels);
      job->packet.reset();
      {
        std::lock_guard<std::mutex> lock(mutex);
        job->result = std::move(r);
        job->done = true;
      }
      finished.notify_all();
    }
  }

  // One packet to one frame (an intra-only decoder without threads holds none back).
  Result Decode(Decoder& d, AVPacket* packet, int64_t pts_ms, std::vector<uint8_t>& pixels) const {
    Result bad;
    bad.status = Status::kCorrupt;
    bad.pts_ms = pts_ms;
    if (reader->check_slice_crc_ &&
        !Ffv1SlicesIntact(packet->data, static_cast<size_t>(packet->size), &bad.problem)) {
      return bad;
    }
    const int sent = avcodec_send_packet(d.context.get(), packet);
    if (sent < 0) {
      bad.problem = "cannot decode: " + av::ErrorText(sent);
      return bad;
    }
    const int ret = avcodec_receive_frame(d.context.get(), d.frame.get());
    if (ret == AVERROR(EAGAIN)) {
      bad.problem = "the decoder gave no picture for this frame";
      return bad;
    }
    if (ret < 0) {
      bad.problem = "cannot decode: " + av::ErrorText(ret);
      return bad;
    }
    Result r = d.Take(reader->format_, reader->width_, reader->height_, pixels);
    r.pts_ms = pts_ms;
    return r;
  }

  // Waits for the oldest job and hands its result out; its frame's bytes are swapped into `pixels`.
  Result TakeFront(std::vector<uint8_t>& pixels) {
    Job& job = *jobs.front();
    {
      std::unique_lock<std::mutex> lock(mutex);
      finished.wait(lock, [&] { return job.done; });
    }
    Result r = std::move(job.result);
    if (r.status == Status::kFrame) pixels.swap(job.pixels);
    if (job.pixels.capacity() > 0) spare_pixels.push_back(std::move(job.pixels));
    jobs.pop_front();
    return r;
  }
};

VideoReader::VideoReader(const std::string& path, PixelFormat format, int width, int height,
                         int decode_threads)
    : path_(path), format_(format), width_(width), height_(height) {
  av::InstallLogBridge();
  passthrough_ = format == PixelFormat::kMJPEG;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such video file");

  AVFormatContext* raw = nullptr;
  const int ret =
      avformat_open_input(&raw, path.c_str(), av_find_input_format("matroska"), nullptr);
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
    throw InputError(path, "video is " + std::to_string(par->width) + "x" +
                               std::to_string(par->height) + ", session.json says " +
                               std::to_string(width) + "x" + std::to_string(height));
  }
  packet_ = av::NewPacket();
  if (passthrough_) {
    if (par->codec_id != AV_CODEC_ID_MJPEG) {
      throw InputError(path, std::string("an mjpeg camera's video must hold MJPEG, found ") +
                                 avcodec_get_name(par->codec_id));
    }
    return;
  }
  const AVDictionaryEntry* crc =
      av_dict_get(stream->metadata, "SPRITESTATION_SLICECRC", nullptr, 0);
  check_slice_crc_ =
      par->codec_id == AV_CODEC_ID_FFV1 && crc != nullptr && std::strcmp(crc->value, "1") == 0;

  int threads = decode_threads;
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (threads >= 2 && DecodesFramesIndependently(par)) {
    parallel_ = std::make_unique<Parallel>(this, stream, threads);
  } else {
    decoder_ = std::make_unique<Decoder>(path, stream,
                                         0);  // slice threads for FFV1, frame threads for H.264
  }
}

VideoReader::~VideoReader() = default;

int VideoReader::decode_threads() const {
  return parallel_ ? static_cast<int>(parallel_->workers.size()) : 1;
}

VideoReader::Demuxed VideoReader::ReadPacket() {
  using Kind = Demuxed::Kind;
  while (true) {
    const int ret = av_read_frame(input_.get(), packet_.get());
    if (ret == AVERROR_EOF) {
      draining_ = true;
      return {};
    }
    if (ret < 0) {
      // A damaged or cut-off block. At the end of the file this is a truncation.
      const bool at_end = avio_feof(input_->pb) != 0;
      if (at_end || ++consecutive_read_errors_ >= kMaxConsecutiveReadErrors) draining_ = true;
      Demuxed d;
      d.kind = Kind::kCorrupt;
      d.problem = at_end ? "the file ends inside a frame (truncated): " + av::ErrorText(ret)
                         : "damaged Matroska data: " + av::ErrorText(ret);
      return d;
    }
    if (packet_->stream_index != stream_index_) {
      av_packet_unref(packet_.get());
      continue;
    }
    consecutive_read_errors_ = 0;
    const int64_t ts = packet_->pts != AV_NOPTS_VALUE ? packet_->pts : packet_->dts;
    Demuxed d;
    d.kind = Kind::kPacket;
    d.pts_ms = ts == AV_NOPTS_VALUE ? -1 : av_rescale_q(ts, time_base_, av::kMillis);
    last_sent_pts_ms_ = d.pts_ms;
    if (packet_->flags & AV_PKT_FLAG_CORRUPT) {
      av_packet_unref(packet_.get());
      d.kind = Kind::kCorrupt;
      d.problem = "the container marks the frame as corrupt";
    }
    return d;
  }
}

VideoReader::Result VideoReader::Next(std::vector<uint8_t>& pixels) {
  return parallel_ ? NextParallel(pixels) : NextSequential(pixels);
}

VideoReader::Result VideoReader::NextParallel(std::vector<uint8_t>& pixels) {
  // Keep every decoder thread busy: demux up to a few packets each ahead of the caller.
  while (!draining_ &&
         parallel_->jobs.size() < kPacketsAheadPerThread * parallel_->workers.size()) {
    Demuxed d = ReadPacket();
    if (d.kind == Demuxed::Kind::kEnd) break;
    auto job = std::make_unique<Parallel::Job>();
    job->result.pts_ms = d.pts_ms;
    if (d.kind == Demuxed::Kind::kCorrupt) {
      job->result.status = Status::kCorrupt;
      job->result.problem = d.problem;
      job->done = true;  // no thread sees it
      parallel_->jobs.push_back(std::move(job));
      continue;
    }
    job->packet = av::NewPacket();
    av_packet_move_ref(job->packet.get(), packet_.get());
    parallel_->Submit(std::move(job));
  }
  if (parallel_->jobs.empty()) return {};
  return parallel_->TakeFront(pixels);
}

VideoReader::Result VideoReader::NextSequential(std::vector<uint8_t>& pixels) {
  while (true) {
    if (!passthrough_) {
      // Frames the decoder holds come first.
      const int ret = avcodec_receive_frame(decoder_->context.get(), decoder_->frame.get());
      if (ret == AVERROR_EOF) return {};
      if (ret != AVERROR(EAGAIN)) {
        Result r;
        r.status = Status::kCorrupt;
        r.pts_ms = last_sent_pts_ms_;
        if (ret < 0) {
          r.problem = "cannot decode: " + av::ErrorText(ret);
          return r;
        }
        const int64_t ts = decoder_->frame->best_effort_timestamp;
        const int64_t pts_ms =
            ts == AV_NOPTS_VALUE ? last_sent_pts_ms_ : av_rescale_q(ts, time_base_, av::kMillis);
        r = decoder_->Take(format_, width_, height_, pixels);
        r.pts_ms = pts_ms;
        return r;
      }
    }
    if (draining_) return {};
    const Demuxed d = ReadPacket();
    if (d.kind == Demuxed::Kind::kEnd) {
      if (passthrough_) return {};
      avcodec_send_packet(decoder_->context.get(), nullptr);
      continue;
    }
    Result bad;
    bad.status = Status::kCorrupt;
    bad.pts_ms = d.pts_ms;
    bad.problem = d.problem;
    if (d.kind == Demuxed::Kind::kCorrupt) {
      // Given up on the rest of the file: what the decoder holds still comes out.
      if (draining_ && !passthrough_) avcodec_send_packet(decoder_->context.get(), nullptr);
      return bad;
    }
    if (check_slice_crc_ &&
        !Ffv1SlicesIntact(packet_->data, static_cast<size_t>(packet_->size), &bad.problem)) {
      av_packet_unref(packet_.get());
      return bad;
    }
    if (passthrough_) {
      pixels.assign(packet_->data, packet_->data + packet_->size);
      av_packet_unref(packet_.get());
      Result r;
      r.status = Status::kFrame;
      r.pts_ms = d.pts_ms;
      return r;
    }
    const int sent = avcodec_send_packet(decoder_->context.get(), packet_.get());
    av_packet_unref(packet_.get());
    if (sent < 0) {
      bad.problem = "cannot decode: " + av::ErrorText(sent);
      return bad;
    }
  }
}

}  // namespace ss
