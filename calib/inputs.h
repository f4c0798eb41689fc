#pragma once
// Where calibration views come from: a recorded session (core/session.h,
// replayed through capture/) or a list of image files / a folder of images.
// Each camera's sampled frames go through board detection; an unreadable
// image or frame becomes a rejected view with the reason, never a crash.
#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/detect.h"

namespace ss::calib {

struct CameraViews {
  std::string name;  // session camera name, or "camera0" for images
  int width = 0, height = 0;
  std::string model_path;        // the session's .cameramodel for this camera ("" when none)
  std::vector<BoardView> views;  // one per sampled frame / image
  std::vector<int>
      frames;  // per view: frame index (the same index = the same instant across cameras)
};

struct SampleOptions {
  int every = 0;       // use every N-th frame; 0 = spread `max_views` over the session
  int max_views = 40;  // per camera
  int first = 0;       // skip frames before this index
  int count = 0;       // 0 = to the end; else this many frames from `first`
  std::vector<std::string> cameras;  // only these session cameras ("" = all)
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// True when `path` is a folder holding session.json.
bool IsSessionDir(const std::string& path);

// Detects the board in a session's frames. InputError for a bad session or an
// unknown camera name.
std::vector<CameraViews> DetectInSession(const std::string& dir, const BoardSpec& board,
                                         const DetectOptions& detect, const SampleOptions& sample);

// Detects the board in image files (a folder is expanded to its images, sorted).
// InputError when there is no image at all or the images differ in size.
CameraViews DetectInImages(const std::vector<std::string>& paths, const BoardSpec& board,
                           const DetectOptions& detect, const std::string& name = "camera0");

}  // namespace ss::calib
