#pragma once
// The studio's animal: a hamster-like articulated body (torso, rump, head,
// ears, eyes, nose, four legs with paws, tail) built from primitives, posed from
// an AnimalState (ground position, heading, gait phase, rearing and leaning),
// and a behaviour model that walks across the open floor (0.1-0.2 m/s) toward
// places it picks, runs in short bursts (up to ~0.5 m/s), turns both ways,
// pauses and idles, now and then leans on a wall and, very rarely, rears up
// facing a camera.
//
// Animal frame: x forward, y left, z up; origin on the floor under the body
// centre (the "root"; it stays put while the animal rears on its hind legs).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "synth/primitives.h"
#include "synth/random.h"
#include "synth/scene.h"

namespace ss::synth {

// How one animal looks: size and coat.
struct AnimalLook {
  double scale = 1.0;                          // 1: body 0.16 m nose to tail
  Eigen::Vector3f fur{0.22f, 0.42f, 0.68f};    // B G R albedo of the back
  Eigen::Vector3f belly{0.72f, 0.82f, 0.88f};  // belly and muzzle
  uint64_t seed = 0;                           // fur texture
};

// A look drawn from a few coats (golden, grey, dark brown, cream) and sizes.
AnimalLook RandomAnimalLook(uint64_t seed);

// The articulation at one instant.
struct AnimalState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // root, ground x y
  double heading_rad = 0.0;   // direction of the nose, from the ground x axis
  double speed_mps = 0.0;     // forward speed of the root
  double gait_phase = 0.0;    // [0, 1): cycle of the legs (frozen when still)
  double stepping = 0.0;      // 0..1: amplitude of the leg cycle (0 standing still)
  double trot = 0.0;          // 0: walk leg pattern, 1: trot (diagonal pairs)
  double stride_m = 0.06;     // length of one gait cycle
  double rear = 0.0;          // 0..1: on all fours .. upright on the hind legs
  double lean = 0.0;          // 0..1: front paws raised onto a wall ahead
  double head_yaw_rad = 0.0;  // looking around
  double time_s = 0.0;        // for breathing and sniffing
  std::string pose = "idle";  // walk, trot, turn, idle, lean, stand
};

// The body's primitives in the ground frame, tagged with `subject` and `slice`.
std::vector<Primitive> AnimalPrimitives(const AnimalLook& look, const AnimalState& state,
                                        int subject, int slice = 0);

// Forward reach of the body (from the root, along the heading) at a lean of 0..1.
double ForwardReach(const AnimalLook& look, double lean);
// ForwardReach at full lean: the front paws up on a wall.
double LeanReach(const AnimalLook& look);

// The behaviour model: a seeded sequence of activities integrated in time.
class AnimalBehaviour {
 public:
  // `cameras`: ground positions of the camera centres (the animal rears facing one).
  AnimalBehaviour(const Studio& studio, const AnimalLook& look, uint64_t seed,
                  const Eigen::Vector2d& start, double heading_rad,
                  std::vector<Eigen::Vector3d> cameras);
  // Advances by dt seconds; `others` are the other animals' roots (kept apart). `seek`: while
  // walking, steer toward this point too (another animal, `--crossing`: their paths cross).
  void Step(double dt_s, const std::vector<Eigen::Vector2d>& others,
            const Eigen::Vector2d* seek = nullptr);
  const AnimalState& state() const { return state_; }
  const AnimalLook& look() const { return look_; }

 private:
  enum class Activity { kIdle, kPause, kWalk, kTrot, kTurn, kToWall, kLean, kToCamera, kStand };
  void Choose();
  // Starts walking (or, `run`, a burst of running) toward a new goal on the open floor.
  void StartWalk(bool run);
  // A place on the open floor, away from the walls, preferably some way off.
  Eigen::Vector2d PickGoal();
  void Integrate(double dt_s, const std::vector<Eigen::Vector2d>& others);
  // Turns the heading toward `target_rad` at up to `rate` rad/s; true when there.
  bool TurnToward(double target_rad, double rate, double dt_s);
  // Free room ahead of the root along `heading_rad` before a wall (metres).
  double RoomAhead(const Eigen::Vector2d& position, double heading_rad) const {
    return synth::RoomAhead(*studio_, position, heading_rad);
  }

  const Studio* studio_;
  AnimalLook look_;
  std::vector<Eigen::Vector3d> cameras_;
  Rng rng_;
  AnimalState state_;
  Activity activity_ = Activity::kIdle;
  double activity_left_s_ = 0.0;  // time left in the activity
  double target_speed_ = 0.0;
  double target_heading_ = 0.0;
  double steer_ = 0.0;        // rad/s of the wander
  double stage_s_ = 0.0;      // time in the current sub-stage (lean/stand hold)
  int stage_ = 0;             // sub-stage: 0 approach/turn, 1 up, 2 hold, 3 down
  double look_target_ = 0.0;  // head yaw target
  Eigen::Vector2d goal_ = Eigen::Vector2d::Zero();  // where a walk or run heads
  const Eigen::Vector2d* seek_ = nullptr;           // during Step only
};

}  // namespace ss::synth
