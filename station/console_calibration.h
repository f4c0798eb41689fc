#pragma once
// The calibration wizard in the console (`/api/calibration/...`, docs/console.md):
// one CalibrationWizard (calib/wizard.h) per chosen camera, fed from the running
// station's frames (Station::SetFrameWatcher: every frame the pipeline thread
// sees, not the 5 Hz previews), each on a thread of its own. The operator
// solves, drops views, redoes a step, sets the enclosure and saves from the
// page; the state (views, coverage, diversity, checklist, ground pose,
// enclosure, a long step's progress) goes out in the status the events stream
// sends. Saving writes the models and the config (config/station_save.h) and
// restarts the live station with them inside the daemon.
//
// Threads: the API's threads call the routes (start, actions, save) and the status;
// each camera's wizard runs on a thread of its own, fed by the station's pipeline
// threads through the frame watcher; the thread that replaces the host's station (a
// replay route, a save, a retrain) re-taps the new one from the host's station change
// listener (StationHost::AddStationChangeListener), before its switch returns.
// Lock order: the host's switch_mutex_ -> its listeners_ lock -> Impl::tap_mutex ->
// Impl::mutex (held for a copy) -> a camera's state lock; Impl::tap_mutex -> the host's
// mutex_ (current()) and the station's locks (Status, the watcher's). Neither Impl lock is
// held while calling the host's switching methods (the save calls ApplyLiveConfig with
// none), so the listener may take them.
#include <memory>
#include <vector>

#include "station/api_part.h"

namespace ss {

class ConsoleCalibration : public api::Part {
 public:
  explicit ConsoleCalibration(api::Context context);
  ~ConsoleCalibration() override;

  std::vector<api::Route> Routes() override;
  void AddStatus(nlohmann::json& status) const override;
  void Stop() override;

  // The wizard's state (`status.calibration`), without and with each camera's `online` and
  // `message` from the station's status (what GET /api/calibration and the actions answer).
  nlohmann::json State() const;
  nlohmann::json StateWithCameras() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
