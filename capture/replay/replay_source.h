#pragma once
// Replays a recorded session (core/session.h) as a FrameSource: every camera's
// frames merged in device-timestamp order, each with its original timestamp_ns
// and sequence number from the CSV and in the camera's own pixel format (a
// Bayer session replays as Bayer). One thread per camera reads its video a few
// frames ahead into reused buffers; FFV1 and ffvhuff frames are decoded in
// parallel by decoder threads of their own (VideoReader, decode_threads).
//
// Damage does not stop a replay: a corrupt frame, a truncated video or a video
// that cannot be opened is logged as [capture.replay] naming the file and the
// frame, counted in stats(), and the readable rest is delivered. A bad
// session.json or a malformed CSV is bad input: the constructor throws InputError.
// A camera model that is missing or unreadable is reported the same way as a
// damaged video (its camera replays without a model_path).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_config.h"
#include "capture/frame_source.h"
#include "core/session.h"

namespace ss {

struct ReplayOptions {
  bool realtime = false;  // keep the original inter-frame timing (else as fast as possible)
  int loops = 1;          // passes over the session (>= 0); 0 = until Stop()
  int frames_ahead = 4;   // decoded frames each camera may hold ready (>= 1)
  // decoder threads per camera (>= 0): 0 = one decoder thread per core, 1 = one decoder
  // (VideoReader)
  int decode_threads = 0;
  std::string camera;  // replay only this camera of the session ("" = every camera); it is then
                       // Frame::camera 0
  // Later passes shift timestamp_ns by the session's span (plus one frame) and
  // sequence by the camera's sequence span, so time never runs backwards.
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// A station camera's keys of `source: replay` (CameraConfig::backend): a recorded session's camera
// in place of a device, in test mode.
struct ReplayCameraKeys {
  std::string session;         // the session folder (absolute)
  std::string session_camera;  // the camera within the session; "" = the station camera's name
  bool loop = false;           // start over at the end
  bool realtime = true;        // paced by the device timestamps
  bool operator==(const ReplayCameraKeys&) const = default;
};

// A station camera `name` of source replay with those keys (capture/replay/replay_backend.cc).
CameraConfig ReplayCameraConfig(std::string name, ReplayCameraKeys keys);

// What one camera's replay came to so far.
struct ReplayCameraStats {
  std::string name;
  uint64_t frames_in_csv = 0;  // rows per pass
  uint64_t frames_delivered = 0;
  uint64_t frames_unreadable = 0;   // rows whose frame was corrupt or missing from the video
  uint64_t frames_without_row = 0;  // video frames the CSV does not list (recording interrupted)
  uint64_t recorded_gaps = 0;  // frames the CSV's sequence numbers skip (lost before recording)
  // sum of the CSV's drops_before (lost at the device or the recorder)
  uint64_t recorded_drops = 0;
  uint64_t errors = 0;  // reported problems (one per corrupt frame / truncation / unopenable file)
  std::vector<std::string> problems;  // the first few messages, each naming the file and the frame
};

class ReplaySource : public FrameSource {
 public:
  // Reads DIR/session.json and every camera's CSV (InputError naming the file
  // on any problem) and starts decoding.
  explicit ReplaySource(const std::string& dir, const ReplayOptions& options = {});
  ~ReplaySource() override;
  ReplaySource(const ReplaySource&) = delete;
  ReplaySource& operator=(const ReplaySource&) = delete;

  const std::vector<SourceCamera>& cameras() const override;
  std::optional<Frame> Next() override;
  void Stop() override;
  SourceStats stats() const override;
  bool WaitsForReader() const override;

  const SessionInfo& session() const;
  std::vector<ReplayCameraStats> camera_stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
