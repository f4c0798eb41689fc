// The replay backend: a recorded session's camera in place of a device (test mode).
#include "capture/camera_backend.h"
#include "capture/replay/replay_source.h"

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
                         nullptr});
}

}  // namespace ss
