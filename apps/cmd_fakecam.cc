// spritestation fakecam SESSION --address 127.0.0.1 [--serial S] [--pixel-format F]
// [--camera NAME] [--fps F] [--loop N] [--lost-packets R] [--duration S] [--json]:
// serves one camera of a recorded session as an emulated GigE Vision camera
// until interrupted (SIGINT/SIGTERM), the duration passes, or a finite replay ends.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "capture/aravis/fake_gige_options.h"
#include "core/error.h"
#include "core/frame.h"
#ifdef SPRITESTATION_HAVE_ARAVIS
#include "capture/aravis/fake_gige_camera.h"
#endif

namespace ss::apps {
namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop.store(true); }

struct FakecamArgs {
  std::string session;
  FakeGigEOptions options;   // the flags bound to its fields
  std::string pixel_format;  // "": the session's
  double duration_s = 0.0;
  bool json = false;
};

void RunFakecam(const FakecamArgs& a) {
#ifdef SPRITESTATION_HAVE_ARAVIS
  FakeGigEOptions options = a.options;
  if (!a.pixel_format.empty()) {
    options.pixel_format = ParsePixelFormat(a.pixel_format);
    if (!options.pixel_format)
      throw InputError("--pixel-format", "unknown pixel format '" + a.pixel_format + "'");
  }
  FakeGigECamera camera(a.session, options);
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  // The ready line: scripts and tests wait for it before opening the camera.
  std::printf("fakecam: serving %s on %s: %s %dx%d at %.2f frames/s\n", camera.device_id().c_str(),
              options.address.c_str(), PixelFormatName(camera.pixel_format()).c_str(),
              camera.width(), camera.height(), camera.fps());
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop.load() && !camera.finished()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (a.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
            a.duration_s) {
      break;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (a.json) {
    nlohmann::json out = {{"device_id", camera.device_id()},
                          {"address", options.address},
                          {"pixel_format", PixelFormatName(camera.pixel_format())},
                          {"width", camera.width()},
                          {"height", camera.height()},
                          {"fps", camera.fps()},
                          {"frames_served", camera.frames_served()},
                          {"seconds", seconds}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("fakecam: served %llu frames in %.1f s\n",
                static_cast<unsigned long long>(camera.frames_served()), seconds);
  }
#else
  (void)a;
  throw WorkError("fakecam",
                  "this build has no Aravis support (configure with SPRITESTATION_ARAVIS=ON and "
                  "libaravis-dev installed)");
#endif
}

}  // namespace

void AddFakecamCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("fakecam", "Serve a recorded session as an emulated GigE Vision camera");
  auto a = std::make_shared<FakecamArgs>();
  cmd->add_option("session", a->session, "Session folder (holds session.json)")->required();
  cmd->add_option("--address", a->options.address,
                  "IPv4 address or interface to serve on (GVCP port 3956)")
      ->capture_default_str();
  cmd->add_option("--serial", a->options.serial,
                  "Serial number; the device id is Aravis-Fake-SERIAL")
      ->capture_default_str();
  cmd->add_option("--camera", a->options.camera, "Session camera to serve (default: the first)");
  cmd->add_option("--pixel-format", a->pixel_format,
                  "mono8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8 or rgb8 (default: the "
                  "session's, else rgb8)");
  cmd->add_option("--fps", a->options.fps, "Frame rate (default: the session camera's)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--loop", a->options.loops, "Passes over the session (0: forever)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--lost-packets", a->options.lost_packet_ratio,
                  "Share of GVSP packets dropped on purpose (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--duration", a->duration_s,
                  "Stop after this many seconds (0: until interrupted)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", a->json, "Print the final report as JSON");
  cmd->callback([a] { RunFakecam(*a); });
}

}  // namespace ss::apps
