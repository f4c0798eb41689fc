#pragma once
// Opens what a station camera's config names: its FrameSource (replay, v4l2,
// aravis, libcamera when built) and its camera model.
#include <memory>
#include <optional>

#include "capture/camera_config.h"
#include "capture/frame_source.h"
#include "core/camera_model.h"

namespace ss {

// Opens and starts the camera; its frames carry Frame::camera = `camera_index`.
// WorkError naming the camera when the device cannot be opened (absent, busy):
// the station retries later. InputError naming the config field for a setting
// the backend refuses or cannot express.
std::unique_ptr<FrameSource> OpenCameraSource(const CameraConfig& camera, int camera_index);

// The camera's model file: the config's `model`, else the one its device brings (the backend's
// model_file: a replayed session camera's); "" when it has none. InputError naming the file
// when the backend cannot tell (an unreadable session).
std::string ModelFileForCamera(const CameraConfig& camera);

// The camera's model, read from ModelFileForCamera: nullopt for an uncalibrated live camera.
// InputError naming the file when it cannot be read.
std::optional<CameraModel> ModelForCamera(const CameraConfig& camera);

}  // namespace ss
