// The station closes a camera's source on a detached thread (a dead device can take seconds
// to close; see CameraRunner::CloseSource). A test process must not end while one still runs:
// past main(), OpenCV's thread-local storage is gone and the close aborts the process. The
// daemon waits for them before exiting (cmd_daemon.cc); the station tests wait here.
#include <gtest/gtest.h>

#include "station/camera_runner.h"

namespace {

class WaitForCameraClosesAtExit : public ::testing::Environment {
 public:
  void TearDown() override {
    EXPECT_TRUE(ss::WaitForCameraCloses(30.0)) << "a camera source is still closing";
  }
};

[[maybe_unused]] ::testing::Environment* const kWaitForCloses =
    ::testing::AddGlobalTestEnvironment(new WaitForCameraClosesAtExit);

}  // namespace
