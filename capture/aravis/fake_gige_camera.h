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
#include <string>

#include "capture/aravis/fake_gige_options.h"
#include "core/frame.h"

namespace ss {

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
