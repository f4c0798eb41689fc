// The judge (judge/judge.h) on hand-made sequences over the column bank (judge_test_bank.h),
// whose answers are worked out by hand in each test.
#include "judge/judge.h"

#include <gtest/gtest.h>

#include "animate/bank_graph.h"
#include "tests/judge/judge_test_bank.h"
#include "tests/support/error_text.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

class JudgeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    bank_ = dir_ / "columns.ssbank";
    ids_ = testing::ColumnBank::Write(bank_);
    file_.bank_paths = {bank_};
  }
  // A sprite showing `ids` at the given positions (x along +x, all at y).
  static SpriteSequence Sequence(const std::string& name, const std::vector<int64_t>& ids,
                                 const std::vector<double>& x, double y = 0.0) {
    SpriteSequence s;
    s.name = name;
    for (size_t t = 0; t < ids.size(); ++t) {
      s.frames.push_back({0, ids[t]});
      s.positions_m.emplace_back(x.empty() ? 0.0 : x[t], y);
    }
    return s;
  }
  std::vector<int64_t> A(std::initializer_list<int> frames) const { return Pick(ids_.a, frames); }
  std::vector<int64_t> B(std::initializer_list<int> frames) const { return Pick(ids_.b, frames); }
  std::vector<int64_t> C(std::initializer_list<int> frames) const { return Pick(ids_.c, frames); }
  static std::vector<int64_t> Pick(const std::vector<int64_t>& clip,
                                   std::initializer_list<int> frames) {
    std::vector<int64_t> out;
    for (int m : frames) out.push_back(clip[m]);
    return out;
  }

  testing::ScratchDir dir_;
  std::string bank_;
  testing::ColumnBank ids_;
  SequenceFile file_;
};

TEST_F(JudgeTest, StutterIsTheShareOfStepsRepeatingAFrameOfTheWindow) {
  // A0 A1 A2 A3 A1 A2 A3 A4: steps 4, 5 and 6 show frames shown 3 steps before.
  file_.sprites = {Sequence("a", A({0, 1, 2, 3, 1, 2, 3, 4}), {})};
  JudgeOptions options;
  options.jumps = false;
  Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.stutter.steps, 8);
  EXPECT_EQ(j.stutter.repeats, 3);
  EXPECT_DOUBLE_EQ(j.stutter.share, 3.0 / 8);
  EXPECT_FALSE(j.jumps.measured);
  EXPECT_EQ(j.stutter.replayed, 3);
  // Within 2 steps nothing repeats: each frame came back 3 steps later. That is still a loop
  // played again, whatever the window.
  options.stutter_window_steps = 2;
  j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.stutter.repeats, 0);
  EXPECT_DOUBLE_EQ(j.stutter.share, 0.0);
  EXPECT_EQ(j.stutter.replayed, 3);
  EXPECT_DOUBLE_EQ(j.stutter.replayed_share, 3.0 / 8);
}

// A floor sprite crossing +x at 0.3 m/s (1 cm a step at 30 fps), then standing still. Frame 1
// faces +x, frame 2 faces +y (sideways) unless the sequence turns it back by -90 degrees; frame 3
// is upright (no heading).
TEST(MeasureFacing, TheAngleBetweenTheDrawnHeadingAndTheMotion) {
  SpriteSequence s;
  s.name = "mouse";
  for (int t = 0; t < 12; ++t) {
    s.frames.push_back({0, t < 4 ? 1 : 2});
    s.positions_m.emplace_back(0.01 * std::min(t, 8), 0.0);
  }
  const auto heading_of = [](const BankFrameRef& f) -> std::optional<double> {
    if (f.sprite_id == 3) return std::nullopt;
    return f.sprite_id == 1 ? 0.0 : M_PI / 2;
  };
  // Over +-3 steps, steps 0-10 move faster than 0.05 m/s (step 10: 1 cm in 4 steps, 0.075 m/s);
  // step 11's window holds still. Steps 0-3 face the motion, 4-10 slide sideways.
  FacingFigures f = MeasureFacing({s}, 30.0, 0.05, 3, heading_of);
  EXPECT_TRUE(f.measured);
  EXPECT_EQ(f.moving_steps, 11);
  ASSERT_TRUE(f.median_deg && f.p90_deg);
  EXPECT_NEAR(*f.median_deg, 90.0, 1e-9);
  EXPECT_NEAR(*f.p90_deg, 90.0, 1e-9);
  // Turned back by the sequence, the same frames face the way they go.
  s.turns_rad.assign(12, -M_PI / 2);
  for (int t = 0; t < 4; ++t) s.turns_rad[t] = 0.0;
  f = MeasureFacing({s}, 30.0, 0.05, 3, heading_of);
  EXPECT_NEAR(*f.median_deg, 0.0, 1e-9);
  EXPECT_NEAR(*f.p90_deg, 0.0, 1e-9);
  // Upright frames carry no heading: nothing is measured.
  for (BankFrameRef& r : s.frames) r.sprite_id = 3;
  f = MeasureFacing({s}, 30.0, 0.05, 3, heading_of);
  EXPECT_FALSE(f.measured);
  EXPECT_EQ(f.moving_steps, 0);
  EXPECT_FALSE(f.median_deg);
}

TEST_F(JudgeTest, ReplayedCountsALoopPastTheStutterWindow) {
  // A stride of 4 frames played three times (A0-A3 thrice, then A4): no step repeats a frame of
  // the 2 before, but 8 of 13 steps show a frame shown earlier; a second sprite's frames are its
  // own (B0-B2 are not replays of anything).
  file_.sprites = {Sequence("a", A({0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 4}), {}),
                   Sequence("b", B({0, 1, 2}), {})};
  JudgeOptions options;
  options.jumps = false;
  options.stutter_window_steps = 2;
  const Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.stutter.repeats, 0);
  EXPECT_EQ(j.stutter.replayed, 8);
  EXPECT_DOUBLE_EQ(j.stutter.replayed_share, 8.0 / 16);
  EXPECT_NE(JudgementReport(j).find("replayed    50.0 % (8 steps"), std::string::npos)
      << JudgementReport(j);
}

TEST_F(JudgeTest, StutterLeavesOutFramesTaggedStill) {
  // C0-C4 are tagged still: C0 C1 C0 C1 holds still on purpose; C5 C6 C5 repeats once.
  file_.sprites = {Sequence("c", C({0, 1, 0, 1, 5, 6, 5}), {})};
  JudgeOptions options;
  options.jumps = false;
  Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.stutter.still_steps, 4);
  EXPECT_EQ(j.stutter.repeats, 1);
  EXPECT_DOUBLE_EQ(j.stutter.share, 1.0 / 3);
  EXPECT_EQ(j.stutter.replayed, 1);  // C5 again; the still frames held on purpose are not loops
  // Without the still tag every repeat counts: steps 2, 3 and 6 of 7.
  options.still_tags = {};
  j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.stutter.repeats, 3);
  EXPECT_DOUBLE_EQ(j.stutter.share, 3.0 / 7);
}

TEST_F(JudgeTest, ClonesAreSpritesShowingTheSameFramesTogether) {
  // a and b show A0-A3 one step apart (copies); c shows B0-B9, then A0-A4 ten steps after a
  // (not copies).
  file_.sprites = {Sequence("a", A({0, 1, 2, 3, 4}), {}), Sequence("b", A({4, 0, 1, 2, 3}), {}),
                   Sequence("c", B({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}), {})};
  for (const int64_t id : A({0, 1, 2, 3, 4})) file_.sprites[2].frames.push_back({0, id});
  for (size_t t = 0; t < 5; ++t) file_.sprites[2].positions_m.emplace_back(0.0, 0.0);
  JudgeOptions options;
  options.jumps = false;
  Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  // a: 4 of 5 (b shows A0-A3 a step later; A4 four steps before, past the lag of 2); b: 4 of 5
  // likewise; c: none (its A0-A4 come 9-10 steps after theirs).
  EXPECT_EQ(j.clones.steps, 25);
  EXPECT_EQ(j.clones.cloned_steps, 8);
  EXPECT_EQ(j.clones.sprites_cloned, 2);
  EXPECT_DOUBLE_EQ(j.clones.share, 8.0 / 25);
  options.clone_lag_steps = 0;  // only the same step: none
  j = JudgeSequences(file_, file_.bank_paths, nullptr, options);
  EXPECT_EQ(j.clones.cloned_steps, 0);
  EXPECT_EQ(JudgementJson(j)["clones"]["share"], 0.0);
}

TEST_F(JudgeTest, JumpsAreMeasuredAgainstTheNaturalSuccessor) {
  // A8 A9 | A0 A1 A2 | C3 C4 | B5 B6: A9 -> A0 leaves the clip's end (nothing replaced);
  // A2 -> C3 shows A3's pixels (jump 0); C4 -> B5 shows B5 for C5 (A5's pixels): 20 x 20
  // pixels at 0.75 = 300 px, 10 ordinary steps of 30 px.
  file_.sprites = {Sequence("a",
                            {ids_.a[8], ids_.a[9], ids_.a[0], ids_.a[1], ids_.a[2], ids_.c[3],
                             ids_.c[4], ids_.b[5], ids_.b[6]},
                            {})};
  const Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr);
  ASSERT_TRUE(j.jumps.measured);
  EXPECT_EQ(j.jumps.transitions, 3);
  EXPECT_EQ(j.jumps.unmeasured, 1);
  ASSERT_EQ(j.jumps.each.size(), 3u);
  EXPECT_EQ(j.jumps.each[0].step, 2);
  EXPECT_FALSE(j.jumps.each[0].jump.has_value());
  EXPECT_EQ(j.jumps.each[1].natural, ids_.a[3]);
  EXPECT_DOUBLE_EQ(*j.jumps.each[1].jump, 0.0);
  EXPECT_DOUBLE_EQ(*j.jumps.each[2].jump, 10.0);
  EXPECT_DOUBLE_EQ(*j.jumps.median, 5.0);
  EXPECT_DOUBLE_EQ(*j.jumps.p95, 9.5);
  EXPECT_DOUBLE_EQ(*j.jumps.max, 10.0);
  EXPECT_EQ(j.jumps.median_step_px, std::vector<double>{30.0});
  // The report names the most visible first.
  const std::string report = JudgementReport(j);
  EXPECT_NE(report.find("10.00: a step 7 shows sprite " + std::to_string(ids_.b[5]) + " for " +
                        std::to_string(ids_.c[5])),
            std::string::npos)
      << report;
}

TEST_F(JudgeTest, ASequenceOfOneClipHasNoTransitions) {
  file_.sprites = {Sequence("a", A({0, 1, 2, 3, 4}), {})};
  const Judgement j = JudgeSequences(file_, file_.bank_paths, nullptr);
  EXPECT_EQ(j.jumps.transitions, 0);
  EXPECT_FALSE(j.jumps.median.has_value());
  EXPECT_DOUBLE_EQ(j.stutter.share, 0.0);
  EXPECT_EQ(JudgementJson(j)["jumps"]["median"], nullptr);
}

// A spec over the column bank: "a" walks a 0.9 m path along +x and ends at (0.9, 0); "b" stands
// at (0.25, 0.1), on frames tagged still; the two keep 0.2 m apart.
AnimationSpec ColumnSpec(const std::string& bank) {
  AnimationSpec spec;
  spec.path = "columns.yaml";
  spec.bank_paths = {bank};
  SpriteSpecEntry a;
  a.name = "a";
  PathSpec path;
  path.place.field = "sprites[0].constraints[0].path";
  path.points_m = {{0, 0}, {0.9, 0}};
  a.path = path;
  LocationSpec end;
  end.place.field = "sprites[0].constraints[1].location";
  end.target_m = {0.9, 0};
  a.locations = {end};
  SpriteSpecEntry b;
  b.name = "b";
  b.anchor_m = {0.25, 0.1};
  FrameSpec still;
  still.place.field = "sprites[1].constraints[0].frames";
  still.tag = "still";
  b.frames = {still};
  spec.sprites = {a, b};
  spec.collisions = {{{}, {}, 0.2, 1.0}};
  spec.length = LengthSpec{12, 1.0};
  spec.initial_frames = 12;
  return spec;
}

TEST_F(JudgeTest, ConstraintOutcomesOfAPathSweptHalfway) {
  // "a" walks A0..A9 from x = 0 to 0.45 m, 2 cm off the line: half the 0.9 m path.
  std::vector<double> x(10);
  for (int t = 0; t < 10; ++t) x[t] = 0.05 * t;
  file_.sprites = {
      Sequence("a", A({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}), x, 0.02),
      Sequence("b", C({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}), std::vector<double>(10, 0.25), 0.1)};
  const Scene scene(ColumnSpec(bank_), LoadBankGraph({bank_}, {"still"}));
  const Judgement j = JudgeSequences(file_, file_.bank_paths, &scene);
  ASSERT_TRUE(j.constraints_judged);
  ASSERT_EQ(j.paths.size(), 1u);
  EXPECT_NEAR(j.paths[0].swept_share, 0.5, 1e-9);
  EXPECT_EQ(j.paths[0].finished_step, -1);
  EXPECT_NEAR(j.paths[0].max_deviation_m, 0.02, 1e-9);
  EXPECT_NEAR(j.paths[0].median_deviation_m, 0.02, 1e-9);
  EXPECT_EQ(j.paths[0].field, "sprites[0].constraints[0].path");
  // The location's window is the last step: 0.45 m short of the target (and 2 cm aside).
  ASSERT_EQ(j.locations.size(), 1u);
  EXPECT_EQ(j.locations[0].first_step, 9);
  EXPECT_NEAR(j.locations[0].last_m, std::hypot(0.45, 0.02), 1e-9);
  // Closest at x = 0.25 (step 5): 8 cm; closer than 0.2 m at x = 0.1 ... 0.4 (7 steps).
  ASSERT_EQ(j.collisions.size(), 1u);
  EXPECT_NEAR(j.collisions[0].closest_m, 0.08, 1e-9);
  EXPECT_EQ(j.collisions[0].closest_step, 5);
  EXPECT_EQ(j.collisions[0].steps_closer, 7);
  // "b" shows still frames (C0-C4) for 5 of its 10 steps.
  ASSERT_EQ(j.frames.size(), 1u);
  EXPECT_EQ(j.frames[0].steps_on, 5);
  EXPECT_DOUBLE_EQ(j.frames[0].on_share, 0.5);
  EXPECT_EQ(j.frames[0].set, "tag still");
  // Both are 10 frames long against a minimum of 12.
  EXPECT_EQ(j.lengths[0].frames, 10);
  EXPECT_EQ(j.lengths[0].min_frames, 12);
  EXPECT_NE(JudgementReport(j).find("swept 50.0 %"), std::string::npos) << JudgementReport(j);
}

TEST_F(JudgeTest, ASequenceNotOfTheSpecIsRefusedByName) {
  file_.sprites = {Sequence("a", A({0, 1}), {}), Sequence("z", C({0, 1}), {})};
  const Scene scene(ColumnSpec(bank_), LoadBankGraph({bank_}, {"still"}));
  const std::string why =
      testing::InputErrorOf([&] { JudgeSequences(file_, file_.bank_paths, &scene); });
  EXPECT_NE(why.find("sprites[1].name"), std::string::npos) << why;
}

TEST_F(JudgeTest, AStepOfAnotherBankIsRefusedByField) {
  file_.sprites = {Sequence("a", A({0, 1}), {})};
  file_.sprites[0].frames[1].bank = 1;
  const std::string why =
      testing::InputErrorOf([&] { JudgeSequences(file_, file_.bank_paths, nullptr); });
  EXPECT_NE(why.find("sprites[0].steps[1][0]"), std::string::npos) << why;
}

}  // namespace
}  // namespace ss
