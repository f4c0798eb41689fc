// Each capture component's options: the defaults are valid, a value out of range is refused
// naming its field, and the component refuses it with an InputError before opening anything.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "capture/recording/session_writer.h"
#include "capture/replay/replay_source.h"
#include "capture/replay/session_plate.h"
#include "core/error.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"
#include "tests/support/test_support.h"
#ifdef SPRITESTATION_HAVE_V4L2
#include "capture/v4l2/v4l2_source.h"
#endif
#ifdef SPRITESTATION_HAVE_ARAVIS
#include "capture/aravis/aravis_source.h"
#include "capture/aravis/fake_gige_camera.h"
#endif

namespace ss {
namespace {

using testing::InputErrorOf;
using testing::Names;
using testing::Problems;
using testing::ScratchDir;

TEST(CaptureOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(RecordingOptions{}), "");
  EXPECT_EQ(Problems(ReplayOptions{}), "");
  EXPECT_EQ(Problems(PlateOptions{}), "");
#ifdef SPRITESTATION_HAVE_ARAVIS
  EXPECT_EQ(Problems(AravisOptions{}), "");
  EXPECT_EQ(Problems(FakeGigEOptions{}), "");
#endif
}

TEST(CaptureOptions, Recording) {
  RecordingOptions o;
  o.codec = "vp9";
  o.flush_interval_ms = -1;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "codec")) << why;
  EXPECT_TRUE(Names(why, "flush_interval_ms")) << why;
  ScratchDir dir;
  o = {};
  o.flush_interval_ms = -5;
  const std::string what = InputErrorOf([&] { SessionWriter writer(dir / "s", "s", o); });
  EXPECT_EQ(what, "recording options: flush_interval_ms: expected 0 or more, got -5");
}

TEST(CaptureOptions, Replay) {
  ReplayOptions o;
  o.loops = -1;
  EXPECT_TRUE(Names(Problems(o), "loops"));
  o = {};
  o.frames_ahead = 0;
  o.decode_threads = -2;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "frames_ahead")) << why;
  EXPECT_TRUE(Names(why, "decode_threads")) << why;
  // Refused before the session is read.
  const std::string what = InputErrorOf([&] { ReplaySource source("/no/session", o); });
  EXPECT_EQ(what.rfind("replay options: frames_ahead: ", 0), 0u) << what;
}

TEST(CaptureOptions, Plate) {
  PlateOptions o;
  o.first_frame = 5;
  o.last_frame = 2;
  EXPECT_TRUE(Names(Problems(o), "last_frame"));
  o = {};
  o.first_frame = -1;
  o.samples = 1001;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "first_frame")) << why;
  EXPECT_TRUE(Names(why, "samples")) << why;
  const std::string what = InputErrorOf([&] { ReadSessionPlate("/no/session", "cam0", o); });
  EXPECT_EQ(what.rfind("plate options: first_frame: ", 0), 0u) << what;
}

#ifdef SPRITESTATION_HAVE_ARAVIS
#ifdef SPRITESTATION_HAVE_V4L2
TEST(CaptureOptions, V4l2) {
  EXPECT_EQ(Problems(V4l2Options{}), "");
  V4l2Options o;
  o.height = 480;  // without a width
  o.gain = -2;
  o.fps = std::nan("");
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "width/height")) << why;
  EXPECT_TRUE(Names(why, "gain")) << why;
  EXPECT_TRUE(Names(why, "fps")) << why;
  // Refused before the device is opened (there is none here).
  o = {};
  o.device = "/dev/no-such-video-device";
  o.buffers = 1;
  EXPECT_EQ(InputErrorOf([&] { V4l2Source source(o); }),
            "v4l2 options: buffers: expected 2 or more, got 1");
}
#endif

TEST(CaptureOptions, Aravis) {
  AravisOptions o;
  o.width = 640;  // without a height
  EXPECT_TRUE(Names(Problems(o), "width/height"));
  o = {};
  o.exposure_us = std::nan("");
  o.red_ratio = 0;
  o.frame_timeout_ms = 0;
  o.pixel_format = PixelFormat::kNV12;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "exposure_us")) << why;
  EXPECT_TRUE(Names(why, "red_ratio")) << why;
  EXPECT_TRUE(Names(why, "frame_timeout_ms")) << why;
  EXPECT_TRUE(Names(why, "pixel_format")) << why;
  // Refused before any camera is looked for.
  o = {};
  o.camera = "Aravis-Fake-NOSUCHCAM";
  o.buffers = 1;
  const std::string what = InputErrorOf([&] { AravisSource source(o); });
  EXPECT_EQ(what, "aravis options: buffers: expected 2 or more, got 1");
}

TEST(CaptureOptions, FakeGigE) {
  FakeGigEOptions o;
  o.serial = "";
  o.lost_packet_ratio = 1.5;
  o.loops = -1;
  const std::string why = Problems(o);
  EXPECT_TRUE(Names(why, "serial")) << why;
  EXPECT_TRUE(Names(why, "lost_packet_ratio")) << why;
  EXPECT_TRUE(Names(why, "loops")) << why;
  o = {};
  o.pixel_format = PixelFormat::kYUYV;
  const std::string what = InputErrorOf([&] { FakeGigECamera camera("/no/session", o); });
  EXPECT_EQ(what.rfind("fake camera options: pixel_format: ", 0), 0u) << what;
}
#endif

}  // namespace
}  // namespace ss
