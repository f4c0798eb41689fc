#pragma once
// An emulated GigE Vision camera serving one camera of a recorded session over
// the real protocol (GVCP control on UDP 3956, GVSP streaming) through Aravis's
// fake camera: every frame the fake camera sends is filled, by its fill-pattern
// callback, with the next frame of the session, and carries that frame's device
// timestamp. So discovery by address, register access, packet resend and the
// stream counters all run as with a real camera. `spritestation fakecam` and
// the tests use it on loopback.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/frame.h"

namespace ss {

struct FakeGigEOptions {
  std::string address = "127.0.0.1";  // IPv4 address or interface name to serve on
  // the camera's serial number (its device id is "Aravis-Fake-SERIAL")
  std::string serial = "SS0001";
  std::string camera;                       // which session camera ("" = the first)
  std::optional<PixelFormat> pixel_format;  // streamed format: mono8, bayer_*8, rgb8; unset = the
                                            // session's when GigE carries it, else rgb8
  double fps = 0.0;                         // frame rate; 0 = the session camera's
  int loops = 0;                            // passes over the session; 0 = forever
  // share of GVSP packets dropped on purpose (0..1), to exercise resend
  double lost_packet_ratio = 0.0;
};

class FakeGigECamera {
 public:
  // Reads the session (InputError naming the file or option) and starts serving;
  // WorkError naming the address when it cannot bind there (port 3956 taken, no such interface).
  FakeGigECamera(const std::string& session_dir, FakeGigEOptions options);
  ~FakeGigECamera();
  FakeGigECamera(const FakeGigECamera&) = delete;
  FakeGigECamera& operator=(const FakeGigECamera&) = delete;

  const std::string& device_id() const;  // what AravisOptions::camera accepts besides the address
  PixelFormat pixel_format() const;      // the format streamed by default
  int width() const;
  int height() const;
  double fps() const;
  uint64_t frames_served() const;  // frames handed to the GVSP sender
  // The camera's exposure (us) and raw gain registers, as the client last set them over GVCP.
  uint32_t exposure_us() const;
  uint32_t gain() const;
  // True once a finite replay (loops > 0) has served its last frame; later frames repeat it.
  bool finished() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Converts a frame into `target` (mono8, bayer_*8, rgb8, bgr8) of the same size, into `out`.
// Same format: the bytes are copied. InputError for a target GigE cannot carry.
void ConvertForGigE(const Frame& frame, PixelFormat target, std::vector<uint8_t>& out);

}  // namespace ss
