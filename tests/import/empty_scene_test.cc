// The empty scene `import` makes for footage that is never empty (import/empty_scene.h).
#include "import/empty_scene.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "import/import_session.h"

namespace ss {
namespace {

// A noisy grey floor (level 100 +- noise) with a bright walker over columns [x, x + 10).
cv::Mat Frame(cv::RNG& rng, int walker_x, double noise) {
  cv::Mat f(20, 40, CV_8UC3);
  rng.fill(f, cv::RNG::NORMAL, cv::Scalar::all(100), cv::Scalar::all(noise));
  if (walker_x >= 0) f.colRange(walker_x, walker_x + 10).setTo(cv::Scalar(240, 230, 220));
  return f;
}

TEST(MedianAndSpread, SeesThroughAWalkerAndMeasuresTheNoise) {
  cv::RNG rng(7);
  std::vector<cv::Mat> frames;
  frames.reserve(31);
  for (int i = 0; i < 31; ++i)
    frames.push_back(Frame(rng, (i % 3) * 10, 4.0));  // each column covered 1/3 of the time
  const RobustBackground b = MedianAndSpread(frames);
  const cv::Scalar median = cv::mean(b.median), spread = cv::mean(b.spread);
  // The walker covers each pixel a third of the time: the median is the floor, pulled a little up.
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(median[c], 100, 3);
    // MAD x 1.4826 estimates the noise std (4), raised by the walker's third of the samples.
    EXPECT_GT(spread[c], 3);
    EXPECT_LT(spread[c], 9);
  }
  double max_value;
  cv::minMaxLoc(b.median.reshape(1), nullptr, &max_value);
  EXPECT_LT(max_value, 130) << "the walker is in the median";
}

TEST(Winsorized, RemovesTheWalkerAndKeepsTheBackgroundsOwnNoise) {
  cv::RNG rng(11);
  std::vector<cv::Mat> frames;
  frames.reserve(31);
  for (int i = 0; i < 31; ++i) frames.push_back(Frame(rng, -1, 4.0));
  const RobustBackground b = MedianAndSpread(frames);
  const cv::Mat with_walker = Frame(rng, 15, 4.0);
  double kept = 0;
  const cv::Mat w = Winsorized(with_walker, b, 2.5, &kept);
  double max_value;
  cv::minMaxLoc(w.reshape(1), nullptr, &max_value);
  EXPECT_LT(max_value, 100 + 2.5 * 8) << "the walker is gone";
  EXPECT_GT(kept, 0.65);  // the floor's values stay (a quarter of the frame is walker)
  EXPECT_LT(kept, 0.80);
  // The floor outside the walker is left as it was: its noise is still there.
  cv::Scalar mean, std;
  cv::meanStdDev(w.colRange(0, 10), mean, std);
  EXPECT_GT(std[0], 3);
  EXPECT_EQ(cv::norm(w.colRange(0, 10), with_walker.colRange(0, 10), cv::NORM_INF) <= 2.5 * 8,
            true);
}

TEST(EvenFrameSampler, KeepsAnEvenSpreadOfUnknownManyFrames) {
  for (const int offered : {5, 31, 64, 100, 1000}) {
    EvenFrameSampler s(31);
    cv::Mat f(1, 1, CV_8UC3);
    for (int i = 0; i < offered; ++i) {
      f.setTo(cv::Scalar::all(i % 256));
      s.Offer(f);
    }
    const int n = static_cast<int>(s.frames().size());
    if (offered <= 62) {
      EXPECT_EQ(n, offered);
    } else {
      EXPECT_GE(n, 31) << offered;
      EXPECT_LE(n, 62) << offered;
    }
  }
  EXPECT_EQ(EvenIndices(10, 5), (std::vector<int>{1, 3, 5, 7, 9}));
  EXPECT_EQ(EvenIndices(3, 6), (std::vector<int>{0, 0, 1, 1, 2, 2}));
}

TEST(ParseTimeRange, ReadsSecondsAndNamesTheFlagWhenItCannot) {
  EXPECT_EQ(ParseTimeRange("12.5-30", "--range").start_s, 12.5);
  EXPECT_EQ(ParseTimeRange("12.5-30", "--range").end_s, 30);
  EXPECT_TRUE(std::isinf(ParseTimeRange("5-", "--range").end_s));
  EXPECT_EQ(ParseTimeRange("-7", "--range").start_s, 0);
  for (const char* bad : {"", "5", "a-b", "1-2-3", "3-1", "2-2", "1-inf"}) {
    try {
      ParseTimeRange(bad, "--empty-range");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--empty-range"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace ss
