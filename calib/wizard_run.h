#pragma once
// The calibration wizard on a camera: frames from a FrameSource (live or a
// replayed session) fed to a CalibrationWizard until it is done, a frame
// budget is spent, the stream ends, or the camera stays silent too long (then
// the source is stopped and the wizard ends with what it saw). The command
// line's `calibrate wizard` runs it; so can anything else that owns a camera.
#include <functional>

#include "calib/wizard.h"
#include "capture/frame_source.h"

namespace ss::calib {

struct WizardRunOptions {
  int max_frames = 0;     // stop after this many frames; 0: until done or the stream ends
  double silent_s = 5.0;  // a camera without a frame this long ends the run
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct WizardRunResult {
  int frames = 0;       // fed to the wizard
  bool silent = false;  // ended because the camera stopped delivering
};

// `after_frame` runs after each frame (progress, the wizard's log). Does not call Finish().
WizardRunResult RunWizardOnSource(FrameSource& source, CalibrationWizard& wizard,
                                  const WizardRunOptions& options,
                                  const std::function<void()>& after_frame = nullptr);

}  // namespace ss::calib
