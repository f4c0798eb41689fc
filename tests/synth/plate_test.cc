// The clean plate: the per-pixel median on hand-made stacks, and a synthetic session's
// plate against the noise-free empty enclosure the renderer drew (truth/<cam>_plate.png).
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/replay/replay_source.h"
#include "capture/replay/session_plate.h"
#include "core/error.h"
#include "core/frame.h"
#include "core/image_median.h"
#include "synth/studio_session.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using ss::testing::ScratchDir;

cv::Mat Filled(int rows, int cols, int type, const cv::Scalar& value) {
  return cv::Mat(rows, cols, type, value);
}

TEST(PerPixelMedian, TakesEachBytesMedianAndIgnoresAPassingSubject) {
  // Five frames of a grey floor; a bright "subject" crosses pixel (1, 2) in two of them and
  // pixel (0, 0) in one: the median keeps the floor everywhere.
  std::vector<cv::Mat> stack;
  stack.reserve(5);
  for (int i = 0; i < 5; ++i) stack.push_back(Filled(3, 4, CV_8UC3, cv::Scalar(100 + i, 50, 10)));
  stack[1].at<cv::Vec3b>(1, 2) = {255, 255, 255};
  stack[3].at<cv::Vec3b>(1, 2) = {250, 0, 255};
  stack[4].at<cv::Vec3b>(0, 0) = {0, 0, 0};
  const cv::Mat m = PerPixelMedian(stack);
  ASSERT_EQ(m.type(), CV_8UC3);
  EXPECT_EQ(m.at<cv::Vec3b>(2, 3), cv::Vec3b(102, 50, 10));
  // (1, 2): blue of 100, 255, 102, 250, 104 -> 104; green 50, 255, 50, 0, 50 -> 50; red 10, 255,
  // 10, 255, 10 -> 10
  EXPECT_EQ(m.at<cv::Vec3b>(1, 2), cv::Vec3b(104, 50, 10));
  // (0, 0): blue 100, 101, 102, 103, 0 -> 101
  EXPECT_EQ(m.at<cv::Vec3b>(0, 0), cv::Vec3b(101, 50, 10));
  // An even count takes the lower middle value: one of the inputs', never an average.
  const cv::Mat even = PerPixelMedian({Filled(1, 1, CV_8UC1, 10), Filled(1, 1, CV_8UC1, 30),
                                       Filled(1, 1, CV_8UC1, 20), Filled(1, 1, CV_8UC1, 40)});
  EXPECT_EQ(even.at<uint8_t>(0, 0), 20);
}

TEST(PerPixelMedian, RefusesAnEmptyOrMixedStackNamingIt) {
  EXPECT_THROW(PerPixelMedian({}, "plate"), InputError);
  try {
    PerPixelMedian({Filled(2, 2, CV_8UC3, 0), Filled(2, 3, CV_8UC3, 0)}, "plate");
    FAIL() << "a mixed stack was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("image 1 is 3x2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PerPixelMedian({Filled(2, 2, CV_32FC1, 0)}, "plate"), InputError);
}

double MeanAbsDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar s = cv::mean(d);
  return (s[0] + s[1] + s[2]) / 3.0;
}

TEST(SessionPlate, IsTheNoiseFreeEmptyEnclosure) {
  ScratchDir dir;
  synth::SynthOptions o;
  o.out_dir = dir / "s";
  o.kind = synth::SynthKind::kAnimal;
  o.seconds = 2.0;
  o.fps = 15.0;
  o.width = 320;
  o.height = 240;
  o.cameras = 1;
  o.subjects = 1;
  o.seed = 5;
  o.empty_lead_in_s = 1.0;  // frames 0..14 are the empty enclosure, the animal is in 15..29
  o.write_mattes = false;
  synth::RenderStudioSession(o);
  const cv::Mat truth = cv::imread(o.out_dir + "/truth/cam0_plate.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(truth.empty());

  PlateOptions empty;
  empty.first_frame = 0;
  empty.last_frame = 14;
  const SessionPlate plate = ReadSessionPlate(o.out_dir, "cam0", empty);
  EXPECT_EQ(plate.frames_used, 15);
  EXPECT_EQ(plate.first_frame, 0);
  EXPECT_EQ(plate.last_frame, 14);
  EXPECT_EQ(plate.last_timestamp_ns, 14 * 1000000000LL / 15);
  ASSERT_EQ(plate.bgr.size(), truth.size());

  // One noisy frame against the truth, then the median of 15.
  ReplayOptions one_camera;
  one_camera.camera = "cam0";
  ReplaySource source(o.out_dir, one_camera);
  const cv::Mat first = ToBgr(*source.Next());
  source.Stop();
  const double single = MeanAbsDifference(first, truth),
               median = MeanAbsDifference(plate.bgr, truth);
  std::printf("plate: mean |frame 0 - truth| %.3f, mean |median of 15 - truth| %.3f levels\n",
              single, median);
  EXPECT_LT(median, 0.6 * single);
  EXPECT_LT(median, 0.8);

  // Taken where the animal is, the plate shows it: the test can tell the two apart.
  PlateOptions animal;
  animal.first_frame = 20;
  animal.last_frame = 29;
  const SessionPlate with_animal = ReadSessionPlate(o.out_dir, "cam0", animal);
  cv::Mat d;
  cv::absdiff(with_animal.bgr, truth, d);
  cv::Mat grey;
  cv::cvtColor(d, grey, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(grey > 40), 50) << "the idle animal is in every one of frames 20..29";
  cv::absdiff(plate.bgr, truth, d);
  cv::cvtColor(d, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::countNonZero(grey > 40), 0);
}

TEST(SessionPlate, NamesAnUnknownCameraAndAnEmptyRange) {
  ScratchDir dir;
  synth::SynthOptions o;
  o.out_dir = dir / "s";
  o.kind = synth::SynthKind::kAnimal;
  o.seconds = 0.4;
  o.fps = 10.0;
  o.width = 160;
  o.height = 120;
  o.cameras = 1;
  o.write_mattes = false;
  synth::RenderStudioSession(o);
  EXPECT_THROW(ReadSessionPlate(o.out_dir, "cam7"), InputError);
  PlateOptions past;
  past.first_frame = 100;
  past.last_frame = 110;
  try {
    ReadSessionPlate(o.out_dir, "cam0", past);
    FAIL() << "a range past the end was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no readable frame in frames 100..110 (it has 4)"),
              std::string::npos)
        << e.what();
  }
  PlateOptions backwards;
  backwards.first_frame = 5;
  backwards.last_frame = 2;
  EXPECT_THROW(ReadSessionPlate(o.out_dir, "cam0", backwards), InputError);
}

}  // namespace
}  // namespace ss
