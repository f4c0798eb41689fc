#pragma once
// A station camera's block of the config (`cameras[]`, docs/config.md): what a camera backend
// (capture/camera_backend.h) opens a device from. The station config (config/station_config.h)
// reads it; capture owns it, as the backends are what it configures. What every backend of a
// device takes is a field here; a backend's own keys are a struct of its own, in its folder,
// held in `backend` (the keys it binds, CameraBackend::keys).
#include <optional>
#include <string>

#include "core/any_block.h"
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
  std::string name;           // unique; the stem of its recorded files
  std::string source;         // the backend's name: "replay" | "v4l2" | "aravis" | "libcamera"
  AnyBlock backend;           // the keys of its own the source's backend binds (its struct)
  std::string pixel_format;   // core/frame.h names ("yuyv", "bayer_rg8"...); "" = device default
  int width = 0, height = 0;  // 0 = device default
  double fps = 0;             // 0 = device default
  std::optional<double> exposure_us;  // unset = keep the device's current value, locked
  std::optional<double> gain_db;      // unset = keep the device's current value, locked
  WhiteBalanceConfig white_balance;
  std::string model;  // .cameramodel (absolute); "" = the session's, or none
  bool operator==(const CameraConfig&) const = default;
};

}  // namespace ss
