// SideBySide (issue 19): a billboard matte of two subjects side by side, told from one subject
// by a split into two tall parts and a width above one subject's (ClipBatcher::MarkMerged, which
// tags the clip's sprites held back from before the split showed: clip_batcher_test.cc).
#include "pipeline/track/side_by_side.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ss {
namespace {

constexpr double kPxPerM = 40;

// A billboard matte (BGRA, alpha 255 inside) 2.5 m wide and 2 m tall with people as boxes:
// each {left, width, top} in metres, standing on the bottom row.
cv::Mat Billboard(const std::vector<cv::Vec3d>& people) {
  cv::Mat bgra(static_cast<int>(2 * kPxPerM), static_cast<int>(2.5 * kPxPerM), CV_8UC4,
               cv::Scalar(0, 0, 0, 0));
  for (const cv::Vec3d& p : people) {
    const cv::Point tl(static_cast<int>(p[0] * kPxPerM), static_cast<int>(p[2] * kPxPerM));
    const cv::Point br(static_cast<int>((p[0] + p[1]) * kPxPerM), bgra.rows);
    cv::rectangle(bgra, cv::Rect(tl, br), cv::Scalar(20, 30, 40, 255), cv::FILLED);
  }
  return bgra;
}

TEST(SideBySide, TwoPeopleApartSplitAndOneDoesNot) {
  const SideBySideOptions o;
  // Two 0.5 m wide people 0.1 m apart: the matte splits, 1.1 m wide less the 5 % of its matte
  // at each side.
  const MatteLook two = MeasureMatteLook(Billboard({{0.2, 0.5, 0.3}, {0.8, 0.5, 0.2}}), kPxPerM, o);
  EXPECT_TRUE(two.split);
  EXPECT_NEAR(two.width_m, 1.0, 0.05);
  // One person: no column is nearly empty with a quarter of the matte on each side.
  const MatteLook one = MeasureMatteLook(Billboard({{0.9, 0.5, 0.2}}), kPxPerM, o);
  EXPECT_FALSE(one.split);
  EXPECT_NEAR(one.width_m, 0.45, 0.05);
  // A hand apart from the body: too small a part, and too short.
  EXPECT_FALSE(MeasureMatteLook(Billboard({{0.9, 0.5, 0.2}, {1.45, 0.1, 1.0}}), kPxPerM, o).split);
  // A child of 1.2 m beside an adult of 1.8 m is two: 2/3 of the whole's height, over
  // min_part_height; a bag of 0.6 m on the floor beside one is not.
  EXPECT_TRUE(MeasureMatteLook(Billboard({{0.3, 0.5, 0.2}, {0.9, 0.45, 0.8}}), kPxPerM, o).split);
  EXPECT_FALSE(MeasureMatteLook(Billboard({{0.3, 0.5, 0.2}, {0.9, 0.6, 1.4}}), kPxPerM, o).split);
  // Joined at the shoulders, the neck is not empty: no split (width alone does not say two).
  EXPECT_FALSE(
      MeasureMatteLook(Billboard({{0.2, 0.5, 0.3}, {0.8, 0.5, 0.2}, {0.6, 0.3, 0.4}}), kPxPerM, o)
          .split);
  // A single-channel matte reads the same.
  cv::Mat alpha;
  cv::extractChannel(Billboard({{0.2, 0.5, 0.3}, {0.8, 0.5, 0.2}}), alpha, 3);
  EXPECT_TRUE(MeasureMatteLook(alpha, kPxPerM, o).split);
  EXPECT_FALSE(MeasureMatteLook(cv::Mat::zeros(10, 10, CV_8U), kPxPerM, o).split);
}

TEST(SideBySide, WideIsAgainstTheMedianOfOneSubject) {
  SideBySide judge;
  // No verdict before min_widths sprites of one subject.
  EXPECT_FALSE(judge.IsWide(5.0));
  for (int i = 0; i < SideBySideOptions{}.min_widths - 1; ++i) judge.AddOne(0.5);
  EXPECT_FALSE(judge.IsWide(5.0));
  judge.AddOne(0.5);
  EXPECT_DOUBLE_EQ(judge.median_width_m(), 0.5);
  EXPECT_TRUE(judge.IsWide(0.76));   // 1.5 x 0.5 = 0.75
  EXPECT_FALSE(judge.IsWide(0.74));  // a subject whose matte broke in two: one wide
  // The median follows the camera's subjects: a window of median_window widths.
  for (int i = 0; i < SideBySideOptions{}.median_window; ++i) judge.AddOne(0.2);
  EXPECT_DOUBLE_EQ(judge.median_width_m(), 0.2);
  EXPECT_TRUE(judge.IsWide(0.31));
  // Off.
  SideBySide off({.min_width_ratio = 0});
  for (int i = 0; i < 50; ++i) off.AddOne(0.5);
  EXPECT_FALSE(off.IsWide(100));
}

TEST(SideBySide, OptionsNameTheirFields) {
  SideBySideOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.min_width_ratio = 0.5;
  o.max_neck_share = 2;
  o.min_widths = 500;
  EXPECT_FALSE(o.IsValid(&why));
  for (const char* field : {"min_width_ratio: ", "max_neck_share: ", "min_widths: "})
    EXPECT_NE(why.find(field), std::string::npos) << field << " in " << why;
  EXPECT_THROW(SideBySide{o}, InputError);
}

}  // namespace
}  // namespace ss
