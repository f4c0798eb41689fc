#include "calib/wizard_run.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/frame.h"
#include "core/option_checks.h"

namespace ss::calib {

bool WizardRunOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(max_frames, AtLeast(0), "max_frames", "0 (until done) or a number of frames");
  check.Within(silent_s, Positive(), "silent_s", "a positive number of seconds");
  return check.ok();
}

WizardRunResult RunWizardOnSource(FrameSource& source, CalibrationWizard& wizard,
                                  const WizardRunOptions& options,
                                  const std::function<void()>& after_frame) {
  if (std::string why; !options.IsValid(&why)) throw InputError("wizard run options", why);
  // A live camera that stops delivering (unplugged, its stream ended) ends the run with what
  // it has; Next() itself waits for frames as long as the source lives. (The station's
  // CameraRunner does the same, then reopens the camera.)
  using Clock = std::chrono::steady_clock;
  WizardRunResult result;
  std::atomic<int64_t> last_frame_ns{Clock::now().time_since_epoch().count()};
  std::atomic<bool> reading{true}, silent{false};
  cv::Mat bgr;
  {
    std::jthread watchdog([&] {
      const auto limit = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(options.silent_s));
      while (reading.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (Clock::now().time_since_epoch().count() - last_frame_ns.load() > limit.count()) {
          silent.store(true);
          source.Stop();
          return;
        }
      }
    });
    struct StopWatching {
      std::atomic<bool>& reading;
      ~StopWatching() { reading.store(false); }  // before the jthread joins, also on a throw
    } stop_watching{reading};
    while (!wizard.done() && (options.max_frames <= 0 || result.frames < options.max_frames)) {
      auto frame = source.Next();
      if (!frame) break;
      last_frame_ns.store(Clock::now().time_since_epoch().count());
      ToBgr(*frame, bgr);
      wizard.Feed(bgr, static_cast<int>(frame->sequence),
                  frame->timestamp_ns > 0 ? static_cast<double>(frame->timestamp_ns) * 1e-9 : NAN);
      ++result.frames;
      if (after_frame) after_frame();
    }
  }
  source.Stop();
  result.silent = silent.load();
  return result;
}

}  // namespace ss::calib
