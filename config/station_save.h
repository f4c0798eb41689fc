#pragma once
// Saving a calibration into a station: each camera's .cameramodel where its
// config says (`cameras[].model`, else CALIBRATION_DIR/NAME.cameramodel), the
// enclosure floor and new model paths into the config file, every file
// replaced atomically (written beside it, then renamed over it) and the file
// it replaces kept beside it as NAME.previous-<UTC>.EXT. Every new file is
// written before any is renamed: a folder that cannot be written fails the
// save with nothing changed. Also the edits of a config's YAML text that keep the rest as
// written. In config/ (namespace calib, as its users know it), above the config it edits and
// the calibration it saves.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/station_config.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

struct StationSaveRequest {
  std::vector<std::pair<std::string, CameraModel>> models;  // (camera name, model)
  std::optional<GroundPolygon> floor;                       // the enclosure, when found
  std::string config_path;      // the station's config file; "": none (only `config` changes)
  std::string calibration_dir;  // where models of cameras without `model:` go
  std::string stamp;            // UTC, for the previous files' names ("20261202T071000Z")
};

struct StationSaveResult {
  std::vector<std::string> files;     // written (models, then the config)
  std::vector<std::string> previous;  // the files they replaced, kept under their new names
  StationConfig config;               // the station's config with the new models and floor
};

// WorkError naming the folder or file that cannot be written; InputError naming the camera
// when it is not in `config` or the edited config does not hold.
StationSaveResult SaveStationCalibration(const StationConfig& config,
                                         const StationSaveRequest& request);

// Sets `cameras[NAME].model` in a station config's YAML text, keeping everything else as
// written; InputError naming `origin` when the camera's entry is not found.
std::string SetCameraModelPath(const std::string& config_yaml, const std::string& camera,
                               const std::string& path, const std::string& origin);

// "DIR/NAME.previous-STAMP.EXT" for "DIR/NAME.EXT".
std::string PreviousFileName(const std::string& path, const std::string& stamp);

// Replaces (or adds) `enclosure.floor` in a station config's YAML text, keeping
// everything else as written. The result is checked by ParseStationConfig
// (InputError naming `origin` when it does not hold).
std::string ReplaceEnclosureFloor(const std::string& config_yaml, const GroundPolygon& floor,
                                  const std::string& origin);

}  // namespace ss::calib
