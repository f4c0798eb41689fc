// The wizard's capture loop (calib/wizard_run.h) without a camera: a scripted FrameSource
// delivers a few grey frames, then ends its stream, goes silent or throws.
#include "calib/wizard_run.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "calib/board.h"
#include "core/error.h"

namespace ss::calib {
namespace {

constexpr int kWidth = 160, kHeight = 120;

// `frames` grey frames, then what `after` says: the end of the stream, silence (Next() blocks
// until Stop(), as a camera that stopped delivering does), or an unrecoverable error.
class ScriptedSource : public FrameSource {
 public:
  enum class After { kEnd, kSilence, kThrow };
  ScriptedSource(int frames, After after)
      : frames_(frames),
        after_(after),
        cameras_{{"cam0", kWidth, kHeight, PixelFormat::kBGR8, 30, ""}} {}
  const std::vector<SourceCamera>& cameras() const override { return cameras_; }
  std::optional<Frame> Next() override {
    if (stopped_) return std::nullopt;
    if (frames_ < 0 || next_ < static_cast<uint64_t>(frames_)) {
      Frame f = Frame::Owned(PixelFormat::kBGR8, kWidth, kHeight,
                             std::vector<uint8_t>(kWidth * kHeight * 3, 128));
      f.sequence = next_++;
      return f;
    }
    if (after_ == After::kThrow) throw WorkError("cam0", "unplugged");
    while (after_ == After::kSilence && !stopped_)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    return std::nullopt;
  }
  void Stop() override {
    stopped_ = true;
    ++stops;
  }
  SourceStats stats() const override { return {}; }

  std::atomic<int> stops{0};

 private:
  int frames_;  // < 0: no end
  After after_;
  std::vector<SourceCamera> cameras_;
  uint64_t next_ = 0;
  std::atomic<bool> stopped_{false};
};

CalibrationWizard GreyWizard() {
  WizardOptions o;
  o.board = ParseBoardSpec("chessboard:10x7:0.03");
  o.detect.exhaustive = false;
  return CalibrationWizard("cam0", kWidth, kHeight, o);
}

TEST(WizardRun, StopsAtTheFrameBudget) {
  ScriptedSource source(-1, ScriptedSource::After::kEnd);
  CalibrationWizard wizard = GreyWizard();
  WizardRunOptions options;
  options.max_frames = 5;
  int after = 0;
  const WizardRunResult r = RunWizardOnSource(source, wizard, options, [&] { ++after; });
  EXPECT_EQ(r.frames, 5);
  EXPECT_EQ(after, 5);
  EXPECT_FALSE(r.silent);
  EXPECT_GE(source.stops.load(), 1);  // the source is stopped on the way out
  EXPECT_FALSE(wizard.done());        // Finish() is the caller's
  EXPECT_FALSE(wizard.board_seen());
}

TEST(WizardRun, EndsWithTheStream) {
  ScriptedSource source(4, ScriptedSource::After::kEnd);
  CalibrationWizard wizard = GreyWizard();
  const WizardRunResult r = RunWizardOnSource(source, wizard, WizardRunOptions{});
  EXPECT_EQ(r.frames, 4);
  EXPECT_FALSE(r.silent);
}

TEST(WizardRun, ASilentCameraEndsTheRunWithWhatWasSeen) {
  ScriptedSource source(3, ScriptedSource::After::kSilence);
  CalibrationWizard wizard = GreyWizard();
  WizardRunOptions options;
  options.silent_s = 0.3;
  const auto start = std::chrono::steady_clock::now();
  const WizardRunResult r = RunWizardOnSource(source, wizard, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.frames, 3);
  EXPECT_TRUE(r.silent);
  EXPECT_GE(seconds, 0.3);
  EXPECT_LT(seconds, 10.0);
}

TEST(WizardRun, AnErrorFromTheSourceReachesTheCallerAndStopsTheWatchdog) {
  ScriptedSource source(2, ScriptedSource::After::kThrow);
  CalibrationWizard wizard = GreyWizard();
  WizardRunOptions options;
  // Were the watchdog left watching, leaving the loop would wait out its 60 s.
  options.silent_s = 60;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(RunWizardOnSource(source, wizard, options), WorkError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

}  // namespace
}  // namespace ss::calib
