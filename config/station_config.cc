#include "config/station_config.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "config/config_detail.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"
#include "core/posix.h"
#include "core/yaml_reader.h"

// Reading a config: the text (here), its keys (config_keys.cc), its values (config_validate.cc).
namespace ss {
namespace {

namespace fs = std::filesystem;
using namespace yaml_text;
using Messages = YamlMessages;
using Reader = YamlReader;

// Throws on kInvalid; logs adjustments; hands the report back.
void Conclude(const ConfigReport& report, ConfigReport* out) {
  if (out) *out = report;
  if (report.status == ConfigStatus::kInvalid) throw InputError(Join(report.errors, "\n"));
  for (const auto& a : report.adjustments) Log("core.config")->warn("adjusted: {}", a);
}

}  // namespace

std::string ConfigReport::Summary() const {
  std::vector<std::string> lines = errors;
  for (const auto& a : adjustments) lines.push_back("adjusted: " + a);
  return Join(lines, "\n");
}

StationConfig ParseStationConfig(const std::string& yaml, const std::string& origin,
                                 const std::string& base_dir, ConfigReport* report,
                                 const ConfigOptions& options) {
  const YAML::Node root = LoadOneDocument(yaml, origin);
  if (root.IsNull()) {
    throw InputError(origin,
                     "the config is empty (expected sections such as cameras, enclosure, storage)");
  }
  std::map<std::string, int> lines;
  Messages msg(origin, lines);
  Reader r(msg, lines, base_dir);

  StationConfig cfg = config_detail::Defaults();
  cfg.storage.bank = r.Resolve(cfg.storage.bank);
  cfg.storage.recording_dir = r.Resolve(cfg.storage.recording_dir);
  cfg.storage.spool_dir = r.Resolve(cfg.storage.spool_dir);
  config_detail::StationKeys(cfg).Read(r, root, "");

  config_detail::Validate(cfg, msg, options);
  Conclude(config_detail::MakeReport(msg), report);
  return cfg;
}

StationConfig LoadStationConfig(const std::string& path, ConfigReport* report,
                                const ConfigOptions& options) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a config file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open the config: ") + ErrnoText(errno));
  const std::string text = ReadWithinLimit(in, path, "a config file");
  const fs::path base = fs::absolute(fs::path(path), ec).parent_path();
  return ParseStationConfig(text, path, base.string(), report, options);
}

const char* ToText(RecordingMode mode) { return TextOf(mode, kRecordingModeTexts); }

}  // namespace ss
