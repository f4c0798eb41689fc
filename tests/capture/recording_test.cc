// Recording sessions and replaying them: bit-exact for every raw format (FFV1),
// close for the lossy codecs, MJPEG cameras stored as they came.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <tuple>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <utility>

#include "capture/recording/session_writer.h"
#include "capture/recording/video_reader.h"
#include "capture/replay/replay_source.h"
#include "core/camera_model.h"
#include "core/error.h"
#include "core/session.h"
#include "tests/capture/session_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::RecordTestSession;
using ss::testing::ScratchDir;
using ss::testing::TestCamera;
using ss::testing::TestFrame;
using ss::testing::TestPixels;

std::vector<Frame> ReplayAll(const std::string& dir, const ReplayOptions& options = {}) {
  ReplaySource source(dir, options);
  std::vector<Frame> frames;
  while (auto f = source.Next()) frames.push_back(std::move(*f));
  return frames;
}

struct FormatCase {
  PixelFormat format;
  int width;
  int height;
  std::string codec = "ffv1";  // every lossless codec of core/recording_codecs.h
};

class LosslessRoundTrip : public ::testing::TestWithParam<FormatCase> {};

TEST_P(LosslessRoundTrip, ReplaysBitExactWithTimestampsAndSequences) {
  const FormatCase c = GetParam();
  ScratchDir dir;
  const std::string session = dir / "s";
  const int count = 12;
  const int64_t t0 = 5'000'000'123;
  // Irregular timestamps and a sequence gap, as a real camera delivers them.
  {
    SessionWriter writer(session, "lossless", {.codec = c.codec});
    const int cam = writer.AddCamera(TestCamera("cam0", c.format, c.width, c.height), nullptr);
    for (int i = 0; i < count; ++i) {
      const uint64_t seq = 100 + static_cast<uint64_t>(i) + (i >= 6 ? 2 : 0);
      const int64_t ts = t0 + i * 33'333'333LL + (i % 3) * 1'000'117LL;
      writer.Write(TestFrame(c.format, c.width, c.height, cam, seq, ts), i == 6 ? 2 : 0);
    }
    writer.Close();
  }
  const SessionInfo info = ReadSessionInfo(session);
  ASSERT_EQ(info.cameras.size(), 1u);
  EXPECT_EQ(info.cameras[0].codec, c.codec);
  EXPECT_EQ(info.cameras[0].pixel_format, c.format);

  ReplaySource source(session);
  ASSERT_EQ(source.cameras().size(), 1u);
  EXPECT_EQ(source.cameras()[0].format, c.format);
  int i = 0;
  while (auto f = source.Next()) {
    ASSERT_LT(i, count);
    const uint64_t seq = 100 + static_cast<uint64_t>(i) + (i >= 6 ? 2 : 0);
    EXPECT_EQ(f->format, c.format);
    EXPECT_EQ(f->width, c.width);
    EXPECT_EQ(f->height, c.height);
    EXPECT_EQ(f->sequence, seq);
    EXPECT_EQ(f->timestamp_ns, t0 + i * 33'333'333LL + (i % 3) * 1'000'117LL);
    const auto expected = TestPixels(c.format, c.width, c.height, 0, seq);
    ASSERT_EQ(f->size, expected.size());
    EXPECT_EQ(std::memcmp(f->data, expected.data(), expected.size()), 0)
        << "frame " << i << " differs";
    ++i;
  }
  EXPECT_EQ(i, count);
  const SourceStats stats = source.stats();
  EXPECT_EQ(stats.frames_delivered, static_cast<uint64_t>(count));
  EXPECT_EQ(stats.errors, 0u);
  EXPECT_EQ(stats.frames_dropped, 2u);  // the sequence gap
  const auto rows = ReadFrameCsv(session + "/cam0.frames.csv");
  ASSERT_EQ(rows.size(), static_cast<size_t>(count));
  EXPECT_EQ(rows[6].drops_before, 2u);
}

INSTANTIATE_TEST_SUITE_P(Formats, LosslessRoundTrip,
                         ::testing::Values(FormatCase{PixelFormat::kBGR8, 96, 64},
                                           FormatCase{PixelFormat::kRGB8, 97, 63},
                                           FormatCase{PixelFormat::kMono8, 64, 48},
                                           FormatCase{PixelFormat::kBayerRG8, 96, 64},
                                           FormatCase{PixelFormat::kBayerGB8, 80, 60},
                                           FormatCase{PixelFormat::kYUYV, 96, 64},
                                           FormatCase{PixelFormat::kNV12, 96, 64},
                                           FormatCase{PixelFormat::kBGR8, 96, 64, "ffvhuff"},
                                           FormatCase{PixelFormat::kRGB8, 97, 63, "ffvhuff"},
                                           FormatCase{PixelFormat::kMono8, 64, 48, "ffvhuff"},
                                           FormatCase{PixelFormat::kBayerGB8, 80, 60, "ffvhuff"},
                                           FormatCase{PixelFormat::kYUYV, 96, 64, "ffvhuff"},
                                           FormatCase{PixelFormat::kNV12, 96, 64, "ffvhuff"}),
                         [](const auto& info) {
                           return PixelFormatName(info.param.format) + "_" + info.param.codec;
                         });

TEST(Recording, MjpegCameraKeepsItsJpegs) {
  ScratchDir dir;
  const std::string session = dir / "s";
  std::vector<std::vector<uint8_t>> jpegs;
  {
    SessionWriter writer(session, "mjpeg", {.codec = "ffv1"});  // an MJPEG camera ignores the codec
    const int cam = writer.AddCamera(TestCamera("usb", PixelFormat::kMJPEG, 64, 48), nullptr);
    for (int i = 0; i < 5; ++i) {
      cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(i * 40, 100, 200 - i * 30));
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", bgr, jpeg);
      jpegs.push_back(jpeg);
      Frame f = Frame::Owned(PixelFormat::kMJPEG, 64, 48, jpeg);
      f.camera = cam;
      f.sequence = static_cast<uint64_t>(i);
      f.timestamp_ns = i * 10'000'000LL;
      writer.Write(f);
    }
  }
  EXPECT_EQ(ReadSessionInfo(session).cameras[0].codec, "mjpeg");
  const auto frames = ReplayAll(session);
  ASSERT_EQ(frames.size(), jpegs.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].format, PixelFormat::kMJPEG);
    ASSERT_EQ(frames[i].size, jpegs[i].size());
    EXPECT_EQ(std::memcmp(frames[i].data, jpegs[i].data(), frames[i].size), 0);
  }
}

double Psnr(const Frame& frame, const std::vector<uint8_t>& expected) {
  double sum = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    const double d = static_cast<double>(frame.data[i]) - expected[i];
    sum += d * d;
  }
  const double mse = sum / static_cast<double>(expected.size());
  return mse == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
}

TEST(Recording, LossyCodecsReplayCloseInTheCameraFormat) {
  for (const std::string codec : {"mjpeg", "h264"}) {
    for (PixelFormat format : {PixelFormat::kBGR8, PixelFormat::kBayerBG8, PixelFormat::kYUYV}) {
      ScratchDir dir;
      const std::string session = dir / "s";
      RecordTestSession(session, format, 128, 96, 8, {.codec = codec}, 33'000'000, 0,
                        /*smooth=*/true);
      EXPECT_EQ(ReadSessionInfo(session).cameras[0].codec, codec);
      const auto frames = ReplayAll(session);
      ASSERT_EQ(frames.size(), 8u) << codec;
      for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].format, format);
        EXPECT_EQ(frames[i].sequence, i);
        const auto expected = TestPixels(format, 128, 96, 0, i, true);
        ASSERT_EQ(frames[i].size, expected.size());
        EXPECT_GT(Psnr(frames[i], expected), 30.0)
            << codec << " " << PixelFormatName(format) << " frame " << i;
      }
    }
  }
}

TEST(Recording, RejectsFramesThatDoNotMatchTheCamera) {
  ScratchDir dir;
  SessionWriter writer(dir / "s", "x");
  const int cam = writer.AddCamera(TestCamera("cam0", PixelFormat::kBGR8, 32, 32), nullptr);
  EXPECT_THROW(writer.Write(TestFrame(PixelFormat::kMono8, 32, 32, cam, 0, 0)), InputError);
  EXPECT_THROW(writer.Write(TestFrame(PixelFormat::kBGR8, 32, 16, cam, 0, 0)), InputError);
  EXPECT_THROW(writer.Write(TestFrame(PixelFormat::kBGR8, 32, 32, 5, 0, 0)), InputError);
  EXPECT_THROW(SessionWriter(dir / "s", "again"), WorkError);  // not an empty folder
  EXPECT_THROW(SessionWriter(dir / "t", "x", {.codec = "vp9"}), InputError);
}

TEST(Recording, CameraModelIsStoredBesideTheVideo) {
  ScratchDir dir;
  const std::string session = dir / "s";
  Rigid3 cam_from_ground;
  cam_from_ground.translation = Eigen::Vector3d(0.1, -0.2, 3.0);
  const CameraModel model("LENSMODEL_PINHOLE", {800, 810, 320, 240}, 640, 480, cam_from_ground);
  {
    SessionWriter writer(session, "calibrated");
    writer.AddCamera(TestCamera("cam0", PixelFormat::kMono8, 640, 480), &model);
  }
  EXPECT_EQ(ReadSessionInfo(session).cameras[0].model, "cam0.cameramodel");
  ReplaySource source(session);
  ASSERT_EQ(source.cameras()[0].model_path, session + "/cam0.cameramodel");
  const CameraModel back = CameraModel::Read(source.cameras()[0].model_path);
  EXPECT_EQ(back.intrinsics(), model.intrinsics());
  EXPECT_TRUE(back.cam_from_ground().translation.isApprox(cam_from_ground.translation));
  EXPECT_FALSE(source.Next().has_value());  // no frames were recorded
}

TEST(Recording, DeviceNamesBecomeSafeUniqueFileStems) {
  ScratchDir dir;
  const std::string session = dir / "s";
  {
    SessionWriter writer(session, "names");
    writer.AddCamera(TestCamera("/dev/video0", PixelFormat::kMono8, 16, 16), nullptr);
    writer.AddCamera(TestCamera("/dev/video0", PixelFormat::kMono8, 16, 16), nullptr);
    writer.AddCamera(TestCamera("", PixelFormat::kMono8, 16, 16), nullptr);
  }
  const SessionInfo info = ReadSessionInfo(session);
  ASSERT_EQ(info.cameras.size(), 3u);
  EXPECT_EQ(info.cameras[0].name, "dev_video0");
  EXPECT_EQ(info.cameras[1].name, "dev_video0-2");
  EXPECT_EQ(info.cameras[2].name, "cam2");
  EXPECT_TRUE(std::filesystem::exists(session + "/dev_video0-2.mkv"));
}

TEST(Replay, MergesCamerasInTimestampOrder) {
  ScratchDir dir;
  const std::string session = dir / "s";
  // cam0 (BGR8) every 10 ms from 0; cam1 (Bayer) every 15 ms from 3 ms; one tie at 30 ms... none:
  // 3+15k.
  {
    SessionWriter writer(session, "two");
    const int a = writer.AddCamera(TestCamera("left", PixelFormat::kBGR8, 48, 32, 100), nullptr);
    const int b =
        writer.AddCamera(TestCamera("right", PixelFormat::kBayerGR8, 40, 30, 66.7), nullptr);
    // Written out of global order on purpose: the replay orders by device time.
    for (int i = 0; i < 20; ++i)
      writer.Write(TestFrame(PixelFormat::kBGR8, 48, 32, a, i, i * 10'000'000LL));
    for (int i = 0; i < 14; ++i) {
      writer.Write(
          TestFrame(PixelFormat::kBayerGR8, 40, 30, b, 1000 + i, 3'000'000LL + i * 15'000'000LL));
    }
  }
  const auto frames = ReplayAll(session);
  ASSERT_EQ(frames.size(), 34u);
  int per_camera[2] = {0, 0};
  for (size_t i = 0; i < frames.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(frames[i - 1].timestamp_ns, frames[i].timestamp_ns) << "at " << i;
    }
    const Frame& f = frames[i];
    ASSERT_TRUE(f.camera == 0 || f.camera == 1);
    const int k = per_camera[f.camera]++;
    if (f.camera == 0) {
      EXPECT_EQ(f.format, PixelFormat::kBGR8);
      EXPECT_EQ(f.sequence, static_cast<uint64_t>(k));
    } else {
      EXPECT_EQ(f.format, PixelFormat::kBayerGR8);
      EXPECT_EQ(f.sequence, 1000u + k);
    }
    const auto expected = TestPixels(f.format, f.width, f.height, f.camera, f.sequence);
    EXPECT_EQ(std::memcmp(f.data, expected.data(), expected.size()), 0);
  }
  EXPECT_EQ(per_camera[0], 20);
  EXPECT_EQ(per_camera[1], 14);
}

TEST(Replay, LoopsShiftTimeForward) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kMono8, 32, 16, 5, {}, 20'000'000, 7'000'000'000LL);
  const auto frames = ReplayAll(session, {.loops = 3});
  ASSERT_EQ(frames.size(), 15u);
  for (size_t i = 1; i < frames.size(); ++i) {
    EXPECT_LT(frames[i - 1].timestamp_ns, frames[i].timestamp_ns);
    EXPECT_EQ(frames[i].sequence, frames[i - 1].sequence + 1);  // sequence span 5 per pass
  }
  // Pixels repeat each pass.
  EXPECT_EQ(std::memcmp(frames[0].data, frames[5].data, frames[0].size), 0);
  EXPECT_EQ(frames[0].timestamp_ns, 7'000'000'000LL);
}

TEST(Replay, HeldFramesDoNotStallTheReplay) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kBGR8, 32, 16, 40);
  ReplaySource source(session, {.frames_ahead = 2});
  std::vector<Frame> held;  // the consumer keeps every frame: buffers must not run out
  while (auto f = source.Next()) held.push_back(std::move(*f));
  ASSERT_EQ(held.size(), 40u);
  for (const auto& f : held) {
    const auto expected = TestPixels(PixelFormat::kBGR8, 32, 16, 0, f.sequence);
    EXPECT_EQ(std::memcmp(f.data, expected.data(), expected.size()), 0) << f.sequence;
  }
}

// Issue 19: FFV1 and ffvhuff frames are decoded by several decoder threads at once. Each
// camera format, in either codec, must come back as the same bytes in the same order as
// with one decoder, and as recorded.
class ParallelDecoding : public ::testing::TestWithParam<std::tuple<std::string, PixelFormat>> {};

TEST_P(ParallelDecoding, GivesTheFramesOneDecoderGivesInFileOrder) {
  const auto& [codec, format] = GetParam();
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, format, 96, 64, 41, {.codec = codec});
  // The reader really decodes with three threads (else this test would compare a path with itself).
  EXPECT_EQ(VideoReader(session + "/cam0.mkv", format, 96, 64, 3).decode_threads(), 3);
  EXPECT_EQ(VideoReader(session + "/cam0.mkv", format, 96, 64, 1).decode_threads(), 1);
  const std::vector<Frame> one = ReplayAll(session, {.decode_threads = 1});
  const std::vector<Frame> three = ReplayAll(session, {.decode_threads = 3});
  ASSERT_EQ(one.size(), 41u);
  ASSERT_EQ(three.size(), 41u);
  for (size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(three[i].sequence, i);
    ASSERT_EQ(three[i].timestamp_ns, one[i].timestamp_ns);
    ASSERT_EQ(three[i].size, one[i].size);
    EXPECT_EQ(std::memcmp(three[i].data, one[i].data, one[i].size), 0) << "frame " << i;
    const auto expected = TestPixels(format, 96, 64, 0, i);
    EXPECT_EQ(std::memcmp(three[i].data, expected.data(), expected.size()), 0) << "frame " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(
    LosslessCodecs, ParallelDecoding,
    ::testing::Combine(::testing::Values("ffv1", "ffvhuff"),
                       ::testing::Values(PixelFormat::kBGR8, PixelFormat::kRGB8,
                                         PixelFormat::kMono8, PixelFormat::kYUYV,
                                         PixelFormat::kNV12)),
    [](const auto& info) {
      return std::get<0>(info.param) + "_" + PixelFormatName(std::get<1>(info.param));
    });

TEST(ParallelDecoding, LossyCodecsKeepOneDecoder) {
  ScratchDir dir;
  const std::string session = dir / "s";
  RecordTestSession(session, PixelFormat::kBGR8, 96, 64, 5, {.codec = "h264"}, 33'000'000,
                    1'000'000'000, true);
  EXPECT_EQ(VideoReader(session + "/cam0.mkv", PixelFormat::kBGR8, 96, 64, 4).decode_threads(), 1);
  EXPECT_EQ(ReplayAll(session, {.decode_threads = 4}).size(), 5u);
}

}  // namespace
}  // namespace ss
