// The Aravis backend against the emulated GigE Vision camera on loopback: real
// GVCP discovery by address and device id, register writes, GVSP streaming and
// packet resend, with every delivered frame compared to the recorded session.
#include <gtest/gtest.h>

#ifdef SPRITESTATION_HAVE_ARAVIS

#include <chrono>
#include <cstring>
#include <memory>
#include <thread>

#include <opencv2/imgproc.hpp>
#include <utility>

#include "capture/aravis/aravis_source.h"
#include "capture/aravis/fake_gige_camera.h"
#include "core/error.h"
#include "tests/capture/session_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::RecordTestSession;
using ss::testing::ScratchDir;
using ss::testing::TestPixels;

constexpr int kW = 640;
constexpr int kH = 480;
constexpr int kFrames = 8;
constexpr int64_t kT0 = 1'000'000'000;
constexpr int64_t kPeriod = 33'000'000;

// UDP port 3956 on 127.0.0.1 takes one camera at a time; another test process
// may hold it for a moment, so binding is retried for a while.
std::unique_ptr<FakeGigECamera> StartFakecam(const std::string& dir,
                                             const FakeGigEOptions& options) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (true) {
    try {
      return std::make_unique<FakeGigECamera>(dir, options);
    } catch (const WorkError&) {
      if (std::chrono::steady_clock::now() > deadline) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }
}

// The session frame index a delivered timestamp belongs to (replays loop, each
// pass shifted by the session's span plus one frame period at its 30 fps); -1 when none.
int SessionIndex(int64_t timestamp_ns) {
  const int64_t pass_span = (kFrames - 1) * kPeriod + static_cast<int64_t>(1e9 / 30.0);
  const int64_t offset = (timestamp_ns - kT0) % pass_span;
  if (timestamp_ns < kT0 || offset % kPeriod != 0) return -1;
  return static_cast<int>(offset / kPeriod);
}

struct Received {
  AravisStreamStats stream;
  SourceStats totals;
  uint64_t sequence_span = 0;  // last delivered sequence - first + 1
};

// Opens the fake camera, takes `count` frames, and checks each against `expected(index)`.
template <typename Expected>
Received Receive(AravisOptions options, int count, PixelFormat format, Expected expected) {
  AravisSource source(std::move(options));
  EXPECT_EQ(source.cameras().size(), 1u);
  EXPECT_EQ(source.cameras()[0].width, kW);
  EXPECT_EQ(source.cameras()[0].height, kH);
  EXPECT_EQ(source.cameras()[0].format, format);
  uint64_t first_sequence = 0;
  uint64_t last_sequence = 0;
  for (int i = 0; i < count; ++i) {
    auto frame = source.Next();
    if (!frame) {
      ADD_FAILURE() << "stream ended after " << i << " frames";
      break;
    }
    EXPECT_EQ(frame->format, format);
    if (i > 0) {
      EXPECT_GT(frame->sequence, last_sequence);
    }
    if (i == 0) first_sequence = frame->sequence;
    last_sequence = frame->sequence;
    const int index = SessionIndex(frame->timestamp_ns);
    EXPECT_GE(index, 0) << "timestamp " << frame->timestamp_ns << " is no session frame's";
    if (index < 0) continue;
    const std::vector<uint8_t> want = expected(index);
    EXPECT_EQ(frame->size, want.size());
    EXPECT_EQ(std::memcmp(frame->data, want.data(), std::min(want.size(), frame->size)), 0)
        << "session frame " << index;
  }
  const AravisStreamStats s = source.stream_stats();
  const SourceStats totals = source.stats();
  EXPECT_EQ(totals.frames_delivered, static_cast<uint64_t>(count));
  EXPECT_GE(s.completed, static_cast<uint64_t>(count));
  EXPECT_GE(s.received_packets,
            static_cast<uint64_t>(count) * 3);  // leader, data, trailer at the least
  EXPECT_GE(s.transferred_bytes, static_cast<uint64_t>(count) * FrameBytes(format, kW, kH));
  return {s, totals, last_sequence - first_sequence + 1};
}

TEST(AravisFakecam, Mono8SessionArrivesBitExactByAddress) {
  ScratchDir dir;
  const std::string session = dir / "mono";
  RecordTestSession(session, PixelFormat::kMono8, kW, kH, kFrames);
  FakeGigEOptions fo;
  fo.serial = "SSTMONO";
  fo.fps = 100;
  auto cam = StartFakecam(session, fo);
  EXPECT_EQ(cam->device_id(), "Aravis-Fake-SSTMONO");

  AravisOptions ao;
  ao.camera = "127.0.0.1";
  ao.packet_size = 8000;
  ao.exposure_us = 5000;
  ao.gain = 3;
  ao.fps = 100;
  const Received r = Receive(ao, 2 * kFrames + 3, PixelFormat::kMono8, [](int i) {
    return TestPixels(PixelFormat::kMono8, kW, kH, 0, static_cast<uint64_t>(i));
  });
  // The settings reached the camera's registers over GVCP.
  EXPECT_EQ(cam->exposure_us(), 5000u);
  EXPECT_EQ(cam->gain(), 3u);
  EXPECT_GE(cam->frames_served(), static_cast<uint64_t>(2 * kFrames + 3));
  // Every sequence number between the first and last frame is either delivered or counted as
  // dropped.
  EXPECT_EQ(r.sequence_span, 2 * kFrames + 3 + r.totals.frames_dropped);
  EXPECT_EQ(r.totals.frames_dropped, r.stream.failures + r.stream.sequence_gaps);
}

TEST(AravisFakecam, BgrSessionStreamsAsRgb8AndBayerAsIsByDeviceId) {
  ScratchDir dir;
  const std::string bgr_session = dir / "bgr";
  RecordTestSession(bgr_session, PixelFormat::kBGR8, kW, kH, kFrames);
  {
    FakeGigEOptions fo;
    fo.serial = "SSTRGB";
    fo.fps = 100;
    auto cam = StartFakecam(bgr_session, fo);
    EXPECT_EQ(cam->pixel_format(),
              PixelFormat::kRGB8);  // GigE's fake camera carries RGB8, not BGR8
    AravisOptions ao;
    ao.camera = cam->device_id();  // found by discovery, not by address
    ao.packet_size = 8000;
    Receive(ao, kFrames + 2, PixelFormat::kRGB8, [](int i) {
      auto bgr = TestPixels(PixelFormat::kBGR8, kW, kH, 0, static_cast<uint64_t>(i));
      std::vector<uint8_t> rgb(bgr.size());
      cv::cvtColor(cv::Mat(kH, kW, CV_8UC3, bgr.data()), cv::Mat(kH, kW, CV_8UC3, rgb.data()),
                   cv::COLOR_BGR2RGB);
      return rgb;
    });
  }
  const std::string bayer_session = dir / "bayer";
  RecordTestSession(bayer_session, PixelFormat::kBayerGR8, kW, kH, kFrames);
  FakeGigEOptions fo;
  fo.serial = "SSTBAY";
  fo.fps = 100;
  auto cam = StartFakecam(bayer_session, fo);
  AravisOptions ao;
  ao.camera = "127.0.0.1";
  ao.packet_size = 8000;
  Receive(ao, kFrames, PixelFormat::kBayerGR8, [](int i) {
    return TestPixels(PixelFormat::kBayerGR8, kW, kH, 0, static_cast<uint64_t>(i));
  });
}

// Aravis 0.8's fake camera ignores resend requests, so a frame that lost a
// packet stays incomplete: it must be requested, counted and never delivered.
TEST(AravisFakecam, LostPacketsAreRequestedCountedAndNeverDelivered) {
  ScratchDir dir;
  const std::string session = dir / "mono";
  RecordTestSession(session, PixelFormat::kMono8, kW, kH, kFrames);
  FakeGigEOptions fo;
  fo.serial = "SSTLOSS";
  fo.fps = 60;
  // 3 % of packets: at 1 % a run of ~12 frames (~470 packets) lost none about one run in ten
  // here (Aravis draws the losses from an unseeded generator), and the test failed.
  fo.lost_packet_ratio = 0.03;
  auto cam = StartFakecam(session, fo);
  AravisOptions ao;
  ao.camera = "127.0.0.1";
  ao.packet_size = 8000;  // ~40 packets a frame: about one frame in three arrives whole
  const Received r = Receive(ao, kFrames, PixelFormat::kMono8, [](int i) {
    return TestPixels(PixelFormat::kMono8, kW, kH, 0, static_cast<uint64_t>(i));
  });
  EXPECT_GT(r.stream.missing_packets, 0u);
  EXPECT_GT(r.stream.resend_requests, 0u);
  EXPECT_GT(r.totals.frames_dropped, 0u);
  // Every block id between the first and last delivered frame was delivered or counted as dropped
  // (a drop before the first delivered frame counts too, hence <=).
  EXPECT_LE(r.sequence_span, kFrames + r.totals.frames_dropped);
}

TEST(AravisFakecam, PixelFormatTheCameraLacksIsNamed) {
  ScratchDir dir;
  const std::string session = dir / "mono";
  RecordTestSession(session, PixelFormat::kMono8, kW, kH, 2);
  FakeGigEOptions fo;
  fo.serial = "SSTFMT";
  auto cam = StartFakecam(session, fo);
  AravisOptions ao;
  ao.camera = "127.0.0.1";
  ao.pixel_format = PixelFormat::kNV12;
  try {
    AravisSource source(ao);
    FAIL() << "NV12 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel_format"), std::string::npos) << e.what();
  }
  ao.pixel_format = PixelFormat::kBGR8;  // GigE carries it, the fake camera does not offer it
  try {
    AravisSource source(ao);
    FAIL() << "BGR8 accepted by a camera without it";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("BGR8"), std::string::npos) << e.what();
  }
  // Fixed white balance ratios on a camera without BalanceRatio (the fake camera): refused by name.
  ao.pixel_format = PixelFormat::kMono8;
  ao.white_balance = WhiteBalanceMode::kManual;
  ao.red_ratio = 1.4;
  try {
    AravisSource source(ao);
    FAIL() << "white balance ratios accepted by a camera without BalanceRatio";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("white_balance"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("BalanceRatio"), std::string::npos) << e.what();
  }
  ao.white_balance = WhiteBalanceMode::kDevice;  // left as the camera has it: opens
  EXPECT_NO_THROW(AravisSource{ao});
}

TEST(AravisFakecam, MissingCameraIsAWorkErrorNamingIt) {
  AravisOptions ao;
  ao.camera = "Aravis-Fake-NOSUCHCAM";
  try {
    AravisSource source(ao);
    FAIL() << "opened a camera that does not exist";
  } catch (const WorkError& e) {
    EXPECT_NE(std::string(e.what()).find("NOSUCHCAM"), std::string::npos) << e.what();
  }
}

TEST(AravisFakecam, UnreadableSessionIsRefusedBeforeServing) {
  ScratchDir dir;
  FakeGigEOptions fo;
  fo.serial = "SSTBAD";
  EXPECT_THROW(FakeGigECamera(dir / "missing", fo), InputError);
  fo.pixel_format = PixelFormat::kYUYV;
  const std::string session = dir / "mono";
  RecordTestSession(session, PixelFormat::kMono8, 64, 48, 2);
  EXPECT_THROW(FakeGigECamera(session, fo), InputError);
}

}  // namespace
}  // namespace ss

#else

TEST(AravisFakecam, SkippedWithoutAravis) {
  GTEST_SKIP() << "built without the Aravis backend (SPRITESTATION_ARAVIS)";
}

#endif
