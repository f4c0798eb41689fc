// pipeline/transitions/visible_jump.h on billboards and on a bank whose differences are known by
// hand (judge_test_bank.h). Here rather than in tests/pipeline: the judge is its one reader
// among the suites, and this suite builds in seconds.
#include "pipeline/transitions/visible_jump.h"

#include <gtest/gtest.h>

#include "tests/judge/judge_test_bank.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

RgbaBillboard Filled(int w, int h, uint8_t value, uint8_t alpha, double ax, double ay) {
  RgbaBillboard b;
  b.width = w;
  b.height = h;
  b.anchor_x_px = ax;
  b.anchor_y_px = ay;
  for (int i = 0; i < w * h; ++i) b.rgba.insert(b.rgba.end(), {value, value, value, alpha});
  return b;
}

TEST(ContactAlignedDifference, CountsAFullyChangedPixelAsOnePx) {
  // Opaque white against transparent: colour 3 x 255 and alpha 255 per pixel, 4 pixels.
  EXPECT_DOUBLE_EQ(
      ContactAlignedDifference_px(Filled(2, 2, 255, 255, 1, 1), Filled(2, 2, 255, 0, 1, 1)), 4.0);
  // Transparent pixels differ in nothing, whatever their colour.
  EXPECT_DOUBLE_EQ(
      ContactAlignedDifference_px(Filled(3, 3, 255, 0, 1, 2), Filled(3, 3, 0, 0, 1, 2)), 0.0);
}

TEST(ContactAlignedDifference, AlignsTheContactPoints) {
  // The same 4x4 patch inside a larger transparent billboard, 3 px right and 1 px down, its
  // contact point moved with it: no difference. Misaligned by a pixel: the patch's edges differ.
  RgbaBillboard patch = Filled(4, 4, 200, 255, 1.5, 3);
  RgbaBillboard framed = Filled(9, 7, 0, 0, 4.5, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      std::copy(patch.Pixel(x, y), patch.Pixel(x, y) + 4,
                framed.rgba.begin() + ((y + 1) * 9 + (x + 3)) * 4);
    }
  }
  EXPECT_DOUBLE_EQ(ContactAlignedDifference_px(patch, framed), 0.0);
  EXPECT_DOUBLE_EQ(ContactAlignedDifference_px(framed, patch), 0.0);
  framed.anchor_x_px += 1;
  // One column appears, one disappears: 2 columns of 4 opaque pixels, colour 200 x 3 + alpha.
  EXPECT_NEAR(ContactAlignedDifference_px(patch, framed), 8 * (3 * 200 + 255) / 1020.0, 1e-12);
}

TEST(ContactAlignedDifference, RefusesAMalformedBillboard) {
  RgbaBillboard bad = Filled(2, 2, 0, 255, 1, 1);
  bad.rgba.pop_back();
  EXPECT_NE(testing::InputErrorOf([&] { ContactAlignedDifference_px(bad, bad); }), "");
}

class VisibleJumpMeterTest : public ::testing::Test {
 protected:
  void SetUp() override { ids_ = testing::ColumnBank::Write(dir_ / "columns.ssbank"); }
  testing::ScratchDir dir_;
  testing::ColumnBank ids_;
};

TEST_F(VisibleJumpMeterTest, MedianStepIsTheBanksOrdinaryFrameStep) {
  const Bank bank(dir_ / "columns.ssbank");
  VisibleJumpMeter meter(bank);
  EXPECT_DOUBLE_EQ(meter.Difference_px(ids_.a[3], ids_.a[4]), 30.0);
  EXPECT_DOUBLE_EQ(meter.MedianStep_px(), testing::ColumnBank::kMedianStep_px);
  // Sampled from a few pairs, the same here (every step is 30 px).
  VisibleJumpMeter sampled(bank, {.max_pairs = 3});
  EXPECT_DOUBLE_EQ(sampled.MedianStep_px(), 30.0);
}

TEST_F(VisibleJumpMeterTest, NaturalSuccessorIsTheNextFrameOfTheClip) {
  const Bank bank(dir_ / "columns.ssbank");
  const VisibleJumpMeter meter(bank);
  EXPECT_EQ(meter.NaturalSuccessor(ids_.a[2]), ids_.a[3]);
  EXPECT_EQ(meter.NaturalSuccessor(ids_.b[9]), std::nullopt);  // the clip's end
  EXPECT_EQ(meter.NaturalSuccessor(123456), std::nullopt);
}

TEST_F(VisibleJumpMeterTest, JumpIsZeroForTheNaturalSuccessorAndLargeForAnotherPicture) {
  const Bank bank(dir_ / "columns.ssbank");
  VisibleJumpMeter meter(bank);
  EXPECT_EQ(meter.Jump(ids_.a[2], ids_.a[3]), 0.0);
  EXPECT_EQ(meter.Jump(ids_.a[2], ids_.c[3]), 0.0);  // C's frame 3 has A's frame 3's pixels
  // One frame early: one ordinary step.
  EXPECT_DOUBLE_EQ(*meter.Jump(ids_.a[2], ids_.a[2]), 1.0);
  // A3 against B5: 18 columns of 20 pixels at 0.75 = 270 px, 9 ordinary steps.
  EXPECT_DOUBLE_EQ(*meter.Jump(ids_.a[2], ids_.b[5]), 9.0);
  EXPECT_EQ(meter.Jump(ids_.a[9], ids_.b[0]), std::nullopt);  // nothing replaced
}

TEST_F(VisibleJumpMeterTest, RefusesBadOptions) {
  const Bank bank(dir_ / "columns.ssbank");
  const std::string why = testing::InputErrorOf([&] { VisibleJumpMeter(bank, {.max_pairs = 0}); });
  EXPECT_NE(why.find("max_pairs"), std::string::npos) << why;
}

}  // namespace
}  // namespace ss
