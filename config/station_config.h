#pragma once
// The station config (the `config/` layer, above the pipeline and below the station, so that
// it can name the components it configures): one YAML file (docs/config.md,
// docs/station.example.yaml). Loading answers Valid / Adjusted (with what was adjusted) / Invalid
// (with every reason, each naming the field path and YAML line, e.g. `station.yaml:14:
// cameras[1].fps: expected a positive number, got "fast"`). Unknown keys are refused by name.
// Relative paths are resolved against the config file's folder.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_config.h"
#include "core/enum_text.h"
#include "core/geometry.h"
#include "pipeline/key/keying_config.h"
#include "pipeline/run/camera_pipeline.h"

namespace ss {

inline constexpr int kConfigVersion = 1;

// Closed sets are enums in the program and text only in the config file and the API. The
// camera's (capture/camera_config.h) and the keyers' (pipeline/key/keying_config.h) are their
// owners'.
enum class RecordingMode { kOff, kAll, kUsable };  // all frames, or those that gave a usable sprite

inline constexpr EnumText<RecordingMode> kRecordingModeTexts[] = {
    {RecordingMode::kOff, "off"}, {RecordingMode::kAll, "all"}, {RecordingMode::kUsable, "usable"}};

const char* ToText(RecordingMode mode);

struct EnclosureConfig {
  GroundPolygon floor;         // ground metres, vertices in order
  double wall_height_m = 0.0;  // walls occlude the floor behind them up to this height
  bool operator==(const EnclosureConfig&) const = default;
};

struct PipelineConfig {
  int min_area_px = 400;         // smaller blobs are noise
  int border_margin_px = 2;      // distance to keep from the image border
  int floor_margin_px = 3;       // floor pixels required around the silhouette
  double wall_margin_m = 0.005;  // contact point distance to keep from the floor polygon's edge
  double still_speed_m_per_s = 0.05;  // slower than this counts as not moving
  // the tracker's speed limit: a subject faster than this starts a new clip
  double max_speed_m_per_s = 1.0;
  double max_still_s = 2.0;  // still periods longer than this are discarded
  int min_clip_frames = 5;   // shorter clips are discarded
  // Noise (docs/pipeline.md, `noise`): keyed background, not a subject. 0 turns a test off.
  double noise_min_solidity = 0.25;      // noise when the matte fills less of its convex hull
  double noise_recover_solidity = 0.30;  // a subject noise the frame before stays noise below this
  double noise_thick_px = 2.0;           // interior: more than this from the matte's edge (pixels)
  double noise_min_thick_share = 0.0;    // ... or when less of the matte is interior
  double noise_min_largest_share = 0.0;  // ... or its largest part holds less of it
  double noise_min_mean_alpha = 0.0;     // ... or its mean alpha (of 1) is lower
  // Billboard scale in pixels per metre, the same for the whole bank; 0 = `auto` (chosen from
  // the cameras, or the bank's own scale when it holds sprites: pipeline/run/bank_scale.h).
  double px_per_m = 0;
  int workers = 0;       // OpenCV threads inside a frame's work; 0 = OpenCV's default
  int queue_frames = 8;  // per-camera queue between capture and pipeline
  bool operator==(const PipelineConfig&) const = default;
};

// The transition table kept by the station (and ingest): which sprites take part.
struct TransitionsConfig {
  // Sprites tagged `merged` (two or more subjects in one blob, docs/pipeline.md) are left out
  // of transitions unless this is true.
  bool include_merged = false;
  bool operator==(const TransitionsConfig&) const = default;
};

struct StorageConfig {
  std::string bank;           // the sprite bank (absolute)
  std::string recording_dir;  // where recorded sessions go (absolute)
  RecordingMode recording = RecordingMode::kOff;
  std::string recording_codec = "ffv1";      // "ffv1" | "mjpeg" | "h264"
  int64_t stop_recording_below_mib = 20480;  // free disk under which raw recording stops
  int64_t stop_sprites_below_mib = 2048;     // ... and under which sprite storage stops
  // Where clip batches wait on disk while the bank cannot take them (a PostgreSQL server gone,
  // a SQLite file locked past every retry), and how much they may fill; drained in order when
  // the bank answers again, also at the next start (absolute).
  std::string spool_dir;
  int64_t spool_max_mib = 4096;
  bool operator==(const StorageConfig&) const = default;
};

struct ControlConfig {
  std::string address = "127.0.0.1";
  int port = 8360;    // 0 = any free port (reported at start)
  std::string token;  // required when address is not loopback (>= 16 chars)
  bool operator==(const ControlConfig&) const = default;
};

struct LoggingConfig {
  std::string level = "info";                     // trace debug info warn error critical off
  std::map<std::string, std::string> components;  // per component, e.g. capture.aravis: debug
  bool operator==(const LoggingConfig&) const = default;
};

struct StationConfig {
  int version = kConfigVersion;
  std::vector<CameraConfig> cameras;
  KeyingConfig keying;
  EnclosureConfig enclosure;
  PipelineConfig pipeline;
  TransitionsConfig transitions;
  StorageConfig storage;
  ControlConfig control;
  LoggingConfig logging;
  bool operator==(const StationConfig&) const = default;
};

enum class ConfigStatus { kValid, kAdjusted, kInvalid };

struct ConfigReport {
  ConfigStatus status = ConfigStatus::kValid;
  std::vector<std::string> adjustments;  // "FILE:LINE: FIELD: what was changed"
  std::vector<std::string> errors;       // "FILE:LINE: FIELD: reason"
  std::string Summary() const;           // one line per adjustment or error
};

struct ConfigOptions {
  bool check_files = true;  // the model, session and token files must exist
};

// Loads and validates. Throws InputError (every error, one per line) when the
// file is missing, not YAML, has unknown keys, wrong types or invalid values.
// Adjustments are logged ("core.config") and returned in `report`.
StationConfig LoadStationConfig(const std::string& path, ConfigReport* report = nullptr,
                                const ConfigOptions& options = {});
// The same from YAML text; `origin` names it in messages, `base_dir` resolves relative paths.
StationConfig ParseStationConfig(const std::string& yaml, const std::string& origin,
                                 const std::string& base_dir, ConfigReport* report = nullptr,
                                 const ConfigOptions& options = {});
// Checks values and cross-field rules of a config however it was built; fixes
// what can be fixed (status kAdjusted). `lines` maps field paths to YAML lines.
ConfigReport ValidateStationConfig(StationConfig& config, const std::string& origin = "config",
                                   const std::map<std::string, int>& lines = {},
                                   const ConfigOptions& options = {});

// The camera pipeline's options from the config's keying, enclosure and pipeline sections.
// rectify.px_per_m is the config's pipeline.px_per_m, 0 for auto: the caller sets the bank's
// scale (ChooseBankScale, pipeline/run/bank_scale.h) before making a CameraPipeline.
CameraPipelineOptions PipelineOptionsFromConfig(const StationConfig& config);

// True for 127.0.0.0/8, ::1 and "localhost".
bool IsLoopbackAddress(const std::string& address);

}  // namespace ss
