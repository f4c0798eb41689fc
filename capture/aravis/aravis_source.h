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
  int camera_index = 0;  // Frame::camera of every frame
  std::optional<PixelFormat> pixel_format;  // unset = keep the camera's
  int width = 0;                            // region size; 0 = keep the camera's
  int height = 0;
  double exposure_us = 0.0;  // > 0: set it and turn auto exposure off (a keyer needs it fixed)
  double gain = -1.0;        // >= 0: set it and turn auto gain off
  double fps = 0.0;          // > 0: set the acquisition frame rate
  // device: leave it; once: auto once, then locked
  WhiteBalanceMode white_balance = WhiteBalanceMode::kDevice;
  double red_ratio = 1.0, blue_ratio = 1.0;  // manual: BalanceRatio of red and of blue (green = 1)
  bool packet_resend = true;                 // ask the camera to resend lost GVSP packets
  int packet_size = 0;          // GVSP packet bytes; 0 = negotiate the largest that passes
  int buffers = 16;             // stream buffers (frames held by consumers count against them)
  int frame_timeout_ms = 2000;  // no frame for this long counts as one error (the stream goes on)
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
