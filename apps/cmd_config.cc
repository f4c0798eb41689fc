// spritestation config check FILE [--json] [--no-file-checks]: validates a
// station config without starting anything (docs/config.md). Exit 0 when it is
// valid or was adjusted, 2 when it is invalid, each error naming the field and line.
// spritestation config keys [--markdown | --update DOC]: every key with its type, default
// and doc, as the code binds them; --update rewrites DOC's key tables (docs/config.md).
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "config/station_config.h"
#include "core/error.h"
#include "core/replace_file.h"
#include "station/station.h"

namespace ss::apps {
namespace {

const char* StatusName(ConfigStatus status) {
  switch (status) {
    case ConfigStatus::kValid:
      return "valid";
    case ConfigStatus::kAdjusted:
      return "adjusted";
    case ConfigStatus::kInvalid:
      return "invalid";
  }
  return "invalid";
}

void Check(const std::string& path, bool json, bool check_files) {
  ConfigOptions options;
  options.check_files = check_files;
  ConfigReport report;
  StationConfig config;
  try {
    config = LoadStationConfig(path, &report, options);
  } catch (const InputError& e) {
    if (json) {
      // The report is filled for invalid values; file and syntax errors come as the message alone.
      nlohmann::json j = {
          {"config", path},
          {"status", "invalid"},
          {"adjustments", report.adjustments},
          {"errors", report.errors.empty() ? std::vector<std::string>{e.what()} : report.errors}};
      std::printf("%s\n", j.dump(2).c_str());
    }
    throw;
  }
  // What the daemon would lack to store sprites (it starts all the same; station/station.h).
  const std::vector<std::string> gaps =
      check_files ? CalibrationGaps(config) : std::vector<std::string>{};
  // The cameras that would key sprites and keep none (an upright billboard from above).
  const std::vector<std::string> steep =
      check_files ? SteepViews(config) : std::vector<std::string>{};
  // What the daemon refuses at start although the file is valid (no cameras: a file for
  // `ingest --config`, which takes the session's), in the daemon's words.
  std::vector<std::string> daemon_refuses;
  try {
    CheckStationConfig(config);
  } catch (const InputError& e) {
    daemon_refuses.emplace_back(e.what());
  }
  if (json) {
    nlohmann::json j = {{"config", path},
                        {"status", StatusName(report.status)},
                        {"adjustments", report.adjustments},
                        {"errors", report.errors},
                        {"to_calibrate", gaps},
                        {"too_steep", steep},
                        {"daemon_refuses", daemon_refuses},
                        {"cameras", config.cameras.size()}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("%s: %s (%zu camera%s)\n", path.c_str(), StatusName(report.status),
              config.cameras.size(), config.cameras.size() == 1 ? "" : "s");
  for (const auto& a : report.adjustments) std::printf("  adjusted: %s\n", a.c_str());
  for (const auto& d : daemon_refuses) std::printf("  the daemon refuses it: %s\n", d.c_str());
  for (const auto& g : gaps) std::printf("  to calibrate: %s\n", g.c_str());
  for (const auto& v : steep) std::printf("  too steep: %s\n", v.c_str());
  if (!gaps.empty()) {
    std::printf(
        "  (the station starts and streams; what lacks these stores no sprites until the "
        "console's calibration page saves them)\n");
  }
}

// Rewrites the key tables of `doc` in place (a temporary file renamed over it).
void UpdateDoc(const std::string& doc) {
  std::ifstream in(doc, std::ios::binary);
  if (!in) throw InputError(doc + ": cannot read it");
  std::stringstream text;
  text << in.rdbuf();
  const std::string now = WithConfigKeyTables(text.str(), doc);
  if (now == text.str()) {
    std::printf("%s: the key tables are up to date\n", doc.c_str());
    return;
  }
  ReplaceFile(doc, now, "the key tables");
  std::printf("%s: key tables rewritten\n", doc.c_str());
}

}  // namespace

void AddConfigCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("config", "Check a station config file");
  cmd->require_subcommand(1);
  auto* check =
      cmd->add_subcommand("check", "Validate a station config (fields, types, values, files)");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto no_files = std::make_shared<bool>(false);
  check->add_option("config", *path, "The station YAML file")->required();
  check->add_flag("--json", *json, "Report as JSON");
  check->add_flag("--no-file-checks", *no_files,
                  "Do not require the model, session and token files to exist");
  check->callback([path, json, no_files] { Check(*path, *json, !*no_files); });

  auto* keys = cmd->add_subcommand(
      "keys", "Every config key: its type, default and doc, as the code binds them");
  auto markdown = std::make_shared<bool>(false);
  auto update = std::make_shared<std::string>();
  auto* md = keys->add_flag("--markdown", *markdown,
                            "docs/config.md's key tables, each between its markers");
  keys->add_option("--update", *update, "Rewrite this file's key tables (docs/config.md)")
      ->excludes(md);
  keys->callback([markdown, update] {
    if (!update->empty()) {
      UpdateDoc(*update);
    } else {
      std::fputs((*markdown ? ConfigKeysMarkdown() : ConfigKeysText()).c_str(), stdout);
    }
  });
}

}  // namespace ss::apps
