#pragma once
// Animation jobs (issue 37, docs/console.md "Studio"): a spec a client sends the station is
// optimized, judged and rendered in the background, one job at a time, below capture's
// priority, and saved beside the bank, each job in a folder of its own that is never reused:
//   FOLDER/NNNN/spec.yaml       the spec as sent
//               job.json        state, times, error (rewritten at each change of state)
//               sequences.json  as `spritestation animate` writes it, the judge's figures in
//                               its summary (once optimized)
//               cost.png        the cost curve, as `animate` draws it
//               render.mp4      the animation, as `spritestation render` makes it
//               frames/NNNNN.jpg the same frames, one file a step, for the page's player
// A spec may name only files under the station's folders (SpecFileRules): anything else is
// refused by its line before it is opened, as is a time budget over the station's cap.
//
// Threads: Submit, Cancel and the readers run on the HTTP workers; one job thread runs the
// optimizer, the judge and the renderer. `mu_` guards the current job's state and progress; the
// job thread holds it only to copy figures in or out (never while it optimizes or renders).
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace ss {

struct AnimationJobsOptions {
  std::string folder;              // where jobs are saved (made by the first job)
  std::string base_dir;            // relative names in a spec resolve here
  std::vector<std::string> roots;  // the folders a spec may name files under (not empty)
  double max_time_budget_s = 600;  // a spec's optimizer.time_budget_s at most this
  int threads = 1;                 // the optimizer's threads (the F/B sets)
  // The most the optimizer's F/B sets may take (they grow with the bank, set_size and the
  // distinct frame constraints): a job over it fails before they are made, saying so.
  int64_t max_set_bytes = int64_t{2} << 30;
  bool render = true;  // false: no render.mp4 and frames (tests of the optimizer)
  // Called after a job's state changes and with its figures 4 times a second (on the job's
  // thread, no lock held).
  std::function<void()> changed;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

enum class AnimationJobState { kQueued, kRunning, kRendering, kDone, kFailed, kCancelled };
const char* AnimationJobStateName(AnimationJobState state);  // "queued", "running", ...

class AnimationJobs {
 public:
  // Jobs saved by an earlier run stay listed; one that was still running then is marked
  // failed ("the station stopped while it ran").
  explicit AnimationJobs(AnimationJobsOptions options);
  ~AnimationJobs();  // Stop()
  AnimationJobs(const AnimationJobs&) = delete;
  AnimationJobs& operator=(const AnimationJobs&) = delete;

  // Checks the spec (InputError "spec:LINE: FIELD: reason" lines, or naming
  // optimizer.time_budget_s over the cap), saves it in a new folder and starts the job; its id.
  // ConflictError while another job is queued, running or rendering.
  int64_t Submit(const std::string& spec_text);
  // A job as GET /api/animations/ID answers (docs/console.md); NotFoundError for an unknown id.
  nlohmann::json Job(int64_t id) const;
  // Every saved job, newest first: {"jobs": [{"id", "state", "name", "created", "files"}]}.
  nlohmann::json List() const;
  // Asks the running job to stop (it is "cancelled" within a second); its JSON. A job already
  // ended is left as it is. NotFoundError for an unknown id.
  nlohmann::json Cancel(int64_t id);
  // The current job's figures for the status stream: null when none ran since the start, else
  // {"id", "state", "seconds", "cost", "best_cost", "turns", "restarts"}. Never blocks on work.
  nlohmann::json Brief() const;
  // The absolute path of a job's file (spec.yaml, job.json, sequences.json, cost.png,
  // render.mp4) or of step `step`'s frame; NotFoundError when the job or the file is not there.
  std::string File(int64_t id, const std::string& name) const;
  std::string Frame(int64_t id, int step) const;
  // Cancels the running job and waits for its thread. Idempotent.
  void Stop();

  const AnimationJobsOptions& options() const { return options_; }

 private:
  struct Current;
  void Run(std::shared_ptr<Current> job);
  std::string FolderOf(int64_t id) const;

  AnimationJobsOptions options_;
  mutable std::mutex mu_;
  std::shared_ptr<Current> current_;  // the last job started (guarded by mu_)
  std::thread thread_;                // its thread (joined before the next starts)
};

}  // namespace ss
