#include "station/recorder.h"

#include <atomic>
#include <mutex>
#include <thread>

#include "core/error.h"
#include "core/log.h"
#include "pipeline/run/bounded_queue.h"

namespace ss {

struct StationRecorder::Impl {
  struct Item {
    Frame frame;
    uint64_t drops_before = 0;
  };
  struct Camera {
    std::unique_ptr<BoundedQueue<Item>> queue;
    std::thread thread;
    int writer_index = -1;       // SessionWriter's camera index, once added
    uint64_t pending_drops = 0;  // under mutex
    bool failed = false;
  };

  std::unique_ptr<SessionWriter> writer;
  std::function<std::string()> refusal;
  bool usable_only = false;
  int queue_frames = 16;
  std::vector<Camera> cameras;
  mutable std::mutex mutex;
  RecorderStats stats;
  bool closed = false;

  // Whether recording has stopped, asking `refusal` while it has not (only until it refuses).
  bool Refused() {
    {
      std::lock_guard lock(mutex);
      if (!stats.stopped.empty()) return true;
    }
    if (!refusal) return false;
    std::string why = refusal();
    if (why.empty()) return false;
    std::lock_guard lock(mutex);
    if (stats.stopped.empty()) {
      Log("station.recorder")->warn("recording {} stopped: {}", stats.dir, why);
      stats.stopped = std::move(why);
    }
    return true;
  }

  void Run(Camera& cam) {
    while (std::optional<Item> item = cam.queue->Pop()) {
      if (cam.failed || Refused()) continue;
      try {
        Frame f = item->frame;
        f.camera = cam.writer_index;
        writer->Write(f, item->drops_before);
        std::lock_guard lock(mutex);
        ++stats.frames_written;
      } catch (const std::exception& e) {
        cam.failed = true;
        Log("station.recorder")->error("{}", e.what());
        std::lock_guard lock(mutex);
        if (stats.error.empty()) stats.error = e.what();
      }
    }
  }
};

StationRecorder::StationRecorder(const std::string& dir, const std::string& name,
                                 const RecordingOptions& options, bool usable_only, int cameras,
                                 std::function<std::string()> refusal, int queue_frames)
    : impl_(std::make_unique<Impl>()) {
  impl_->writer = std::make_unique<SessionWriter>(dir, name, options);
  impl_->refusal = std::move(refusal);
  impl_->usable_only = usable_only;
  impl_->queue_frames = queue_frames;
  impl_->stats.dir = impl_->writer->dir();
  impl_->cameras.resize(static_cast<size_t>(cameras));
  for (Impl::Camera& cam : impl_->cameras) {
    cam.queue = std::make_unique<BoundedQueue<Impl::Item>>(static_cast<size_t>(queue_frames));
    cam.thread = std::thread([this, &cam] { impl_->Run(cam); });
  }
}

StationRecorder::~StationRecorder() { Close(); }

void StationRecorder::Offer(int camera, const SourceCamera& source, const CameraModel* model,
                            const Frame& frame, uint64_t drops_before, bool usable) {
  Impl& s = *impl_;
  if (camera < 0 || static_cast<size_t>(camera) >= s.cameras.size()) return;
  if (s.usable_only && !usable) return;
  Impl::Camera& cam = s.cameras[static_cast<size_t>(camera)];
  std::lock_guard lock(s.mutex);
  if (s.closed || cam.failed || !s.stats.stopped.empty()) return;
  if (cam.writer_index < 0) {
    try {
      cam.writer_index = s.writer->AddCamera(source, model);
    } catch (const std::exception& e) {
      cam.failed = true;
      if (s.stats.error.empty()) s.stats.error = e.what();
      return;
    }
  }
  // A copy: a camera's frame may borrow one of the few stream buffers of its device.
  Frame copy = Frame::Owned(frame.format, frame.width, frame.height,
                            std::vector<uint8_t>(frame.data, frame.data + frame.size));
  copy.sequence = frame.sequence;
  copy.timestamp_ns = frame.timestamp_ns;
  if (cam.queue->TryPush(
          {std::move(copy), cam.pending_drops + (s.usable_only ? 0 : drops_before)})) {
    cam.pending_drops = 0;
  } else {
    ++cam.pending_drops;
    ++s.stats.frames_dropped;
  }
}

void StationRecorder::Close() {
  Impl& s = *impl_;
  {
    std::lock_guard lock(s.mutex);
    if (s.closed) return;
    s.closed = true;
  }
  for (Impl::Camera& cam : s.cameras) cam.queue->Close();
  for (Impl::Camera& cam : s.cameras) {
    if (cam.thread.joinable()) cam.thread.join();
  }
  try {
    s.writer->Close();
  } catch (const std::exception& e) {
    std::lock_guard lock(s.mutex);
    if (s.stats.error.empty()) s.stats.error = e.what();
  }
}

RecorderStats StationRecorder::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace ss
