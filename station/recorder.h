#pragma once
// The station's raw recording (storage.recording: all | usable) in the
// recorded-session format, so a studio session can be replayed later. Every
// camera has its own queue and encoding thread: encoding never slows capture
// or the pipeline, and a full queue drops the frame (counted, and noted in the
// CSV's drops_before of the next frame written).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/recording/session_writer.h"
#include "core/camera_model.h"
#include "core/frame.h"

namespace ss {

struct RecorderStats {
  std::string dir;
  uint64_t frames_written = 0;
  uint64_t frames_dropped = 0;  // the recording queue was full
  std::string error;            // the first write error (recording stops for that camera)
  std::string stopped;          // why recording stopped for every camera (the disk guard's word)
};

class StationRecorder {
 public:
  // Creates the session folder DIR (WorkError naming it when it exists or cannot be made).
  // `refusal`, asked by each camera's thread before it writes a frame, says why nothing more may
  // be written ("" while it may): from then on no camera writes, and Close finalizes the files.
  StationRecorder(const std::string& dir, const std::string& name, const RecordingOptions& options,
                  bool usable_only, int cameras, std::function<std::string()> refusal = {},
                  int queue_frames = 16);
  ~StationRecorder();  // Close()
  StationRecorder(const StationRecorder&) = delete;
  StationRecorder& operator=(const StationRecorder&) = delete;

  // A frame of station camera `camera` (described by `source`, with its model or null).
  // Kept when the recording takes every frame, or this one gave a usable sprite.
  void Offer(int camera, const SourceCamera& source, const CameraModel* model, const Frame& frame,
             uint64_t drops_before, bool usable);
  // Writes what is queued and finalizes the files. Idempotent.
  void Close();
  RecorderStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
