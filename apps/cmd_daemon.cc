// spritestation daemon --config station.yaml [--session NAME] [--duration S]
// [--weights FILE] [--no-transitions] [--json]: the live station. Every camera
// of the config streams through the live pipeline; sprites are stored in the
// bank during a capture session (--session starts one at once; otherwise over
// the control API), and transitions are kept current. Runs until SIGTERM or
// SIGINT (a clean stop: open clips stored, recordings finalized, bank
// committed), or --duration seconds. SIGHUP reloads the config where safe.
// Under systemd (Type=notify) it reports READY, STOPPING and the watchdog.
#include <malloc.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "config/station_config.h"
#include "core/error.h"
#include "core/log.h"
#include "pipeline/transitions/weights.h"
#include "station/camera_runner.h"
#include "station/control_server.h"
#include "station/station.h"
#include "station/station_host.h"
#include "station/station_status.h"
#include "web/web_files.h"
#ifdef SPRITESTATION_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace ss::apps {
namespace {

struct DaemonArgs {
  std::string config;
  std::string session;
  double duration_s = 0;
  std::string weights;
  bool no_transitions = false;
  double offline_after_s = 3.0;
  bool json = false;
  std::string web_dir;
  std::vector<std::string> replay_dirs;
};

void Notify([[maybe_unused]] const std::string& state) {
#ifdef SPRITESTATION_HAVE_SYSTEMD
  sd_notify(0, state.c_str());
#endif
}

// Microseconds between watchdog pings systemd asks for (0: none).
uint64_t WatchdogUsec() {
#ifdef SPRITESTATION_HAVE_SYSTEMD
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) return usec;
#endif
  return 0;
}

// At most 4 malloc arenas (glibc's default is 8 a core). Every HTTP connection is a thread, and
// each thread's arena kept the bodies it had read: 32 clients streaming bodies over the 1 MiB
// limit took the daemon 49-67 MiB over its idle peak with the default, 39-47 MiB with 4
// (DaemonTest.ChunkedBodiesOverTheLimitAre413AndCostNoMemory: within 64 MiB). The station
// bench (4 cameras at 1280x720, 30 fps) runs the same with both: 121-122 frames/s, key
// 0.28-0.32 ms a frame, latency p99 136-137 ms (bench/RESULTS.md, "The daemon's malloc arenas").
// MALLOC_ARENA_MAX in the environment still decides.
void LimitMallocArenas() {
  // Called before any thread of the daemon starts: nothing else reads the environment or the
  // allocator's settings at the same time.
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr)  // NOLINT(concurrency-mt-unsafe)
    mallopt(M_ARENA_MAX, 4);                       // NOLINT(concurrency-mt-unsafe)
}

void RunDaemon(const DaemonArgs& a) {
  LimitMallocArenas();  // before any thread starts
  ConfigReport report;
  StationOptions options;
  options.config = LoadStationConfig(a.config, &report);
  try {
    CheckStationConfig(options.config);  // as `config check` says it
  } catch (const InputError& e) {
    throw InputError(a.config, e.what());
  }
  if (!a.weights.empty()) {
    options.weights = LoadWeights(a.weights);
    options.weights_path = a.weights;
  }
  options.transitions = !a.no_transitions;
  if (!(a.offline_after_s > 0))
    throw InputError("--offline-after", "expected a positive number of seconds");
  options.offline_after_s = a.offline_after_s;

  // Signals are taken by this thread alone (sigtimedwait below): block them before any thread
  // starts.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // The console's replay page lists the sessions under these folders.
  std::vector<std::string> replay_roots;
  if (!options.config.storage.recording_dir.empty())
    replay_roots.push_back(options.config.storage.recording_dir);
  if (a.replay_dirs.empty()) {
    std::error_code ec;
    if (std::filesystem::is_directory("recordings", ec)) {
      replay_roots.push_back(std::filesystem::absolute("recordings", ec).string());
    }
  }
  for (const std::string& dir : a.replay_dirs) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
      throw InputError("--replay-dir", dir + ": no such folder");
    replay_roots.push_back(std::filesystem::absolute(dir, ec).lexically_normal().string());
  }
  ControlServerOptions control_options;
  control_options.config_path = std::filesystem::absolute(a.config).string();
  control_options.config = options.config.control;
  if (!a.web_dir.empty()) {
    std::error_code ec;
    if (!std::filesystem::exists(std::filesystem::path(a.web_dir) / "index.html", ec)) {
      throw InputError("--web-dir",
                       a.web_dir + ": has no index.html (expected the source tree's web/ folder)");
    }
    control_options.web_dir = a.web_dir;
  }
  control_options.embedded = FindEmbeddedWebFile;

  StationHost host(options, replay_roots);
  host.Start();
  ControlServer control(host, control_options);
  const int port = control.Start();
  if (!a.session.empty()) host.current()->StartSession(a.session);
  // The ready line: scripts and tests read the port from it.
  std::printf("daemon: control API on %s (port %d)\n", control.url().c_str(), port);
  std::fflush(stdout);
  Notify("READY=1\nSTATUS=running, control API on " + control.url());

  const uint64_t watchdog_usec = WatchdogUsec();
  const auto start = std::chrono::steady_clock::now();
  auto log = Log("station");
  while (true) {
    if (watchdog_usec > 0) Notify("WATCHDOG=1");
    timespec wait{0, 250'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) {
      log->info("{}: stopping", sig == SIGINT ? "SIGINT" : "SIGTERM");
      break;
    }
    if (sig == SIGHUP) {
      Notify("RELOADING=1");
      try {
        const StationConfig next = LoadStationConfig(a.config);
        host.current()->Reload(next);
      } catch (const std::exception& e) {
        log->error("SIGHUP: the config was not reloaded (the running one is kept): {}", e.what());
      }
      Notify("READY=1");
    }
    if (a.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
            a.duration_s) {
      break;
    }
  }
  Notify("STOPPING=1");
  control.Stop();
  host.Stop();
  const StationStatus status = host.current()->Status();
  // Cameras that stopped answering are still being closed on threads of their own.
  const bool cameras_closed = WaitForCameraCloses(2.0);
  if (a.json) {
    std::printf("%s\n", StatusToJson(status).dump(2).c_str());
  } else {
    std::printf("daemon: stopped; %llu sprites stored this run, bank %s\n",
                static_cast<unsigned long long>(status.sprites_stored), status.bank_path.c_str());
    for (const CameraStatus& c : status.cameras) {
      std::printf(
          "  %s: %llu frames, %llu processed, dropped %llu (queue full) + %llu (at the source), "
          "%llu reopens\n",
          c.name.c_str(), static_cast<unsigned long long>(c.frames_captured),
          static_cast<unsigned long long>(c.frames_processed),
          static_cast<unsigned long long>(c.dropped_queue_full),
          static_cast<unsigned long long>(c.dropped_at_source),
          static_cast<unsigned long long>(c.reopens));
    }
  }
  if (!cameras_closed) {
    // Everything of the station is stored and closed; only unanswered device closes remain.
    log->warn("a camera that stopped answering is not closed yet; exiting without waiting for it");
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(0);
  }
}

}  // namespace

void AddDaemonCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "daemon", "Run the live station from a config file (cameras, pipeline, bank, HTTP control)");
  auto a = std::make_shared<DaemonArgs>();
  cmd->add_option("--config", a->config, "Station config (docs/config.md)")->required();
  cmd->add_option("--session", a->session, "Start a capture session with this name at once");
  cmd->add_option("--duration", a->duration_s,
                  "Stop after this many seconds (0: until SIGTERM/SIGINT)");
  cmd->add_option("--weights", a->weights,
                  "Transition classifier weights (default: the shipped ones)");
  cmd->add_flag("--no-transitions", a->no_transitions,
                "Do not keep the bank's transitions current");
  cmd->add_option("--offline-after", a->offline_after_s,
                  "A camera silent this many seconds is marked offline and reopened");
  cmd->add_flag("--json", a->json, "Print the final status as JSON when stopped");
  cmd->add_option("--web-dir", a->web_dir,
                  "Serve the console's pages from this folder (a source tree's web/) "
                  "instead of the copy built in");
  cmd->add_option("--replay-dir", a->replay_dirs,
                  "A folder of recorded sessions for the console's replay page "
                  "(repeatable; default: recordings/ here, and storage.recording_dir)");
  cmd->callback([a] { RunDaemon(*a); });
}

}  // namespace ss::apps
