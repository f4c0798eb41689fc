// The recorder puts frames on disk while it is still running: what a reader
// sees of a session whose writer has not been closed (the state a kill leaves).
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <thread>

#include "capture/recording/session_writer.h"
#include "capture/replay/replay_source.h"
#include "core/error.h"
#include "core/session.h"
#include "tests/capture/session_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::ScratchDir;
using ss::testing::TestCamera;
using ss::testing::TestFrame;
using ss::testing::TestPixels;

size_t CsvRows(const std::string& path) { return ReadFrameCsv(path).size(); }

// Replays what is on disk now; every frame must be the one written under its sequence.
std::vector<Frame> ReplayIntact(const std::string& session, PixelFormat format, int w, int h) {
  ReplaySource source(session);
  std::vector<Frame> frames;
  while (auto f = source.Next()) {
    const auto expected = TestPixels(format, w, h, f->camera, f->sequence);
    EXPECT_EQ(f->size, expected.size());
    EXPECT_EQ(std::memcmp(f->data, expected.data(), std::min(f->size, expected.size())), 0)
        << f->sequence;
    frames.push_back(std::move(*f));
  }
  EXPECT_EQ(source.stats().errors, 0u) << source.stats().last_error;
  return frames;
}

TEST(WriterFlush, IntervalZeroPutsEveryFrameOnDiskBeforeWriteReturns) {
  ScratchDir dir;
  const std::string session = dir / "s";
  SessionWriter writer(session, "sync", {.flush_interval_ms = 0});
  const int cam = writer.AddCamera(TestCamera("cam0", PixelFormat::kBGR8, 64, 48), nullptr);
  for (uint64_t seq = 0; seq < 6; ++seq) {
    writer.Write(TestFrame(PixelFormat::kBGR8, 64, 48, cam, seq,
                           1'000'000'000 + static_cast<int64_t>(seq) * 33'000'000));
    // The writer is still open: what a kill right now would leave.
    ASSERT_EQ(CsvRows(session + "/cam0.frames.csv"), seq + 1);
    const auto frames = ReplayIntact(session, PixelFormat::kBGR8, 64, 48);
    ASSERT_EQ(frames.size(), seq + 1);
    for (size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(frames[i].sequence, i);
  }
  writer.Close();
  EXPECT_EQ(ReplayIntact(session, PixelFormat::kBGR8, 64, 48).size(), 6u);
}

TEST(WriterFlush, WhileWritingTheCsvListsOnlyFramesTheVideoHolds) {
  ScratchDir dir;
  const std::string session = dir / "s";
  SessionWriter writer(session, "steady", {.flush_interval_ms = 40});
  const int cam = writer.AddCamera(TestCamera("cam0", PixelFormat::kMono8, 32, 32), nullptr);
  uint64_t seq = 0;
  auto write = [&] {
    writer.Write(
        TestFrame(PixelFormat::kMono8, 32, 32, cam, seq, static_cast<int64_t>(seq) * 5'000'000));
    ++seq;
  };
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(150)) {
    write();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // 150 ms after the first frame: if nothing was flushed yet, this Write flushes.
  write();
  const size_t rows = CsvRows(session + "/cam0.frames.csv");
  EXPECT_GT(rows, 0u);
  EXPECT_LE(rows, seq);
  // Whatever the CSV lists, the video holds, bit-exact (the writer is still open).
  const auto frames = ReplayIntact(session, PixelFormat::kMono8, 32, 32);
  EXPECT_EQ(frames.size(), rows);
  writer.Close();
  EXPECT_EQ(CsvRows(session + "/cam0.frames.csv"), seq);
}

TEST(WriterFlush, FramesBeforeAPauseReachTheDiskWithoutFurtherWrites) {
  ScratchDir dir;
  const std::string session = dir / "s";
  SessionWriter writer(session, "pause", {.flush_interval_ms = 20});
  const int a = writer.AddCamera(TestCamera("a", PixelFormat::kYUYV, 32, 16), nullptr);
  const int b = writer.AddCamera(TestCamera("b", PixelFormat::kBGR8, 16, 16), nullptr);
  for (uint64_t seq = 0; seq < 7; ++seq) {
    writer.Write(
        TestFrame(PixelFormat::kYUYV, 32, 16, a, seq, static_cast<int64_t>(seq) * 10'000'000));
    if (seq < 3)
      writer.Write(TestFrame(PixelFormat::kBGR8, 16, 16, b, seq,
                             static_cast<int64_t>(seq) * 10'000'000 + 1));
  }
  // Nothing more is written: the background flusher must bring both cameras to disk.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline &&
         (CsvRows(session + "/a.frames.csv") < 7 || CsvRows(session + "/b.frames.csv") < 3)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(CsvRows(session + "/a.frames.csv"), 7u);
  ASSERT_EQ(CsvRows(session + "/b.frames.csv"), 3u);
  ReplaySource source(session);
  size_t per_camera[2] = {0, 0};
  while (auto f = source.Next()) {
    const auto expected = TestPixels(f->format, f->width, f->height, f->camera, f->sequence);
    ASSERT_EQ(f->size, expected.size());
    EXPECT_EQ(std::memcmp(f->data, expected.data(), expected.size()), 0);
    EXPECT_EQ(f->sequence, per_camera[f->camera]++);
  }
  EXPECT_EQ(per_camera[0], 7u);
  EXPECT_EQ(per_camera[1], 3u);
  EXPECT_EQ(source.stats().errors, 0u) << source.stats().last_error;
}

}  // namespace
}  // namespace ss
