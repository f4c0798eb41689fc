#include "pipeline/track/tracker.h"

#include <gtest/gtest.h>

namespace ss {
namespace {

constexpr int64_t kFrameNs = 33'333'333;

TEST(Tracker, TwoSubjectsKeepTheirIdsWhileCrossingPaths) {
  Tracker tracker;
  // Two subjects walking towards each other along x at 0.3 m/s, 4 cm apart in y.
  std::vector<int> first;
  for (int f = 0; f < 60; ++f) {
    const double x = -0.3 + 0.3 * f / 30.0;
    const std::vector<TrackInput> in = {{Eigen::Vector2d(x, 0.0), 1000},
                                        {Eigen::Vector2d(-x, 0.04), 1000}};
    const auto ids = tracker.Update(f * kFrameNs, in);
    if (f == 0) first = ids;
    EXPECT_EQ(ids, first) << "frame " << f;
  }
  EXPECT_NE(first[0], first[1]);
  EXPECT_EQ(tracker.live_subjects(), 2);
}

TEST(Tracker, AJumpBeyondTheSpeedLimitIsANewSubject) {
  Tracker tracker;
  const auto a = tracker.Update(0, {{Eigen::Vector2d(0, 0), 500}});
  const auto b = tracker.Update(kFrameNs, {{Eigen::Vector2d(0.5, 0), 500}});
  EXPECT_NE(a[0], b[0]);
  // A blob three times as large is not the same sprite either.
  const auto c = tracker.Update(2 * kFrameNs, {{Eigen::Vector2d(0.5, 0), 1600}});
  EXPECT_NE(b[0], c[0]);
}

TEST(Tracker, SubjectsUnseenForTooLongAreForgotten) {
  Tracker tracker;
  tracker.Update(0, {{Eigen::Vector2d(0, 0), 500}});
  tracker.Update(kFrameNs, {});
  EXPECT_EQ(tracker.live_subjects(), 1);
  tracker.Update(kFrameNs * 40, {});
  EXPECT_EQ(tracker.live_subjects(), 0);
}

TEST(ClipCutter, ClipsAreRunsOfConsecutiveUsableFrames) {
  ClipCutter cutter;
  // Subject 7: usable, usable, unusable, usable, then unseen.
  auto e = cutter.Update({7}, {true});
  ASSERT_EQ(e.size(), 1u);
  const int64_t first = e[0].clip;
  EXPECT_GE(first, 0);
  e = cutter.Update({7}, {true});
  EXPECT_EQ(e[0].clip, first);
  e = cutter.Update({7}, {false});
  EXPECT_EQ(e[0].clip, -1);
  EXPECT_TRUE(e[0].closes);
  EXPECT_EQ(e[0].closed_clip, first);
  e = cutter.Update({7}, {true});
  const int64_t second = e[0].clip;
  EXPECT_NE(second, first);
  e = cutter.Update({}, {});
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(e[0].closes);
  EXPECT_EQ(e[0].closed_clip, second);
  EXPECT_TRUE(cutter.CloseAll().empty());
}

TEST(ClipCutter, CloseAllEndsOpenClips) {
  ClipCutter cutter;
  cutter.Update({1, 2}, {true, true});
  EXPECT_EQ(cutter.CloseAll().size(), 2u);
}

}  // namespace
}  // namespace ss
