// Camera backends register themselves; the station opens cameras by the config's `source`.
#include <gtest/gtest.h>

#include "capture/camera_backend.h"
#include "capture/camera_source.h"
#include "core/error.h"

namespace ss {
namespace {

TEST(CameraBackends, TheBuiltInBackendsAreRegisteredByName) {
  std::vector<std::string> names;
  for (const CameraBackend* b : CameraBackends()) names.push_back(b->name);
  EXPECT_NE(std::find(names.begin(), names.end(), "replay"), names.end());
#ifdef SPRITESTATION_HAVE_ARAVIS
  EXPECT_NE(std::find(names.begin(), names.end(), "aravis"), names.end());
#endif
#ifdef SPRITESTATION_HAVE_V4L2
  EXPECT_NE(std::find(names.begin(), names.end(), "v4l2"), names.end());
#endif
  ASSERT_NE(FindCameraBackend("replay"), nullptr);
  EXPECT_FALSE(FindCameraBackend("replay")->list) << "replay has no devices to list";
  EXPECT_EQ(FindCameraBackend("gopro"), nullptr);
}

TEST(CameraBackends, AnUnknownSourceIsRefusedByFieldWithWhatIsBuiltIn) {
  CameraConfig camera;
  camera.name = "cam3";
  camera.source = "gopro";
  try {
    OpenCameraSource(camera, 0);
    FAIL() << "opened a camera of an unknown backend";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cameras.cam3.source"), std::string::npos) << what;
    EXPECT_NE(what.find("replay"), std::string::npos) << what;
  }
}

TEST(CameraBackends, ANewBackendIsFoundOnceAndOnlyOnce) {
  CameraBackend test{"test-pattern", "a backend of this test",
                     [](const CameraConfig&, int) { return std::unique_ptr<FrameSource>(); },
                     [] {
                       return std::vector<FoundCamera>{{"test-pattern", "tp0", "", "", "", ""}};
                     }};
  RegisterCameraBackend(test);
  const CameraBackend* found = FindCameraBackend("test-pattern");
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found->list().at(0).id, "tp0");
  EXPECT_THROW(RegisterCameraBackend(test), WorkError);
}

TEST(CameraBackends, LiveOptionsComeFromTheConfig) {
  struct Options {
    std::string name;
    int camera_index = 0;
    std::optional<PixelFormat> pixel_format;
    int width = 0, height = 0;
    double fps = 0, exposure_us = 0;
    int frame_timeout_ms = 0;
  } options;
  CameraConfig camera;
  camera.name = "cam1";
  camera.pixel_format = "yuyv";
  camera.width = 1280;
  camera.exposure_us = 4000;
  SetLiveOptions(camera, 2, options);
  EXPECT_EQ(options.camera_index, 2);
  EXPECT_EQ(options.pixel_format, PixelFormat::kYUYV);
  EXPECT_EQ(options.width, 1280);
  EXPECT_DOUBLE_EQ(options.exposure_us, 4000);
  camera.pixel_format = "yuv9000";
  EXPECT_THROW(SetLiveOptions(camera, 2, options), InputError);
}

}  // namespace
}  // namespace ss
