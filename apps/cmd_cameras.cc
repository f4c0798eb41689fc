// spritestation cameras [--json]: lists the cameras this machine can open —
// V4L2 capture devices, what Aravis discovers (GigE Vision, USB3 Vision) and
// libcamera's cameras — with the id to put in the station config.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#ifdef SPRITESTATION_HAVE_ARAVIS
#include "capture/aravis/aravis_source.h"
#endif
#ifdef SPRITESTATION_HAVE_V4L2
#include "capture/v4l2/v4l2_source.h"
#endif
#ifdef SPRITESTATION_HAVE_LIBCAMERA
#include "capture/libcamera/libcamera_source.h"
#include "core/log.h"
#endif

namespace ss::apps {
namespace {

void RunCameras(bool json) {
  nlohmann::json out = nlohmann::json::array();
#ifdef SPRITESTATION_HAVE_V4L2
  for (const auto& d : ListV4l2Devices()) {
    out.push_back({{"backend", "v4l2"}, {"id", d.path}, {"model", d.card}, {"driver", d.driver},
                   {"address", d.bus}, {"serial", ""}});
  }
#endif
#ifdef SPRITESTATION_HAVE_ARAVIS
  for (const auto& d : ListAravisDevices()) {
    out.push_back({{"backend", "aravis"}, {"id", d.id}, {"model", d.vendor + " " + d.model},
                   {"driver", d.protocol}, {"address", d.address}, {"serial", d.serial}});
  }
#endif
#ifdef SPRITESTATION_HAVE_LIBCAMERA
  try {
    for (const auto& d : ListLibcameraCameras()) {
      out.push_back({{"backend", "libcamera"}, {"id", d.id}, {"model", d.model}, {"driver", "libcamera"},
                     {"address", d.location}, {"serial", ""}});
    }
  } catch (const std::exception& e) {  // a broken libcamera must not hide the other backends
    Log("apps.cameras")->warn("{}", e.what());
  }
#endif
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
  auto* cmd = app.add_subcommand("cameras", "List the cameras V4L2, Aravis and libcamera can open");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print the list as JSON");
  cmd->callback([json] { RunCameras(*json); });
}

}  // namespace ss::apps
