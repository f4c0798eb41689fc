#pragma once
// Camera backends by name: what a station camera's `source` names opens one of
// its devices, and `spritestation cameras` asks each what this machine has.
// Each backend lives in its own folder with one file that defines
// `void RegisterNAMECameraBackend()` (calling RegisterCameraBackend), and one
// line in capture/CMakeLists.txt (spritestation_camera_backend) builds it in and
// calls it; nothing else in the project names a backend (replay aside: the station's test
// mode). A backend also owns its keys of a station camera's config block: a struct of its
// own, held in CameraConfig::backend, whose fields it binds and whose values it checks.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_config.h"
#include "capture/frame_source.h"
#include "core/options_binder.h"

namespace ss {

// A device a backend found, with the id a station config names it by.
struct FoundCamera {
  std::string backend;  // the backend's name, the config's `source`
  std::string id;       // `device:` (v4l2) or `camera_id:` (aravis, libcamera)
  std::string model, driver, address, serial;
};

// A file a camera's config names that must exist (checked when the config checks files).
struct CameraFile {
  std::string key;   // the camera's key that names it
  std::string file;  // the file itself (a folder's key may name a file in it)
  std::string what;  // what it is, for the message: "recorded session (session.json)"
};

struct CameraBackend {
  std::string name;  // the config's `source`: "v4l2", "aravis", ...
  std::string description;
  // Opens and starts the camera; its frames carry Frame::camera = `camera_index`. WorkError
  // naming the camera when the device cannot be opened (the station retries later);
  // InputError naming the config field for a setting the backend refuses.
  std::function<std::unique_ptr<FrameSource>(const CameraConfig& camera, int camera_index)> open;
  // The devices present now; unset for a backend that has none to list (replay).
  std::function<std::vector<FoundCamera>()> list;
  // Binds the camera keys of its own (beyond name, source, model and the device settings) to
  // the fields of its struct in `camera.backend` (`Use<T>()`; core/options_binder.h); the
  // config reads them for its cameras.
  std::function<void(OptionsBinder& keys, CameraConfig& camera)> keys;
  // Its rules on a camera's values beyond their types: one "KEY: reason" line per problem in
  // `why` (core/option_checks.h), KEY the config's. It may fill a key whose default is another
  // key's value (replay's session_camera). Unset: no rules.
  std::function<bool(CameraConfig& camera, std::string* why)> check;
  // The files a camera's values name that must exist; unset: none.
  std::function<std::vector<CameraFile>(const CameraConfig& camera)> files;
  // The camera model file its device brings, for a camera whose config names none (replay: the
  // session camera's); "" when it brings none. InputError naming the file it cannot read. Unset:
  // none.
  std::function<std::string(const CameraConfig& camera)> model_file;
  // Takes the device settings, which the config binds for it (pixel_format, width, height, fps,
  // exposure_us, gain_db, white_balance; SetLiveOptions): every backend of a device, not replay.
  bool device_settings = true;
};

// Called by each backend's registration function; a second backend of the same name is an error.
void RegisterCameraBackend(CameraBackend backend);
// nullptr when no backend of that name is built in.
const CameraBackend* FindCameraBackend(const std::string& name);
// Every backend built in, by name.
std::vector<const CameraBackend*> CameraBackends();
std::vector<std::string> CameraBackendNames();

// The config's pixel format; nullopt when unset. InputError naming cameras.NAME.pixel_format when
// unknown.
std::optional<PixelFormat> PixelFormatOf(const CameraConfig& camera);

// What every live backend's options share, from the camera's config.
template <typename Options>
void SetLiveOptions(const CameraConfig& camera, int camera_index, Options& options) {
  options.name = camera.name;
  options.camera_index = camera_index;
  options.pixel_format = PixelFormatOf(camera);
  options.width = camera.width;
  options.height = camera.height;
  options.fps = camera.fps;
  if (camera.exposure_us) options.exposure_us = *camera.exposure_us;
  options.frame_timeout_ms = 1000;  // the station decides when a silent camera is offline
}

}  // namespace ss
