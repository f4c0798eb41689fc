// The libcamera backend without a camera: the camera manager starts and lists
// what it finds, an unknown id is refused naming it and the ids found, formats
// map to libcamera's (RGB888 is B,G,R in memory), a station config maps to
// the controls, and only the controls a camera lists are planned, the rest
// named as ignored. Streaming from a real driver is tests/libcamera/uvc_test.cc; the
// `spritestation cameras` command is tested in tests/e2e/cameras_cli_test.cc.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "capture/camera_source.h"
#include "capture/libcamera/libcamera_config.h"
#include "capture/libcamera/libcamera_source.h"
#include "config/station_config.h"
#include "core/error.h"

namespace ss {
namespace {

bool Contains(const std::vector<std::string>& list, const std::string& prefix) {
  for (const auto& s : list) {
    if (s.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

TEST(Libcamera, ManagerStartsAndListsCameras) {
  const auto cameras = ListLibcameraCameras();
  for (const auto& c : cameras) EXPECT_FALSE(c.id.empty());
  // The shared manager stops when the last user lets go and starts again.
  EXPECT_EQ(ListLibcameraCameras().size(), cameras.size());
}

TEST(Libcamera, UnknownIdNamesItAndTheIdsFound) {
  const auto cameras = ListLibcameraCameras();
  LibcameraOptions o;
  o.camera_id = "no-such-camera-42";
  try {
    LibcameraSource source(o);
    FAIL() << "opened a camera that does not exist";
  } catch (const WorkError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-such-camera-42"), std::string::npos) << what;
    if (cameras.empty()) {
      EXPECT_NE(what.find("no cameras found"), std::string::npos) << what;
    }
    for (const auto& c : cameras) EXPECT_NE(what.find(c.id), std::string::npos) << what;
  }
}

TEST(Libcamera, FormatsLibcameraCannotCarryAreRefusedBeforeOpening) {
  LibcameraOptions o;
  o.camera_id = "no-such-camera";
  o.pixel_format = PixelFormat::kBayerRG8;
  try {
    LibcameraSource source(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel_format"), std::string::npos) << e.what();
  }
  o.pixel_format = PixelFormat::kYUYV;
  o.buffers = 1;
  EXPECT_THROW(LibcameraSource{o}, InputError);
}

TEST(Libcamera, OptionsOutOfRangeAreRefusedNamingTheField) {
  std::string why = "stale";
  EXPECT_TRUE(LibcameraOptions{}.IsValid(&why)) << why;
  EXPECT_EQ(why, "");
  LibcameraOptions o;
  o.height = 480;  // without a width
  o.awb_settle_frames = 0;
  o.red_gain = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why.rfind("width/height: ", 0), 0u) << why;
  EXPECT_NE(why.find("\nred_gain: "), std::string::npos) << why;
  EXPECT_NE(why.find("\nawb_settle_frames: "), std::string::npos) << why;
  o = {};
  o.camera_id = "no-such-camera";
  o.frame_timeout_ms = 0;
  try {
    LibcameraSource source(o);
    FAIL() << "a frame timeout of 0 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "libcamera options: frame_timeout_ms: expected at least 1 ms, got 0");
  }
}

TEST(Libcamera, FormatNamesFollowLibcamerasDrmConvention) {
  EXPECT_EQ(LibcameraFormatName(PixelFormat::kYUYV), "YUYV");
  EXPECT_EQ(LibcameraFormatName(PixelFormat::kNV12), "NV12");
  EXPECT_EQ(LibcameraFormatName(PixelFormat::kMJPEG), "MJPEG");
  EXPECT_EQ(LibcameraFormatName(PixelFormat::kBGR8), "RGB888");  // B, G, R in memory
  EXPECT_EQ(LibcameraFormatName(PixelFormat::kRGB8), "BGR888");
  EXPECT_FALSE(LibcameraFormatName(PixelFormat::kMono8));
  EXPECT_EQ(FromLibcameraFormatName("RGB888"), PixelFormat::kBGR8);
  EXPECT_EQ(FromLibcameraFormatName("MJPEG"), PixelFormat::kMJPEG);
  EXPECT_FALSE(FromLibcameraFormatName("SRGGB10"));
}

// Every control a typical libcamera sensor pipeline lists, with ranges.
std::map<std::string, LibcameraControlRange> FullCamera() {
  return {{"AeEnable", {0, 1}},          {"ExposureTime", {10, 66000}},
          {"AnalogueGain", {1.0, 16.0}}, {"AwbEnable", {0, 1}},
          {"ColourGains", {0.0, 32.0}},  {"FrameDurationLimits", {16666, 200000}}};
}

TEST(Libcamera, ControlsPlannedFromTheOptions) {
  LibcameraOptions o;
  o.exposure_us = 8000.4;
  o.analogue_gain = 2.0;
  o.white_balance = LibcameraWhiteBalance::kManual;
  o.red_gain = 1.8;
  o.blue_gain = 1.4;
  o.fps = 30;
  const LibcameraControlPlan plan = PlanLibcameraControls(o, FullCamera());
  EXPECT_TRUE(plan.ignored.empty());
  EXPECT_EQ(plan.ae_enable, false);
  EXPECT_EQ(plan.exposure_time_us, 8000);
  ASSERT_TRUE(plan.analogue_gain);
  EXPECT_FLOAT_EQ(*plan.analogue_gain, 2.0f);
  EXPECT_EQ(plan.awb_enable, false);
  ASSERT_TRUE(plan.colour_gains);
  EXPECT_FLOAT_EQ((*plan.colour_gains)[0], 1.8f);
  EXPECT_FLOAT_EQ((*plan.colour_gains)[1], 1.4f);
  ASSERT_TRUE(plan.frame_duration_limits_us);
  EXPECT_EQ((*plan.frame_duration_limits_us)[0], 33333);
  EXPECT_EQ((*plan.frame_duration_limits_us)[1], 33333);
  EXPECT_FALSE(plan.lock_awb_after_settling);
}

TEST(Libcamera, NothingAskedLocksExposureWhereItIs) {
  const LibcameraControlPlan plan = PlanLibcameraControls(LibcameraOptions{}, FullCamera());
  EXPECT_EQ(plan.ae_enable, false);  // the config's "unset = the device's current value, locked"
  EXPECT_FALSE(plan.exposure_time_us || plan.analogue_gain || plan.awb_enable ||
               plan.colour_gains || plan.frame_duration_limits_us);
  EXPECT_TRUE(plan.ignored.empty());
  // A camera without automatic exposure: nothing to lock, nothing asked, nothing ignored.
  const LibcameraControlPlan fixed =
      PlanLibcameraControls(LibcameraOptions{}, {{"Brightness", {-1, 1}}});
  EXPECT_FALSE(fixed.ae_enable);
  EXPECT_TRUE(fixed.ignored.empty());
}

TEST(Libcamera, ControlsTheCameraDoesNotListAreNamedAsIgnored) {
  // What libcamera 0.0.3's UVC pipeline lists for a webcam with manual exposure but no gain.
  const std::map<std::string, LibcameraControlRange> uvc = {
      {"AeEnable", {0, 1}}, {"ExposureTime", {100, 500000}}, {"Brightness", {-1, 1}}};
  LibcameraOptions o;
  o.exposure_us = 10000;
  o.analogue_gain = 4.0;
  o.white_balance = LibcameraWhiteBalance::kManual;
  o.fps = 25;
  const LibcameraControlPlan plan = PlanLibcameraControls(o, uvc);
  EXPECT_EQ(plan.ae_enable, false);
  EXPECT_EQ(plan.exposure_time_us, 10000);
  EXPECT_FALSE(plan.analogue_gain);
  EXPECT_FALSE(plan.awb_enable);
  EXPECT_FALSE(plan.colour_gains);
  EXPECT_FALSE(plan.frame_duration_limits_us);
  EXPECT_EQ(plan.ignored.size(), 4u);
  EXPECT_TRUE(Contains(plan.ignored, "AnalogueGain (gain)"));
  EXPECT_TRUE(Contains(plan.ignored, "AwbEnable (white_balance)"));
  EXPECT_TRUE(Contains(plan.ignored, "ColourGains (white_balance)"));
  EXPECT_TRUE(Contains(plan.ignored, "FrameDurationLimits (fps)"));
}

TEST(Libcamera, WhiteBalanceOnceLetsAwbSettleThenLocks) {
  LibcameraOptions o;
  o.white_balance = LibcameraWhiteBalance::kOnce;
  const LibcameraControlPlan plan = PlanLibcameraControls(o, FullCamera());
  EXPECT_EQ(plan.awb_enable, true);
  EXPECT_TRUE(plan.lock_awb_after_settling);
  const LibcameraControlPlan none = PlanLibcameraControls(o, {{"AeEnable", {0, 1}}});
  EXPECT_FALSE(none.lock_awb_after_settling);
  EXPECT_TRUE(Contains(none.ignored, "AwbEnable (white_balance)"));
}

TEST(Libcamera, ValuesOutsideAListedRangeAreRefusedNamingTheOption) {
  LibcameraOptions o;
  o.exposure_us = 100000;  // above 66000
  try {
    PlanLibcameraControls(o, FullCamera());
    FAIL();
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("exposure_us:", 0), 0u) << what;
    EXPECT_NE(what.find("10..66000"), std::string::npos) << what;
  }
  o = {};
  o.fps = 120;  // shorter than the 16666 us minimum frame duration
  EXPECT_THROW(PlanLibcameraControls(o, FullCamera()), InputError);
  o = {};
  o.white_balance = LibcameraWhiteBalance::kManual;
  o.red_gain = 40;
  EXPECT_THROW(PlanLibcameraControls(o, FullCamera()), InputError);
}

TEST(Libcamera, StationConfigMapsToTheOptions) {
  const std::string yaml =
      "cameras:\n"
      "  - name: pi\n"
      "    source: libcamera\n"
      "    camera_id: /base/soc/i2c0mux/i2c@1/imx219@10\n"
      "    pixel_format: nv12\n"
      "    width: 1280\n"
      "    height: 720\n"
      "    fps: 30\n"
      "    exposure_us: 5000\n"
      "    gain_db: 6.0206\n"
      "    white_balance: {mode: manual, red_gain: 1.9, blue_gain: 1.5}\n";
  ConfigOptions check;
  check.check_files = false;
  const StationConfig cfg = ParseStationConfig(yaml, "station.yaml", "/studio", nullptr, check);
  ASSERT_EQ(cfg.cameras.size(), 1u);
  const LibcameraOptions o = LibcameraOptionsFromConfig(cfg.cameras[0], 3);
  EXPECT_EQ(o.camera_id, "/base/soc/i2c0mux/i2c@1/imx219@10");
  EXPECT_EQ(o.name, "pi");
  EXPECT_EQ(o.camera_index, 3);
  EXPECT_EQ(o.pixel_format, PixelFormat::kNV12);
  EXPECT_EQ(o.width, 1280);
  EXPECT_EQ(o.height, 720);
  EXPECT_DOUBLE_EQ(o.fps, 30);
  EXPECT_DOUBLE_EQ(o.exposure_us, 5000);
  EXPECT_NEAR(o.analogue_gain, 2.0, 1e-4);  // 6.02 dB is twice the signal
  EXPECT_EQ(o.white_balance, LibcameraWhiteBalance::kManual);
  EXPECT_DOUBLE_EQ(o.red_gain, 1.9);
  EXPECT_DOUBLE_EQ(o.blue_gain, 1.5);

  const LibcameraControlPlan plan = PlanLibcameraControls(o, FullCamera());
  EXPECT_EQ(plan.exposure_time_us, 5000);
  EXPECT_NEAR(*plan.analogue_gain, 2.0f, 1e-4);
  EXPECT_FLOAT_EQ((*plan.colour_gains)[0], 1.9f);
  EXPECT_EQ(plan.ae_enable, false);
  EXPECT_EQ(plan.awb_enable, false);

  CameraConfig once = cfg.cameras[0];
  once.white_balance.mode = WhiteBalanceMode::kOnce;
  EXPECT_EQ(LibcameraOptionsFromConfig(once, 0).white_balance, LibcameraWhiteBalance::kOnce);
  once.white_balance.mode = WhiteBalanceMode::kDevice;
  once.gain_db.reset();
  const LibcameraOptions device = LibcameraOptionsFromConfig(once, 0);
  EXPECT_EQ(device.white_balance, LibcameraWhiteBalance::kDevice);
  EXPECT_EQ(device.analogue_gain, 0.0);  // gain left alone

  CameraConfig kelvin = cfg.cameras[0];
  kelvin.white_balance.temperature_k = 5600;
  try {
    LibcameraOptionsFromConfig(kelvin, 0);
    FAIL() << "a colour temperature was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.pi.white_balance.temperature_k"),
              std::string::npos)
        << e.what();
  }
}

TEST(Libcamera, TheStationOpensLibcameraCamerasByTheirConfig) {
  CameraConfig camera;
  camera.name = "pi";
  camera.source = "libcamera";
  camera.backend.Use<LibcameraCameraKeys>().camera_id = "absent-camera-7";
  try {
    OpenCameraSource(camera, 0);
    FAIL() << "opened an absent camera";
  } catch (const WorkError& e) {  // the station retries a WorkError later
    EXPECT_NE(std::string(e.what()).find("absent-camera-7"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ss
