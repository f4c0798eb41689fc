// The libcamera backend: cameras behind libcamera's pipeline handlers.
#include "capture/camera_backend.h"
#include "capture/libcamera/libcamera_config.h"
#include "capture/libcamera/libcamera_source.h"

namespace ss {

void RegisterLibcameraCameraBackend() {
  RegisterCameraBackend(
      {"libcamera", "cameras behind libcamera's pipeline handlers",
       [](const CameraConfig& camera, int camera_index) -> std::unique_ptr<FrameSource> {
         return std::make_unique<LibcameraSource>(LibcameraOptionsFromConfig(camera, camera_index));
       },
       [] {
         std::vector<FoundCamera> out;
         for (const auto& d : ListLibcameraCameras()) {
           out.push_back({"libcamera", d.id, d.model, "libcamera", d.location, ""});
         }
         return out;
       },
       [](OptionsBinder& keys, CameraConfig& camera) {
         keys.Add("camera_id", &camera.backend.Use<LibcameraCameraKeys>().camera_id, "a string",
                  "the camera's id, as `spritestation cameras` lists it; empty: the first camera");
       },
       nullptr});
}

}  // namespace ss
