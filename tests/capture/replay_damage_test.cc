// What a killed recorder, a truncated or corrupted video and a garbage CSV do to a replay.
// What `spritestation replay` says of such sessions is tested in
// tests/e2e/replay_cli_damage_test.cc.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "capture/recording/session_writer.h"
#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/posix.h"
#include "core/session.h"
#include "tests/capture/session_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::RecordSessionWithGarbageCsv;
using ss::testing::RecordTestSession;
using ss::testing::RecordTruncatedSession;
using ss::testing::ScratchDir;
using ss::testing::TestCamera;
using ss::testing::TestFrame;
using ss::testing::TestPixels;

int64_t MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1'000'000'000LL + ts.tv_nsec;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string AllProblems(const ReplaySource& source) {
  std::string all;
  for (const auto& c : source.camera_stats()) {
    for (const auto& p : c.problems) all += p + "\n";
  }
  return all;
}

// Every frame delivered must be the one recorded under its sequence number.
void ExpectFramesIntact(const std::vector<Frame>& frames, PixelFormat format, int w, int h) {
  for (const auto& f : frames) {
    const auto expected = TestPixels(format, w, h, f.camera, f.sequence);
    ASSERT_EQ(f.size, expected.size());
    EXPECT_EQ(std::memcmp(f.data, expected.data(), expected.size()), 0)
        << "sequence " << f.sequence;
  }
}

// The recorder process of the KilledRecorder tests: records 320x240 BGR8 at
// ~60 fps with device time = CLOCK_MONOTONIC into $SS_TEST_RECORDER_DIR;
// after $SS_TEST_RECORDER_FRAMES frames it idles (0: it records until killed).
// Started by StartRecorder as a fresh exec of this test binary, so the child
// inherits no threads (OpenCV's pool, sanitizer runtimes) from the parent.
TEST(KilledRecorder, RecorderProcess) {
  const std::optional<std::string> session = Environment("SS_TEST_RECORDER_DIR");
  if (!session) GTEST_SKIP() << "runs only as the child process of the other KilledRecorder tests";
  const int stop_after = std::stoi(Environment("SS_TEST_RECORDER_FRAMES").value_or("0"));
  SessionWriter writer(*session, "killed");
  const int cam = writer.AddCamera(TestCamera("cam0", PixelFormat::kBGR8, 320, 240, 60), nullptr);
  for (uint64_t seq = 0; stop_after == 0 || seq < static_cast<uint64_t>(stop_after); ++seq) {
    writer.Write(TestFrame(PixelFormat::kBGR8, 320, 240, cam, seq, MonotonicNs()));
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
  }
  std::ofstream(*session + ".written") << "done";  // tells the parent it is idle now
  while (true) pause();
}

pid_t StartRecorder(const std::string& session, int stop_after) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  // The forked child has one thread: nothing reads the environment while it is written.
  const std::string frames = std::to_string(stop_after);
  setenv("SS_TEST_RECORDER_DIR", session.c_str(), 1);    // NOLINT(concurrency-mt-unsafe)
  setenv("SS_TEST_RECORDER_FRAMES", frames.c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
  execl("/proc/self/exe", "capture_tests", "--gtest_filter=KilledRecorder.RecorderProcess",
        nullptr);
  _exit(127);
}

// Polls until `done` holds (true) or `seconds` pass (false).
bool WaitFor(const std::function<bool()>& done, int seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

size_t CsvRowsSoFar(const std::string& path) {
  try {
    return ReadFrameCsv(path).size();
  } catch (const InputError&) {
    return 0;  // not created yet
  }
}

void Kill(pid_t pid) {
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the recorder exited on its own with " << WEXITSTATUS(status);
}

TEST(KilledRecorder, AllButTheLastSecondIsReadable) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const pid_t pid = StartRecorder(session, 0);
  // Once the recording is well under way (30 frames on disk), let it run 1.5 s more.
  const bool started =
      WaitFor([&] { return CsvRowsSoFar(session + "/cam0.frames.csv") >= 30; }, 60);
  if (started) std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const int64_t kill_ns = MonotonicNs();
  Kill(pid);

  ReplaySource source(session);
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  ASSERT_GE(frames.size(), 30u) << "the recorder wrote too little to judge";
  // The frames form an unbroken prefix of what was written, each bit-exact...
  for (size_t i = 0; i < frames.size(); ++i) ASSERT_EQ(frames[i].sequence, i);
  ExpectFramesIntact(frames, PixelFormat::kBGR8, 320, 240);
  // ...reaching to within a second of the kill: every older frame survived.
  EXPECT_LT(kill_ns - frames.back().timestamp_ns, 1'000'000'000LL)
      << "last readable frame is " << (kill_ns - frames.back().timestamp_ns) / 1e6
      << " ms older than the kill";
  // The CSV never lists a frame the video lost, so the replay sees no damage.
  const SourceStats stats = source.stats();
  EXPECT_EQ(stats.errors, 0u) << AllProblems(source);
  EXPECT_EQ(source.camera_stats()[0].frames_unreadable, 0u);
  EXPECT_EQ(source.camera_stats()[0].frames_in_csv, frames.size());
}

TEST(KilledRecorder, FramesWrittenBeforeAPauseAreFlushedInTheBackground) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const pid_t pid = StartRecorder(session, 10);  // 10 frames, then nothing more is written
  const bool written = WaitFor([&] { return std::filesystem::exists(session + ".written"); }, 60);
  std::this_thread::sleep_for(
      std::chrono::milliseconds(1000));  // the writer itself does nothing now
  Kill(pid);
  ASSERT_TRUE(written) << "the recorder never finished its 10 frames";
  ReplaySource source(session);
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  ASSERT_EQ(frames.size(), 10u);
  ExpectFramesIntact(frames, PixelFormat::kBGR8, 320, 240);
  EXPECT_EQ(source.stats().errors, 0u) << AllProblems(source);
}

// Damage is read the same with one decoder and with decoder threads decoding frames in
// parallel (issue 19): each test runs with both.
class DamagedVideo : public ::testing::TestWithParam<int> {
 protected:
  ReplayOptions Options() const { return {.decode_threads = GetParam()}; }
};

TEST_P(DamagedVideo, TruncatedFileReplaysItsReadablePartAndNamesTheFile) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const std::string video = RecordTruncatedSession(session);

  ReplaySource source(session, Options());
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  ASSERT_GT(frames.size(), 5u);
  ASSERT_LT(frames.size(), 30u);
  for (size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(frames[i].sequence, i);
  ExpectFramesIntact(frames, PixelFormat::kBGR8, 160, 120);
  const SourceStats stats = source.stats();
  EXPECT_GE(stats.errors, 1u);
  EXPECT_EQ(stats.frames_dropped, 30u - frames.size());
  EXPECT_TRUE(Contains(stats.last_error, video)) << stats.last_error;
  EXPECT_TRUE(Contains(AllProblems(source),
                       video + ": video ends after " + std::to_string(frames.size()) +
                           " of the 30 frames listed in " + session + "/cam0.frames.csv"))
      << AllProblems(source);
}

TEST_P(DamagedVideo, CutAnywhereTheReadablePrefixReplaysIntact) {
  ScratchDir dir;
  const std::string original = dir / "original";
  RecordTestSession(original, PixelFormat::kYUYV, 64, 48, 20);
  const auto size = std::filesystem::file_size(original + "/cam0.mkv");
  uint64_t previous = 0;
  for (int cut = 0; cut <= 40; ++cut) {
    const std::string session = dir / ("cut" + std::to_string(cut));
    std::filesystem::copy(original, session);
    std::filesystem::resize_file(session + "/cam0.mkv", size * static_cast<uintmax_t>(cut) / 40);
    ReplaySource source(session, Options());
    std::vector<Frame> frames;
    while (auto f = source.Next()) frames.push_back(std::move(*f));
    for (size_t i = 0; i < frames.size(); ++i) ASSERT_EQ(frames[i].sequence, i) << "cut " << cut;
    ExpectFramesIntact(frames, PixelFormat::kYUYV, 64, 48);
    EXPECT_GE(frames.size(), previous) << "cut " << cut;  // a longer file never gives fewer frames
    previous = frames.size();
    if (frames.size() < 20) {
      EXPECT_GE(source.stats().errors, 1u) << "cut " << cut << ": missing frames went unreported";
      EXPECT_TRUE(Contains(source.stats().last_error, session + "/cam0.mkv"))
          << source.stats().last_error;
    }
  }
  EXPECT_EQ(previous, 20u);
}

TEST_P(DamagedVideo, CorruptFrameIsNamedAndSkipped) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kBGR8, 160, 120, 30);
  const std::string video = session + "/cam0.mkv";
  {
    // Flip a run of bytes in the middle of the file: inside some frame's data.
    std::fstream file(video, std::ios::in | std::ios::out | std::ios::binary);
    const auto size = static_cast<std::streamoff>(std::filesystem::file_size(video));
    file.seekg(size / 2);
    char bytes[16];
    file.read(bytes, sizeof(bytes));
    for (char& b : bytes) b = static_cast<char>(~b);
    file.seekp(size / 2);
    file.write(bytes, sizeof(bytes));
  }
  ReplaySource source(session, Options());
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  ExpectFramesIntact(frames, PixelFormat::kBGR8, 160, 120);
  EXPECT_GE(frames.size(), 25u);  // only the damaged frame (or its cluster) is lost
  EXPECT_LT(frames.size(), 30u);
  const std::string problems = AllProblems(source);
  EXPECT_TRUE(Contains(problems, video + ": frame")) << problems;
  EXPECT_GE(source.stats().errors, 1u);
  EXPECT_EQ(source.stats().frames_dropped, 30u - frames.size());
}

INSTANTIATE_TEST_SUITE_P(DecodeThreads, DamagedVideo, ::testing::Values(1, 3),
                         [](const auto& info) { return std::to_string(info.param) + "_decoders"; });

TEST(UnopenableVideo, SkipsItsCameraOnly) {
  ScratchDir dir;
  const std::string session = dir / "s";
  {
    SessionWriter writer(session, "two");
    const int a = writer.AddCamera(TestCamera("a", PixelFormat::kMono8, 32, 32), nullptr);
    const int b = writer.AddCamera(TestCamera("b", PixelFormat::kMono8, 32, 32), nullptr);
    for (int i = 0; i < 5; ++i) {
      writer.Write(TestFrame(PixelFormat::kMono8, 32, 32, a, i, i * 1000));
      writer.Write(TestFrame(PixelFormat::kMono8, 32, 32, b, i, i * 1000 + 1));
    }
  }
  std::ofstream(session + "/b.mkv", std::ios::trunc) << "this is not a video";
  ReplaySource source(session);
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  ASSERT_EQ(frames.size(), 5u);
  for (const auto& f : frames) EXPECT_EQ(f.camera, 0);
  EXPECT_TRUE(Contains(source.stats().last_error, session + "/b.mkv: not a readable Matroska file"))
      << source.stats().last_error;
}

TEST(DamagedCsv, GarbageCsvIsAnInputErrorNamingTheFile) {
  ScratchDir dir;
  const std::string session = dir / "s";
  const std::string csv = RecordSessionWithGarbageCsv(session);
  try {
    ReplaySource source(session);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              csv + ":3: field 'timestamp_ns': expected an integer, got 'bogus'");
  }
}

TEST(DamagedCsv, CsvLongerThanVideoIsReportedNotFatal) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kMono8, 32, 32, 6);
  std::ofstream(session + "/cam0.frames.csv", std::ios::app) << "6,999000000000,6,0\n";
  ReplaySource source(session);
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  EXPECT_EQ(frames.size(), 6u);
  EXPECT_EQ(source.stats().errors, 1u);
  EXPECT_TRUE(Contains(source.stats().last_error, "video ends after 6 of the 7 frames"))
      << source.stats().last_error;
}

TEST(Pacing, RealTimeKeepsTheOriginalSpacing) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kMono8, 32, 32, 8, {}, 50'000'000);  // 350 ms of frames
  ReplaySource source(session, {.realtime = true});
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::chrono::steady_clock::duration> arrivals;
  while (auto f = source.Next()) arrivals.push_back(std::chrono::steady_clock::now() - start);
  ASSERT_EQ(arrivals.size(), 8u);
  // A paced frame never arrives before its time (no upper bound: the machine may be busy).
  for (size_t i = 0; i < arrivals.size(); ++i) {
    EXPECT_GE(arrivals[i],
              std::chrono::milliseconds(50 * static_cast<int>(i)) - std::chrono::milliseconds(1))
        << "frame " << i;
  }
}

TEST(Pacing, StopReleasesAWaitingNext) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kMono8, 32, 32, 2, {},
                    3600'000'000'000LL);  // an hour apart
  ReplaySource source(session, {.realtime = true});
  ASSERT_TRUE(source.Next().has_value());
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    source.Stop();
  });
  EXPECT_FALSE(source.Next().has_value());  // would block for an hour without Stop()
  stopper.join();
  EXPECT_FALSE(source.Next().has_value());
}

}  // namespace
}  // namespace ss
