#include "synth/figure.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "synth/angles.h"
#include "synth/random.h"

namespace ss::synth {
namespace {

enum Joint {
  kHead,
  kNeck,
  kShoulderL,
  kElbowL,
  kWristL,
  kShoulderR,
  kElbowR,
  kWristR,
  kPelvis,
  kHipL,
  kKneeL,
  kAnkleL,
  kHipR,
  kKneeR,
  kAnkleR,
  kJointCount
};

struct ArmDirs {
  Eigen::Vector3d upper, fore;  // figure frame, unit
};

// One arm's directions for a pose. `side` +1 left, -1 right; vectors are given
// as (forward, outward, up) and mirrored for the right arm.
ArmDirs ArmFor(ArmPose pose, int side, const Eigen::Vector3d& shoulder,
               const Eigen::Vector3d& head_centre, const FigureBuild& b) {
  auto out = [side](double x, double o, double z) {
    return Eigen::Vector3d(x, side * o, z).normalized();
  };
  const double s = b.height_m / 1.75;
  ArmDirs d;
  switch (pose) {
    case ArmPose::kRest:
      d.upper = out(0.0, 0.10, -1.0);
      d.fore = out(0.14, 0.05, -1.0);
      break;
    case ArmPose::kY:
      d.upper = out(0.08, 0.62, 0.78);
      d.fore = d.upper;
      break;
    case ArmPose::kM: {  // hands on top of the head
      d.upper = out(0.10, 0.70, 0.71);
      const Eigen::Vector3d elbow = shoulder + b.upper_arm_m * d.upper;
      d.fore = (head_centre + Eigen::Vector3d(0.02, side * 0.03, 0.09 * s) - elbow).normalized();
      break;
    }
    case ArmPose::kA: {  // hands meeting above the head
      d.upper = out(0.05, 0.32, 0.95);
      const Eigen::Vector3d elbow = shoulder + b.upper_arm_m * d.upper;
      d.fore = (head_centre + Eigen::Vector3d(0.03, -side * 0.03, 0.30 * s) - elbow).normalized();
      break;
    }
    case ArmPose::kC:  // both arms to the figure's left, curved like a C
      if (side > 0) {
        d.upper = out(0.05, 0.80, 0.60);
        d.fore = out(0.05, 0.10, 1.0);
      } else {
        d.upper = out(0.30, -0.90, -0.10);
        d.fore = out(0.10, -0.50, -0.85);
      }
      break;
  }
  return d;
}

Material Cloth(const Eigen::Vector3f& colour, uint64_t seed) {
  Material m;
  m.pattern = Pattern::kCloth;
  m.colour = colour;
  m.texture = 0.12f;
  m.texture_scale = 5.0f;
  m.seed = static_cast<uint32_t>(seed);
  return m;
}

Material Plain(const Eigen::Vector3f& colour, uint64_t seed, float texture = 0.05f) {
  Material m;
  m.pattern = Pattern::kPlain;
  m.colour = colour;
  m.texture = texture;
  m.seed = static_cast<uint32_t>(seed);
  return m;
}

}  // namespace

const std::vector<std::string>& FigureJointNames() {
  static const std::vector<std::string> names = {
      "head",   "neck",  "shoulder_l", "elbow_l", "wrist_l", "shoulder_r", "elbow_r", "wrist_r",
      "pelvis", "hip_l", "knee_l",     "ankle_l", "hip_r",   "knee_r",     "ankle_r"};
  return names;
}

FigureBuild FigureBuildFor(int variant) {
  FigureBuild b;
  if (variant == 1) {
    b.height_m = 1.56;
    b.shoulder_half_m = 0.205;
    b.hip_half_m = 0.11;
    b.hip_height_m = 0.76;
    b.upper_arm_m = 0.30;
    b.forearm_m = 0.27;
    b.girth = 1.25;
    b.shirt = {0.15f, 0.45f, 0.75f};     // orange-red (not green)
    b.trousers = {0.45f, 0.30f, 0.20f};  // blue jeans
    b.skin = {0.30f, 0.42f, 0.60f};
  }
  return b;
}

std::string ArmPoseName(ArmPose pose) {
  switch (pose) {
    case ArmPose::kRest:
      return "rest";
    case ArmPose::kY:
      return "Y";
    case ArmPose::kM:
      return "M";
    case ArmPose::kC:
      return "C";
    case ArmPose::kA:
      return "A";
  }
  return "?";
}

std::vector<Eigen::Vector3d> FigureJoints(const FigureBuild& b, const FigureState& st) {
  const double s = b.height_m / 1.75;
  const double w = std::clamp(st.walking, 0.0, 1.0);
  const double phi = 2.0 * M_PI * st.gait_phase;
  std::vector<Eigen::Vector3d> j(kJointCount);
  // Trunk, in the figure frame with the pelvis over the origin.
  const double sway =
      w * 0.025 * std::sin(phi) + (1.0 - w) * 0.012 * std::sin(2.0 * M_PI * 0.21 * st.time_s);
  const double breathe = 0.004 * std::sin(2.0 * M_PI * 0.25 * st.time_s);
  j[kPelvis] = {0.0, sway, b.hip_height_m + 0.03 * s};
  j[kNeck] = {0.02 * w, sway * 0.6, 0.857 * b.height_m + breathe};
  j[kHead] = j[kNeck] + Eigen::Vector3d(0.015, 0.0, 0.075 * b.height_m);
  // Legs: hip flexion and knee bend over the cycle (right leg half a cycle later).
  const double leg = (b.hip_height_m - 0.08 * s) / 2.0;
  for (int side : {1, -1}) {
    const double p = phi + (side > 0 ? 0.0 : M_PI);
    const double hip_flex = w * 0.42 * std::sin(p);
    const double knee = w * (0.12 + 0.55 * std::max(0.0, std::sin(p + 1.3))) + (1.0 - w) * 0.03;
    const Eigen::Vector3d hip = j[kPelvis] + Eigen::Vector3d(0.0, side * b.hip_half_m, -0.03 * s);
    const Eigen::Vector3d thigh(std::sin(hip_flex), 0.0, -std::cos(hip_flex));
    const Eigen::Vector3d shin(std::sin(hip_flex - knee), 0.0, -std::cos(hip_flex - knee));
    j[side > 0 ? kHipL : kHipR] = hip;
    j[side > 0 ? kKneeL : kKneeR] = hip + leg * thigh;
    j[side > 0 ? kAnkleL : kAnkleR] = hip + leg * thigh + leg * shin;
  }
  // The body drops so that the lower ankle stands on the floor.
  const double drop = std::min(j[kAnkleL].z(), j[kAnkleR].z()) - 0.08 * s;
  for (auto& p : j) p.z() -= drop;
  // Arms: blend of two poses, plus the walking swing.
  const double blend = Smooth(st.blend);
  for (int side : {1, -1}) {
    const Eigen::Vector3d shoulder =
        j[kNeck] + Eigen::Vector3d(0.0, side * b.shoulder_half_m, -0.05 * s);
    const ArmDirs a = ArmFor(st.from, side, shoulder, j[kHead], b);
    const ArmDirs c = ArmFor(st.to, side, shoulder, j[kHead], b);
    Eigen::Vector3d upper = ((1.0 - blend) * a.upper + blend * c.upper).normalized();
    Eigen::Vector3d fore = ((1.0 - blend) * a.fore + blend * c.fore).normalized();
    const bool resting =
        (st.to == ArmPose::kRest && blend > 0.5) || (st.from == ArmPose::kRest && blend < 0.5);
    if (resting) {
      const double swing = -w * 0.38 * std::sin(phi + (side > 0 ? 0.0 : M_PI));
      const Eigen::Matrix3d r =
          Eigen::AngleAxisd(-swing, Eigen::Vector3d::UnitY()).toRotationMatrix();
      upper = r * upper;
      fore =
          Eigen::AngleAxisd(-swing - 0.25 * w, Eigen::Vector3d::UnitY()).toRotationMatrix() * fore;
    }
    j[side > 0 ? kShoulderL : kShoulderR] = shoulder;
    j[side > 0 ? kElbowL : kElbowR] = shoulder + b.upper_arm_m * upper;
    j[side > 0 ? kWristL : kWristR] = shoulder + b.upper_arm_m * upper + b.forearm_m * fore;
  }
  // Figure frame -> ground.
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(st.heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(st.position.x(), st.position.y(), 0.0);
  for (auto& p : j) p = r * p + t;
  return j;
}

std::vector<Primitive> FigurePrimitives(const FigureBuild& b, const std::vector<Eigen::Vector3d>& j,
                                        double heading_rad, int subject, uint64_t seed) {
  const double s = b.height_m / 1.75, g = b.girth;
  std::vector<Primitive> out;
  auto add = [&](Primitive p) {
    p.subject = subject;
    out.push_back(p);
  };
  const Eigen::Vector3d forward(std::cos(heading_rad), std::sin(heading_rad), 0.0);
  // A rotation whose z follows `axis` and whose x faces forward.
  auto frame = [&](const Eigen::Vector3d& axis) {
    const Eigen::Vector3d z = axis.normalized();
    Eigen::Vector3d x = forward - forward.dot(z) * z;
    if (x.norm() < 1e-6) x = z.unitOrthogonal();
    x.normalize();
    Eigen::Matrix3d r;
    r.col(0) = x;
    r.col(1) = z.cross(x);
    r.col(2) = z;
    return r;
  };
  const Material shirt = Cloth(b.shirt, Mix(seed, 1)), trousers = Cloth(b.trousers, Mix(seed, 2));
  const Material skin = Plain(b.skin, Mix(seed, 3)),
                 hair = Plain({0.08f, 0.10f, 0.14f}, Mix(seed, 4), 0.15f);
  const Material shoes = Plain({0.10f, 0.10f, 0.11f}, Mix(seed, 5));
  const Eigen::Vector3d spine = j[kNeck] - j[kPelvis];
  const Eigen::Matrix3d r_spine = frame(spine);
  // Trunk: hips, belly, chest with shoulders.
  add(Primitive::Ellipsoid(j[kPelvis] + 0.02 * spine, r_spine,
                           Eigen::Vector3d(0.12 * g, b.hip_half_m + 0.085 * g, 0.15 * s),
                           trousers));
  add(Primitive::Ellipsoid(j[kPelvis] + 0.35 * spine, r_spine,
                           Eigen::Vector3d(0.115 * g, 0.15 * g + 0.02, 0.17 * s), shirt));
  add(Primitive::Ellipsoid(j[kPelvis] + 0.68 * spine, r_spine,
                           Eigen::Vector3d(0.125 * g, b.shoulder_half_m * 0.92 + 0.01, 0.20 * s),
                           shirt));
  for (int sh : {kShoulderL, kShoulderR})
    add(Primitive::Capsule(j[sh], j[sh] - 0.03 * spine.normalized(), 0.062 * g, shirt));
  // Neck and head (hair on the back and top).
  const Eigen::Vector3d head_axis = j[kHead] - j[kNeck];
  add(Primitive::Capsule(j[kNeck] - 0.02 * head_axis, j[kHead] - 0.55 * head_axis, 0.048 * g,
                         skin));
  const Eigen::Matrix3d r_head = frame(head_axis);
  add(Primitive::Ellipsoid(j[kHead], r_head, Eigen::Vector3d(0.098, 0.082, 0.115) * s, skin));
  add(Primitive::Ellipsoid(j[kHead] + r_head * Eigen::Vector3d(-0.02, 0.0, 0.03) * s, r_head,
                           Eigen::Vector3d(0.095, 0.086, 0.10) * s, hair));
  // Arms: short sleeves, then skin; hands.
  for (int side = 0; side < 2; ++side) {
    const int sh = side == 0 ? kShoulderL : kShoulderR, el = side == 0 ? kElbowL : kElbowR,
              wr = side == 0 ? kWristL : kWristR;
    const Eigen::Vector3d sleeve_end = j[sh] + 0.55 * (j[el] - j[sh]);
    add(Primitive::Capsule(j[sh], sleeve_end, 0.052 * g, shirt));
    add(Primitive::Capsule(sleeve_end, j[el], 0.042 * g, skin));
    add(Primitive::Capsule(j[el], j[wr], 0.036 * g, skin));
    const Eigen::Vector3d hand_dir = (j[wr] - j[el]).normalized();
    add(Primitive::Ellipsoid(j[wr] + 0.07 * s * hand_dir, frame(hand_dir),
                             Eigen::Vector3d(0.028, 0.045, 0.075) * s, skin));
  }
  // Legs and shoes.
  for (int side = 0; side < 2; ++side) {
    const int hp = side == 0 ? kHipL : kHipR, kn = side == 0 ? kKneeL : kKneeR,
              an = side == 0 ? kAnkleL : kAnkleR;
    add(Primitive::Capsule(j[hp], j[kn], 0.078 * g, trousers));
    add(Primitive::Capsule(j[kn], j[an] + Eigen::Vector3d(0, 0, 0.02 * s), 0.058 * g, trousers));
    Eigen::Matrix3d r_foot;
    r_foot.col(0) = forward;
    r_foot.col(2) = Eigen::Vector3d::UnitZ();
    r_foot.col(1) = r_foot.col(2).cross(r_foot.col(0));
    add(Primitive::Ellipsoid(j[an] + 0.07 * s * forward - Eigen::Vector3d(0, 0, 0.04 * s), r_foot,
                             Eigen::Vector3d(0.13, 0.05 * g, 0.04) * s, shoes));
  }
  return out;
}

}  // namespace ss::synth
