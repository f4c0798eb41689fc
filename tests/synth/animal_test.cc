// The animal's body and behaviour, without rendering: it stands on the floor,
// stays inside the enclosure, and over a few minutes shows every behaviour.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "synth/animal.h"
#include "synth/directors.h"
#include "synth/scene.h"

namespace ss::synth {
namespace {

TEST(AnimalBody, PawsRestOnTheFloorAndNothingSinksBelowIt) {
  AnimalLook look;
  AnimalState s;
  s.position = {0.1, -0.05};
  s.heading_rad = 0.7;
  double lowest = 1e9;
  for (const Primitive& p : AnimalPrimitives(look, s, 0)) lowest = std::min(lowest, p.LowestZ());
  EXPECT_NEAR(lowest, 0.0, 1e-9);
  // Walking: some paw is always on the floor; no part below it.
  s.speed_mps = 0.1;
  s.stepping = 1.0;
  for (double phase = 0; phase < 1.0; phase += 0.05) {
    s.gait_phase = phase;
    lowest = 1e9;
    for (const Primitive& p : AnimalPrimitives(look, s, 0)) lowest = std::min(lowest, p.LowestZ());
    EXPECT_NEAR(lowest, 0.0, 1e-9) << "phase " << phase;
  }
}

TEST(AnimalBody, RearingRaisesTheHeadAndLeanReachesForward) {
  AnimalLook look;
  AnimalState s;
  auto top = [&](const AnimalState& st) {
    double z = 0;
    for (const Primitive& p : AnimalPrimitives(look, st, 0)) z = std::max(z, p.HighestZ());
    return z;
  };
  const double on_all_fours = top(s);
  s.rear = 1.0;
  EXPECT_GT(top(s), on_all_fours + 0.05);
  EXPECT_GT(LeanReach(look), 0.03);
  EXPECT_LT(LeanReach(look), 0.12);
}

// Runs one animal's behaviour for `seconds` and collects what it did.
struct SimRun {
  std::map<std::string, int> poses;
  int wall_touches = 0, lean_frames = 0, lean_touching = 0, left_floor = 0;
  double max_speed = 0;
};

SimRun Simulate(uint64_t seed, double seconds, int subjects = 1) {
  const Studio studio = MakeStudio(StudioKind::kEnclosure, seed);
  const auto cameras = MakeCameras(studio, 2, 160, 120, seed);
  DirectorOptions o;
  o.seed = seed;
  o.subjects = subjects;
  auto director = MakeAnimalDirector(studio, cameras, o);
  SimRun run;
  FrameSnapshot snap;
  for (int f = 0; f < seconds * 30; ++f) {
    director->Frame(f / 30.0, &snap);
    for (const SubjectTruth& t : snap.subjects) {
      run.poses[t.pose] += 1;
      run.wall_touches += t.touches_wall;
      run.left_floor += t.leaves_floor;
      run.max_speed = std::max(run.max_speed, t.speed_mps);
      if (t.pose == "lean") {
        ++run.lean_frames;
        run.lean_touching += t.touches_wall;
      }
      EXPECT_TRUE(studio.floor.ContainsWithMargin(t.position, 0.02)) << t.position.transpose();
    }
  }
  return run;
}

TEST(AnimalBehaviour, ShowsEveryBehaviourAndStaysOnTheFloor) {
  std::set<std::string> seen;
  int lean_frames = 0, lean_touching = 0;
  for (uint64_t seed : {1, 2, 3}) {
    const SimRun run = Simulate(seed, 200.0);
    for (const auto& [pose, n] : run.poses) seen.insert(pose);
    EXPECT_EQ(run.left_floor, 0);
    EXPECT_LT(run.max_speed, 0.55);  // runs in bursts up to ~0.5 m/s (scale up to 1.12)
    // Rests: some of the time is spent idle (mostly it explores, tests/synth/motion_test.cc).
    EXPECT_GT(run.poses.count("idle") ? run.poses.at("idle") : 0, 200 * 30 / 20) << "seed " << seed;
    lean_frames += run.lean_frames;
    lean_touching += run.lean_touching;
  }
  for (const char* pose : {"walk", "trot", "turn", "idle", "lean", "stand"})
    EXPECT_TRUE(seen.count(pose)) << pose;
  ASSERT_GT(lean_frames, 0);
  EXPECT_EQ(lean_touching, lean_frames);  // leaning means paws on the wall
}

TEST(AnimalBehaviour, SeveralAnimalsKeepApartAndDeterministic) {
  const Studio studio = MakeStudio(StudioKind::kEnclosure, 5);
  const auto cameras = MakeCameras(studio, 1, 160, 120, 5);
  DirectorOptions o;
  o.seed = 5;
  o.subjects = 3;
  auto a = MakeAnimalDirector(studio, cameras, o);
  auto b = MakeAnimalDirector(studio, cameras, o);
  FrameSnapshot sa, sb;
  double closest = 1e9;
  for (int f = 0; f < 60 * 30; ++f) {
    a->Frame(f / 30.0, &sa);
    b->Frame(f / 30.0, &sb);
    ASSERT_EQ(sa.subjects.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      ASSERT_EQ(sa.subjects[i].position, sb.subjects[i].position);
      for (size_t j = i + 1; j < 3; ++j) {
        closest = std::min(closest, (sa.subjects[i].position - sa.subjects[j].position).norm());
      }
    }
  }
  EXPECT_GT(closest, 0.10);
}

}  // namespace
}  // namespace ss::synth
