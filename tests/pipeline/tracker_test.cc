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

using Blob = MergeDetector::Blob;

// Two subjects seen apart, then in one blob (the tracker keeps one id, loses the other), then
// apart again: the blob is merged from the frame they meet to the frame they split.
TEST(MergeDetector, TwoTracksInOneBlobAreMergedUntilTheySplit) {
  MergeDetector d;
  const cv::Rect a(100, 100, 30, 40), b(150, 100, 30, 40), both(100, 100, 80, 40);
  for (int f = 0; f < 5; ++f)
    EXPECT_EQ(d.Update({{0, a, 1000}, {1, b, 1000}}), std::vector<bool>({false, false}));
  for (int f = 0; f < 10; ++f) EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({true}));
  // The tracker gives the blob a new id (its contact point jumped): still both subjects.
  EXPECT_EQ(d.Update({{2, both, 1900}}), std::vector<bool>({true}));
  // Apart: the blob's own track and one found again (or new) inside its box.
  EXPECT_EQ(d.Update({{2, a, 1000}, {1, b, 1000}}), std::vector<bool>({false, false}));
  EXPECT_EQ(d.Update({{2, a, 1000}, {1, b, 1000}}), std::vector<bool>({false, false}));
  // And together again at once: the pieces of a merged blob are subjects.
  EXPECT_EQ(d.Update({{2, both, 2000}}), std::vector<bool>({true}));
}

// A piece of one subject keyed apart for a frame and joined again is no second subject.
TEST(MergeDetector, APieceOfOneSubjectIsNoSecondSubject) {
  MergeDetector d;
  const cv::Rect body(100, 100, 60, 40), head(100, 100, 20, 20), rest(125, 100, 35, 40);
  for (int f = 0; f < 5; ++f) EXPECT_EQ(d.Update({{0, body, 1500}}), std::vector<bool>({false}));
  EXPECT_EQ(d.Update({{0, rest, 1100}, {1, head, 400}}), std::vector<bool>({false, false}));
  for (int f = 0; f < 5; ++f) EXPECT_EQ(d.Update({{0, body, 1500}}), std::vector<bool>({false}));
}

// A merged blob that shrinks to less than half its area at the merge holds one subject again
// (the other left unseen, e.g. behind a wall); a lost frame forgets everything.
TEST(MergeDetector, AMergedBlobThatShrinksToOneSubjectIsNoLongerMerged) {
  MergeDetector d;
  const cv::Rect a(100, 100, 30, 40), b(140, 100, 30, 40), both(100, 100, 70, 40);
  for (int f = 0; f < 5; ++f) d.Update({{0, a, 1000}, {1, b, 1000}});
  EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({true}));
  EXPECT_EQ(d.Update({{0, both, 1200}}), std::vector<bool>({true}));
  EXPECT_EQ(d.Update({{0, a, 950}}), std::vector<bool>({false}));
  EXPECT_EQ(d.Update({{0, a, 1000}}), std::vector<bool>({false}));
  d.Update({{0, a, 1000}, {1, b, 1000}});
  d.Update({{0, a, 1000}, {1, b, 1000}});
  d.Update({{0, a, 1000}, {1, b, 1000}});
  EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({true}));
  d.Reset();
  EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({false}));
}

// A subject lost for a frame and found again under a new id, whose box lies inside both its own
// track's box and a big blob's box (a crowd at the frame's edge): it came out of its own track,
// not of both (vtest.avi frame 152: one person tagged merged).
TEST(MergeDetector, APieceInsideTwoTracksBoxesCameOutOfTheTighterOne) {
  MergeDetector d;
  const cv::Rect crowd(100, 0, 600, 300), person(400, 200, 60, 100);
  for (int f = 0; f < 5; ++f) {
    d.Update({{0, cv::Rect(100, 0, 200, 150), 3000}, {1, cv::Rect(400, 0, 200, 150), 3000}});
  }
  // The two meet in one blob whose box grows over the person's.
  EXPECT_EQ(d.Update({{0, crowd, 6000}, {2, person, 1300}}), std::vector<bool>({true, false}));
  // The person, under a new id (its contact point jumped), and the crowd under a new id too.
  EXPECT_EQ(d.Update({{3, crowd, 6000}, {4, cv::Rect(404, 202, 56, 100), 1300}}),
            std::vector<bool>({true, false}));
  EXPECT_EQ(d.Update({{3, crowd, 6000}, {4, cv::Rect(410, 202, 56, 100), 1300}}),
            std::vector<bool>({true, false}));
}

// A small subject swallowed by a big one's blob comes out again under its own id: the big one's
// piece keeps most of the area but holds one subject again (vtest.avi frame 212: a person
// tagged merged for 20 frames after the other had left).
TEST(MergeDetector, ASwallowedTrackComingOutAgainTakesItsCountAlong) {
  MergeDetector d;
  const cv::Rect big(100, 100, 40, 100), small(150, 60, 20, 40), both(100, 60, 70, 140);
  for (int f = 0; f < 5; ++f) d.Update({{0, big, 1500}, {1, small, 500}});
  EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({true}));
  EXPECT_EQ(d.Update({{0, both, 2000}}), std::vector<bool>({true}));
  // Apart again; the big one keeps 3/4 of the merged area.
  EXPECT_EQ(d.Update({{0, big, 1550}, {1, small, 500}}), std::vector<bool>({false, false}));
  EXPECT_EQ(d.Update({{0, big, 1550}, {1, small, 500}}), std::vector<bool>({false, false}));
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
