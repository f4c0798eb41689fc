#pragma once
// The animation studio's part of the control API (`/api/animations...`, docs/console.md
// "Studio"): what a spec sent to this station may use (its bank, its cameras' models, images
// in their folders, the enclosure, the bank's tags), and animation jobs run by the controller
// in station/animation_jobs.h, whose state every console receives in the status.
//
// The jobs are saved beside the bank (FOLDER/animations; for a PostgreSQL bank beside the
// recordings folder); a spec may name files under the bank's, the recordings', the config's and
// the camera models' folders and the replay roots, relative names resolving in the bank's.
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "station/animation_jobs.h"
#include "station/api_part.h"

namespace ss {

struct StationConfig;

// The jobs' options for a station with this config (folder, roots, base folder).
AnimationJobsOptions StationAnimationOptions(const StationConfig& config,
                                             const std::string& config_path,
                                             const std::vector<std::string>& replay_roots);

class ConsoleAnimations : public api::Part {
 public:
  explicit ConsoleAnimations(api::Context context);
  ~ConsoleAnimations() override;  // Stop()

  std::vector<api::Route> Routes() override;
  void AddStatus(nlohmann::json& status) const override;  // "animation": the jobs' Brief()
  void Stop() override;

  // POST /api/animations/spec.json {"spec": YAML} -> {"spec": the YAML as JSON}: the page reads
  // any spec so (docs/examples' too); InputError naming the line of text that is not YAML.
  // GET /api/animations/inputs: {"bank", "cameras": [{"name", "model"}] (the station's cameras'
  // models, then the .cameramodel files beside the bank), "backgrounds",
  // "enclosure": [[x, y]...], "tags", "max_time_budget_s", "frame_rate"}.
  nlohmann::json Inputs() const;

 private:
  AnimationJobs& Jobs() const;  // WorkError when the daemon has no station config

  api::Context context_;
  std::unique_ptr<AnimationJobs> jobs_;
};

}  // namespace ss
