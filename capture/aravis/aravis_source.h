#pragma once
// A GigE Vision / USB3 Vision camera through Aravis as a FrameSource. Opens
// the camera by device id ("Aravis-Fake-GV01", a serial number) or by IP
// address, configures it (pixel format, region, exposure, gain, frame rate,
// packet size and resend), and streams into a ring of Aravis buffers that are
// lent to the Frames without a copy and returned when the last copy dies.
//
// Frame::sequence is the camera's block id, widened past the 16-bit wrap of
// GigE Vision 1.x; Frame::timestamp_ns is the device timestamp. Incomplete
// frames (missing packets after resends, timeouts) are never delivered: they
// and the sequence gaps count in stats().frames_dropped, and the stream's own
// counters are in stream_stats().
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera_config.h"
#include "capture/frame_source.h"

namespace ss {

struct AravisOptions {
  std::string camera;    // device id, serial number or IP address ("" = the first camera found)
  std::string name;      // SourceCamera::name ("" = the device id)
  int camera_index = 0;  // Frame::camera of every frame (>= 0)
  // unset = keep the camera's; else a GigE/USB3 Vision format (mono8, bayer_*8, rgb8, bgr8, yuyv)
  std::optional<PixelFormat> pixel_format;
  int width = 0;   // region width, px; 0 = keep the camera's (with height: both or neither)
  int height = 0;  // region height, px; 0 = keep the camera's
  // exposure time, microseconds; > 0: set it and turn auto exposure off (a keyer needs it
  // fixed), 0 = leave it
  double exposure_us = 0.0;
  double gain = -1.0;  // gain, dB; >= 0: set it and turn auto gain off, < 0 = leave it
  double fps = 0.0;    // frames per second; > 0: set the acquisition frame rate, 0 = leave it
  // device: leave it; once: auto once, then locked
  WhiteBalanceMode white_balance = WhiteBalanceMode::kDevice;
  // manual: BalanceRatio of red and of blue (green = 1), unitless (> 0)
  double red_ratio = 1.0, blue_ratio = 1.0;
  bool packet_resend = true;  // ask the camera to resend lost GVSP packets
  int packet_size = 0;        // GVSP packet bytes; 0 = negotiate the largest that passes
  int buffers = 16;           // stream buffers (>= 2; frames held by consumers count against them)
  // no frame for this long, milliseconds (>= 1), counts as one error (the stream goes on)
  int frame_timeout_ms = 2000;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// A station camera's keys of `source: aravis` (CameraConfig::backend).
struct AravisCameraKeys {
  std::string camera_id;      // the device id; or
  std::string address;        // a GigE Vision camera's IP address
  bool packet_resend = true;  // AravisOptions's
  int packet_size = 0;        // AravisOptions's
  bool operator==(const AravisCameraKeys&) const = default;
};

// The stream's own counters (Aravis's ArvStream infos).
struct AravisStreamStats {
  uint64_t completed = 0;       // buffers filled completely
  uint64_t failures = 0;        // buffers given up (missing packets, size mismatch, aborted)
  uint64_t underruns = 0;       // frames lost because no empty buffer was queued
  uint64_t timeouts = 0;        // buffers that timed out waiting for packets
  uint64_t missing_frames = 0;  // frames never seen (block id jumps)
  uint64_t received_packets = 0;
  uint64_t missing_packets = 0;
  uint64_t resend_requests = 0;
  uint64_t resent_packets = 0;
  uint64_t transferred_bytes = 0;
  uint64_t sequence_gaps = 0;  // frames the delivered block ids skip (seen by this backend)
};

// One camera Aravis can see.
struct AravisDeviceInfo {
  std::string id;       // what AravisOptions::camera accepts
  std::string address;  // IP address (GigE) or USB path
  std::string vendor;
  std::string model;
  std::string serial;
  std::string protocol;  // "GigEVision", "USB3Vision", "Fake"
};

// Every camera Aravis discovers now (GigE discovery broadcasts on every interface).
std::vector<AravisDeviceInfo> ListAravisDevices();

class AravisSource : public FrameSource {
 public:
  // Opens and configures the camera and starts acquisition. WorkError naming
  // the camera when it cannot be found or opened, InputError naming the option
  // when the camera refuses a setting or the pixel format is not supported.
  explicit AravisSource(AravisOptions options);
  ~AravisSource() override;
  AravisSource(const AravisSource&) = delete;
  AravisSource& operator=(const AravisSource&) = delete;

  const std::vector<SourceCamera>& cameras() const override;
  std::optional<Frame> Next() override;
  void Stop() override;
  SourceStats stats() const override;

  AravisStreamStats stream_stats() const;
  int packet_size() const;  // the GVSP packet size in use (0 for USB3)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
