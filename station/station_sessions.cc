// The station's capture sessions (start, stop, rename) and what taps the frames while one runs:
// the recorder and the frame watcher.
#include <atomic>
#include <filesystem>
#include <mutex>

#include "core/bank.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/utc_time.h"
#include "station/recorder.h"
#include "station/station.h"
#include "station/station_impl.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using station_detail::Clock;
using station_detail::kPreviewIntervalS;
using station_detail::kPreviewIntervalSessionS;

// A session name: what a studio user types, kept usable as a folder name.
std::string CheckSessionName(const std::string& name) {
  if (name.empty() || name.size() > 100)
    throw InputError("name", "a session name needs 1 to 100 characters");
  for (const char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
          c == ' ')) {
      throw InputError(
          "name", "\"" + name + "\": only letters, digits, space, '-', '_' and '.' are allowed");
    }
  }
  if (name == "." || name == "..")
    throw InputError("name", "\"" + name + "\" is not a session name");
  return name;
}

// SessionStatus::revision: one count for every station of the process.
uint64_t NextSessionRevision() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}

}  // namespace

void Station::Impl::Tap(int camera, const Frame& frame, uint64_t drops_before, bool usable) {
  {
    std::lock_guard lock(watcher_mutex);
    if (watcher) watcher(camera, frame);
  }
  std::lock_guard lock(recorder_mutex);
  if (!recorder) return;
  const std::optional<SourceCamera> source = runners[static_cast<size_t>(camera)]->source_camera();
  if (!source) return;
  const std::optional<CameraModel>& model = models[static_cast<size_t>(camera)];
  recorder->Offer(camera, *source, model ? &*model : nullptr, frame, drops_before, usable);
}

void Station::Impl::StopRecording(const std::string& why) {
  std::unique_ptr<StationRecorder> done;
  {
    std::lock_guard lock(recorder_mutex);
    done.swap(recorder);
  }
  if (!done) return;
  done->Close();
  std::lock_guard lock(recorder_mutex);
  last_recording = done->stats();
  log->info("recording {} closed ({} frames, {} dropped){}", last_recording.dir,
            last_recording.frames_written, last_recording.frames_dropped,
            why.empty() ? "" : ": " + why);
}

SessionStatus Station::StartSession(const std::string& requested_name) {
  Impl& s = *impl_;
  const std::string name = CheckSessionName(requested_name);
  std::lock_guard control(s.control_mutex);
  std::unique_lock lock(s.session_mutex);
  if (s.state != StationState::kRunning)
    throw ConflictError("session", "the station is not running");
  if (s.session.active)
    throw ConflictError("session", "session \"" + s.session.name + "\" is running; stop it first");
  const std::string created = UtcNowIso();
  SessionRecord record;
  record.uid = name + "@" + created;
  record.name = name;
  record.created = created;
  record.source = "station";
  std::vector<int64_t> camera_ids(s.runners.size(), 0);
  {
    std::lock_guard bank_lock(s.bank_mutex);
    const int64_t session_id = s.bank->AddSession(record);
    s.session = SessionStatus{};
    s.session.bank_session_id = session_id;
    for (size_t i = 0; i < s.runners.size(); ++i) {
      if (!s.models[i]) continue;
      CameraRecord camera;
      camera.name = s.runners[i]->name();
      camera.cameramodel = s.models[i]->ToText();
      camera.width = s.models[i]->width();
      camera.height = s.models[i]->height();
      camera_ids[i] = s.bank->AddCamera(session_id, camera);
    }
  }
  s.session.active = true;
  s.session_active = true;
  s.session.revision = NextSessionRevision();
  s.session.name = name;
  s.session.started = created;
  s.session_started = Clock::now();
  const StorageConfig storage = s.StorageSettings();
  if (storage.recording != RecordingMode::kOff && s.disk.Check(true).state == StorageState::kOk) {
    const fs::path dir = fs::path(storage.recording_dir) / (name + "-" + UtcNowStamp());
    RecordingOptions recording;
    recording.codec = storage.recording_codec;
    try {
      auto recorder = std::make_unique<StationRecorder>(
          dir.string(), name, recording, storage.recording == RecordingMode::kUsable,
          static_cast<int>(s.runners.size()), [&s] { return s.disk.RecordingRefusal(); });
      std::lock_guard rec_lock(s.recorder_mutex);
      s.recorder = std::move(recorder);
      s.session.recording_dir = dir.string();
    } catch (const std::exception& e) {
      s.log->error("recording: {}", e.what());
      std::lock_guard rec_lock(s.recorder_mutex);
      s.last_recording.error = e.what();
    }
  }
  SessionStatus out = s.session;
  lock.unlock();  // the writer updates the session's counts meanwhile
  for (size_t i = 0; i < s.runners.size(); ++i) s.runners[i]->SetBankCamera(camera_ids[i]);
  // Previews back off while a session stores: fewer snapshots for the pipeline threads to copy.
  for (auto& r : s.runners) r->set_preview_interval(kPreviewIntervalSessionS);
  s.log->info("session \"{}\" started (bank session {})", name, out.bank_session_id);
  s.Changed();
  return out;
}

SessionStatus Station::StopSession() {
  Impl& s = *impl_;
  std::lock_guard control(s.control_mutex);
  {
    std::lock_guard lock(s.session_mutex);
    if (!s.session.active) throw ConflictError("session", "no session is running");
  }
  // Every open clip closes into the writer queue under the session's cameras; then
  // the writer stores them all before the session is reported stopped.
  for (auto& r : s.runners) r->SetBankCamera(0);
  s.WaitWriterIdle();
  s.StopRecording("the session stopped");
  std::lock_guard lock(s.session_mutex);
  s.session.active = false;
  s.session_active = false;
  s.session.revision = NextSessionRevision();
  for (auto& r : s.runners) r->set_preview_interval(kPreviewIntervalS);
  s.session.seconds = Seconds(Clock::now() - s.session_started);
  s.log->info("session \"{}\" stopped: {} sprites stored", s.session.name,
              s.session.sprites_stored);
  s.Changed();
  return s.session;
}

SessionStatus Station::RenameSession(const std::string& requested_name) {
  Impl& s = *impl_;
  const std::string name = CheckSessionName(requested_name);
  std::lock_guard control(s.control_mutex);
  std::lock_guard lock(s.session_mutex);
  if (!s.session.active) throw ConflictError("session", "no session is running");
  {
    std::lock_guard bank_lock(s.bank_mutex);
    s.bank->RenameSession(s.session.bank_session_id, name);
  }
  s.log->info("session \"{}\" renamed \"{}\"", s.session.name, name);
  s.session.name = name;
  s.session.revision = NextSessionRevision();
  s.Changed();
  return s.session;
}

}  // namespace ss
