// pipeline/transitions/transition_jumps.h: the visible jumps of a transition table, on the bank
// whose differences are known by hand (judge_test_bank.h) and on sprites held in memory.
#include "pipeline/transitions/transition_jumps.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "tests/judge/judge_test_bank.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

class TransitionJumpsTest : public ::testing::Test {
 protected:
  void SetUp() override { ids_ = testing::ColumnBank::Write(dir_ / "columns.ssbank"); }
  testing::ScratchDir dir_;
  testing::ColumnBank ids_;
};

TEST_F(TransitionJumpsTest, SummarizesByKind) {
  const Bank bank(dir_ / "columns.ssbank");
  VisibleJumpMeter meter(bank);
  const std::vector<std::pair<int64_t, int64_t>> table = {
      {ids_.a[2], ids_.a[3]},  // the natural successor: 0
      {ids_.a[4], ids_.a[1]},  // back in its clip: A1 against A5, two columns, 1 step
      {ids_.a[2], ids_.c[3]},  // C3 has A3's pixels: 0
      {ids_.a[2], ids_.b[5]},  // 18 columns of another picture: 9 steps
      {ids_.a[9], ids_.b[0]},  // leaves A's last frame: nothing replaced
  };
  const TransitionJumpSummary s = MeasureTransitionJumps(meter, table);
  EXPECT_EQ(s.transitions, 5);
  EXPECT_DOUBLE_EQ(s.median_step_px, testing::ColumnBank::kMedianStep_px);
  EXPECT_EQ(s.all.sampled, 5);
  EXPECT_EQ(s.all.measured, 4);
  EXPECT_EQ(s.all.unmeasured, 1);
  EXPECT_DOUBLE_EQ(*s.all.median, 0.5);  // of {0, 0, 1, 9}
  EXPECT_DOUBLE_EQ(*s.all.max, 9.0);
  EXPECT_EQ(s.within_clip.measured, 2);
  EXPECT_DOUBLE_EQ(*s.within_clip.median, 0.5);  // of {0, 1}
  EXPECT_EQ(s.joining_clips.sampled, 3);
  EXPECT_EQ(s.joining_clips.unmeasured, 1);
  EXPECT_DOUBLE_EQ(*s.joining_clips.median, 4.5);  // of {0, 9}
  EXPECT_DOUBLE_EQ(*s.joining_clips.p95, 0.95 * 9.0);
  EXPECT_EQ(s.original_mirror.sampled, 0);
  EXPECT_FALSE(s.original_mirror.median);

  const nlohmann::json j = s.ToJson();
  EXPECT_DOUBLE_EQ(j["median"].get<double>(), 0.5);
  EXPECT_EQ(j["by_kind"]["joining_clips"]["measured"], 2);
  EXPECT_TRUE(j["by_kind"]["original_mirror"]["median"].is_null());
  EXPECT_NE(s.ToText().find("median 0.50, p95"), std::string::npos) << s.ToText();
}

TEST_F(TransitionJumpsTest, SamplesEvenlyAndRefusesBadOptions) {
  const Bank bank(dir_ / "columns.ssbank");
  VisibleJumpMeter meter(bank);
  std::vector<std::pair<int64_t, int64_t>> table;
  table.reserve(9);
  // B's frame m against A's frame m + 1 (the natural successor): 270 px, 9 steps.
  for (int m = 0; m < 8; ++m) table.emplace_back(ids_.a[m], ids_.b[m]);
  table.emplace_back(ids_.a[9], ids_.a[0]);  // unmeasured
  const TransitionJumpSummary s = MeasureTransitionJumps(meter, table, {.max_transitions = 3});
  EXPECT_EQ(s.transitions, 9);
  EXPECT_EQ(s.all.sampled, 3);  // the 0th, 3rd and 6th
  EXPECT_EQ(s.all.measured, 3);
  EXPECT_DOUBLE_EQ(*s.all.p95, 9.0);
  const TransitionJumpSummary none = MeasureTransitionJumps(meter, table, {.max_transitions = 0});
  EXPECT_EQ(none.all.sampled, 0);
  EXPECT_EQ(none.median_step_px, 0.0);
  const std::string why =
      testing::InputErrorOf([&] { MeasureTransitionJumps(meter, table, {.max_transitions = -1}); });
  EXPECT_NE(why.find("max_transitions"), std::string::npos) << why;
}

RgbaBillboard Column(int column, bool mirrored) {
  RgbaBillboard b;
  b.width = b.height = 8;
  b.anchor_x_px = 4;
  b.anchor_y_px = 7;
  b.rgba.assign(8 * 8 * 4, 255);
  for (int y = 0; y < 8; ++y) {
    uint8_t* p = b.rgba.data() + (y * 8 + (mirrored ? 7 - column : column)) * 4;
    p[0] = p[1] = p[2] = 0;
  }
  return b;
}

TEST(TransitionJumps, TellsOriginalsFromMirrorsInMemory) {
  // One clip of 4 frames (ids 1-4) and its mirror (ids 11-14), billboards in memory.
  std::vector<JumpFrame> frames;
  for (int m = 0; m < 4; ++m) {
    frames.push_back({1 + m, 1, false, m < 3 ? std::optional<int64_t>(2 + m) : std::nullopt});
    frames.push_back({11 + m, 1, true, m < 3 ? std::optional<int64_t>(12 + m) : std::nullopt});
  }
  int loads = 0;
  VisibleJumpMeter meter(
      frames,
      [&](int64_t id) {
        ++loads;
        if (id >= 11 && id <= 14) return Column(static_cast<int>(id - 11), true);
        if (id >= 1 && id <= 4) return Column(static_cast<int>(id - 1), false);
        throw std::out_of_range("no sprite " + std::to_string(id));
      },
      "");
  EXPECT_EQ(meter.KindOf(1, 3), TransitionKind::kWithinClip);
  EXPECT_EQ(meter.KindOf(2, 13), TransitionKind::kOriginalMirror);
  EXPECT_EQ(meter.KindOf(2, 99), std::nullopt);
  // Every step moves the black column by one: 2 columns of 8 pixels at 0.75 = 12 px.
  EXPECT_DOUBLE_EQ(meter.MedianStep_px(), 12.0);
  const TransitionJumpSummary s = MeasureTransitionJumps(meter, {{1, 2}, {1, 12}, {2, 99}});
  EXPECT_EQ(s.all.sampled, 3);
  EXPECT_EQ(s.all.unmeasured, 1);  // 99 is no sprite
  EXPECT_EQ(s.within_clip.measured, 1);
  EXPECT_DOUBLE_EQ(*s.within_clip.median, 0.0);
  EXPECT_EQ(s.original_mirror.measured, 1);
  // Mirrored column 1 is at x = 6, the natural successor's at x = 1: one step.
  EXPECT_DOUBLE_EQ(*s.original_mirror.median, 1.0);
  EXPECT_GT(loads, 0);
}

}  // namespace
}  // namespace ss
