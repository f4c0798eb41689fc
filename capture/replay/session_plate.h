#pragma once
// The clean plate of one camera of a recorded session: the per-pixel median of its
// empty-enclosure frames. By default the first 30 frames, which are what a keyer learns
// the empty enclosure from when the session is ingested (keying.training_frames); a
// range that the subject crosses works too when it moves enough within it.
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace ss {

struct PlateOptions {
  // the range of the camera's frames (0-based, as replayed: unreadable ones skipped), >= 0
  int64_t first_frame = 0;
  int64_t last_frame = 29;  // inclusive (>= first_frame)
  // frames taken (1..1000), spread evenly over the range (all of them when fewer)
  int samples = 30;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

struct SessionPlate {
  cv::Mat bgr;  // CV_8UC3, the camera's size
  int frames_used = 0;
  int64_t first_frame = 0, last_frame = 0;  // the frames used, first and last
  int64_t first_timestamp_ns = 0, last_timestamp_ns = 0;
};

// InputError naming the session and the field for an unknown camera, a bad range or a
// camera without one readable frame in the range; a range past the recording's end uses
// the frames there are. Unreadable frames are skipped (and not counted).
SessionPlate ReadSessionPlate(const std::string& session_dir, const std::string& camera,
                              const PlateOptions& options = {});

}  // namespace ss
