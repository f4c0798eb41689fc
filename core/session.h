#pragma once
// The recorded-session format (version 1), documented in docs/formats.md:
//   SESSION/session.json               what the session holds (SessionInfo)
//   SESSION/<camera>.mkv               Matroska video, FFV1 lossless by default
//   SESSION/<camera>.frames.csv        one row per frame: index,timestamp_ns,sequence,drops_before
//   SESSION/<camera>.cameramodel       the camera's mrcal model (optional)
//   SESSION/truth/                     ground truth, synthetic sessions only
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "core/frame.h"

namespace ss {

inline constexpr int kSessionFormatVersion = 1;

struct SessionCamera {
  std::string name;        // "cam0"; also the stem of its files
  std::string video;       // file name relative to the session, e.g. "cam0.mkv"
  std::string frames_csv;  // e.g. "cam0.frames.csv"
  std::string model;       // e.g. "cam0.cameramodel"; empty when uncalibrated
  int width = 0;
  int height = 0;
  // as the camera delivered it, and as replay returns it
  PixelFormat pixel_format = PixelFormat::kBGR8;
  std::string codec = "ffv1";  // "ffv1" | "mjpeg" | "h264"
  double fps = 30.0;
  // Frames recorded, written when the recording was closed; -1 while it runs or
  // after it was killed (then the CSV is all there is).
  int64_t frames = -1;
};

struct SessionInfo {
  int format_version = kSessionFormatVersion;
  std::string name;
  std::string created;     // ISO 8601, UTC
  bool synthetic = false;  // true when truth/ is present
  std::vector<SessionCamera> cameras;
};

// Reads DIR/session.json. InputError naming the file and the field on any problem.
SessionInfo ReadSessionInfo(const std::string& dir);
// Writes DIR/session.json atomically (temp file + rename).
void WriteSessionInfo(const std::string& dir, const SessionInfo& info);

struct FrameRecord {
  int64_t index = 0;          // position in the video file
  int64_t timestamp_ns = 0;   // device timestamp
  uint64_t sequence = 0;      // device sequence number
  uint64_t drops_before = 0;  // frames the device or the recorder lost just before this one
};

// Reads a per-frame CSV. A malformed row throws InputError "PATH:LINE: reason".
std::vector<FrameRecord> ReadFrameCsv(const std::string& path);

// Appends rows to a per-frame CSV, flushed row by row so a killed recorder keeps them.
class FrameCsvWriter {
 public:
  explicit FrameCsvWriter(
      const std::string& path);  // WorkError naming the file when it cannot open
  void Append(const FrameRecord& record);
  void Close();

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace ss
