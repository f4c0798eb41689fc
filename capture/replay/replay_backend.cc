// The replay backend: a recorded session's camera in place of a device (test mode).
#include "capture/camera_backend.h"
#include "capture/replay/replay_source.h"
#include "core/option_checks.h"

namespace ss {

void RegisterReplayCameraBackend() {
  RegisterCameraBackend({"replay", "a recorded session's camera (test mode)",
                         [](const CameraConfig& camera, int) -> std::unique_ptr<FrameSource> {
                           ReplayOptions options;
                           options.realtime = camera.realtime;
                           options.loops = camera.loop ? 0 : 1;
                           options.camera =
                               camera.session_camera.empty() ? camera.name : camera.session_camera;
                           return std::make_unique<ReplaySource>(camera.session, options);
                         },
                         nullptr,
                         [](OptionsBinder& keys, CameraConfig& camera) {
                           keys.AddPath("session", &camera.session, "the recorded session's folder")
                               .Add("session_camera", &camera.session_camera, "a string",
                                    "the camera within the session (default: its name)")
                               .Add("loop", &camera.loop, "start over at the end")
                               .Add("realtime", &camera.realtime, "paced by the device timestamps");
                         },
                         [](CameraConfig& camera, std::string* why) {
                           OptionProblems check(why);
                           check(!camera.session.empty(), "session",
                                 "a replay camera needs the session folder it replays");
                           if (camera.session_camera.empty()) camera.session_camera = camera.name;
                           return check.ok();
                         },
                         false});
}

}  // namespace ss
