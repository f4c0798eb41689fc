// The Aravis backend: GigE Vision and USB3 Vision cameras.
#include "capture/aravis/aravis_source.h"
#include "capture/camera_backend.h"

namespace ss {

void RegisterAravisCameraBackend() {
  RegisterCameraBackend(
      {"aravis", "GigE Vision and USB3 Vision cameras (Aravis)",
       [](const CameraConfig& camera, int camera_index) -> std::unique_ptr<FrameSource> {
         AravisOptions options;
         options.camera = camera.camera_id.empty() ? camera.address : camera.camera_id;
         SetLiveOptions(camera, camera_index, options);
         if (camera.gain_db) options.gain = *camera.gain_db;
         options.white_balance = camera.white_balance.mode;
         options.red_ratio = camera.white_balance.red_gain;
         options.blue_ratio = camera.white_balance.blue_gain;
         options.packet_resend = camera.packet_resend;
         options.packet_size = camera.packet_size;
         options.buffers = 32;  // frames queued for the pipeline hold their buffers
         return std::make_unique<AravisSource>(options);
       },
       [] {
         std::vector<FoundCamera> out;
         for (const auto& d : ListAravisDevices()) {
           out.push_back(
               {"aravis", d.id, d.vendor + " " + d.model, d.protocol, d.address, d.serial});
         }
         return out;
       }});
}

}  // namespace ss
