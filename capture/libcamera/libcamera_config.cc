#include "capture/libcamera/libcamera_config.h"

#include <cmath>

#include "core/error.h"

namespace ss {

LibcameraOptions LibcameraOptionsFromConfig(const CameraConfig& camera, int camera_index) {
  const std::string field = "cameras." + camera.name + ".";
  LibcameraOptions o;
  o.camera_id = camera.backend.Get<LibcameraCameraKeys>().camera_id;
  o.name = camera.name;
  o.camera_index = camera_index;
  if (!camera.pixel_format.empty()) {
    o.pixel_format = ParsePixelFormat(camera.pixel_format);
    if (!o.pixel_format)
      throw InputError(field + "pixel_format", "unknown '" + camera.pixel_format + "'");
  }
  o.width = camera.width;
  o.height = camera.height;
  o.fps = camera.fps;
  if (camera.exposure_us) o.exposure_us = *camera.exposure_us;
  if (camera.gain_db) o.analogue_gain = std::pow(10.0, *camera.gain_db / 20.0);
  const WhiteBalanceConfig& wb = camera.white_balance;
  switch (wb.mode) {
    case WhiteBalanceMode::kDevice:
      o.white_balance = LibcameraWhiteBalance::kDevice;
      break;
    case WhiteBalanceMode::kOnce:
      o.white_balance = LibcameraWhiteBalance::kOnce;
      break;
    case WhiteBalanceMode::kManual:
      if (wb.temperature_k > 0) {
        throw InputError(
            field + "white_balance.temperature_k",
            "libcamera fixes white balance as red/blue ColourGains: give red_gain and blue_gain");
      }
      o.white_balance = LibcameraWhiteBalance::kManual;
      o.red_gain = wb.red_gain;
      o.blue_gain = wb.blue_gain;
      break;
  }
  o.buffers = 8;              // frames queued for the pipeline hold their buffers
  o.frame_timeout_ms = 1000;  // the station decides when a silent camera is offline
  return o;
}

}  // namespace ss
