// The replay backend: a recorded session's camera in place of a device (test mode).
#include <filesystem>
#include <utility>

#include "capture/camera_backend.h"
#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/option_checks.h"
#include "core/session.h"

namespace ss {

namespace fs = std::filesystem;

namespace {

// The camera of the session it replays: session_camera, or its own name.
const std::string& SessionCameraOf(const CameraConfig& camera, const ReplayCameraKeys& own) {
  return own.session_camera.empty() ? camera.name : own.session_camera;
}

}  // namespace

CameraConfig ReplayCameraConfig(std::string name, ReplayCameraKeys keys) {
  CameraConfig camera;
  camera.name = std::move(name);
  camera.source = "replay";
  camera.backend.Use<ReplayCameraKeys>() = std::move(keys);
  return camera;
}

void RegisterReplayCameraBackend() {
  RegisterCameraBackend(
      {"replay", "a recorded session's camera (test mode)",
       [](const CameraConfig& camera, int) -> std::unique_ptr<FrameSource> {
         const auto& own = camera.backend.Get<ReplayCameraKeys>();
         ReplayOptions options;
         options.realtime = own.realtime;
         options.loops = own.loop ? 0 : 1;
         options.camera = SessionCameraOf(camera, own);
         return std::make_unique<ReplaySource>(own.session, options);
       },
       nullptr,
       [](OptionsBinder& keys, CameraConfig& camera) {
         auto& own = camera.backend.Use<ReplayCameraKeys>();
         keys.AddPath("session", &own.session,
                      "a recorded-session folder (holds `session.json`, see docs/formats.md)")
             .Default("required")
             .Add("session_camera", &own.session_camera, "a string",
                  "which of the session's cameras to replay")
             .Default("the camera's `name`")
             .Add("loop", &own.loop, "start over at the end of the recording")
             .Add("realtime", &own.realtime,
                  "pace frames by their recorded device timestamps (`false`: as fast as "
                  "possible)");
       },
       [](CameraConfig& camera, std::string* why) {
         auto& own = camera.backend.Use<ReplayCameraKeys>();
         OptionProblems check(why);
         check(!own.session.empty(), "session",
               "a replay camera needs the session folder it replays");
         if (own.session_camera.empty()) own.session_camera = camera.name;
         return check.ok();
       },
       [](const CameraConfig& camera) -> std::vector<CameraFile> {
         const auto& own = camera.backend.Get<ReplayCameraKeys>();
         if (own.session.empty()) return {};
         return {{"session", (fs::path(own.session) / "session.json").string(),
                  "recorded session (session.json)"}};
       },
       [](const CameraConfig& camera) -> std::string {
         const auto& own = camera.backend.Get<ReplayCameraKeys>();
         const std::string& name = SessionCameraOf(camera, own);
         for (const SessionCamera& c : ReadSessionInfo(own.session).cameras) {
           if (c.name != name) continue;
           return c.model.empty() ? "" : (fs::path(own.session) / c.model).string();
         }
         throw InputError(own.session + "/session.json",
                          "the session has no camera '" + name + "' (cameras." + camera.name + ")");
       },
       false});
}

}  // namespace ss
