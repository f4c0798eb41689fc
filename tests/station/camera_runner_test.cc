// A camera runner whose camera goes away mid-way and comes back (a source that
// throws, then a fresh one numbering its frames from 0 again), without a daemon.
#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/camera_model.h"
#include "core/error.h"
#include "station/camera_runner.h"

namespace ss {
namespace {

// Green frames, numbered and timed from 0 at every open; the first opened source throws after
// `fail_after` frames, as an unplugged camera does.
class GreenSource : public FrameSource {
 public:
  GreenSource(int fail_after)
      : fail_after_(fail_after), cameras_{{"cam0", 320, 240, PixelFormat::kBGR8, 30, ""}} {}
  const std::vector<SourceCamera>& cameras() const override { return cameras_; }
  std::optional<Frame> Next() override {
    if (stopped_) return std::nullopt;
    if (fail_after_ >= 0 && next_ >= static_cast<uint64_t>(fail_after_))
      throw WorkError("cam0", "unplugged");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::vector<uint8_t> pixels(320 * 240 * 3);
    for (size_t i = 0; i < pixels.size(); i += 3) {
      pixels[i] = 30;
      pixels[i + 1] = 190;
      pixels[i + 2] = 40;
    }
    Frame f = Frame::Owned(PixelFormat::kBGR8, 320, 240, std::move(pixels));
    f.sequence = next_;
    f.timestamp_ns = static_cast<int64_t>(next_) * 33'333'333 + 1'000'000;
    ++next_;
    return f;
  }
  void Stop() override { stopped_ = true; }
  SourceStats stats() const override { return {}; }

 private:
  int fail_after_;
  std::vector<SourceCamera> cameras_;
  uint64_t next_ = 0;
  std::atomic<bool> stopped_{false};
};

TEST(CameraRunner, AReopenedCameraLearnsFromItsNewStreamOnly) {
  Rigid3 cam_from_ground;  // looking straight down from 1 m
  cam_from_ground.rotation << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam_from_ground.translation = Eigen::Vector3d(0, 0, 1);
  CameraRunnerOptions o;
  o.camera.name = "cam0";
  o.camera.source = "test";
  o.model = CameraModel("LENSMODEL_PINHOLE", {300, 300, 160, 120}, 320, 240, cam_from_ground);
  o.floor = GroundPolygon({{-0.4, -0.3}, {0.4, -0.3}, {0.4, 0.3}, {-0.4, 0.3}});
  o.offline_after_s = 1.0;
  o.backoff_min_s = 0.05;
  std::atomic<int> opens{0};
  // The first stream ends 12 frames into the 30 the keyer learns from.
  o.open_source = [&](const CameraConfig&, int) -> std::unique_ptr<FrameSource> {
    return std::make_unique<GreenSource>(opens++ == 0 ? 12 : -1);
  };
  CameraRunner runner(
      0, o, [](const StationBatch&) {}, nullptr);
  runner.Start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  CameraStatus status = runner.status();
  while (status.learnt_from.frames == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    status = runner.status();
  }
  runner.Stop();
  ASSERT_EQ(status.learnt_from.frames, 30u) << "the keyer never started learning";
  EXPECT_GE(opens.load(), 2);
  EXPECT_GE(status.reopens, 1u);
  // All 30 from the second stream: its numbering, first before last.
  EXPECT_EQ(status.learnt_from.first_sequence, 0);
  EXPECT_EQ(status.learnt_from.last_sequence, 29);
  EXPECT_LT(status.learnt_from.first_timestamp_ns, status.learnt_from.last_timestamp_ns);
}

}  // namespace
}  // namespace ss
