#pragma once
// How the keypoints of another tool (DeepLabCut body parts, OpenPose BODY_25, COCO-17)
// become the joints of a skeleton definition. A mapping file (format
// "spritestation.joint_mapping", version 1; docs/skeletons.md) names, for each joint,
// one source keypoint or several to average (COCO has no neck: the shoulders' midpoint).
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "animate/skeleton/skeleton.h"

namespace ss {

// One source keypoint, by name ("LWrist", "left_wrist", "snout") or by index.
struct SourceKeypoint {
  std::string name;  // empty when given by index
  int index = -1;
};

struct JointMapping {
  std::string context;   // the mapping file, for error messages
  SkeletonDef skeleton;  // the joints produced
  // Per joint of `skeleton`: the keypoints averaged into it; empty = never observed.
  std::vector<std::vector<SourceKeypoint>> sources;
  std::optional<float> min_confidence;  // keypoints below it become missing joints
};

JointMapping JointMappingFromJson(const nlohmann::json& json, const std::string& context);
JointMapping LoadJointMapping(const std::string& path);

// Built-in mappings onto HumanSkeleton(): OpenPose BODY_25 and COCO-17 keypoints.
const JointMapping& Body25ToHuman14();
const JointMapping& Coco17ToHuman14();

// Keypoint names of the known layouts, in index order.
const std::vector<std::string>& Body25KeypointNames();
const std::vector<std::string>& Coco17KeypointNames();

// A mapping resolved against one file's keypoint list: indices per joint.
struct ResolvedMapping {
  std::vector<std::vector<int>> sources;  // per joint, indices into the file's keypoints
  float min_confidence = 0;
};

// Resolves names and checks indices against `keypoint_names` (the file's layout; an index
// must be below keypoint_names.size()). Throws InputError naming the mapping file, the
// joint and `data_context` when a keypoint does not exist there.
ResolvedMapping ResolveMapping(const JointMapping& mapping,
                               const std::vector<std::string>& keypoint_names,
                               const std::string& data_context, float min_confidence);

// One source keypoint as read from a file.
struct Keypoint {
  float x_px = 0;
  float y_px = 0;
  float confidence = 0;
  bool present = false;
};

// The joints of one frame: each joint is the mean of its keypoints, present when all of
// them are present with confidence >= min_confidence; its confidence is their minimum.
SkeletonFrame MapKeypoints(const ResolvedMapping& mapping, const std::vector<Keypoint>& keypoints,
                           int64_t frame);

}  // namespace ss
