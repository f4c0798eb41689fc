#include "capture/recording/session_writer.h"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "capture/recording/video_writer.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/recording_codecs.h"
#include "core/utc_time.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A file stem from a device name: "/dev/video0" -> "dev_video0"; "" -> fallback.
std::string SafeStem(const std::string& name, const std::string& fallback) {
  std::string stem;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    stem += ok ? c : '_';
  }
  while (!stem.empty() && (stem.front() == '_' || stem.front() == '.')) stem.erase(stem.begin());
  return stem.empty() ? fallback : stem;
}

}  // namespace

struct SessionWriter::Impl {
  struct Camera {
    SessionCamera meta;
    std::unique_ptr<VideoWriter> video;
    std::unique_ptr<FrameCsvWriter> csv;
    std::mutex mutex;                 // guards everything below and the writers
    std::deque<FrameRecord> pending;  // rows whose frames are not yet on disk
    int64_t frames_written = 0;
    int64_t rows_written = 0;
    int64_t first_timestamp_ns = 0;
    int64_t last_pts_ms = -1;
    Clock::time_point oldest_pending;  // when the oldest frame in `pending` was written
    std::string failure;               // a background flush that failed; reported by the next Write
  };

  std::string dir;
  RecordingOptions options;
  SessionInfo info;
  std::mutex cameras_mutex;  // guards `cameras` (the vector, not the cameras) and `info`
  std::vector<std::unique_ptr<Camera>> cameras;
  bool closed = false;

  std::thread flusher;
  std::mutex flusher_mutex;
  std::condition_variable flusher_wake;
  bool stop_flusher = false;

  // Closes the cluster, then writes the rows of every frame now on disk. Caller holds c.mutex.
  static void Flush(Camera& c) {
    c.video->Flush();
    const int64_t durable = c.video->frames_muxed();
    while (c.rows_written < durable && !c.pending.empty()) {
      c.csv->Append(c.pending.front());
      c.pending.pop_front();
      ++c.rows_written;
    }
    if (!c.pending.empty()) c.oldest_pending = Clock::now();  // frames still inside the encoder
  }

  // True when the oldest frame not yet on disk has waited flush_interval_ms. Caller holds c.mutex.
  bool FlushDue(const Camera& c, Clock::time_point now) const {
    return !c.pending.empty() &&
           now - c.oldest_pending >= std::chrono::milliseconds(options.flush_interval_ms);
  }

  // Flushes cameras whose oldest unflushed frame has waited flush_interval_ms.
  void FlusherLoop() {
    const auto interval = std::chrono::milliseconds(std::max(options.flush_interval_ms, 10));
    std::unique_lock<std::mutex> lock(flusher_mutex);
    while (!stop_flusher) {
      flusher_wake.wait_for(lock, interval / 2);
      if (stop_flusher) break;
      std::vector<Camera*> list;
      {
        std::lock_guard<std::mutex> g(cameras_mutex);
        for (auto& c : cameras) list.push_back(c.get());
      }
      for (Camera* c : list) {
        std::unique_lock<std::mutex> cl(c->mutex, std::try_to_lock);
        // A camera the writing thread holds is flushed by that thread itself.
        if (!cl.owns_lock() || !c->failure.empty() || !FlushDue(*c, Clock::now())) continue;
        try {
          Flush(*c);
        } catch (const std::exception& e) {
          c->failure = e.what();
          Log("capture.recording")->error("{}", e.what());
        }
      }
    }
  }
};

bool RecordingOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(FindRecordingCodec(codec) != nullptr, "codec",
        "unknown codec '" + codec + "' (expected " + RecordingCodecNames() + ")");
  check.Within(flush_interval_ms, AtLeast(0), "flush_interval_ms", "0 or more");
  return check.ok();
}

SessionWriter::SessionWriter(const std::string& dir, const std::string& name,
                             const RecordingOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (std::string why; !options.IsValid(&why)) throw InputError("recording options", why);
  std::error_code ec;
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec))) {
    throw WorkError(dir,
                    "exists and is not an empty folder; a session is recorded into a new folder");
  }
  fs::create_directories(dir, ec);
  if (ec) throw WorkError(dir, "cannot create the session folder: " + ec.message());
  impl_->dir = dir;
  impl_->options = options;
  impl_->info.name = name;
  impl_->info.created = UtcNowIso();
  impl_->info.synthetic = options.synthetic;
  WriteSessionInfo(dir, impl_->info);
  impl_->flusher = std::thread([impl = impl_.get()] { impl->FlusherLoop(); });
}

SessionWriter::~SessionWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    Log("capture.recording")->error("closing {}: {}", impl_->dir, e.what());
  }
}

int SessionWriter::AddCamera(const SourceCamera& camera, const CameraModel* model) {
  std::lock_guard<std::mutex> lock(impl_->cameras_mutex);
  if (impl_->closed) throw WorkError(impl_->dir, "camera added after Close()");
  const int index = static_cast<int>(impl_->cameras.size());
  const std::string where =
      impl_->dir + ": camera " + std::to_string(index) + " ('" + camera.name + "')";
  if (camera.width <= 0 || camera.height <= 0) {
    throw InputError(where, "size " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height) + " is not positive");
  }
  if ((camera.format == PixelFormat::kYUYV || camera.format == PixelFormat::kNV12) &&
      camera.width % 2 != 0) {
    throw InputError(where, PixelFormatName(camera.format) + " needs an even width");
  }
  if (camera.format == PixelFormat::kNV12 && camera.height % 2 != 0) {
    throw InputError(where, "nv12 needs an even height");
  }

  // A unique file stem per camera.
  std::set<std::string> taken;
  for (const auto& c : impl_->cameras) taken.insert(c->meta.name);
  std::string stem = SafeStem(camera.name, "cam" + std::to_string(index));
  for (int n = 2; taken.count(stem) != 0; ++n)
    stem = SafeStem(camera.name, "cam") + "-" + std::to_string(n);

  auto cam = std::make_unique<Impl::Camera>();
  SessionCamera& meta = cam->meta;
  meta.name = stem;
  meta.video = stem + ".mkv";
  meta.frames_csv = stem + ".frames.csv";
  meta.width = camera.width;
  meta.height = camera.height;
  meta.pixel_format = camera.format;
  meta.codec = camera.format == PixelFormat::kMJPEG ? "mjpeg" : impl_->options.codec;
  meta.fps = camera.fps > 0 ? camera.fps : 30.0;
  if (camera.fps <= 0) {
    Log("capture.recording")
        ->info("{}: frame rate unknown, recording it as 30 fps (timestamps stay exact)", where);
  }
  const fs::path dir(impl_->dir);
  if (model != nullptr) {
    meta.model = stem + ".cameramodel";
    model->Write((dir / meta.model).string());
  }
  cam->video = std::make_unique<VideoWriter>((dir / meta.video).string(), meta.pixel_format,
                                             meta.width, meta.height, meta.fps, meta.codec);
  cam->csv = std::make_unique<FrameCsvWriter>((dir / meta.frames_csv).string());
  impl_->info.cameras.push_back(meta);
  WriteSessionInfo(impl_->dir, impl_->info);
  impl_->cameras.push_back(std::move(cam));
  Log("capture.recording")
      ->info("{}: recording camera '{}' ({} {}x{}, {}) into {}", impl_->dir, stem,
             PixelFormatName(meta.pixel_format), meta.width, meta.height, meta.codec, meta.video);
  return index;
}

void SessionWriter::Write(const Frame& frame, uint64_t drops_before) {
  Impl::Camera* cam = nullptr;
  {
    std::lock_guard<std::mutex> lock(impl_->cameras_mutex);
    if (impl_->closed) throw WorkError(impl_->dir, "frame written after Close()");
    if (frame.camera < 0 || frame.camera >= static_cast<int>(impl_->cameras.size())) {
      throw InputError(impl_->dir, "frame for camera " + std::to_string(frame.camera) +
                                       ", but the session has " +
                                       std::to_string(impl_->cameras.size()) + " camera(s)");
    }
    cam = impl_->cameras[static_cast<size_t>(frame.camera)].get();
  }
  const SessionCamera& meta = cam->meta;
  const std::string where =
      impl_->dir + ": camera '" + meta.name + "' frame " + std::to_string(frame.sequence);
  if (frame.format != meta.pixel_format || frame.width != meta.width ||
      frame.height != meta.height) {
    throw InputError(where, "is " + PixelFormatName(frame.format) + " " +
                                std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                                ", the camera records " + PixelFormatName(meta.pixel_format) + " " +
                                std::to_string(meta.width) + "x" + std::to_string(meta.height));
  }
  const size_t expected = FrameBytes(frame.format, frame.width, frame.height);
  if (frame.data == nullptr || (expected != 0 && frame.size != expected) ||
      (expected == 0 && frame.size == 0)) {
    throw InputError(where, "holds " + std::to_string(frame.size) + " bytes, expected " +
                                (expected != 0 ? std::to_string(expected) : std::string("a JPEG")));
  }

  std::lock_guard<std::mutex> lock(cam->mutex);
  if (!cam->failure.empty()) throw WorkError(cam->failure);
  if (cam->frames_written == 0) cam->first_timestamp_ns = frame.timestamp_ns;
  const int64_t pts = VideoPtsMs(cam->last_pts_ms, cam->first_timestamp_ns, frame.timestamp_ns);
  cam->video->Write(frame.data, frame.size, pts);
  cam->last_pts_ms = pts;
  FrameRecord row;
  row.index = cam->frames_written++;
  row.timestamp_ns = frame.timestamp_ns;
  row.sequence = frame.sequence;
  row.drops_before = drops_before;
  const auto now = Clock::now();
  if (cam->pending.empty()) cam->oldest_pending = now;
  cam->pending.push_back(row);
  // Steady writing flushes here; when frames stop coming the background flusher does it.
  if (impl_->FlushDue(*cam, now)) Impl::Flush(*cam);
}

void SessionWriter::Close() {
  {
    std::lock_guard<std::mutex> lock(impl_->cameras_mutex);
    if (impl_->closed) return;
    impl_->closed = true;
  }
  {
    std::lock_guard<std::mutex> lock(impl_->flusher_mutex);
    impl_->stop_flusher = true;
  }
  impl_->flusher_wake.notify_all();
  if (impl_->flusher.joinable()) impl_->flusher.join();

  std::string first_error;
  for (auto& cam : impl_->cameras) {
    std::lock_guard<std::mutex> lock(cam->mutex);
    try {
      cam->video->Close();  // drains the encoder: every frame written is now in the file
      while (!cam->pending.empty()) {
        cam->csv->Append(cam->pending.front());
        cam->pending.pop_front();
        ++cam->rows_written;
      }
      cam->csv->Close();
    } catch (const std::exception& e) {
      if (first_error.empty()) first_error = e.what();
    }
  }
  if (!first_error.empty()) throw WorkError(first_error);
  // The frame counts mark the recording as closed: a reader can now tell a
  // truncated CSV from a killed recorder's.
  std::lock_guard<std::mutex> lock(impl_->cameras_mutex);
  for (size_t i = 0; i < impl_->cameras.size(); ++i) {
    impl_->info.cameras[i].frames = impl_->cameras[i]->rows_written;
  }
  WriteSessionInfo(impl_->dir, impl_->info);
}

const std::string& SessionWriter::dir() const { return impl_->dir; }

}  // namespace ss
