#include "animate/skeleton/skeleton.h"

#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ss {

std::optional<int> SkeletonDef::JointIndex(std::string_view joint) const {
  for (int i = 0; i < joint_count(); ++i) {
    if (joints[i] == joint) return i;
  }
  return std::nullopt;
}

SkeletonDef MakeSkeletonDef(std::string name, std::vector<std::string> joints,
                            const std::vector<std::pair<std::string, std::string>>& limbs,
                            const std::string& context, int root_limb) {
  SkeletonDef def;
  def.name = std::move(name);
  def.joints = std::move(joints);
  if (def.joints.size() < 3) throw InputError(context, "a skeleton needs at least 3 joints");
  std::set<std::string> seen;
  for (const auto& joint : def.joints) {
    if (joint.empty()) throw InputError(context, "a joint has an empty name");
    if (!seen.insert(joint).second)
      throw InputError(context, "joint '" + joint + "' is listed twice");
  }
  std::set<std::pair<int, int>> seen_limbs;
  for (const auto& [from, to] : limbs) {
    const auto a = def.JointIndex(from);
    const auto b = def.JointIndex(to);
    if (!a) throw InputError(context, "limb " + from + "-" + to + ": unknown joint '" + from + "'");
    if (!b) throw InputError(context, "limb " + from + "-" + to + ": unknown joint '" + to + "'");
    if (*a == *b) throw InputError(context, "limb " + from + "-" + to + " joins a joint to itself");
    if (!seen_limbs.insert({std::min(*a, *b), std::max(*a, *b)}).second) {
      throw InputError(context, "limb " + from + "-" + to + " is listed twice");
    }
    def.limbs.push_back({*a, *b});
  }
  if (root_limb < 0 || root_limb >= def.limb_count()) {
    throw InputError(context, "root limb " + std::to_string(root_limb) + " is out of range");
  }
  def.root_limb = root_limb;
  for (int j = 0; j < def.joint_count(); ++j) {
    std::vector<int> at_joint;
    for (int l = 0; l < def.limb_count(); ++l) {
      if (def.limbs[l].from == j || def.limbs[l].to == j) at_joint.push_back(l);
    }
    for (size_t p = 0; p < at_joint.size(); ++p) {
      for (size_t q = p + 1; q < at_joint.size(); ++q)
        def.pairs.push_back({j, at_joint[p], at_joint[q]});
    }
  }
  if (def.pairs.empty()) {
    throw InputError(context, "no two limbs share a joint, so there is no angle to compare");
  }
  return def;
}

const SkeletonDef& HumanSkeleton() {
  static const SkeletonDef def = MakeSkeletonDef(
      "human14",
      {"head", "neck", "shoulder_l", "elbow_l", "wrist_l", "shoulder_r", "elbow_r", "wrist_r",
       "pelvis", "hip_l", "knee_l", "ankle_l", "hip_r", "knee_r", "ankle_r"},
      {{"pelvis", "neck"},
       {"neck", "head"},
       {"neck", "shoulder_l"},
       {"shoulder_l", "elbow_l"},
       {"elbow_l", "wrist_l"},
       {"neck", "shoulder_r"},
       {"shoulder_r", "elbow_r"},
       {"elbow_r", "wrist_r"},
       {"pelvis", "hip_l"},
       {"hip_l", "knee_l"},
       {"knee_l", "ankle_l"},
       {"pelvis", "hip_r"},
       {"hip_r", "knee_r"},
       {"knee_r", "ankle_r"}},
      "human14");
  return def;
}

std::optional<SkeletonDef> BuiltinSkeleton(std::string_view name) {
  if (name == "human14") return HumanSkeleton();
  return std::nullopt;
}

namespace {

std::pair<std::string, std::string> LimbFromJson(const nlohmann::json& limb,
                                                 const std::string& context) {
  if (!limb.is_array() || limb.size() != 2 || !limb[0].is_string() || !limb[1].is_string()) {
    throw InputError(context, "a limb must be [\"joint\", \"joint\"], got " + limb.dump());
  }
  return {limb[0].get<std::string>(), limb[1].get<std::string>()};
}

}  // namespace

SkeletonDef SkeletonDefFromJson(const nlohmann::json& json, const std::string& context) {
  if (json.is_string()) {
    auto builtin = BuiltinSkeleton(json.get<std::string>());
    if (!builtin)
      throw InputError(context, "no built-in skeleton named '" + json.get<std::string>() + "'");
    return *builtin;
  }
  if (!json.is_object())
    throw InputError(context, "skeleton: expected an object or a built-in name");
  const auto joints_it = json.find("joints");
  const auto limbs_it = json.find("limbs");
  if (joints_it == json.end() || !joints_it->is_array()) {
    throw InputError(context, "skeleton: 'joints' must be an array of names");
  }
  if (limbs_it == json.end() || !limbs_it->is_array()) {
    throw InputError(context, "skeleton: 'limbs' must be an array of [joint, joint]");
  }
  std::vector<std::string> joints;
  for (const auto& j : *joints_it) {
    if (!j.is_string())
      throw InputError(context, "skeleton: joint names must be strings, got " + j.dump());
    joints.push_back(j.get<std::string>());
  }
  std::vector<std::pair<std::string, std::string>> limbs;
  for (const auto& l : *limbs_it) limbs.push_back(LimbFromJson(l, context));
  int root = 0;
  if (const auto it = json.find("root_limb"); it != json.end()) {
    const auto wanted = LimbFromJson(*it, context);
    root = -1;
    for (size_t i = 0; i < limbs.size(); ++i) {
      if (limbs[i] == wanted) root = static_cast<int>(i);
    }
    if (root < 0) throw InputError(context, "root_limb " + it->dump() + " is not one of the limbs");
  }
  const std::string name = json.value("name", std::string("custom"));
  return MakeSkeletonDef(name, std::move(joints), limbs, context, root);
}

nlohmann::json SkeletonDefToJson(const SkeletonDef& def) {
  nlohmann::json limbs = nlohmann::json::array();
  for (const auto& l : def.limbs) limbs.push_back({def.joints[l.from], def.joints[l.to]});
  const auto& root = def.limbs[def.root_limb];
  return {{"name", def.name},
          {"joints", def.joints},
          {"limbs", limbs},
          {"root_limb", {def.joints[root.from], def.joints[root.to]}}};
}

SkeletonDef LoadSkeletonDef(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the skeleton definition");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  if (json.value("format", std::string()) != "spritestation.skeleton") {
    throw InputError(path, "format: expected \"spritestation.skeleton\"");
  }
  if (json.value("version", 0) != 1) throw InputError(path, "version: only version 1 is known");
  return SkeletonDefFromJson(json, path);
}

void SaveSkeletonDef(const SkeletonDef& def, const std::string& path) {
  nlohmann::json json = SkeletonDefToJson(def);
  json["format"] = "spritestation.skeleton";
  json["version"] = 1;
  std::ofstream out(path);
  out << json.dump(2) << "\n";
  if (!out) throw WorkError(path, "cannot write the skeleton definition");
}

SkeletonFrame EmptySkeletonFrame(const SkeletonDef& def, int64_t frame) {
  SkeletonFrame f;
  f.frame = frame;
  f.joints.resize(def.joints.size());
  return f;
}

}  // namespace ss
