// The synthetic subjects move like the animals they stand for (docs/synth.md, "How the subjects
// move"): asserted on their truth over a short simulated run, without rendering.
#include <gtest/gtest.h>

#include "synth/directors.h"
#include "synth/motion_stats.h"
#include "synth/scene.h"

namespace ss::synth {
namespace {

MotionStats SimulatedStats(bool fly, uint64_t seed, double seconds, int subjects) {
  const Studio studio = MakeStudio(StudioKind::kEnclosure, seed);
  const auto cameras = MakeCameras(studio, 1, 160, 120, seed);
  DirectorOptions o;
  o.seed = seed;
  o.subjects = subjects;
  auto director = fly ? MakeFlyDirector(studio, o) : MakeAnimalDirector(studio, cameras, o);
  std::vector<MotionSample> samples;
  FrameSnapshot snap;
  for (int f = 0; f < seconds * 30; ++f) {
    director->Frame(f / 30.0, &snap);
    for (size_t i = 0; i < snap.subjects.size(); ++i) {
      const SubjectTruth& t = snap.subjects[i];
      samples.push_back(
          {f, static_cast<int>(i), t.position, t.heading_rad, t.speed_mps, t.pose, t.touches_wall});
    }
  }
  return MeasureMotion(samples, 30.0, studio.half_x, studio.half_y);
}

double Share(const MotionStats& s, const std::string& pose) {
  return s.pose_share.count(pose) ? s.pose_share.at(pose) : 0.0;
}

TEST(SynthMotion, TheHamsterWalksRunsTurnsBothWaysAndCrossesTheFloor) {
  const MotionStats s = SimulatedStats(false, 4, 300.0, 1);
  SCOPED_TRACE(MotionStatsText(s));
  // Walks at 0.1-0.2 m/s, runs in bursts up to ~0.5 m/s.
  EXPECT_GE(s.speed_median_mps, 0.08);
  EXPECT_LE(s.speed_median_mps, 0.2);
  EXPECT_GE(s.speed_p99_mps, 0.3);
  EXPECT_LE(s.speed_max_mps, 0.55);
  EXPECT_GE(s.running_share, 0.03);
  EXPECT_GE(s.moving_share, 0.6);
  // Turns both ways, about as often.
  EXPECT_GE(s.turning_left_share, 0.15);
  EXPECT_GE(s.turning_right_share, 0.15);
  // Crosses the open floor rather than following the walls.
  EXPECT_LE(s.wall_touch_share, 0.06);
  EXPECT_LE(s.near_wall_share, 0.35);
  EXPECT_GE(s.centre_share, 0.2);
  EXPECT_GE(s.cells_visited_share, 0.6);
  // Stands up, but rarely.
  EXPECT_LE(Share(s, "stand"), 0.04);
}

TEST(SynthMotion, FliesSitStillMostlyWalkAndDart) {
  const MotionStats s = SimulatedStats(true, 4, 120.0, 4);
  SCOPED_TRACE(MotionStatsText(s));
  EXPECT_GE(Share(s, "sit") + Share(s, "groom"), 0.5);
  EXPECT_GE(Share(s, "walk"), 0.1);
  EXPECT_GE(Share(s, "dart"), 0.01);
  EXPECT_LE(s.moving_share, 0.5);
  EXPECT_GE(s.speed_p99_mps, 0.25);
  EXPECT_GE(s.turning_left_share, 0.05);
  EXPECT_GE(s.turning_right_share, 0.05);
  EXPECT_LE(s.wall_touch_share, 0.1);
}

}  // namespace
}  // namespace ss::synth
