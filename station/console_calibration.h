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
