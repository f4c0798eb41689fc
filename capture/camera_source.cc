#include "capture/camera_source.h"

#include "capture/camera_backend.h"
#include "core/error.h"

namespace ss {

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
  const CameraBackend* backend = FindCameraBackend(camera.source);
  if (backend == nullptr || !backend->model_file) return std::nullopt;
  const std::string file = backend->model_file(camera);
  if (file.empty()) return std::nullopt;
  return CameraModel::Read(file);
}

}  // namespace ss
