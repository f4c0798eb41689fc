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

std::string ModelFileForCamera(const CameraConfig& camera) {
  if (!camera.model.empty()) return camera.model;
  const CameraBackend* backend = FindCameraBackend(camera.source);
  return backend != nullptr && backend->model_file ? backend->model_file(camera) : "";
}

std::optional<CameraModel> ModelForCamera(const CameraConfig& camera) {
  const std::string file = ModelFileForCamera(camera);
  if (file.empty()) return std::nullopt;
  return CameraModel::Read(file);
}

}  // namespace ss
