#include "core/frame.h"

#include <gtest/gtest.h>

#include <cstring>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ss {
namespace {

cv::Mat Gradient(int w, int h) {
  cv::Mat bgr(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x)
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 4 % 256, y * 8 % 256, (x + y) % 256);
  }
  return bgr;
}

Frame FromMat(PixelFormat format, const cv::Mat& m) {
  std::vector<uint8_t> bytes(m.data, m.data + m.total() * m.elemSize());
  const int h = format == PixelFormat::kNV12 ? m.rows * 2 / 3 : m.rows;
  return Frame::Owned(format, m.cols, h, std::move(bytes));
}

TEST(PixelFormat, NamesRoundTrip) {
  for (const char* name : {"mono8", "bayer_rg8", "bayer_gr8", "bayer_gb8", "bayer_bg8", "rgb8",
                           "bgr8", "yuyv", "nv12", "mjpeg"}) {
    auto f = ParsePixelFormat(name);
    ASSERT_TRUE(f.has_value()) << name;
    EXPECT_EQ(PixelFormatName(*f), name);
  }
  EXPECT_FALSE(ParsePixelFormat("rgb16").has_value());
}

TEST(PixelFormat, FrameBytes) {
  EXPECT_EQ(FrameBytes(PixelFormat::kBGR8, 640, 480), 640u * 480 * 3);
  EXPECT_EQ(FrameBytes(PixelFormat::kYUYV, 640, 480), 640u * 480 * 2);
  EXPECT_EQ(FrameBytes(PixelFormat::kNV12, 640, 480), 640u * 480 * 3 / 2);
  EXPECT_EQ(FrameBytes(PixelFormat::kBayerRG8, 640, 480), 640u * 480);
  EXPECT_EQ(FrameBytes(PixelFormat::kMJPEG, 640, 480), 0u);
}

TEST(ToBgr, RgbSwapsChannels) {
  const cv::Mat bgr = Gradient(32, 16);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  const cv::Mat out = ToBgr(FromMat(PixelFormat::kRGB8, rgb));
  EXPECT_EQ(cv::norm(out, bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ToBgr(FromMat(PixelFormat::kBGR8, bgr)), bgr, cv::NORM_INF), 0.0);
}

TEST(ToBgr, YuvFormatsDecodeNearTheSource) {
  const cv::Mat bgr = Gradient(64, 32);
  cv::Mat i420, yuyv;
  cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420);
  // Build NV12 from I420: Y plane, then U and V interleaved.
  cv::Mat nv12(bgr.rows * 3 / 2, bgr.cols, CV_8UC1);
  std::memcpy(nv12.data, i420.data, bgr.total());
  const size_t q = bgr.total() / 4;
  for (size_t k = 0; k < q; ++k) {
    nv12.data[bgr.total() + 2 * k] = i420.data[bgr.total() + k];
    nv12.data[bgr.total() + 2 * k + 1] = i420.data[bgr.total() + q + k];
  }
  const cv::Mat from_nv12 = ToBgr(FromMat(PixelFormat::kNV12, nv12));
  // Chroma subsampling of a gradient costs a few levels, not more.
  EXPECT_LT(cv::norm(from_nv12, bgr, cv::NORM_L1) / bgr.total() / 3, 6.0);

  // YUYV: pack from the same I420 Y and (row-pair shared) chroma.
  yuyv.create(bgr.rows, bgr.cols, CV_8UC2);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; x += 2) {
      uint8_t* p = yuyv.ptr<uint8_t>(y) + x * 2;
      p[0] = i420.data[y * bgr.cols + x];
      p[2] = i420.data[y * bgr.cols + x + 1];
      p[1] = i420.data[bgr.total() + (y / 2) * (bgr.cols / 2) + x / 2];
      p[3] = i420.data[bgr.total() + q + (y / 2) * (bgr.cols / 2) + x / 2];
    }
  }
  const cv::Mat from_yuyv = ToBgr(FromMat(PixelFormat::kYUYV, yuyv));
  EXPECT_LT(cv::norm(from_yuyv, from_nv12, cv::NORM_L1) / bgr.total() / 3, 3.0);
}

TEST(ToBgr, BayerOfFlatColourDemosaicsToThatColour) {
  // An RGGB mosaic of a flat (B,G,R) = (40, 200, 90) field.
  cv::Mat raw(16, 16, CV_8UC1);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      const bool even_row = y % 2 == 0, even_col = x % 2 == 0;
      raw.at<uint8_t>(y, x) = even_row && even_col ? 90 : (!even_row && !even_col ? 40 : 200);
    }
  }
  const cv::Mat out = ToBgr(FromMat(PixelFormat::kBayerRG8, raw));
  const cv::Vec3b& centre = out.at<cv::Vec3b>(8, 8);
  EXPECT_EQ(centre, cv::Vec3b(40, 200, 90));
}

TEST(ToBgr, MjpegDecodesAndChecksSize) {
  const cv::Mat bgr = Gradient(64, 32);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
  const cv::Mat out = ToBgr(Frame::Owned(PixelFormat::kMJPEG, 64, 32, jpeg));
  EXPECT_LT(cv::norm(out, bgr, cv::NORM_L1) / bgr.total() / 3, 4.0);
  EXPECT_THROW(ToBgr(Frame::Owned(PixelFormat::kMJPEG, 128, 32, jpeg)), InputError);
  EXPECT_THROW(ToBgr(Frame::Owned(PixelFormat::kMJPEG, 64, 32, {1, 2, 3})), InputError);
}

TEST(ToBgr, ShortFrameIsAnInputErrorNamingTheFormat) {
  Frame f = Frame::Owned(PixelFormat::kYUYV, 64, 32, std::vector<uint8_t>(100));
  f.sequence = 17;
  try {
    ToBgr(f);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 17"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("yuyv"), std::string::npos) << e.what();
  }
}

TEST(Frame, BorrowedReleasesWhenTheLastCopyDies) {
  std::vector<uint8_t> buffer(12, 7);
  int released = 0;
  {
    Frame a = Frame::Borrowed(PixelFormat::kMono8, 4, 3, buffer.data(), buffer.size(),
                              [&] { ++released; });
    Frame b = a;
    EXPECT_EQ(b.data, buffer.data());
    a = Frame();
    EXPECT_EQ(released, 0);
  }
  EXPECT_EQ(released, 1);
}

}  // namespace
}  // namespace ss
