// The Aravis backend: GigE Vision and USB3 Vision cameras.
#include "capture/aravis/aravis_source.h"
#include "capture/camera_backend.h"
#include "core/ip_address.h"
#include "core/option_checks.h"

namespace ss {

void RegisterAravisCameraBackend() {
  RegisterCameraBackend(
      {"aravis", "GigE Vision and USB3 Vision cameras (Aravis)",
       [](const CameraConfig& camera, int camera_index) -> std::unique_ptr<FrameSource> {
         const auto& own = camera.backend.Get<AravisCameraKeys>();
         AravisOptions options;
         options.camera = own.camera_id.empty() ? own.address : own.camera_id;
         SetLiveOptions(camera, camera_index, options);
         if (camera.gain_db) options.gain = *camera.gain_db;
         options.white_balance = camera.white_balance.mode;
         options.red_ratio = camera.white_balance.red_gain;
         options.blue_ratio = camera.white_balance.blue_gain;
         options.packet_resend = own.packet_resend;
         options.packet_size = own.packet_size;
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
       },
       [](OptionsBinder& keys, CameraConfig& camera) {
         auto& own = camera.backend.Use<AravisCameraKeys>();
         keys.Add("camera_id", &own.camera_id, "a string",
                  "the device id, as `arv-tool-0.8` lists it; give `camera_id` or `address`, "
                  "not both")
             .Add("address", &own.address, "a string", "a GigE Vision camera's IP address")
             .Type("IP address")
             .Add("packet_resend", &own.packet_resend, "ask the camera to resend lost GVSP packets")
             .Add("packet_size", &own.packet_size, "a packet size in bytes",
                  "GVSP packet size in bytes; `0` negotiates")
             .Type("integer: `0` or 576..16384");
       },
       [](CameraConfig& camera, std::string* why) {
         const auto& own = camera.backend.Get<AravisCameraKeys>();
         OptionProblems check(why);
         check(!own.camera_id.empty() || !own.address.empty(), "camera_id",
               "an aravis camera needs camera_id or address");
         check(own.camera_id.empty() || own.address.empty(), "address",
               "give camera_id or address, not both");
         check(own.address.empty() || IsIpAddress(own.address), "address",
               "expected an IP address, got \"" + own.address + "\"");
         check(
             own.packet_size == 0 || (own.packet_size >= 576 && own.packet_size <= 16384),
             "packet_size",
             "expected 0 (negotiate) or 576..16384 bytes, got " + std::to_string(own.packet_size));
         // GenICam fixes white balance as ratios (BalanceRatio), not as a colour temperature.
         check(camera.white_balance.temperature_k == 0, "white_balance.temperature_k",
               "GigE Vision cameras fix white balance as red/blue ratios: give red_gain and "
               "blue_gain");
         return check.ok();
       }});
}

}  // namespace ss
