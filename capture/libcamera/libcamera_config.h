#pragma once
// A station camera's config (`source: libcamera`) as LibcameraOptions.
#include "capture/camera_config.h"
#include "capture/libcamera/libcamera_source.h"

namespace ss {

// A station camera's keys of `source: libcamera` (CameraConfig::backend).
struct LibcameraCameraKeys {
  std::string camera_id;  // as `spritestation cameras` lists it; "" = the first camera
  bool operator==(const LibcameraCameraKeys&) const = default;
};

// camera_id, pixel_format, width/height, fps, exposure_us, gain_db (as the
// linear AnalogueGain 10^(dB/20)) and white_balance (device / once / manual
// with red_gain, blue_gain as ColourGains). InputError naming the field for an
// unknown pixel format or white balance mode, or a colour temperature (libcamera
// 0.0.3 cannot set one).
LibcameraOptions LibcameraOptionsFromConfig(const CameraConfig& camera, int camera_index);

}  // namespace ss
