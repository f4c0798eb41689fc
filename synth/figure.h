#pragma once
// The studio's articulated figure: a human-like body on the 14-limb skeleton of
// seed 003 (head, neck, shoulders, elbows, wrists, pelvis, hips, knees, ankles),
// posed by forward kinematics from a FigureState (walking, idle, the arm poses
// Y, M, C and A) and dressed in primitives. Two builds: the reference figure
// and a differently proportioned one (shorter, broader, longer arms).
//
// Figure frame: x forward, y left, z up; origin on the floor under the pelvis.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "synth/primitives.h"

namespace ss::synth {

// Joint names in truth order (the skeleton "human14"; left = the figure's own left).
const std::vector<std::string>& FigureJointNames();

struct FigureBuild {
  double height_m = 1.75;
  double shoulder_half_m = 0.19;  // shoulder joint from the body's mid-plane
  double hip_half_m = 0.09;
  double hip_height_m = 0.92;
  double upper_arm_m = 0.30;
  double forearm_m = 0.27;
  double girth = 1.0;                          // body widths scale
  Eigen::Vector3f shirt{0.55f, 0.25f, 0.18f};  // B G R
  Eigen::Vector3f trousers{0.25f, 0.22f, 0.20f};
  Eigen::Vector3f skin{0.45f, 0.58f, 0.78f};
};

// variant 0: reference figure; 1: shorter, broader, long-armed, other clothes.
FigureBuild FigureBuildFor(int variant);

// Arm poses the figure can hold (blended by weight).
enum class ArmPose { kRest, kY, kM, kC, kA };
std::string ArmPoseName(ArmPose pose);

struct FigureState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // pelvis on the floor, ground x y
  double heading_rad = 0.0;
  double speed_mps = 0.0;
  double gait_phase = 0.0;  // [0, 1): one cycle = two steps
  double walking = 0.0;     // 0..1 amplitude of the walk cycle
  ArmPose from = ArmPose::kRest, to = ArmPose::kRest;
  double blend = 1.0;   // 0: `from`, 1: `to`
  double time_s = 0.0;  // idle sway, breathing
  std::string pose = "idle";
};

// The 15 joints in the ground frame, FigureJointNames() order.
std::vector<Eigen::Vector3d> FigureJoints(const FigureBuild& build, const FigureState& state);

// The dressed body around those joints.
std::vector<Primitive> FigurePrimitives(const FigureBuild& build,
                                        const std::vector<Eigen::Vector3d>& joints,
                                        double heading_rad, int subject, uint64_t seed);

}  // namespace ss::synth
