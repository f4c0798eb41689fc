#include "pipeline/describe/sprite_description.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ss {
namespace {

TEST(DescribeBillboard, EllipseGivesItsAreaColourAndEccentricity) {
  cv::Mat bgra(200, 300, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  const double a = 80, b = 30;  // semi-axes, pixels; rotated 30 degrees
  cv::ellipse(bgra, cv::Point(150, 100), cv::Size(static_cast<int>(a), static_cast<int>(b)), 30, 0,
              360, cv::Scalar(10, 200, 90, 255), cv::FILLED);
  const SpriteDescription d = DescribeBillboard(bgra);
  // OpenCV fills every pixel the outline touches: the area of the half-pixel-grown ellipse.
  EXPECT_NEAR(d.area_px, M_PI * (a + 0.5) * (b + 0.5), 0.01 * M_PI * a * b);
  EXPECT_NEAR(d.mean_b, 10, 1e-9);
  EXPECT_NEAR(d.mean_g, 200, 1e-9);
  EXPECT_NEAR(d.mean_r, 90, 1e-9);
  EXPECT_NEAR(d.eccentricity, std::sqrt(1 - (b * b) / (a * a)), 0.01);
}

TEST(DescribeBillboard, DiscIsRoundAndHalfAlphaCountsHalf) {
  cv::Mat bgra(101, 101, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  cv::circle(bgra, cv::Point(50, 50), 40, cv::Scalar(255, 255, 255, 255), cv::FILLED);
  const double full = DescribeBillboard(bgra).area_px;
  EXPECT_LT(DescribeBillboard(bgra).eccentricity, 0.1);
  // Half alpha everywhere: half the area, same colour.
  std::vector<cv::Mat> ch;
  cv::split(bgra, ch);
  ch[3] /= 2;  // 255 / 2 rounds to 128
  cv::merge(ch, bgra);
  const SpriteDescription half = DescribeBillboard(bgra);
  EXPECT_NEAR(half.area_px, full * 128.0 / 255.0, 1.0);
  EXPECT_NEAR(half.mean_r, 255, 1e-9);
}

TEST(DescribeBillboard, EmptyMatteAndWrongTypes) {
  const SpriteDescription d = DescribeBillboard(cv::Mat(10, 10, CV_8UC4, cv::Scalar(0, 255, 0, 0)));
  EXPECT_EQ(d.area_px, 0);
  EXPECT_EQ(d.eccentricity, 0);
  EXPECT_THROW(DescribeBillboard(cv::Mat(10, 10, CV_8UC3)), InputError);
}

TEST(EstimateVelocities, RecoversAConstantVelocityDespiteUnevenTiming) {
  std::vector<int64_t> t;
  std::vector<Eigen::Vector2d> p;
  const Eigen::Vector2d v(0.3, -0.12);
  int64_t now = 1'000'000'000;
  for (int i = 0; i < 12; ++i) {
    now += (i % 3 == 0) ? 40'000'000 : 33'333'333;
    t.push_back(now);
    p.push_back(Eigen::Vector2d(0.1, 0.2) + v * (now * 1e-9));
  }
  for (const Eigen::Vector2d& e : EstimateVelocities(t, p, 2)) EXPECT_LT((e - v).norm(), 1e-9);
}

TEST(EstimateVelocities, OneFrameStandsStillAndNoiseIsSmoothed) {
  EXPECT_EQ(EstimateVelocities({5}, {Eigen::Vector2d(1, 1)})[0], Eigen::Vector2d::Zero());
  // Alternating +-1 mm jitter on a still subject: the 5-frame slope stays far below the jitter's 6
  // cm/s.
  std::vector<int64_t> t;
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < 20; ++i) {
    t.push_back(i * 33'333'333LL);
    p.push_back(Eigen::Vector2d((i % 2 ? 1 : -1) * 0.001, 0));
  }
  const auto v = EstimateVelocities(t, p, 2);
  for (int i = 2; i < 18; ++i) EXPECT_LT(v[i].norm(), 0.025) << i;
  EXPECT_THROW(EstimateVelocities({1, 2}, {Eigen::Vector2d::Zero()}), InputError);
}

}  // namespace
}  // namespace ss
