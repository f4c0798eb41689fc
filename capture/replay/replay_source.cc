#include "capture/replay/replay_source.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>

#include "capture/recording/video_reader.h"
#include "capture/recording/video_writer.h"
#include "core/camera_model.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr size_t kMaxProblemsKept = 20;
constexpr size_t kMaxFreeBuffers = 8;

// Pixel buffers handed out inside Frames and given back when the last copy of
// the frame dies. Shared with the frames, so it outlives the source if it must.
class BufferPool {
 public:
  std::unique_ptr<std::vector<uint8_t>> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<std::vector<uint8_t>>();
    auto buffer = std::move(free_.back());
    free_.pop_back();
    return buffer;
  }
  void Give(std::unique_ptr<std::vector<uint8_t>> buffer) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.size() < kMaxFreeBuffers) free_.push_back(std::move(buffer));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<std::vector<uint8_t>>> free_;
};

}  // namespace

struct ReplaySource::Impl {
  struct Camera {
    int index = 0;
    SessionCamera meta;
    std::string video_path;
    std::string csv_path;
    std::vector<FrameRecord> records;
    std::vector<int64_t> pts_ms;  // each row's timestamp in the video
    uint64_t sequence_span = 1;   // sequence shift per pass
    std::shared_ptr<BufferPool> pool = std::make_shared<BufferPool>();
    std::thread decoder;
    // Guarded by Impl::mutex:
    std::deque<Frame> ready;
    bool finished = false;
    ReplayCameraStats stats;
  };

  std::string dir;
  ReplayOptions options;
  SessionInfo info;
  std::vector<SourceCamera> source_cameras;
  std::vector<std::unique_ptr<Camera>> cams;
  int64_t pass_span_ns = 0;  // timestamp shift per pass

  mutable std::mutex mutex;
  std::condition_variable changed;
  bool stopped = false;
  SourceStats totals;
  bool started = false;
  Clock::time_point wall_start;
  int64_t first_timestamp_ns = 0;

  void Problem(Camera& cam, const std::string& message) {
    Log("capture.replay")->error("{}", message);
    std::lock_guard<std::mutex> lock(mutex);
    ++cam.stats.errors;
    ++totals.errors;
    totals.last_error = message;
    if (cam.stats.problems.size() < kMaxProblemsKept) cam.stats.problems.push_back(message);
  }

  std::string FrameName(const Camera& cam, size_t row) const {
    return cam.video_path + ": frame " + std::to_string(row) + " (sequence " +
           std::to_string(cam.records[row].sequence) + ", timestamp_ns " +
           std::to_string(cam.records[row].timestamp_ns) + ")";
  }

  // Rows [first, end) of the CSV that no frame of the video matches. A row whose timestamp goes
  // back is named as such: the CSV was not written with this video (a recorder forces the
  // video's times forward and the replay does the same, so a real camera's backward step
  // matches).
  std::string MissingRows(const Camera& cam, size_t first, size_t end) const {
    std::string what =
        end - first == 1
            ? "frame " + std::to_string(first) + " listed in " + cam.csv_path + " (timestamp_ns " +
                  std::to_string(cam.records[first].timestamp_ns) + ") is missing from the video"
            : "frames " + std::to_string(first) + ".." + std::to_string(end - 1) + " listed in " +
                  cam.csv_path + " are missing from the video";
    for (size_t i = std::max<size_t>(first, 1); i < end; ++i) {
      if (cam.records[i].timestamp_ns < cam.records[i - 1].timestamp_ns) {
        what += "; row " + std::to_string(i) + "'s timestamp_ns goes back from " +
                std::to_string(cam.records[i - 1].timestamp_ns) + " to " +
                std::to_string(cam.records[i].timestamp_ns) + ": the CSV does not match the video";
        break;
      }
    }
    return cam.video_path + ": " + what;
  }

  // Waits for room in the camera's queue and hands it a frame; false when stopped.
  bool Push(Camera& cam, Frame frame) {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] {
      return stopped || cam.ready.size() < static_cast<size_t>(options.frames_ahead);
    });
    if (stopped) return false;
    cam.ready.push_back(std::move(frame));
    changed.notify_all();
    return true;
  }

  bool Stopped() const {
    std::lock_guard<std::mutex> lock(mutex);
    return stopped;
  }

  // One pass over a camera's video; false when the replay was stopped or the file cannot be read at
  // all.
  bool DecodePass(Camera& cam, int pass) {
    std::unique_ptr<VideoReader> reader;
    try {
      reader = std::make_unique<VideoReader>(cam.video_path, cam.meta.pixel_format, cam.meta.width,
                                             cam.meta.height, options.decode_threads);
    } catch (const std::exception& e) {
      Problem(cam, std::string(e.what()) + " (camera '" + cam.meta.name + "' skipped)");
      std::lock_guard<std::mutex> lock(mutex);
      cam.stats.frames_unreadable += cam.records.size();
      return false;
    }
    const int64_t shift_ns = pass_span_ns * pass;
    const uint64_t shift_seq = cam.sequence_span * static_cast<uint64_t>(pass);
    size_t row = 0;        // next CSV row not yet accounted for
    uint64_t unrowed = 0;  // video frames past the CSV
    auto buffer = cam.pool->Take();
    while (true) {
      if (Stopped()) return false;
      const VideoReader::Result r = reader->Next(*buffer);
      if (r.status == VideoReader::Status::kEnd) break;
      if (r.pts_ms < 0) {
        // Container damage that names no frame. Past the CSV's last row it is the
        // cut-off tail of an interrupted recording, which is expected.
        if (pass == 0) {
          const std::string where =
              cam.video_path + ": after frame " + std::to_string(static_cast<int64_t>(row) - 1);
          if (row < cam.records.size()) {
            Problem(cam, where + ": " + r.problem);
          } else {
            Log("capture.replay")
                ->warn("{}: {} (past the last frame in {})", where, r.problem, cam.csv_path);
          }
        }
        continue;
      }
      // The frame's CSV row, found through its timestamp; rows jumped over are missing from the
      // video.
      size_t at = row;
      while (at < cam.pts_ms.size() && cam.pts_ms[at] < r.pts_ms) ++at;
      if (at == cam.pts_ms.size() || cam.pts_ms[at] != r.pts_ms) {
        // No row carries this timestamp: a frame the CSV does not list (recording interrupted).
        if (r.status == VideoReader::Status::kFrame) ++unrowed;
        continue;
      }
      if (at > row) {
        if (pass == 0) Problem(cam, MissingRows(cam, row, at));
        std::lock_guard<std::mutex> lock(mutex);
        cam.stats.frames_unreadable += at - row;
      }
      if (r.status == VideoReader::Status::kCorrupt) {
        if (pass == 0) Problem(cam, FrameName(cam, at) + ": " + r.problem);
        std::lock_guard<std::mutex> lock(mutex);
        ++cam.stats.frames_unreadable;
        row = at + 1;
        continue;
      }
      row = at + 1;
      const FrameRecord& rec = cam.records[at];
      std::vector<uint8_t>* raw = buffer.release();
      auto pool = cam.pool;
      Frame f = Frame::Borrowed(
          cam.meta.pixel_format, cam.meta.width, cam.meta.height, raw->data(), raw->size(),
          [pool, raw] { pool->Give(std::unique_ptr<std::vector<uint8_t>>(raw)); });
      f.camera = cam.index;
      f.timestamp_ns = rec.timestamp_ns + shift_ns;
      f.sequence = rec.sequence + shift_seq;
      if (!Push(cam, std::move(f))) return false;
      buffer = cam.pool->Take();
    }
    if (row < cam.records.size()) {
      if (pass == 0) {
        Problem(cam, cam.video_path + ": video ends after " + std::to_string(row) + " of the " +
                         std::to_string(cam.records.size()) + " frames listed in " + cam.csv_path +
                         " (file truncated?)");
      }
      std::lock_guard<std::mutex> lock(mutex);
      cam.stats.frames_unreadable += cam.records.size() - row;
    }
    if (unrowed > 0) {
      if (pass == 0) {
        Log("capture.replay")
            ->warn(
                "{}: {} frame(s) at the end are not listed in {} (recording interrupted?); "
                "skipped",
                cam.video_path, unrowed, cam.csv_path);
      }
      std::lock_guard<std::mutex> lock(mutex);
      cam.stats.frames_without_row += unrowed;
    }
    return true;
  }

  void DecodeCamera(Camera& cam) {
    try {
      for (int pass = 0; options.loops == 0 || pass < options.loops; ++pass) {
        if (!DecodePass(cam, pass)) break;
        if (cam.records.empty()) break;  // nothing to loop over
        std::lock_guard<std::mutex> lock(mutex);
        cam.stats.recorded_gaps += RecordedGaps(cam.records);
        for (const auto& r : cam.records) cam.stats.recorded_drops += r.drops_before;
      }
    } catch (const std::exception& e) {
      Problem(cam, cam.video_path + ": replay stopped: " + e.what());
    }
    std::lock_guard<std::mutex> lock(mutex);
    cam.finished = true;
    changed.notify_all();
  }

  static uint64_t RecordedGaps(const std::vector<FrameRecord>& records) {
    uint64_t gaps = 0;
    for (size_t i = 1; i < records.size(); ++i) {
      if (records[i].sequence > records[i - 1].sequence + 1)
        gaps += records[i].sequence - records[i - 1].sequence - 1;
    }
    return gaps;
  }
};

bool ReplayOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(loops, AtLeast(0), "loops", "0 (forever) or more");
  check.Within(frames_ahead, AtLeast(1), "frames_ahead", "at least 1 frame");
  check.Within(decode_threads, AtLeast(0), "decode_threads", "0 (one per core) or more");
  return check.ok();
}

ReplaySource::ReplaySource(const std::string& dir, const ReplayOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (std::string why; !options.IsValid(&why)) throw InputError("replay options", why);
  Impl& s = *impl_;
  s.dir = dir;
  s.options = options;
  s.info = ReadSessionInfo(dir);
  const fs::path root(dir);
  int64_t first = 0;
  int64_t last = 0;
  int64_t period = 0;
  bool any = false;
  if (!options.camera.empty()) {
    bool found = false;
    std::string names;
    for (const SessionCamera& c : s.info.cameras) {
      found = found || c.name == options.camera;
      names += (names.empty() ? "" : ", ") + c.name;
    }
    if (!found) {
      throw InputError((fs::path(dir) / "session.json").string(),
                       "the session has no camera '" + options.camera + "' (it has " + names + ")");
    }
  }
  for (size_t i = 0; i < s.info.cameras.size(); ++i) {
    if (!options.camera.empty() && s.info.cameras[i].name != options.camera) continue;
    auto cam = std::make_unique<Impl::Camera>();
    cam->index = static_cast<int>(s.cams.size());
    cam->meta = s.info.cameras[i];
    cam->video_path = (root / cam->meta.video).string();
    cam->csv_path = (root / cam->meta.frames_csv).string();
    cam->records = ReadFrameCsv(cam->csv_path);
    cam->pts_ms = VideoPtsForRecords(cam->records);
    if (cam->meta.frames > static_cast<int64_t>(cam->records.size())) {
      // Fewer rows than the closed recording wrote (more rows: the video check reports it).
      s.Problem(*cam, cam->csv_path + ": lists " + std::to_string(cam->records.size()) +
                          " frames, but the recording "
                          "was closed with " +
                          std::to_string(cam->meta.frames) + " (" +
                          (root / "session.json").string() + "); the CSV is truncated");
    }
    cam->stats.name = cam->meta.name;
    cam->stats.frames_in_csv = cam->records.size();
    if (!cam->records.empty()) {
      uint64_t lo = cam->records.front().sequence;
      uint64_t hi = lo;
      for (const auto& r : cam->records) {
        lo = std::min(lo, r.sequence);
        hi = std::max(hi, r.sequence);
        first = any ? std::min(first, r.timestamp_ns) : r.timestamp_ns;
        last = any ? std::max(last, r.timestamp_ns) : r.timestamp_ns;
        any = true;
      }
      cam->sequence_span = hi - lo + 1;
    }
    period = std::max(period, static_cast<int64_t>(1e9 / cam->meta.fps));
    SourceCamera sc;
    sc.name = cam->meta.name;
    sc.width = cam->meta.width;
    sc.height = cam->meta.height;
    sc.format = cam->meta.pixel_format;
    sc.fps = cam->meta.fps;
    if (!cam->meta.model.empty()) {
      // A model that cannot be used is reported, and the camera replays uncalibrated.
      const std::string model_path = (root / cam->meta.model).string();
      try {
        const CameraModel model = CameraModel::Read(model_path);
        if (model.width() != sc.width || model.height() != sc.height) {
          throw InputError(model_path, "imager is " + std::to_string(model.width()) + "x" +
                                           std::to_string(model.height()) +
                                           ", the camera records " + std::to_string(sc.width) +
                                           "x" + std::to_string(sc.height));
        }
        sc.model_path = model_path;
      } catch (const InputError& e) {
        s.Problem(*cam, std::string(e.what()) + " (camera '" + cam->meta.name +
                            "' replays without its model)");
      }
    }
    s.source_cameras.push_back(sc);
    s.cams.push_back(std::move(cam));
  }
  s.pass_span_ns = (last - first) + period;
  Log("capture.replay")
      ->debug("{}: replaying {} camera(s){}", dir, s.cams.size(),
              options.realtime ? " in real time" : "");
  for (auto& cam : s.cams) {
    Impl::Camera* c = cam.get();
    c->decoder = std::thread([&s, c] { s.DecodeCamera(*c); });
  }
}

ReplaySource::~ReplaySource() {
  Stop();
  for (auto& cam : impl_->cams) {
    if (cam->decoder.joinable()) cam->decoder.join();
  }
}

const std::vector<SourceCamera>& ReplaySource::cameras() const { return impl_->source_cameras; }

std::optional<Frame> ReplaySource::Next() {
  Impl& s = *impl_;
  std::unique_lock<std::mutex> lock(s.mutex);
  // The next frame is the earliest head among cameras; wait until every live camera has one.
  Impl::Camera* pick = nullptr;
  s.changed.wait(lock, [&] {
    if (s.stopped) return true;
    pick = nullptr;
    for (auto& cam : s.cams) {
      if (cam->ready.empty()) {
        if (!cam->finished) return false;
        continue;
      }
      if (pick == nullptr || cam->ready.front().timestamp_ns < pick->ready.front().timestamp_ns)
        pick = cam.get();
    }
    return true;
  });
  if (s.stopped || pick == nullptr) return std::nullopt;
  Frame frame = std::move(pick->ready.front());
  pick->ready.pop_front();
  s.changed.notify_all();  // room for that camera's decoder

  if (s.options.realtime) {
    if (!s.started) {
      s.started = true;
      s.wall_start = Clock::now();
      s.first_timestamp_ns = frame.timestamp_ns;
    }
    const auto due =
        s.wall_start + std::chrono::nanoseconds(frame.timestamp_ns - s.first_timestamp_ns);
    s.changed.wait_until(lock, due, [&] { return s.stopped; });
    if (s.stopped) return std::nullopt;
  }
  ++pick->stats.frames_delivered;
  ++s.totals.frames_delivered;
  return frame;
}

void ReplaySource::Stop() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->stopped = true;
  impl_->changed.notify_all();
}

bool ReplaySource::WaitsForReader() const { return !impl_->options.realtime; }

SourceStats ReplaySource::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  SourceStats out = impl_->totals;
  out.frames_dropped = 0;
  for (const auto& cam : impl_->cams) {
    out.frames_dropped += cam->stats.recorded_gaps + cam->stats.frames_unreadable;
  }
  return out;
}

const SessionInfo& ReplaySource::session() const { return impl_->info; }

std::vector<ReplayCameraStats> ReplaySource::camera_stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<ReplayCameraStats> out;
  for (const auto& cam : impl_->cams) out.push_back(cam->stats);
  return out;
}

}  // namespace ss
