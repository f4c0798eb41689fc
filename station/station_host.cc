#include "station/station_host.h"

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "pipeline/run/ingest.h"

namespace ss {

namespace fs = std::filesystem;

std::vector<RecordedSessionEntry> FindRecordedSessions(const std::vector<std::string>& roots) {
  std::vector<RecordedSessionEntry> out;
  for (const std::string& root : roots) {
    std::error_code ec;
    if (!fs::is_directory(root, ec)) continue;
    std::vector<fs::path> dirs;
    if (fs::exists(fs::path(root) / "session.json", ec)) dirs.push_back(root);
    for (auto it = fs::recursive_directory_iterator(
             root, fs::directory_options::skip_permission_denied, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (it.depth() >= 1) it.disable_recursion_pending();
      if (it->is_directory(ec) && fs::exists(it->path() / "session.json", ec))
        dirs.push_back(it->path());
    }
    std::sort(dirs.begin(), dirs.end());
    for (const fs::path& dir : dirs) {
      RecordedSessionEntry e;
      e.path = fs::absolute(dir, ec).lexically_normal().string();
      e.root = root;
      try {
        e.info = ReadSessionInfo(e.path);
        for (const SessionCamera& c : e.info.cameras) {
          if (c.frames > 0 && c.fps > 0) e.seconds = std::max(e.seconds, c.frames / c.fps);
        }
      } catch (const std::exception& ex) {
        e.error = ex.what();
      }
      out.push_back(std::move(e));
    }
  }
  return out;
}

nlohmann::json RecordedSessionsToJson(const std::vector<std::string>& roots,
                                      const std::vector<RecordedSessionEntry>& sessions) {
  nlohmann::json list = nlohmann::json::array();
  for (const RecordedSessionEntry& e : sessions) {
    nlohmann::json cameras = nlohmann::json::array();
    for (const SessionCamera& c : e.info.cameras) {
      cameras.push_back({{"name", c.name},
                         {"width", c.width},
                         {"height", c.height},
                         {"frames", c.frames},
                         {"fps", c.fps}});
    }
    list.push_back(
        {{"path", e.path},
         {"name", e.info.name.empty() ? fs::path(e.path).filename().string() : e.info.name},
         {"root", e.root},
         {"cameras", cameras},
         {"seconds", e.seconds},
         {"synthetic", e.info.synthetic},
         {"created", e.info.created},
         {"error", e.error}});
  }
  return {{"roots", roots}, {"sessions", list}};
}

StationConfig ReplayStationConfig(const StationConfig& live, const SessionInfo& session,
                                  const std::string& dir, bool paced, bool loop) {
  StationConfig c = live;
  c.cameras.clear();
  for (const SessionCamera& sc : session.cameras) {
    c.cameras.push_back(ReplayCameraConfig(
        sc.name, {.session = dir, .session_camera = sc.name, .loop = loop, .realtime = paced}));
  }
  // The session's own floor when it has one (read as ingest reads it), else the config's.
  try {
    c.enclosure.floor = FloorForSession(dir, GroundPolygon());
  } catch (const InputError&) {
    // none in the session: the config's floor stays
  }
  return c;
}

StationHost::StationHost(StationOptions live, std::vector<std::string> replay_roots)
    : live_(std::move(live)), replay_roots_(std::move(replay_roots)) {}

StationHost::~StationHost() { Stop(); }

void StationHost::Start() {
  std::lock_guard sw(switch_mutex_);
  auto station = std::make_shared<Station>(Told(live_));
  station->Start();
  running_ = live_;
  {
    std::lock_guard lock(mutex_);
    station_ = std::move(station);
  }
  NotifyStationChange();
}

void StationHost::Stop() {
  std::lock_guard sw(switch_mutex_);
  std::shared_ptr<Station> station = current();
  if (station) station->Stop();
}

std::shared_ptr<Station> StationHost::current() const {
  std::lock_guard lock(mutex_);
  return station_;
}

void StationHost::Replace(StationOptions options) {
  std::shared_ptr<Station> old = current();
  if (old) old->Stop();  // its session stopped and stored, its bank closed
  // The stopped station stays current (its status says "stopped") until the next one runs.
  running_ = options;
  auto next = std::make_shared<Station>(Told(std::move(options)));
  next->Start();
  {
    std::lock_guard lock(mutex_);
    station_ = std::move(next);
  }
  NotifyStationChange();
}

int StationHost::AddStationChangeListener(std::function<void()> listener) {
  return listeners_.Add(std::move(listener));
}

void StationHost::RemoveStationChangeListener(int id) { listeners_.Remove(id); }

void StationHost::NotifyStationChange() {
  listeners_.Notify("station change");
  status_listeners_->Notify("status");  // the mode, and a new station's status
}

int StationHost::AddStatusListener(std::function<void()> listener) {
  return status_listeners_->Add(std::move(listener));
}

void StationHost::RemoveStatusListener(int id) { status_listeners_->Remove(id); }

StationOptions StationHost::Told(StationOptions options) const {
  options.status_changed = [listeners = status_listeners_] { listeners->Notify("status"); };
  return options;
}

void StationHost::StartReplay(const std::string& path, bool paced, bool loop) {
  std::lock_guard sw(switch_mutex_);
  const std::vector<RecordedSessionEntry> sessions = FindRecordedSessions(replay_roots_);
  std::error_code ec;
  const std::string wanted = fs::absolute(path, ec).lexically_normal().string();
  const auto it = std::find_if(sessions.begin(), sessions.end(),
                               [&](const RecordedSessionEntry& e) { return e.path == wanted; });
  if (it == sessions.end()) {
    throw InputError(
        "path",
        "\"" + path +
            "\" is not a recorded session under the replay folders (GET /api/replay/sessions)");
  }
  if (!it->error.empty()) throw InputError("path", it->error);
  StationOptions options = live_;
  options.open_source = nullptr;
  options.config = ReplayStationConfig(live_.config, it->info, it->path, paced, loop);
  const ConfigReport report = ValidateStationConfig(options.config, "replay of " + it->path);
  if (report.status == ConfigStatus::kInvalid) throw InputError("path", report.Summary());
  auto log = Log("station");
  try {
    Replace(options);
  } catch (const std::exception& e) {
    log->error("replay of {} could not start: {}; back to the config's cameras", it->path,
               e.what());
    Replace(live_);
    {
      std::lock_guard lock(mutex_);
      replaying_ = false;
    }
    throw InputError("path", std::string("the replay station could not start: ") + e.what());
  }
  std::lock_guard lock(mutex_);
  replaying_ = true;
  replay_path_ = it->path;
  replay_paced_ = paced;
  replay_loop_ = loop;
  log->info("replaying {} ({}, {})", it->path, paced ? "paced" : "as fast as it runs",
            loop ? "looping" : "once");
}

void StationHost::StopReplay() {
  std::lock_guard sw(switch_mutex_);
  {
    std::lock_guard lock(mutex_);
    if (!replaying_) throw ConflictError("replay", "no replay is running");
  }
  Replace(live_);
  std::lock_guard lock(mutex_);
  replaying_ = false;
  replay_path_.clear();
  Log("station")->info("replay stopped; the config's cameras run again");
}

StationHost::Weights StationHost::weights() const {
  std::lock_guard lock(mutex_);
  return {live_.weights ? *live_.weights : DefaultWeights(), live_.weights_path};
}

void StationHost::UseWeights(const TransitionWeights& weights, const std::string& path) {
  std::lock_guard sw(switch_mutex_);
  const std::shared_ptr<Station> station = current();
  if (station && station->SessionActive()) {
    throw ConflictError(
        "session",
        "a capture session is running; stop it first (the station restarts to use new "
        "weights, which would end the session)");
  }
  const StationOptions before = running_;
  const std::optional<TransitionWeights> live_before = live_.weights;
  const std::string live_path_before = live_.weights_path;
  auto set_live = [&](std::optional<TransitionWeights> w, std::string p) {
    std::lock_guard lock(mutex_);
    live_.weights = std::move(w);
    live_.weights_path = std::move(p);
  };
  set_live(weights, path);
  if (!station) return;  // not started: the next Start uses them
  StationOptions next = running_;
  next.weights = weights;
  next.weights_path = path;
  auto log = Log("station");
  try {
    Replace(next);
  } catch (const std::exception& e) {
    log->error(
        "the station could not start with the weights {}: {}; the previous weights run again", path,
        e.what());
    set_live(live_before, live_path_before);
    Replace(before);
    throw;
  }
  log->info("the station runs with the transition weights {}",
            path.empty() ? "shipped with the build" : path);
}

StationConfig StationHost::live_config() const {
  std::lock_guard lock(mutex_);
  return live_.config;
}

bool StationHost::ApplyLiveConfig(const StationConfig& config) {
  std::lock_guard sw(switch_mutex_);
  StationOptions previous = live_;
  bool replaying = false;
  {
    std::lock_guard lock(mutex_);
    live_.config = config;
    replaying = replaying_;
  }
  if (replaying) return false;
  try {
    Replace(live_);
  } catch (const std::exception& e) {
    Log("station")->error(
        "the station could not start with the new config: {}; the previous one runs again",
        e.what());
    {
      std::lock_guard lock(mutex_);
      live_ = previous;
    }
    Replace(live_);
    throw;
  }
  return true;
}

nlohmann::json StationHost::ModeJson() const {
  std::lock_guard lock(mutex_);
  if (!replaying_) return {{"mode", "live"}, {"replay", nullptr}};
  return {{"mode", "replay"},
          {"replay", {{"path", replay_path_}, {"paced", replay_paced_}, {"loop", replay_loop_}}}};
}

}  // namespace ss
