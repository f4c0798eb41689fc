// SideBySide (issue 19): a billboard matte of two subjects side by side, told from one subject
// by a split into two tall parts and a width above one subject's; and ClipBatcher::MarkMerged,
// which tags the clip's sprites held back from before the split showed.
#include "pipeline/track/side_by_side.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "pipeline/run/clip_batcher.h"

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

MadeSprite Sprite(int64_t f, double width_m) {
  MadeSprite s;
  s.frame = f;
  s.timestamp_ns = f * 100'000'000;
  s.billboard.bgra = cv::Mat(20, 11, CV_8UC4, cv::Scalar(1, 2, 3, 255));
  s.billboard.shadow = cv::Mat::zeros(9, 9, CV_8U);
  s.billboard.anchor_px = Eigen::Vector2d(5, 19);
  s.billboard.point_in_ground = Eigen::Vector3d(0.1 * f, 0, 0);
  s.billboard.right_in_ground = Eigen::Vector2d(1, 0);
  s.billboard.toward_camera = Eigen::Vector2d(0, -1);
  s.billboard.px_per_m = 40;
  s.matte_width_m = width_m;
  return s;
}

// A pair walked in together: frames 0-3 went out in a first batch, 4-6 are held back when frame 6
// shows the split. MarkMerged tags the wide ones still held; the narrow one (the pair one behind
// the other) and the sprites already handed out stay as they are.
TEST(ClipBatcher, MarkMergedTagsTheWideSpritesStillHeld) {
  ClipBatcher batcher(
      1, {.min_clip_frames = 2, .batch_frames = 4, .velocity_half_window = 1, .mirrors = false});
  std::vector<ClipBatch> out;
  const std::vector<double> widths = {1.0, 1.1, 1.0, 1.2, 0.5, 1.1, 1.0};  // one is 0.5 m
  for (int f = 0; f < 7; ++f) batcher.Add(4, 2, Sprite(f, widths[f]), &out);
  const size_t handed_out = out.empty() ? 0 : out[0].sprites.size();
  ASSERT_EQ(handed_out, 4u);  // frames 0-3 (batch_frames 4, one held for the velocity)
  batcher.MarkMerged(4, 0.75);
  batcher.MarkMerged(99, 0.75);  // no such clip: nothing
  batcher.Close(4, &out);
  std::vector<int64_t> tagged;
  for (const ClipBatch& b : out) {
    for (const SpriteRecord& r : b.sprites)
      if (!r.tags.empty()) tagged.push_back(r.frame);
  }
  EXPECT_EQ(tagged, (std::vector<int64_t>{5, 6}));
  EXPECT_EQ(batcher.stored_merged_originals(), 2u);
}

}  // namespace
}  // namespace ss
