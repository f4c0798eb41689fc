// Rendered animations written as video files and decoded again: frame count, and the sprite
// where the camera projects it (animate/video_file.h).
#include "capture/recording/video_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "animate/renderer.h"
#include "animate_test_bank.h"
#include "core/error.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

constexpr double kVideoPxPerM = 400.0;
constexpr int kFrames = 12;

// Centroid of the strongly red pixels of a BGR image ((-1, -1) when there are none).
Eigen::Vector2d RedCentroid(const cv::Mat& bgr) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
      if (p[2] > 150 && p[1] < 100 && p[0] < 100) {
        sum += Eigen::Vector2d(x, y);
        ++count;
      }
    }
  }
  return count > 0 ? Eigen::Vector2d(sum / count) : Eigen::Vector2d(-1, -1);
}

class VideoFileTest : public ::testing::TestWithParam<std::string> {};

TEST_P(VideoFileTest, DecodesToTheFramesWrittenWithTheSpriteWhereItWasProjected) {
  const testing::ScratchDir dir;
  const std::string path = dir / ("anim" + GetParam());
  const CameraModel camera = testing::LookAtCamera(320, 240, 300, {0, -3, 1.5}, {0, 0, 0.1});
  const cv::Mat floor(240, 320, CV_8UC3, cv::Scalar(90, 160, 90));
  const SpriteRenderer renderer(camera, floor);
  // A red block 10 x 15 cm standing on its contact point; it walks 4 cm per frame along x.
  SpritePixels pixels;
  pixels.bgra = cv::Mat(61, 41, CV_8UC4, cv::Scalar(0, 0, 230, 255));
  std::vector<Eigen::Vector2d> expected;
  {
    VideoFileWriter writer(path, camera.width(), camera.height(), 30.0);
    for (int k = 0; k < kFrames; ++k) {
      const Eigen::Vector2d ground(-0.25 + 0.04 * k, 0.1);
      writer.Write(renderer.Render({{&pixels, Eigen::Vector2d(20, 60), kVideoPxPerM, ground}}));
      // The block's centre, 30 px (7.5 cm) above the contact point.
      expected.push_back(camera.ProjectGround({ground.x(), ground.y(), 30.0 / kVideoPxPerM}));
    }
    writer.Close();
    EXPECT_EQ(writer.frames_written(), kFrames);
    if (GetParam() == ".mp4") {
      EXPECT_TRUE(writer.encoder_name() == "libx264" || writer.encoder_name() == "mpeg4");
    }
  }
  const std::vector<cv::Mat> frames = ReadVideoFrames(path);
  ASSERT_EQ(static_cast<int>(frames.size()), kFrames);
  for (int k = 0; k < kFrames; ++k) {
    ASSERT_EQ(frames[k].size(), cv::Size(320, 240));
    const Eigen::Vector2d found = RedCentroid(frames[k]);
    EXPECT_LT((found - expected[k]).norm(), 1.5) << "frame " << k << " found " << found.transpose()
                                                 << " expected " << expected[k].transpose();
  }
  // The floor stays the floor away from the sprite.
  const cv::Vec3b corner = frames[kFrames / 2].at<cv::Vec3b>(10, 10);
  EXPECT_NEAR(corner[0], 90, 6);
  EXPECT_NEAR(corner[1], 160, 6);
}

INSTANTIATE_TEST_SUITE_P(Containers, VideoFileTest, ::testing::Values(".mp4", ".mkv"));

TEST(VideoFile, RefusesWhatItCannotWrite) {
  const testing::ScratchDir dir;
  const std::string base = dir.path().string();
  EXPECT_FALSE(IsVideoPath(base + "/a.avi"));
  EXPECT_TRUE(IsVideoPath(base + "/a.MP4"));
  EXPECT_THROW(VideoFileWriter(base + "/a.avi", 64, 48, 30), InputError);
  EXPECT_THROW(VideoFileWriter(base + "/a.mp4", 64, 48, 30, "ffv1"), InputError);
  EXPECT_THROW(VideoFileWriter(base + "/a.mp4", 63, 48, 30), InputError);
  EXPECT_THROW(ReadVideoFrames(base + "/missing.mp4"), InputError);
  VideoFileWriter writer(base + "/a.mkv", 64, 48, 30, "ffv1");
  EXPECT_THROW(writer.Write(cv::Mat(10, 10, CV_8UC3)), WorkError);
}

}  // namespace
}  // namespace ss
