#pragma once
// A station camera's block of the config (`cameras[]`, docs/config.md): what a camera backend
// (capture/camera_backend.h) opens a device from. The station config (config/station_config.h)
// reads it; capture owns it, as the backends are what it configures.
#include <optional>
#include <string>

#include "core/enum_text.h"

namespace ss {

// Closed sets are enums in the program and text only in the config file and the API.
enum class WhiteBalanceMode {
  kDevice,
  kOnce,
  kManual
};  // device: leave as is; once: auto, then lock

inline constexpr EnumText<WhiteBalanceMode> kWhiteBalanceModeTexts[] = {
    {WhiteBalanceMode::kDevice, "device"},
    {WhiteBalanceMode::kOnce, "once"},
    {WhiteBalanceMode::kManual, "manual"}};

inline const char* ToText(WhiteBalanceMode mode) { return TextOf(mode, kWhiteBalanceModeTexts); }

struct WhiteBalanceConfig {
  WhiteBalanceMode mode = WhiteBalanceMode::kDevice;
  double red_gain = 1.0;  // manual: red/green and blue/green balance ratios
  double blue_gain = 1.0;
  double temperature_k = 0;  // manual: colour temperature instead of ratios (V4L2); 0 = unset
  bool operator==(const WhiteBalanceConfig&) const = default;
};

struct CameraConfig {
  std::string name;            // unique; the stem of its recorded files
  std::string source;          // "replay" | "v4l2" | "aravis" | "libcamera"
  std::string session;         // replay: session folder (absolute)
  std::string session_camera;  // replay: camera within the session (default: name)
  bool loop = false;           // replay: start over at the end
  bool realtime = true;        // replay: paced by the device timestamps
  std::string device;          // v4l2: "/dev/video0"
  std::string camera_id;       // aravis / libcamera: the device id
  std::string address;         // aravis: IP address of a GigE Vision camera
  bool packet_resend = true;   // aravis
  int packet_size = 0;         // aravis: GigE packet size in bytes, 0 = negotiate
  std::string pixel_format;    // core/frame.h names ("yuyv", "bayer_rg8"...); "" = device default
  int width = 0, height = 0;   // 0 = device default
  double fps = 0;              // 0 = device default
  std::optional<double> exposure_us;  // unset = keep the device's current value, locked
  std::optional<double> gain_db;      // unset = keep the device's current value, locked
  WhiteBalanceConfig white_balance;
  std::string model;  // .cameramodel (absolute); "" = the session's, or none
  bool operator==(const CameraConfig&) const = default;
};

}  // namespace ss
