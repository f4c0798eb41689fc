#include "capture/camera_source.h"

#include <filesystem>

#include "capture/camera_backend.h"
#include "core/error.h"
#include "core/session.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

std::string SessionCameraName(const CameraConfig& camera) {
  return camera.session_camera.empty() ? camera.name : camera.session_camera;
}

}  // namespace

std::unique_ptr<FrameSource> OpenCameraSource(const CameraConfig& camera, int camera_index) {
  const CameraBackend* backend = FindCameraBackend(camera.source);
  if (backend == nullptr) {
    std::string built;
    for (const CameraBackend* b : CameraBackends()) built += (built.empty() ? "" : ", ") + b->name;
    throw InputError("cameras." + camera.name + ".source",
                     "no backend \"" + camera.source +
                         "\" is built into this spritestation (built in: " + built + ")");
  }
  return backend->open(camera, camera_index);
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
  throw InputError(camera.session + "/session.json", "the session has no camera '" +
                                                         SessionCameraName(camera) + "' (cameras." +
                                                         camera.name + ")");
}

}  // namespace ss
