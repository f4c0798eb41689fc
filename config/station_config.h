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
#include "pipeline/transitions/bank_sprites.h"

namespace ss {

inline constexpr int kConfigVersion = 1;

// Closed sets are enums in the program and text only in the config file and the API. The
// camera's (capture/camera_config.h) and the keyers' (pipeline/key/keying_config.h) are their
// owners'.
enum class RecordingMode { kOff, kAll, kUsable };  // all frames, or those that gave a usable sprite

inline constexpr EnumText<RecordingMode> kRecordingModeTexts[] = {
    {RecordingMode::kOff, "off"}, {RecordingMode::kAll, "all"}, {RecordingMode::kUsable, "usable"}};

const char* ToText(RecordingMode mode);

// The enclosure section's floor; its wall_height_m is the pipeline's
// (CameraPipelineOptions::usability.wall_height_m, which it tunes).
struct EnclosureConfig {
  GroundPolygon floor;  // ground metres, vertices in order
  bool operator==(const EnclosureConfig&) const = default;
};

// The camera pipeline's options as the config's defaults make them, where these differ from the
// stages' own (docs/config.md is the contract): the keying section is always there (unset, a
// pipeline keys with the chroma keyer's own defaults), pipeline.min_area_px is 400 (the
// extractor's own 40 suits small test frames) and pipeline.px_per_m is `auto` (0).
inline CameraPipelineOptions DefaultPipelineOptions() {
  CameraPipelineOptions o;
  o.keying = KeyingConfig{};
  o.extract.min_area = 400;
  o.rectify.px_per_m = 0;
  return o;
}

// The transition table kept by the station (and ingest): which sprites take part, and how many
// transitions leave each (pipeline/transitions/bank_sprites.h TableChoice).
struct TransitionsConfig {
  // Sprites tagged `merged` (two or more subjects in one blob, docs/pipeline.md) are left out
  // of transitions unless this is true.
  bool include_merged = false;
  int max_per_sprite = TableChoice::kDefaultMaxPerSprite;  // the cheapest; 0: every one
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
  EnclosureConfig enclosure;
  // The keying and pipeline sections and enclosure.wall_height_m: the camera pipeline's own
  // options, bound key by key (config/config_keys.cc); `keying` is always set.
  CameraPipelineOptions pipeline = DefaultPipelineOptions();
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

// No IsValid (core/option_checks.h): its one field is a switch, so no value is out of range.
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

// True for 127.0.0.0/8, ::1 and "localhost".
bool IsLoopbackAddress(const std::string& address);

// The file's keys as config/config_keys.cc binds them, with type, default and doc
// (`spritestation config keys`): one line a key, its path dotted...
std::string ConfigKeysText();
// ... or docs/config.md's key tables in Markdown, each between its markers.
std::string ConfigKeysMarkdown();
// `doc` (named `origin` in errors) with each key table between its markers made anew; throws
// InputError when a marker is broken, names no table, or a table has none.
std::string WithConfigKeyTables(const std::string& doc, const std::string& origin);

}  // namespace ss
