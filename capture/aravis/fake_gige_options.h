#pragma once
// What `spritestation fakecam` and the tests ask of an emulated GigE camera
// (fake_gige_camera.h). Apart from the camera, so that the command binds its flags to these
// fields in a build without Aravis too (where it then says so).
#include <optional>
#include <string>

#include "core/frame.h"

namespace ss {

struct FakeGigEOptions {
  std::string address = "127.0.0.1";  // IPv4 address or interface name to serve on
  // the camera's serial number, 1 to 15 characters (its device id is "Aravis-Fake-SERIAL")
  std::string serial = "SS0001";
  std::string camera;                       // which session camera ("" = the first)
  std::optional<PixelFormat> pixel_format;  // streamed format: mono8, bayer_*8, rgb8; unset = the
                                            // session's when GigE carries it, else rgb8
  double fps = 0.0;  // frame rate, frames per second (>= 0); 0 = the session camera's
  int loops = 0;     // passes over the session (>= 0); 0 = forever
  // share of GVSP packets dropped on purpose (0..1), to exercise resend
  double lost_packet_ratio = 0.0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

}  // namespace ss
