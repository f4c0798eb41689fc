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
                           keys.AddPath("session", &camera.session,
                                        "a recorded-session folder (holds `session.json`, see "
                                        "docs/formats.md)")
                               .Default("required")
                               .Add("session_camera", &camera.session_camera, "a string",
                                    "which of the session's cameras to replay")
                               .Default("the camera's `name`")
                               .Add("loop", &camera.loop, "start over at the end of the recording")
                               .Add("realtime", &camera.realtime,
                                    "pace frames by their recorded device timestamps (`false`: as "
                                    "fast as possible)");
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
