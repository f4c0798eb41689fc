#pragma once
// 2D skeletons (seed 003 §2.1): a definition (named joints, limbs between them) and
// sequences of per-frame joint positions in image pixels. The default definition is the
// paper's 14-limb human; others (a quadruped, a bird) come from a JSON file
// (docs/skeletons.md).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace ss {

// A limb joins two joints; `from` is the end nearer the body's root (only the orientation
// term of the descriptor uses the direction).
struct Limb {
  int from = 0;
  int to = 0;
};

// Two limbs that share a joint: the descriptor compares their angle and length ratio.
struct LimbPair {
  int joint = 0;   // the shared joint
  int limb_a = 0;  // index into SkeletonDef::limbs, limb_a < limb_b
  int limb_b = 0;
};

struct SkeletonDef {
  std::string name;                 // "human14", "quadruped", ...
  std::vector<std::string> joints;  // unique names, in the order frames store them
  std::vector<Limb> limbs;
  int root_limb = 0;            // limb whose image orientation the descriptor may weigh
  std::vector<LimbPair> pairs;  // every pair of limbs sharing a joint (derived)

  int joint_count() const { return static_cast<int>(joints.size()); }
  int limb_count() const { return static_cast<int>(limbs.size()); }
  std::optional<int> JointIndex(std::string_view joint) const;
};

// Checks names and limbs and fills `pairs`. Throws InputError(context, reason).
SkeletonDef MakeSkeletonDef(std::string name, std::vector<std::string> joints,
                            const std::vector<std::pair<std::string, std::string>>& limbs,
                            const std::string& context, int root_limb = 0);

// The paper's human: 15 joints, 14 limbs (docs/skeletons.md lists them).
const SkeletonDef& HumanSkeleton();

// A built-in definition by name ("human14"); std::nullopt if there is none.
std::optional<SkeletonDef> BuiltinSkeleton(std::string_view name);

// {"name", "joints": [...], "limbs": [["a","b"], ...], "root_limb": ["a","b"]}, or a
// string naming a built-in. Throws InputError(context, reason).
SkeletonDef SkeletonDefFromJson(const nlohmann::json& json, const std::string& context);
nlohmann::json SkeletonDefToJson(const SkeletonDef& def);

// A skeleton definition file (format "spritestation.skeleton", version 1).
SkeletonDef LoadSkeletonDef(const std::string& path);
void SaveSkeletonDef(const SkeletonDef& def, const std::string& path);

// One joint in one frame.
struct JointSample {
  float x_px = 0;
  float y_px = 0;
  float confidence = 0;       // 0..1 (importers: likelihood; tracking and users: 1)
  bool present = false;       // false: missing (not observed, below threshold, tracking failed)
  bool interpolated = false;  // filled in across an occlusion
};

struct SkeletonFrame {
  int64_t frame = 0;                // frame number in the clip (or image id)
  std::vector<JointSample> joints;  // in definition order
};

struct SkeletonSequence {
  SkeletonDef skeleton;
  std::string clip;  // free-form id of the clip the frames come from
  double fps = 0;    // 0 when unknown
  std::vector<SkeletonFrame> frames;

  int size() const { return static_cast<int>(frames.size()); }
};

// A frame with every joint missing.
SkeletonFrame EmptySkeletonFrame(const SkeletonDef& def, int64_t frame);

}  // namespace ss
