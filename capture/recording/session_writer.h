#pragma once
// Writes a recorded session (core/session.h) through FFmpeg's libraries: per
// camera a Matroska video (FFV1 lossless by default) and a per-frame CSV, the
// camera models, session.json. Built to survive `kill -9`: session.json is on
// disk from the start, and every flush_interval_ms (from the writing thread and
// from a background flusher when frames stop coming) the video's Matroska
// cluster is closed and handed to the OS, then the CSV rows of those frames are
// written. So all but the last ~0.4 s stays readable, and the CSV never lists a
// frame the video lost (the video may hold a few frames more than the CSV).
#include <memory>
#include <string>

#include "capture/frame_source.h"
#include "core/camera_model.h"
#include "core/frame.h"
#include "core/session.h"

namespace ss {

struct RecordingOptions {
  // "ffv1" (lossless), "mjpeg", "h264" (core/recording_codecs.h); an MJPEG camera is always
  // stored as mjpeg
  std::string codec = "ffv1";
  bool synthetic = false;  // marks session.json; truth/ is written by the caller
  // longest time a written frame waits before it is on disk, milliseconds (>= 0; 0: every frame)
  int flush_interval_ms = 250;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

class SessionWriter {
 public:
  // Creates DIR (which must not exist or be empty) and writes session.json;
  // WorkError naming DIR otherwise, InputError for a bad option.
  SessionWriter(const std::string& dir, const std::string& name,
                const RecordingOptions& options = {});
  ~SessionWriter();  // Close()s; never throws
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  // Adds a camera and returns its index (the Frame::camera to write with).
  // `model` may be null for an uncalibrated camera.
  int AddCamera(const SourceCamera& camera, const CameraModel* model);
  // Appends one frame (its pixel format and size must match the camera's;
  // InputError otherwise) and its CSV row. `drops_before` counts frames lost
  // just before this one. Cameras may be written from different threads.
  void Write(const Frame& frame, uint64_t drops_before = 0);
  // Finalizes every file. Idempotent.
  void Close();

  const std::string& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
