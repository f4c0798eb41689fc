// spritestation cameras [--json]: lists the cameras this machine can open, as
// every built-in camera backend (capture/camera_backend.h) finds them — V4L2
// capture devices, what Aravis discovers (GigE Vision, USB3 Vision),
// libcamera's cameras — with the id to put in the station config.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "capture/camera_backend.h"
#include "core/log.h"

namespace ss::apps {
namespace {

void RunCameras(bool json) {
  nlohmann::json out = nlohmann::json::array();
  for (const CameraBackend* backend : CameraBackends()) {
    if (!backend->list) continue;
    try {
      for (const FoundCamera& d : backend->list()) {
        out.push_back({{"backend", d.backend},
                       {"id", d.id},
                       {"model", d.model},
                       {"driver", d.driver},
                       {"address", d.address},
                       {"serial", d.serial}});
      }
    } catch (const std::exception& e) {  // a broken backend must not hide the others
      Log("apps.cameras")->warn("{}: {}", backend->name, e.what());
    }
  }
  if (json) {
    std::printf("%s\n", out.dump(2).c_str());
    return;
  }
  if (out.empty()) {
    std::printf("no cameras found\n");
    return;
  }
  std::printf("%-9s %-28s %-24s %-12s %s\n", "backend", "id", "model", "driver", "address");
  for (const auto& c : out) {
    std::printf("%-9s %-28s %-24s %-12s %s\n", c["backend"].get<std::string>().c_str(),
                c["id"].get<std::string>().c_str(), c["model"].get<std::string>().c_str(),
                c["driver"].get<std::string>().c_str(), c["address"].get<std::string>().c_str());
  }
}

}  // namespace

void AddCamerasCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "cameras", "List the cameras the built-in backends (V4L2, Aravis, libcamera) can open");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print the list as JSON");
  cmd->callback([json] { RunCameras(*json); });
}

}  // namespace ss::apps
