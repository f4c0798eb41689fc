#include "capture/camera_source.h"

#include <cmath>
#include <filesystem>

#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/session.h"
#ifdef SPRITESTATION_HAVE_ARAVIS
#include "capture/aravis/aravis_source.h"
#endif
#ifdef SPRITESTATION_HAVE_V4L2
#include "capture/v4l2/v4l2_source.h"
#endif
#ifdef SPRITESTATION_HAVE_LIBCAMERA
#include "capture/libcamera/libcamera_config.h"
#endif

namespace ss {
namespace {

namespace fs = std::filesystem;

[[maybe_unused]] std::optional<PixelFormat> PixelFormatOf(const CameraConfig& camera) {
  if (camera.pixel_format.empty()) return std::nullopt;
  const std::optional<PixelFormat> format = ParsePixelFormat(camera.pixel_format);
  if (!format) throw InputError("cameras." + camera.name + ".pixel_format", "unknown '" + camera.pixel_format + "'");
  return format;
}

// What every live backend's options share, from the camera's config.
template <typename Options>
[[maybe_unused]] void SetLiveOptions(const CameraConfig& camera, int camera_index, Options& options) {
  options.name = camera.name;
  options.camera_index = camera_index;
  options.pixel_format = PixelFormatOf(camera);
  options.width = camera.width;
  options.height = camera.height;
  options.fps = camera.fps;
  if (camera.exposure_us) options.exposure_us = *camera.exposure_us;
  options.frame_timeout_ms = 1000;  // the station decides when a silent camera is offline
}

std::string SessionCameraName(const CameraConfig& camera) {
  return camera.session_camera.empty() ? camera.name : camera.session_camera;
}

}  // namespace

std::unique_ptr<FrameSource> OpenCameraSource(const CameraConfig& camera, int camera_index) {
  if (camera.source == "replay") {
    ReplayOptions options;
    options.realtime = camera.realtime;
    options.loops = camera.loop ? 0 : 1;
    options.camera = SessionCameraName(camera);
    return std::make_unique<ReplaySource>(camera.session, options);
  }
  if (camera.source == "aravis") {
#ifdef SPRITESTATION_HAVE_ARAVIS
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
#else
    throw InputError("cameras." + camera.name + ".source", "this build has no Aravis backend (aravis-0.8 not found)");
#endif
  }
  if (camera.source == "v4l2") {
#ifdef SPRITESTATION_HAVE_V4L2
    V4l2Options options;
    options.device = camera.device;
    SetLiveOptions(camera, camera_index, options);
    if (camera.gain_db) options.gain = static_cast<int>(std::lround(*camera.gain_db));
    const WhiteBalanceConfig& wb = camera.white_balance;
    if (wb.mode == "once") options.white_balance_once = true;
    if (wb.mode == "manual") options.white_balance_k = static_cast<int>(std::lround(wb.temperature_k));
    return std::make_unique<V4l2Source>(options);
#else
    throw InputError("cameras." + camera.name + ".source", "this build has no V4L2 backend");
#endif
  }
  if (camera.source == "libcamera") {
#ifdef SPRITESTATION_HAVE_LIBCAMERA
    return std::make_unique<LibcameraSource>(LibcameraOptionsFromConfig(camera, camera_index));
#else
    throw InputError("cameras." + camera.name + ".source", "this build has no libcamera backend (libcamera not found)");
#endif
  }
  throw InputError("cameras." + camera.name + ".source",
                   "the " + camera.source + " backend is not built into this spritestation");
}

std::optional<CameraModel> ModelForCamera(const CameraConfig& camera) {
  if (!camera.model.empty()) return CameraModel::Read(camera.model);
  if (camera.source != "replay") return std::nullopt;
  const SessionInfo info = ReadSessionInfo(camera.session);
  for (const SessionCamera& c : info.cameras) {
    if (c.name != SessionCameraName(camera)) continue;
    if (c.model.empty()) return std::nullopt;
    return CameraModel::Read((fs::path(camera.session) / c.model).string());
  }
  throw InputError(camera.session + "/session.json",
                   "the session has no camera '" + SessionCameraName(camera) + "' (cameras." + camera.name + ")");
}

}  // namespace ss
