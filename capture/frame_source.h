#pragma once
// The one interface every camera backend implements (v4l2, aravis, libcamera,
// replay). A source may carry several cameras (a replayed session does); live
// backends carry one. Next() is called from one capture thread per source.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/frame.h"

namespace ss {

struct SourceCamera {
  std::string name;  // "cam0", a serial number, "/dev/video0"
  int width = 0;
  int height = 0;
  PixelFormat format = PixelFormat::kBGR8;
  double fps = 0.0;
  std::string model_path;  // its .cameramodel, when known
};

struct SourceStats {
  uint64_t frames_delivered = 0;
  // lost at the device or in the file (sequence gaps, unreadable frames)
  uint64_t frames_dropped = 0;
  uint64_t errors = 0;     // recoverable errors (a corrupt frame, a timeout)
  std::string last_error;  // names the file/device and the frame
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual const std::vector<SourceCamera>& cameras() const = 0;
  // Blocks until the next frame; Frame::camera indexes cameras(). std::nullopt
  // at the end of the stream or after Stop(). Recoverable errors are counted in
  // stats() and skipped; unrecoverable ones throw WorkError naming the source.
  virtual std::optional<Frame> Next() = 0;
  // Makes a blocked or future Next() return std::nullopt; callable from any thread.
  virtual void Stop() = 0;
  virtual SourceStats stats() const = 0;
  // True for a source that loses nothing by waiting for its reader (a recording read as fast
  // as it runs): the station then holds it back instead of dropping frames, and learns the
  // enclosure before reading on, so it stores what `ingest` stores. Cameras never wait.
  virtual bool WaitsForReader() const { return false; }
};

}  // namespace ss
