#pragma once
// A station for the station tests: one looping, paced replay camera of a fresh synthetic
// session, and a wait for its status to reach a condition.
#include <chrono>
#include <thread>

#include "capture/replay/replay_source.h"
#include "station/station.h"
#include "station/station_status.h"
#include "synth/studio_session.h"
#include "tests/support/test_support.h"

namespace ss::testing {

template <typename Pred>
bool WaitFor(const Station& station, Pred pred, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred(station.Status())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// A station on one looping, paced replay camera of a fresh 4 s synthetic session in `dir`,
// storing into dir/station.bank with the disk guard off; no transitions worker.
inline StationOptions OneReplayCamera(const ScratchDir& dir) {
  synth::SynthOptions so;
  so.out_dir = dir / "session";
  so.seconds = 4;
  so.fps = 30;
  so.width = 640;
  so.height = 480;
  so.cameras = 1;
  // Its animal stays on the open floor (seed 11's walks into the walls: fewer batches).
  so.seed = 12;
  so.empty_lead_in_s = 1.5;
  so.write_mattes = false;
  synth::RenderStudioSession(so);
  StationOptions options;
  options.config.cameras = {
      ReplayCameraConfig("cam0", {.session = so.out_dir, .loop = true, .realtime = true})};
  options.config.storage.bank = dir / "station.bank";
  options.config.storage.recording_dir = dir / "recordings";
  options.config.storage.stop_recording_below_mib = 0;
  options.config.storage.stop_sprites_below_mib = 0;
  options.transitions = false;
  return options;
}

}  // namespace ss::testing
