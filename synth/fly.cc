#include "synth/fly.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "synth/angles.h"
#include "synth/steering.h"

namespace ss::synth {
namespace {

// Extents at scale 1 in body units (times kFlyLengthM): keeps the fly off the walls.
constexpr double kFrontReach = 0.46;  // head and front feet ahead of the root
constexpr double kBackReach = 0.50;   // wing tips behind it
constexpr double kHalfWidth = 0.36;   // middle feet, wings spread

struct FlyLeg {
  Eigen::Vector3d hip;   // fly frame, body units
  Eigen::Vector2d foot;  // neutral foot on the floor
  int pair;              // 0 front, 1 middle, 2 hind
  double offset;         // tripod phase: L1 R2 L3 against R1 L2 R3
};

const FlyLeg kFlyLegs[6] = {
    {{0.22, 0.05, 0.12}, {0.36, 0.22}, 0, 0.0},  {{0.22, -0.05, 0.12}, {0.36, -0.22}, 0, 0.5},
    {{0.15, 0.06, 0.11}, {0.10, 0.31}, 1, 0.5},  {{0.15, -0.06, 0.11}, {0.10, -0.31}, 1, 0.0},
    {{0.08, 0.05, 0.11}, {-0.18, 0.26}, 2, 0.0}, {{0.08, -0.05, 0.11}, {-0.18, -0.26}, 2, 0.5},
};

}  // namespace

FlyLook RandomFlyLook(uint64_t seed) {
  Rng rng(StreamSeed(seed, "fly-look"));
  FlyLook look;
  // Grey-black house fly, blue-black blow fly, brown flesh fly: none of them green (keyed).
  const Eigen::Vector3f bodies[3] = {
      {0.22f, 0.23f, 0.25f}, {0.36f, 0.22f, 0.14f}, {0.16f, 0.22f, 0.32f}};
  look.body = bodies[rng.UniformInt(0, 2)] * static_cast<float>(rng.Uniform(0.9, 1.1));
  look.scale = rng.Uniform(0.9, 1.1);
  look.seed = rng.Bits();
  return look;
}

std::vector<Primitive> FlyPrimitives(const FlyLook& look, const FlyState& s, int subject,
                                     int slice) {
  // Fly frame (in body lengths) -> ground.
  SubjectParts parts(s.position, s.heading_rad, kFlyLengthM * look.scale, look.seed, subject, slice,
                     24);

  Material body;
  body.pattern = Pattern::kFur;  // bristly: the fur noise, lighter below
  body.colour = look.body;
  body.colour2 = look.body * 1.6f;
  body.texture = 0.25f;
  body.texture_scale = 10.0f;
  Material eye;
  eye.pattern = Pattern::kGlossy;
  eye.colour = look.eyes;
  Material wing;
  wing.pattern = Pattern::kPlain;
  wing.colour = look.wings;
  wing.texture = 0.06f;
  Material leg;
  leg.pattern = Pattern::kLimb;
  leg.colour = look.body * 0.8f;
  leg.colour2 = look.body * 0.6f;

  const double gait = std::clamp(s.stepping, 0.0, 1.0);
  const double breathe = 1.0 + 0.02 * std::sin(2.0 * M_PI * 2.1 * s.time_s);
  const double bob = gait * 0.008 * std::cos(4.0 * M_PI * s.gait_phase);
  const Eigen::Vector3d lift(0.0, 0.0, bob);
  parts.Ellipsoid(Eigen::Vector3d(0.14, 0.0, 0.18) + lift, Eigen::Matrix3d::Identity(),
                  Eigen::Vector3d(0.16, 0.13, 0.12), parts.Seeded(body, 1));  // thorax
  parts.Ellipsoid(Eigen::Vector3d(-0.16, 0.0, 0.15) + lift, RotX(0.0),
                  Eigen::Vector3d(0.21, 0.14 * breathe, 0.095 * breathe),
                  parts.Seeded(body, 2));  // abdomen
  parts.Ellipsoid(Eigen::Vector3d(0.34, 0.0, 0.18) + lift, Eigen::Matrix3d::Identity(),
                  Eigen::Vector3d(0.07, 0.13, 0.10), parts.Seeded(body, 3));  // head
  for (int side : {-1, 1}) {
    parts.Ellipsoid(Eigen::Vector3d(0.36, 0.085 * side, 0.20) + lift, Eigen::Matrix3d::Identity(),
                    Eigen::Vector3d(0.07, 0.06, 0.085), parts.Seeded(eye, 4 + side));
    // Wings folded back over the abdomen, opening out while darting.
    const double a = (22.0 + 40.0 * Smooth(s.wing_spread)) * kDeg;
    const Eigen::Vector3d root(0.10, 0.05 * side, 0.27);
    const Eigen::Vector3d dir(-std::cos(a), side * std::sin(a), 0.0);
    parts.Ellipsoid(root + 0.29 * dir + lift + Eigen::Vector3d(0, 0, 0.02 * s.wing_spread),
                    RotZ(std::atan2(dir.y(), dir.x())), Eigen::Vector3d(0.29, 0.11, 0.008),
                    parts.Seeded(wing, 6 + side));
  }

  // Legs: tripod gait; grooming raises the front pair (rubbed together before the head) or
  // the hind pair (stroked over the wings).
  const double stride = 0.30 + 0.25 * std::clamp(s.speed_mps / 0.4, 0.0, 1.0);
  const double groom = Smooth(s.groom);
  const double rub = std::sin(2.0 * M_PI * 4.0 * s.time_s);
  for (int i = 0; i < 6; ++i) {
    const FlyLeg& l = kFlyLegs[i];
    const double side = l.hip.y() > 0 ? 1.0 : -1.0;
    const double p = Frac(s.gait_phase + l.offset);
    double dx = 0.0, dz = 0.0;
    const double amp = gait * stride / 2.0;
    if (p < 0.5) {
      dx = amp - 2.0 * amp * (p / 0.5);
    } else {
      const double u = (p - 0.5) / 0.5;
      dx = -amp + 2.0 * amp * Smooth(u);
      dz = gait * 0.07 * std::sin(M_PI * u);
    }
    Eigen::Vector3d foot(l.foot.x() + dx, l.foot.y(), 0.012 + dz);
    const bool grooming = (l.pair == 0 && s.groom_front) || (l.pair == 2 && !s.groom_front);
    if (grooming && groom > 0.0) {
      const Eigen::Vector3d raised =
          l.pair == 0 ? Eigen::Vector3d(0.44 + 0.03 * rub, side * (0.03 + 0.02 * rub), 0.10)
                      : Eigen::Vector3d(-0.36 + 0.06 * rub, side * 0.14, 0.20 + 0.03 * rub);
      foot += groom * (raised - foot);
    }
    const Eigen::Vector3d hip = l.hip + lift;
    Eigen::Vector3d knee = hip + 0.5 * (foot - hip);
    knee.y() += side * 0.05;
    knee.z() = std::max(knee.z(), foot.z()) + 0.10;
    parts.Capsule(hip, knee, 0.020, parts.Seeded(leg, 10 + i));
    parts.Capsule(knee, foot, 0.012, parts.Seeded(leg, 20 + i));
  }
  return std::move(parts).Take();
}

// ---------------------------------------------------------------------------

FlyBehaviour::FlyBehaviour(const Studio& studio, const FlyLook& look, uint64_t seed,
                           const Eigen::Vector2d& start, double heading_rad)
    : studio_(&studio), look_(look), rng_(StreamSeed(seed, "fly-behaviour")) {
  state_.position = start;
  state_.heading_rad = heading_rad;
  state_.gait_phase = rng_.Uniform();
  activity_ = Activity::kSit;
  activity_left_s_ = rng_.Uniform(0.3, 2.0);
}

void FlyBehaviour::Choose() {
  Rng& rng = rng_;
  const double unit = kFlyLengthM * look_.scale;
  // Weights: sit, groom, walk, dart, turn. Time shares come out near sit 55 %, groom 20 %,
  // walk 20 %, dart 3 %, turn 2 % (docs/synth.md measures them).
  const double w[5] = {0.34, 0.16, 0.30, 0.12, 0.08};
  double u = rng.Uniform(), acc = 0.0;
  int pick = 0;
  for (; pick < 4; ++pick) {
    acc += w[pick];
    if (u < acc) break;
  }
  target_speed_ = 0.0;
  switch (pick) {
    case 0:
      activity_ = Activity::kSit;
      activity_left_s_ = rng.Uniform(1.0, 8.0);
      break;
    case 1:
      activity_ = Activity::kGroom;
      activity_left_s_ = rng.Uniform(1.0, 5.0);
      state_.groom_front = rng.Chance(0.6);
      break;
    case 2:  // 1.2-3 body lengths a second
      activity_ = Activity::kWalk;
      activity_left_s_ = rng.Uniform(0.5, 3.0);
      target_speed_ = rng.Uniform(1.2, 3.0) * unit;
      break;
    case 3:  // 7-11 body lengths a second, briefly
      activity_ = Activity::kDart;
      activity_left_s_ = rng.Uniform(0.25, 0.6);
      target_speed_ = rng.Uniform(7.0, 11.0) * unit;
      break;
    default:
      activity_ = Activity::kTurn;
      target_heading_ =
          Wrap(state_.heading_rad + (rng.Chance(0.5) ? 1 : -1) * rng.Uniform(45, 180) * kDeg);
      activity_left_s_ = 1.5;
      break;
  }
}

void FlyBehaviour::Step(double dt_s, const std::vector<Eigen::Vector2d>& others) {
  const int n = std::max(1, static_cast<int>(std::ceil(dt_s * 120.0 - 1e-9)));
  for (int i = 0; i < n; ++i) Integrate(dt_s / n, others);
}

void FlyBehaviour::Integrate(double dt, const std::vector<Eigen::Vector2d>& others) {
  FlyState& s = state_;
  const double unit = kFlyLengthM * look_.scale;
  s.time_s += dt;
  activity_left_s_ -= dt;
  Rng& rng = rng_;
  double turn_rate = 0.0;
  const double heading_before = s.heading_rad;
  std::string pose = "sit";
  switch (activity_) {
    case Activity::kSit:
      if (activity_left_s_ <= 0) Choose();
      break;
    case Activity::kGroom:
      pose = "groom";
      if (activity_left_s_ <= 0) Choose();
      break;
    case Activity::kWalk:
    case Activity::kDart: {
      const bool dart = activity_ == Activity::kDart;
      pose = dart ? "dart" : "walk";
      // Tortuous walks: a strong wander; darts go nearly straight.
      steer_ = steer_ * std::exp(-3.0 * dt) + rng.Normal() * (dart ? 1.5 : 5.0) * std::sqrt(dt);
      turn_rate = steer_;
      const double room = SteerFromWalls(*studio_, s.position, s.heading_rad, kFrontReach * unit,
                                         0.6 * unit + 0.4 * s.speed_mps, 0.8, 8.0, &turn_rate);
      SteerFromOthers(s.position, s.heading_rad, others, 2.0 * unit, 6.0, &turn_rate);
      turn_rate = std::clamp(turn_rate, -8.0, 8.0);
      if (room < 0.002) {  // head at the wall: stop and turn away
        s.speed_mps = 0.0;
        activity_ = Activity::kTurn;
        target_heading_ = HeadingAwayFromWall(*studio_, s.position, s.heading_rad, rng);
        activity_left_s_ = 1.5;
        target_speed_ = 0.0;
      } else if (activity_left_s_ <= 0) {
        Choose();
      }
      break;
    }
    case Activity::kTurn: {
      pose = "turn";
      const double diff = Wrap(target_heading_ - s.heading_rad);
      const double step = std::clamp(diff, -6.0 * dt, 6.0 * dt);
      s.heading_rad = Wrap(s.heading_rad + step);
      if (std::abs(diff - step) < 1e-3 || activity_left_s_ <= 0) Choose();
      break;
    }
  }
  // Speed (flies start and stop abruptly) and heading.
  s.speed_mps += std::clamp(target_speed_ - s.speed_mps, -8.0 * dt, 6.0 * dt);
  if (activity_ == Activity::kWalk || activity_ == Activity::kDart) {
    s.heading_rad = Wrap(s.heading_rad + turn_rate * dt);
  }
  Eigen::Vector2d next = StepAhead(s.position, s.heading_rad, &s.speed_mps, dt, others, 1.2 * unit);
  next = KeepBodyInside(*studio_, next, s.heading_rad, kFrontReach * unit, kBackReach * unit,
                        kHalfWidth * unit);
  const double moved = (next - s.position).norm();
  s.position = next;
  const double turned = std::abs(Wrap(s.heading_rad - heading_before));
  const double target_step =
      std::clamp(s.speed_mps / (0.5 * unit), 0.0, 1.0) + (pose == "turn" ? 1.0 : 0.0);
  s.stepping += std::clamp(std::min(1.0, target_step) - s.stepping, -10.0 * dt, 10.0 * dt);
  const double stride_m = (0.30 + 0.25 * std::clamp(s.speed_mps / 0.4, 0.0, 1.0)) * unit;
  s.gait_phase = Frac(s.gait_phase + moved / stride_m + (pose == "turn" ? turned * 0.5 : 0.0));
  const double target_groom = pose == "groom" ? 1.0 : 0.0;
  s.groom += std::clamp(target_groom - s.groom, -5.0 * dt, 5.0 * dt);
  const double target_wings = pose == "dart" ? 1.0 : 0.0;
  s.wing_spread += std::clamp(target_wings - s.wing_spread, -6.0 * dt, 6.0 * dt);
  s.pose = pose;
}

}  // namespace ss::synth
