#pragma once
// The studio's fly (seed 000 §6.2): head with large red eyes, thorax, striped abdomen, two
// wings folded over the back, six legs with a tripod gait, posed from a FlyState; and a
// behaviour model that sits still most of the time, grooms in place (front legs rubbed
// together, hind legs over the wings), walks in short tortuous bouts, darts and turns
// sharply on the spot.
//
// The fly is a stand-in rendered at kFlyLengthM (several times a house fly) so that the
// enclosure's cameras see it at ~20-30 px, as the paper's close-up footage did; its speeds are
// in proportion (body lengths per second as a fly's). Fly frame: x forward, y left, z up, origin
// on the floor under the thorax (the "root").
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "synth/primitives.h"
#include "synth/random.h"
#include "synth/scene.h"

namespace ss::synth {

inline constexpr double kFlyLengthM = 0.07;  // head to wing tips at scale 1

struct FlyLook {
  double scale = 1.0;                          // times kFlyLengthM
  Eigen::Vector3f body{0.22f, 0.23f, 0.25f};   // B G R albedo of thorax and abdomen
  Eigen::Vector3f eyes{0.10f, 0.12f, 0.48f};   // the compound eyes
  Eigen::Vector3f wings{0.66f, 0.64f, 0.60f};  // folded wings (opaque here)
  uint64_t seed = 0;                           // texture
};

// A look drawn from a few body shades and sizes (0.9-1.1).
FlyLook RandomFlyLook(uint64_t seed);

struct FlyState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // root, ground x y
  double heading_rad = 0.0;
  double speed_mps = 0.0;
  double gait_phase = 0.0;   // [0, 1): tripod cycle (frozen when still)
  double stepping = 0.0;     // 0..1: amplitude of the leg cycle
  double groom = 0.0;        // 0..1: legs raised to groom
  bool groom_front = true;   // front legs (else hind legs over the wings)
  double wing_spread = 0.0;  // 0..1: wings opened out (darting)
  double time_s = 0.0;
  std::string pose = "sit";  // sit, groom, walk, dart, turn
};

std::vector<Primitive> FlyPrimitives(const FlyLook& look, const FlyState& state, int subject,
                                     int slice = 0);

class FlyBehaviour {
 public:
  FlyBehaviour(const Studio& studio, const FlyLook& look, uint64_t seed,
               const Eigen::Vector2d& start, double heading_rad);
  // Advances by dt seconds; `others`: the other flies' roots (kept apart).
  void Step(double dt_s, const std::vector<Eigen::Vector2d>& others);
  const FlyState& state() const { return state_; }
  const FlyLook& look() const { return look_; }

 private:
  enum class Activity { kSit, kGroom, kWalk, kDart, kTurn };
  void Choose();
  void Integrate(double dt_s, const std::vector<Eigen::Vector2d>& others);
  double RoomAhead(const Eigen::Vector2d& position, double heading_rad) const {
    return synth::RoomAhead(*studio_, position, heading_rad);
  }

  const Studio* studio_;
  FlyLook look_;
  Rng rng_;
  FlyState state_;
  Activity activity_ = Activity::kSit;
  double activity_left_s_ = 0.0;
  double target_speed_ = 0.0;
  double target_heading_ = 0.0;
  double steer_ = 0.0;
};

}  // namespace ss::synth
