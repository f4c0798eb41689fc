#pragma once
// Test frames with known content and small recorded sessions (some of them damaged), shared by
// the capture tests and the `spritestation replay` tests in tests/e2e.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/recording/session_writer.h"
#include "core/frame.h"

namespace ss::testing {

// Deterministic pixels for (camera, sequence): a gradient plus hash noise, so
// every byte value occurs and neighbouring frames differ. `smooth` drops the
// noise (for the lossy codecs).
inline std::vector<uint8_t> TestPixels(PixelFormat format, int width, int height, int camera,
                                       uint64_t sequence, bool smooth = false) {
  std::vector<uint8_t> bytes(FrameBytes(format, width, height));
  const size_t row = bytes.size() / static_cast<size_t>(height);
  for (size_t i = 0; i < bytes.size(); ++i) {
    const size_t x = i % row;
    const size_t y = i / row;
    uint32_t v =
        static_cast<uint32_t>(x / 2 + y + sequence * 3 + static_cast<uint64_t>(camera) * 50);
    if (!smooth) {
      uint32_t h = static_cast<uint32_t>(i * 2654435761u) ^
                   static_cast<uint32_t>(sequence * 40503u + camera);
      h ^= h >> 13;
      if ((h & 7) == 0) v ^= h >> 5;  // sparse noise: an eighth of the bytes
    }
    bytes[i] = static_cast<uint8_t>(v);
  }
  return bytes;
}

inline Frame TestFrame(PixelFormat format, int width, int height, int camera, uint64_t sequence,
                       int64_t timestamp_ns, bool smooth = false) {
  Frame f = Frame::Owned(format, width, height,
                         TestPixels(format, width, height, camera, sequence, smooth));
  f.camera = camera;
  f.sequence = sequence;
  f.timestamp_ns = timestamp_ns;
  return f;
}

inline SourceCamera TestCamera(const std::string& name, PixelFormat format, int width, int height,
                               double fps = 30.0) {
  SourceCamera c;
  c.name = name;
  c.format = format;
  c.width = width;
  c.height = height;
  c.fps = fps;
  return c;
}

// Records one camera: frames 0..count-1, sequence = frame number + first_sequence,
// timestamps every `period_ns` from `t0_ns`.
inline void RecordTestSession(const std::string& dir, PixelFormat format, int width, int height,
                              int count, const RecordingOptions& options = {},
                              int64_t period_ns = 33'000'000, int64_t t0_ns = 1'000'000'000,
                              bool smooth = false) {
  SessionWriter writer(dir, "test", options);
  const int cam = writer.AddCamera(TestCamera("cam0", format, width, height), nullptr);
  for (int i = 0; i < count; ++i) {
    writer.Write(TestFrame(format, width, height, cam, static_cast<uint64_t>(i),
                           t0_ns + i * period_ns, smooth));
  }
  writer.Close();
}

// A recorded session (camera "cam0", BGR8 160x120, 30 frames) whose video is then cut to 60 %
// of its size; returns the video's path.
inline std::string RecordTruncatedSession(const std::string& dir) {
  RecordTestSession(dir, PixelFormat::kBGR8, 160, 120, 30);
  const std::string video = dir + "/cam0.mkv";
  std::filesystem::resize_file(video, std::filesystem::file_size(video) * 6 / 10);
  return video;
}

// A recorded session (camera "cam0", BGR8 32x32, 5 frames) whose frame CSV is then replaced by
// one with a garbage timestamp on its line 3; returns the CSV's path.
inline std::string RecordSessionWithGarbageCsv(const std::string& dir) {
  RecordTestSession(dir, PixelFormat::kBGR8, 32, 32, 5);
  const std::string csv = dir + "/cam0.frames.csv";
  std::ofstream(csv, std::ios::trunc)
      << "index,timestamp_ns,sequence,drops_before\n0,100,0,0\n1,bogus,1,0\n";
  return csv;
}

}  // namespace ss::testing
