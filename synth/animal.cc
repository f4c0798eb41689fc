#include "synth/animal.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "synth/angles.h"
#include "synth/random.h"
#include "synth/steering.h"

namespace ss::synth {
namespace {

constexpr double kRearPitch = 72.0 * kDeg;  // upright on the hind legs
constexpr double kLeanPitch = 50.0 * kDeg;  // front paws up on a wall
// at scale 1, with the head turned: keeps it off the walls
constexpr double kBodyHalfWidth = 0.060;
constexpr double kNoseReach = 0.108;  // at scale 1, nose tip ahead of the root
constexpr double kTailReach = 0.088;  // at scale 1, tail end behind the root

// Largest x of a primitive (its support along +x).
double SupportX(const Primitive& p) {
  if (p.shape == Shape::kCapsule) return std::max(p.a.x(), p.b.x()) + p.radius;
  return p.centre.x() + p.axes.row(0).norm();
}

struct Leg {
  Eigen::Vector3d joint;  // shoulder or hip, animal frame at scale 1
  double paw_x, paw_y;    // neutral paw position
  bool front;
  double walk_offset, trot_offset;  // phase offsets of the two gaits
};

// LH, LF, RH, RF lift in turn when walking; diagonal pairs when trotting.
const Leg kLegs[4] = {
    {{0.036, 0.022, 0.030}, 0.040, 0.026, true, 0.25, 0.0},      // left front
    {{0.036, -0.022, 0.030}, 0.040, -0.026, true, 0.75, 0.5},    // right front
    {{-0.040, 0.026, 0.028}, -0.038, 0.030, false, 0.0, 0.5},    // left hind
    {{-0.040, -0.026, 0.028}, -0.038, -0.030, false, 0.5, 0.0},  // right hind
};

}  // namespace

AnimalLook RandomAnimalLook(uint64_t seed) {
  Rng rng(StreamSeed(seed, "animal-look"));
  AnimalLook look;
  const Eigen::Vector3f coats[4][2] = {
      {{0.20f, 0.42f, 0.70f}, {0.72f, 0.82f, 0.88f}},  // golden
      {{0.40f, 0.40f, 0.42f}, {0.78f, 0.80f, 0.82f}},  // grey
      {{0.12f, 0.20f, 0.34f}, {0.55f, 0.65f, 0.75f}},  // dark brown
      {{0.66f, 0.76f, 0.84f}, {0.86f, 0.88f, 0.90f}},  // cream
  };
  const int coat = rng.UniformInt(0, 3);
  const float shade = static_cast<float>(rng.Uniform(0.9, 1.1));
  look.fur = coats[coat][0] * shade;
  look.belly = coats[coat][1];
  look.scale = rng.Uniform(0.9, 1.12);
  look.seed = rng.Bits();
  return look;
}

std::vector<Primitive> AnimalPrimitives(const AnimalLook& look, const AnimalState& s, int subject,
                                        int slice) {
  // Animal frame -> ground.
  SubjectParts parts(s.position, s.heading_rad, look.scale, look.seed, subject, slice, 20);

  // Upper body pitched about the hips: rearing and leaning.
  const double rear = Smooth(s.rear), lean = Smooth(s.lean);
  const double pitch = std::max(rear * kRearPitch, lean * kLeanPitch);
  const Eigen::Vector3d pivot(-0.040, 0.0, 0.028);
  const Eigen::Matrix3d r_pitch = RotY(-pitch);
  auto body = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return pivot + r_pitch * (p - pivot);
  };

  const double gait = std::clamp(s.stepping, 0.0, 1.0);
  const double bob = gait * (0.0015 + 0.0025 * s.trot) * std::cos(4.0 * M_PI * s.gait_phase);
  const double sway = gait * 0.04 * std::sin(2.0 * M_PI * s.gait_phase);
  const double breathe = 1.0 + 0.025 * std::sin(2.0 * M_PI * 1.3 * s.time_s);
  const bool idle = s.pose == "idle";
  const double sniff = idle ? 0.0025 * std::sin(2.0 * M_PI * 6.0 * s.time_s) : 0.0;

  Material fur;
  fur.pattern = Pattern::kFur;
  fur.colour = look.fur;
  fur.colour2 = look.belly;
  fur.texture = 0.18f;
  fur.texture_scale = 6.0f;
  Material pink;
  pink.pattern = Pattern::kPlain;
  pink.colour = {0.58f, 0.62f, 0.86f};
  pink.texture = 0.05f;
  Material eye;
  eye.pattern = Pattern::kGlossy;
  eye.colour = {0.03f, 0.03f, 0.04f};
  Material limb;
  limb.pattern = Pattern::kLimb;
  limb.colour = look.fur * 0.9f;
  limb.colour2 = pink.colour;
  limb.texture = 0.1f;

  const Eigen::Vector3d lift(0.0, 0.0, bob);
  const Eigen::Matrix3d r_body = r_pitch * RotX(sway * 0.3);
  // Torso (chest) and rump.
  parts.Ellipsoid(body(Eigen::Vector3d(0.012, 0.0, 0.040)) + lift, r_body,
                  Eigen::Vector3d(0.050, 0.038 * breathe, 0.034 * breathe), parts.Seeded(fur, 1));
  parts.Ellipsoid(body(Eigen::Vector3d(-0.030, 0.0, 0.038)) + lift, r_body,
                  Eigen::Vector3d(0.042, 0.043 * breathe, 0.036), parts.Seeded(fur, 2));
  parts.Ellipsoid(body(Eigen::Vector3d(-0.074, 0.0, 0.028)) + lift, r_body * RotY(0.4),
                  Eigen::Vector3d(0.011, 0.006, 0.006), parts.Seeded(pink, 3));

  // Head: hinged at the neck, turned by head_yaw, held more level than the body.
  const Eigen::Vector3d neck = body(Eigen::Vector3d(0.045, 0.0, 0.046)) + lift;
  const double nod = gait * 0.06 * std::sin(4.0 * M_PI * s.gait_phase + 0.7);
  const Eigen::Matrix3d r_head = RotY(-pitch * 0.45 + nod) * RotZ(s.head_yaw_rad);
  auto head = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return neck + r_head * (p - Eigen::Vector3d(0.045, 0.0, 0.046));
  };
  const Eigen::Vector3d head_centre(0.068, 0.0, 0.047);
  parts.Ellipsoid(head(head_centre), r_head, Eigen::Vector3d(0.033, 0.028, 0.027),
                  parts.Seeded(fur, 4));
  parts.Ellipsoid(head(Eigen::Vector3d(0.058, 0.0, 0.036)), r_head,
                  Eigen::Vector3d(0.022, 0.032, 0.019), parts.Seeded(fur, 5));  // cheeks
  parts.Ellipsoid(head(Eigen::Vector3d(0.099, 0.0, 0.045 + sniff)), r_head,
                  Eigen::Vector3d(0.0055, 0.0065, 0.005), parts.Seeded(pink, 6));
  for (int side : {-1, 1}) {
    parts.Ellipsoid(head(Eigen::Vector3d(0.084, 0.0185 * side, 0.056)), r_head,
                    Eigen::Vector3d(0.0055, 0.0055, 0.0055), parts.Seeded(eye, 7 + side));
    Material ear = pink;
    ear.colour = look.fur * 0.6f + pink.colour * 0.4f;
    parts.Ellipsoid(head(Eigen::Vector3d(0.060, 0.019 * side, 0.073)), r_head * RotX(0.35 * side),
                    Eigen::Vector3d(0.0045, 0.010, 0.011), parts.Seeded(ear, 10 + side));
  }

  // Legs: paws on the floor in stance, lifted and swung forward in swing.
  const double stride = s.stride_m / look.scale;  // in body units
  for (int i = 0; i < 4; ++i) {
    const Leg& leg = kLegs[i];
    const double offset = leg.walk_offset + s.trot * (leg.trot_offset - leg.walk_offset);
    const double duty = 0.65 - 0.15 * s.trot;
    const double amp = gait * duty * stride / 2.0;
    const double lift_h = gait * (0.010 + 0.004 * s.trot);
    const double p = Frac(s.gait_phase + offset);
    double dx = 0.0, dz = 0.0;
    if (p < duty) {
      dx = amp - 2.0 * amp * (p / duty);
    } else {
      const double u = (p - duty) / (1.0 - duty);
      dx = -amp + 2.0 * amp * Smooth(u);
      dz = lift_h * std::sin(M_PI * u);
    }
    Eigen::Vector3d paw(leg.paw_x + dx, leg.paw_y, 0.004 + dz);
    Eigen::Vector3d joint = leg.joint + lift;
    if (leg.front) {
      joint = body(leg.joint) + lift;
      // Rearing: paws held against the chest; leaning: paws reaching to the wall ahead.
      const Eigen::Vector3d tucked = joint + r_pitch * Eigen::Vector3d(0.012, 0.0, -0.018);
      const double up = std::max(rear, lean);
      if (up > 0.0) {
        Eigen::Vector3d raised = tucked;
        if (lean > rear) {
          raised = Eigen::Vector3d(0.0, leg.paw_y * 0.8, 0.0);
          // just ahead of the nose
          raised.x() = body(Eigen::Vector3d(0.101, 0.0, 0.046)).x() + 0.004;
          raised.z() = joint.z() + 0.012;
        }
        paw = paw + up * (raised - paw);
      }
    }
    const Material leg_mat = parts.Seeded(limb, 20 + i);
    const double leg_r = leg.front ? 0.0072 : 0.0085;
    // the leg never dips below the floor
    const Eigen::Vector3d ankle = paw + Eigen::Vector3d(-0.002, 0.0, leg_r);
    parts.Capsule(joint, ankle, leg_r, leg_mat);
    Eigen::Matrix3d r_paw = Eigen::Matrix3d::Identity();
    if (leg.front && std::max(rear, lean) > 0.0) r_paw = RotY(-0.5 * pitch);
    parts.Ellipsoid(paw, r_paw, Eigen::Vector3d(0.0095, 0.0062, 0.004), parts.Seeded(pink, 30 + i));
  }
  return std::move(parts).Take();
}

double LeanReach(const AnimalLook& look) { return ForwardReach(look, 1.0); }

double ForwardReach(const AnimalLook& look, double lean) {
  AnimalState s;
  s.lean = lean;
  double reach = -std::numeric_limits<double>::infinity();
  for (const Primitive& p : AnimalPrimitives(look, s, 0)) reach = std::max(reach, SupportX(p));
  return reach;
}

// ---------------------------------------------------------------------------

AnimalBehaviour::AnimalBehaviour(const Studio& studio, const AnimalLook& look, uint64_t seed,
                                 const Eigen::Vector2d& start, double heading_rad,
                                 std::vector<Eigen::Vector3d> cameras)
    : studio_(&studio),
      look_(look),
      cameras_(std::move(cameras)),
      rng_(StreamSeed(seed, "animal-behaviour")) {
  state_.position = start;
  state_.heading_rad = heading_rad;
  state_.stride_m = 0.06 * look.scale;
  Rng& rng = rng_;
  state_.gait_phase = rng.Uniform();
  // Sessions start with the animal on the move or resting, never mid-stand.
  if (rng.Chance(0.5)) {
    StartWalk(false);
  } else {
    activity_ = Activity::kIdle;
    activity_left_s_ = rng.Uniform(0.5, 2.5);
    target_speed_ = 0.0;
  }
}

bool AnimalBehaviour::TurnToward(double target_rad, double rate, double dt_s) {
  const double diff = Wrap(target_rad - state_.heading_rad);
  const double step = std::clamp(diff, -rate * dt_s, rate * dt_s);
  state_.heading_rad = Wrap(state_.heading_rad + step);
  return std::abs(diff - step) < 1e-3;
}

Eigen::Vector2d AnimalBehaviour::PickGoal() {
  // The open floor: 0.17 m from the end walls and 0.15 m from the side walls (the body is
  // 0.19 m long), so that walks cross the floor rather than follow the walls.
  const double gx = std::max(0.05, studio_->half_x - 0.17);
  const double gy = std::max(0.05, studio_->half_y - 0.15);
  Eigen::Vector2d best = state_.position;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const Eigen::Vector2d g(rng_.Uniform(-gx, gx), rng_.Uniform(-gy, gy));
    if ((g - state_.position).norm() > (best - state_.position).norm()) best = g;
    if ((g - state_.position).norm() > 0.3) break;
  }
  return best;
}

void AnimalBehaviour::StartWalk(bool run) {
  const double k = look_.scale;
  stage_ = 0;
  stage_s_ = 0.0;
  goal_ = PickGoal();
  if (run) {
    activity_ = Activity::kTrot;
    activity_left_s_ = rng_.Uniform(0.5, 1.6);
    target_speed_ = rng_.Uniform(0.30, 0.45) * k;
  } else {
    activity_ = Activity::kWalk;
    activity_left_s_ = rng_.Uniform(2.0, 6.0);
    target_speed_ = rng_.Uniform(0.10, 0.19) * k;
  }
}

void AnimalBehaviour::Choose() {
  Rng& rng = rng_;
  const bool moving =
      activity_ == Activity::kWalk || activity_ == Activity::kTrot || activity_ == Activity::kTurn;
  // Weights: idle, pause, walk, run (trot), turn, to-wall, to-camera (very rare: seed 000 §6.1).
  // Mostly on the move, as a hamster exploring an enclosure: a walk or run follows most
  // things, rests are short, leaning on a wall is rare.
  const double w_moving[7] = {0.06, 0.12, 0.50, 0.17, 0.11, 0.02, 0.02};
  const double w_still[7] = {0.03, 0.02, 0.60, 0.18, 0.13, 0.02, 0.02};
  const double* w = moving ? w_moving : w_still;
  double u = rng.Uniform(), acc = 0.0;
  int pick = 0;
  for (; pick < 6; ++pick) {
    acc += w[pick];
    if (u < acc) break;
  }
  stage_ = 0;
  stage_s_ = 0.0;
  switch (pick) {
    case 0:
      activity_ = Activity::kIdle;
      activity_left_s_ = rng.Uniform(1.0, 5.0);
      target_speed_ = 0.0;
      break;
    case 1:
      activity_ = Activity::kPause;
      activity_left_s_ = rng.Uniform(0.3, 1.2);
      target_speed_ = 0.0;
      break;
    case 2:
      StartWalk(false);
      break;
    case 3:
      StartWalk(true);
      break;
    case 4:
      activity_ = Activity::kTurn;
      target_heading_ =
          Wrap(state_.heading_rad + (rng.Chance(0.5) ? 1 : -1) * rng.Uniform(60, 180) * kDeg);
      activity_left_s_ = 3.0;
      target_speed_ = 0.0;
      break;
    case 5: {
      // Face the nearest wall square on, walk up to it, then lean on it.
      activity_ = Activity::kToWall;
      activity_left_s_ = 8.0;
      target_speed_ = 0.0;
      double best = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 4; ++a) {
        const double h = a * M_PI / 2.0;
        const double room = RoomAhead(state_.position, h);
        if (room < best) {
          best = room;
          target_heading_ = h;
        }
      }
      break;
    }
    default: {
      // Walks on, curving round to face a camera, and rears up as soon as it does.
      activity_ = Activity::kToCamera;
      activity_left_s_ = 4.0;
      target_speed_ = 0.08 * look_.scale;
      const Eigen::Vector3d cam = cameras_.empty()
                                      ? Eigen::Vector3d(0, -1, 1)
                                      : cameras_[static_cast<size_t>(rng.UniformInt(
                                            0, static_cast<int>(cameras_.size()) - 1))];
      target_heading_ = std::atan2(cam.y() - state_.position.y(), cam.x() - state_.position.x());
      break;
    }
  }
  look_target_ = rng.Uniform(-0.5, 0.5);
}

void AnimalBehaviour::Step(double dt_s, const std::vector<Eigen::Vector2d>& others,
                           const Eigen::Vector2d* seek) {
  // Sub-steps of at most 1/120 s keep the motion independent of the frame rate.
  const int n = std::max(1, static_cast<int>(std::ceil(dt_s * 120.0 - 1e-9)));
  seek_ = seek;
  for (int i = 0; i < n; ++i) Integrate(dt_s / n, others);
  seek_ = nullptr;
}

void AnimalBehaviour::Integrate(double dt, const std::vector<Eigen::Vector2d>& others) {
  AnimalState& s = state_;
  const double k = look_.scale;
  s.time_s += dt;
  activity_left_s_ -= dt;
  stage_s_ += dt;
  Rng& rng = rng_;
  double turn_rate = 0.0;  // rad/s of the heading this step
  const double heading_before = s.heading_rad;
  std::string pose = "idle";

  switch (activity_) {
    case Activity::kIdle:
    case Activity::kPause:
      pose = "idle";
      if (activity_left_s_ <= 0) Choose();
      break;
    case Activity::kWalk:
    case Activity::kTrot: {
      pose = activity_ == Activity::kWalk ? "walk" : "trot";
      // A wander on top of heading for the goal; a new goal once there.
      steer_ = steer_ * std::exp(-2.0 * dt) + rng.Normal() * 1.6 * std::sqrt(dt);
      if ((goal_ - s.position).norm() < 0.06 * k) goal_ = PickGoal();
      const Eigen::Vector2d to_goal = goal_ - s.position;
      const double bearing = Wrap(std::atan2(to_goal.y(), to_goal.x()) - s.heading_rad);
      turn_rate = steer_ + std::clamp(2.5 * bearing, -2.5, 2.5);
      // Steer away from walls ahead and from other animals.
      const double room = SteerFromWalls(*studio_, s.position, s.heading_rad, kNoseReach * k,
                                         0.08 * k + 0.5 * s.speed_mps, 0.7, 4.0, &turn_rate);
      SteerFromOthers(s.position, s.heading_rad, others, 0.25 * k, 2.5, &turn_rate);
      if (seek_) {  // --crossing: head for the other animal (and walk on through it)
        const Eigen::Vector2d rel = *seek_ - s.position;
        if (rel.norm() > 0.05 * k) {
          const double bearing = Wrap(std::atan2(rel.y(), rel.x()) - s.heading_rad);
          turn_rate += std::clamp(2.0 * bearing, -2.0, 2.0);
        }
      }
      turn_rate = std::clamp(turn_rate, -4.0, 4.0);
      if (room < 0.004) {  // nose at the wall: stop and turn away
        s.speed_mps = 0.0;
        activity_ = Activity::kTurn;
        target_heading_ = HeadingAwayFromWall(*studio_, s.position, s.heading_rad, rng);
        activity_left_s_ = 3.0;
        target_speed_ = 0.0;
      } else if (activity_left_s_ <= 0) {
        Choose();
      }
      break;
    }
    case Activity::kTurn:
      pose = "turn";
      target_speed_ = 0.0;
      if (TurnToward(target_heading_, 2.6, dt) || activity_left_s_ <= 0) Choose();
      break;
    case Activity::kToWall: {
      if (stage_ == 0) {
        pose = "turn";
        target_speed_ = 0.0;
        if (TurnToward(target_heading_, 2.6, dt)) {
          stage_ = 1;
          stage_s_ = 0;
        }
      } else {
        pose = "walk";
        const double room = RoomAhead(s.position, s.heading_rad) - kNoseReach * k;
        target_speed_ = std::clamp(room * 3.0, 0.02, 0.08) * k;
        if (room < 0.003) {
          activity_ = Activity::kLean;
          s.speed_mps = 0.0;
          target_speed_ = 0.0;
          stage_ = 1;
          stage_s_ = 0;
          activity_left_s_ = rng.Uniform(1.5, 4.0);
        }
      }
      if (activity_left_s_ <= 0 && activity_ == Activity::kToWall) Choose();
      break;
    }
    case Activity::kLean: {
      target_speed_ = 0.0;
      s.speed_mps = 0.0;
      if (stage_ == 1) {
        s.lean = std::min(1.0, s.lean + dt / 0.5);
        if (s.lean >= 1.0) stage_ = 2, stage_s_ = 0;
      } else if (stage_ == 2) {
        if (activity_left_s_ <= 0) stage_ = 3, stage_s_ = 0;
      } else {
        s.lean = std::max(0.0, s.lean - dt / 0.5);
      }
      // The hind paws shuffle so that the front paws just touch the wall.
      // (From where walking stopped at lean 0 to the paws 1.5 mm into the wall at lean 0.25 and
      // up.)
      const double contact = ForwardReach(look_, s.lean) - 0.0015;
      const double w = std::min(1.0, s.lean / 0.25);
      const double target_room = (1.0 - w) * (kNoseReach * k + 0.001) + w * contact;
      const double room = RoomAhead(s.position, s.heading_rad);
      const double move = room - target_room;
      s.position += move * Eigen::Vector2d(std::cos(s.heading_rad), std::sin(s.heading_rad));
      s.gait_phase = Frac(s.gait_phase + std::abs(move) / s.stride_m);
      pose = s.lean > 0.3 ? "lean" : "idle";
      look_target_ = 0.0;
      if (stage_ == 3 && s.lean <= 0.0) {
        activity_ = Activity::kTurn;
        target_heading_ =
            Wrap(s.heading_rad + (rng.Chance(0.5) ? 1 : -1) * rng.Uniform(120, 180) * kDeg);
        activity_left_s_ = 3.0;
      }
      break;
    }
    case Activity::kToCamera: {
      // Walks on while curving round to face the camera, then rears up at once: turning on
      // the spot first would make the turn and the stand-up one still period, which the
      // pipeline discards when it lasts over 2 s (docs/pipeline.md, rule 5).
      const double room = RoomAhead(s.position, s.heading_rad) - kNoseReach * k;
      target_speed_ = room > 0.05 ? 0.08 * k : 0.0;
      pose = target_speed_ > 0 ? "walk" : "turn";
      look_target_ = 0.0;
      if (TurnToward(target_heading_, 2.0, dt) || activity_left_s_ <= 0) {
        activity_ = Activity::kStand;
        stage_ = 1;
        stage_s_ = 0;
        s.speed_mps = 0.0;
        target_speed_ = 0.0;
        activity_left_s_ = rng.Uniform(0.7, 1.3);  // counts the 0.4 s of rising: held 0.3-0.9 s
      }
      break;
    }
    case Activity::kStand:
      look_target_ = 0.0;
      if (stage_ == 1) {
        s.rear = std::min(1.0, s.rear + dt / 0.4);
        if (s.rear >= 1.0) stage_ = 2, stage_s_ = 0;
      } else if (stage_ == 2) {
        if (activity_left_s_ <= 0) stage_ = 3, stage_s_ = 0;
      } else {
        s.rear = std::max(0.0, s.rear - dt / 0.4);
        if (s.rear <= 0.0) StartWalk(false);
      }
      pose = s.rear > 0.5 ? "stand" : "idle";
      break;
  }

  // Speed and heading.
  const double accel = target_speed_ > s.speed_mps ? 1.5 : 2.5;
  s.speed_mps += std::clamp(target_speed_ - s.speed_mps, -accel * dt, accel * dt);
  if (activity_ == Activity::kWalk || activity_ == Activity::kTrot) {
    s.heading_rad = Wrap(s.heading_rad + turn_rate * dt);
  }
  Eigen::Vector2d next = StepAhead(s.position, s.heading_rad, &s.speed_mps, dt, others, 0.14 * k);
  // Keep the body off the walls (leaning on one, its paws are up there).
  if (activity_ != Activity::kLean) {
    next = KeepBodyInside(*studio_, next, s.heading_rad, kNoseReach * k, kTailReach * k,
                          kBodyHalfWidth * k);
  }
  const double moved = (next - s.position).norm();
  s.position = next;
  // Legs: one cycle per stride when moving, stepping on the spot when turning.
  const double target_trot = pose == "trot" ? 1.0 : 0.0;
  const double target_step =
      std::clamp(s.speed_mps / (0.03 * k), 0.0, 1.0) + (pose == "turn" ? 1.0 : 0.0);
  s.stepping += std::clamp(std::min(1.0, target_step) - s.stepping, -5.0 * dt, 5.0 * dt);
  s.trot += std::clamp(target_trot - s.trot, -4.0 * dt, 4.0 * dt);
  s.stride_m = (0.06 + 0.03 * s.trot) * k;
  const double turned = std::abs(Wrap(s.heading_rad - heading_before));
  s.gait_phase = Frac(s.gait_phase + moved / s.stride_m + (pose == "turn" ? turned * 0.35 : 0.0));
  // The head looks around when idle, follows the turn when moving.
  if (pose == "idle" && rng.Chance(dt / 1.5)) look_target_ = rng.Uniform(-0.6, 0.6);
  const double head_target =
      pose == "idle" ? look_target_ : std::clamp(0.25 * turn_rate, -0.5, 0.5);
  s.head_yaw_rad += std::clamp(head_target - s.head_yaw_rad, -3.0 * dt, 3.0 * dt);
  s.pose = pose;
}

}  // namespace ss::synth
