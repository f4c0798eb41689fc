// The V4L2 backend: webcams and capture cards.
#include <cmath>

#include "capture/camera_backend.h"
#include "capture/v4l2/v4l2_source.h"
#include "core/option_checks.h"

namespace ss {

void RegisterV4l2CameraBackend() {
  RegisterCameraBackend(
      {"v4l2", "V4L2 webcams and capture cards",
       [](const CameraConfig& camera, int camera_index) -> std::unique_ptr<FrameSource> {
         V4l2Options options;
         options.device = camera.backend.Get<V4l2CameraKeys>().device;
         SetLiveOptions(camera, camera_index, options);
         if (camera.gain_db) options.gain = static_cast<int>(std::lround(*camera.gain_db));
         const WhiteBalanceConfig& wb = camera.white_balance;
         if (wb.mode == WhiteBalanceMode::kOnce) options.white_balance_once = true;
         if (wb.mode == WhiteBalanceMode::kManual)
           options.white_balance_k = static_cast<int>(std::lround(wb.temperature_k));
         return std::make_unique<V4l2Source>(options);
       },
       [] {
         std::vector<FoundCamera> out;
         for (const auto& d : ListV4l2Devices())
           out.push_back({"v4l2", d.path, d.card, d.driver, d.bus, ""});
         return out;
       },
       [](OptionsBinder& keys, CameraConfig& camera) {
         keys.Add("device", &camera.backend.Use<V4l2CameraKeys>().device, "a string",
                  "the device node, e.g. `/dev/video0`")
             .Default("required");
       },
       [](CameraConfig& camera, std::string* why) {
         OptionProblems check(why);
         check(!camera.backend.Get<V4l2CameraKeys>().device.empty(), "device",
               "a v4l2 camera needs its device, e.g. /dev/video0");
         // V4L2 fixes white balance as a colour temperature (V4L2_CID_WHITE_BALANCE_TEMPERATURE).
         check(camera.white_balance.mode != WhiteBalanceMode::kManual ||
                   camera.white_balance.temperature_k > 0,
               "white_balance.temperature_k",
               "V4L2 devices fix white balance as a colour temperature: give temperature_k");
         return check.ok();
       }});
}

}  // namespace ss
