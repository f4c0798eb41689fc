#include "animate/skeleton/joint_mapping.h"

#include <algorithm>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ss {
namespace {

SourceKeypoint KeypointFromJson(const nlohmann::json& value, const std::string& where) {
  if (value.is_string() && !value.get<std::string>().empty()) return {value.get<std::string>(), -1};
  if (value.is_number_integer() && value.get<int>() >= 0) return {std::string(), value.get<int>()};
  throw InputError(where, "expected a keypoint name or an index >= 0, got " + value.dump());
}

std::string KeypointLabel(const SourceKeypoint& k) {
  return k.name.empty() ? "#" + std::to_string(k.index) : "'" + k.name + "'";
}

}  // namespace

JointMapping JointMappingFromJson(const nlohmann::json& json, const std::string& context) {
  if (!json.is_object()) throw InputError(context, "expected a JSON object");
  if (json.value("format", std::string()) != "spritestation.joint_mapping") {
    throw InputError(context, "format: expected \"spritestation.joint_mapping\"");
  }
  if (!json.contains("version") || json["version"] != 1)
    throw InputError(context, "version: only version 1 is known");
  JointMapping mapping;
  mapping.context = context;
  mapping.skeleton = SkeletonDefFromJson(
      json.contains("skeleton") ? json["skeleton"] : nlohmann::json("human14"), context);
  mapping.sources.resize(mapping.skeleton.joints.size());
  if (const auto it = json.find("min_confidence"); it != json.end()) {
    if (!it->is_number() || it->get<double>() < 0 || it->get<double>() > 1) {
      throw InputError(context, "min_confidence: expected a number within [0, 1]");
    }
    mapping.min_confidence = it->get<float>();
  }
  const auto joints = json.find("joints");
  if (joints == json.end() || !joints->is_object() || joints->empty()) {
    throw InputError(context, "joints: expected an object {joint: keypoint or [keypoints]}");
  }
  for (const auto& [joint, value] : joints->items()) {
    const auto j = mapping.skeleton.JointIndex(joint);
    const std::string where = context + ": joints." + joint;
    if (!j)
      throw InputError(
          where, "skeleton '" + mapping.skeleton.name + "' has no joint named '" + joint + "'");
    if (value.is_array()) {
      if (value.empty()) throw InputError(where, "an empty list of keypoints");
      for (const auto& v : value) mapping.sources[*j].push_back(KeypointFromJson(v, where));
    } else {
      mapping.sources[*j].push_back(KeypointFromJson(value, where));
    }
  }
  return mapping;
}

JointMapping LoadJointMapping(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the joint mapping");
  try {
    return JointMappingFromJson(nlohmann::json::parse(in), path);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
}

const std::vector<std::string>& Body25KeypointNames() {
  static const std::vector<std::string> names = {
      "Nose",   "Neck",    "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow",
      "LWrist", "MidHip",  "RHip",      "RKnee",  "RAnkle", "LHip",      "LKnee",
      "LAnkle", "REye",    "LEye",      "REar",   "LEar",   "LBigToe",   "LSmallToe",
      "LHeel",  "RBigToe", "RSmallToe", "RHeel"};
  return names;
}

const std::vector<std::string>& Coco17KeypointNames() {
  static const std::vector<std::string> names = {
      "nose",           "left_eye",   "right_eye",   "left_ear",   "right_ear",   "left_shoulder",
      "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip",
      "right_hip",      "left_knee",  "right_knee",  "left_ankle", "right_ankle"};
  return names;
}

const JointMapping& Body25ToHuman14() {
  static const JointMapping mapping =
      JointMappingFromJson({{"format", "spritestation.joint_mapping"},
                            {"version", 1},
                            {"skeleton", "human14"},
                            {"joints",
                             {{"head", "Nose"},
                              {"neck", "Neck"},
                              {"shoulder_l", "LShoulder"},
                              {"elbow_l", "LElbow"},
                              {"wrist_l", "LWrist"},
                              {"shoulder_r", "RShoulder"},
                              {"elbow_r", "RElbow"},
                              {"wrist_r", "RWrist"},
                              {"pelvis", "MidHip"},
                              {"hip_l", "LHip"},
                              {"knee_l", "LKnee"},
                              {"ankle_l", "LAnkle"},
                              {"hip_r", "RHip"},
                              {"knee_r", "RKnee"},
                              {"ankle_r", "RAnkle"}}}},
                           "builtin:body25_to_human14");
  return mapping;
}

const JointMapping& Coco17ToHuman14() {
  static const JointMapping mapping =
      JointMappingFromJson({{"format", "spritestation.joint_mapping"},
                            {"version", 1},
                            {"skeleton", "human14"},
                            {"joints",
                             {{"head", "nose"},
                              {"neck", {"left_shoulder", "right_shoulder"}},
                              {"shoulder_l", "left_shoulder"},
                              {"elbow_l", "left_elbow"},
                              {"wrist_l", "left_wrist"},
                              {"shoulder_r", "right_shoulder"},
                              {"elbow_r", "right_elbow"},
                              {"wrist_r", "right_wrist"},
                              {"pelvis", {"left_hip", "right_hip"}},
                              {"hip_l", "left_hip"},
                              {"knee_l", "left_knee"},
                              {"ankle_l", "left_ankle"},
                              {"hip_r", "right_hip"},
                              {"knee_r", "right_knee"},
                              {"ankle_r", "right_ankle"}}}},
                           "builtin:coco17_to_human14");
  return mapping;
}

ResolvedMapping ResolveMapping(const JointMapping& mapping,
                               const std::vector<std::string>& keypoint_names,
                               const std::string& data_context, float min_confidence) {
  ResolvedMapping resolved;
  resolved.min_confidence = mapping.min_confidence.value_or(min_confidence);
  resolved.sources.resize(mapping.sources.size());
  for (size_t j = 0; j < mapping.sources.size(); ++j) {
    for (const auto& key : mapping.sources[j]) {
      int index = key.index;
      if (!key.name.empty()) {
        const auto it = std::find(keypoint_names.begin(), keypoint_names.end(), key.name);
        index = it == keypoint_names.end() ? -1 : static_cast<int>(it - keypoint_names.begin());
      }
      if (index < 0 || index >= static_cast<int>(keypoint_names.size())) {
        std::string known;
        for (const auto& n : keypoint_names) known += (known.empty() ? "" : ", ") + n;
        throw InputError(mapping.context,
                         "joint '" + mapping.skeleton.joints[j] + "' maps to keypoint " +
                             KeypointLabel(key) + ", which " + data_context +
                             " does not have (it has " + std::to_string(keypoint_names.size()) +
                             ": " + known + ")");
      }
      resolved.sources[j].push_back(index);
    }
  }
  return resolved;
}

SkeletonFrame MapKeypoints(const ResolvedMapping& mapping, const std::vector<Keypoint>& keypoints,
                           int64_t frame) {
  SkeletonFrame out;
  out.frame = frame;
  out.joints.resize(mapping.sources.size());
  for (size_t j = 0; j < mapping.sources.size(); ++j) {
    const auto& sources = mapping.sources[j];
    if (sources.empty()) continue;
    JointSample sample;
    sample.present = true;
    sample.confidence = 1;
    for (int index : sources) {
      const Keypoint& k = keypoints.at(index);
      if (!k.present || k.confidence < mapping.min_confidence) {
        sample.present = false;
        break;
      }
      sample.x_px += k.x_px;
      sample.y_px += k.y_px;
      sample.confidence = std::min(sample.confidence, k.confidence);
    }
    if (!sample.present) continue;
    sample.x_px /= static_cast<float>(sources.size());
    sample.y_px /= static_cast<float>(sources.size());
    out.joints[j] = sample;
  }
  return out;
}

}  // namespace ss
