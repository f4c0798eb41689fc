#pragma once
// Inside the station config's reader (config/station_config.cc), for its own files only:
// config_keys.cc binds every key to its field, config_validate.cc checks values.
#include <string>
#include <utility>
#include <vector>

#include "config/station_config.h"
#include "core/options_binder.h"
#include "core/yaml_reader.h"
#include "pipeline/key/keying_keys.h"

namespace ss::config_detail {

extern const std::vector<std::string> kLogLevels;  // logging.level and per component

// A config of the defaults: the fields' own, the keying section there, and the storage's files
// and folders as named relative to the config's folder (station.bank, recordings, spool).
StationConfig Defaults();
// The whole file's keys, bound to `cfg`'s fields.
OptionsBinder StationKeys(StationConfig& cfg);
// The keys of some of its blocks, whose bound numbers' rules Validate checks.
OptionsBinder CameraSettingKeys(CameraConfig& cam);
OptionsBinder WhiteBalanceKeys(WhiteBalanceConfig& wb);
OptionsBinder EnclosureKeys(StationConfig& cfg);
OptionsBinder PipelineKeys(CameraPipelineOptions& p);
OptionsBinder StorageKeys(StorageConfig& s);
OptionsBinder TransitionsKeys(TransitionsConfig& t);
OptionsBinder ControlKeys(ControlConfig& c);
// Checks values and cross-field rules, adjusting what can be fixed; reports to `msg`.
void Validate(StationConfig& cfg, YamlMessages& msg, const ConfigOptions& options);
ConfigReport MakeReport(const YamlMessages& msg);

}  // namespace ss::config_detail
