#include "capture/replay/session_plate.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/frame.h"
#include "core/image_median.h"
#include "core/option_checks.h"

namespace ss {

bool PlateOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(first_frame, AtLeast(0), "first_frame", "at least 0");
  check(last_frame >= first_frame, "last_frame",
        std::to_string(last_frame) + " is before the first frame " + std::to_string(first_frame));
  // Each sample is a full frame held in memory for the median.
  check.Within(samples, Between(1, 1000), "samples", "1..1000 frames");
  return check.ok();
}

SessionPlate ReadSessionPlate(const std::string& session_dir, const std::string& camera,
                              const PlateOptions& o) {
  if (std::string why; !o.IsValid(&why)) throw InputError("plate options", why);
  ReplayOptions replay;
  replay.camera = camera;
  ReplaySource source(session_dir, replay);  // InputError naming the session or the camera
  // Frames wanted: `samples` indices spread evenly over [first, last] (all when fewer).
  const int64_t span = o.last_frame - o.first_frame + 1;
  std::vector<int64_t> wanted;
  if (span <= o.samples) {
    for (int64_t f = o.first_frame; f <= o.last_frame; ++f) wanted.push_back(f);
  } else {
    for (int k = 0; k < o.samples; ++k) {
      wanted.push_back(o.first_frame + static_cast<int64_t>(std::floor(
                                           (k + 0.5) * static_cast<double>(span) / o.samples)));
    }
  }
  SessionPlate plate;
  std::vector<cv::Mat> frames;
  size_t next = 0;
  int64_t index = -1;
  while (next < wanted.size()) {
    std::optional<Frame> frame = source.Next();
    if (!frame) break;
    ++index;
    if (index != wanted[next]) continue;
    ++next;
    if (frames.empty()) {
      plate.first_frame = index;
      plate.first_timestamp_ns = frame->timestamp_ns;
    }
    plate.last_frame = index;
    plate.last_timestamp_ns = frame->timestamp_ns;
    frames.push_back(ToBgr(*frame));
  }
  source.Stop();
  if (frames.empty()) {
    throw InputError(session_dir, "camera " + camera + " has no readable frame in frames " +
                                      std::to_string(o.first_frame) + ".." +
                                      std::to_string(o.last_frame) + " (it has " +
                                      std::to_string(index + 1) + ")");
  }
  plate.frames_used = static_cast<int>(frames.size());
  plate.bgr = PerPixelMedian(frames, session_dir + " camera " + camera);
  return plate;
}

}  // namespace ss
