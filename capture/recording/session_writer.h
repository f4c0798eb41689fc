#pragma once
// Writes a recorded session (core/session.h) through FFmpeg's libraries: per
// camera a Matroska video (FFV1 lossless by default) and a per-frame CSV, the
// camera models, session.json. Built to survive `kill -9`: session.json is on
// disk from the first camera on, CSV rows are flushed per frame and the video
// is flushed at least once a second, so all but the last second stays readable.
#include <memory>
#include <string>

#include "capture/frame_source.h"
#include "core/camera_model.h"
#include "core/frame.h"
#include "core/session.h"

namespace ss {

struct RecordingOptions {
  std::string codec = "ffv1";   // "ffv1" (lossless), "mjpeg", "h264"
  bool synthetic = false;       // marks session.json; truth/ is written by the caller
};

class SessionWriter {
 public:
  // Creates DIR (which must not exist or be empty); WorkError naming DIR otherwise.
  SessionWriter(const std::string& dir, const std::string& name, RecordingOptions options = {});
  ~SessionWriter();  // Close()s; never throws
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  // Adds a camera and returns its index (the Frame::camera to write with).
  // `model` may be null for an uncalibrated camera.
  int AddCamera(const SourceCamera& camera, const CameraModel* model);
  // Appends one frame (its pixel format and size must match the camera's) and
  // its CSV row. `drops_before` counts frames lost just before this one.
  void Write(const Frame& frame, uint64_t drops_before = 0);
  // Finalizes every file. Idempotent.
  void Close();

  const std::string& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
