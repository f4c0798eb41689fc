#include "animate/skeleton/skeleton_json.h"

#include <cmath>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ss {
namespace {

constexpr const char* kFormat = "spritestation.skeleton_sequence";

JointSample JointFromJson(const nlohmann::json& value, const std::string& where) {
  JointSample sample;
  if (value.is_null()) return sample;  // missing
  if (!value.is_array() || value.size() < 2 || value.size() > 3) {
    throw InputError(where, "expected [x, y], [x, y, confidence] or null, got " + value.dump());
  }
  for (const auto& v : value) {
    if (!v.is_number()) throw InputError(where, "coordinates must be numbers, got " + value.dump());
  }
  sample.x_px = value[0].get<float>();
  sample.y_px = value[1].get<float>();
  sample.confidence = value.size() == 3 ? value[2].get<float>() : 1.0f;
  if (!std::isfinite(sample.x_px) || !std::isfinite(sample.y_px)) {
    throw InputError(where, "coordinates must be finite");
  }
  if (!(sample.confidence >= 0 && sample.confidence <= 1)) {
    throw InputError(where, "confidence must be within [0, 1], got " + value[2].dump());
  }
  sample.present = true;
  return sample;
}

}  // namespace

SkeletonFrame SkeletonFrameFromJson(const nlohmann::json& joints, const SkeletonDef& def,
                                    const std::string& where) {
  SkeletonFrame frame;
  frame.joints.resize(def.joints.size());
  if (joints.is_array()) {
    if (joints.size() != def.joints.size()) {
      throw InputError(where, "has " + std::to_string(joints.size()) + " joints, skeleton '" +
                                  def.name + "' has " + std::to_string(def.joints.size()));
    }
    for (size_t j = 0; j < joints.size(); ++j) {
      frame.joints[j] = JointFromJson(joints[j], where + " joint '" + def.joints[j] + "'");
    }
    return frame;
  }
  if (!joints.is_object()) throw InputError(where, "'joints' must be an object or an array");
  for (const auto& [name, value] : joints.items()) {
    if (!def.JointIndex(name)) {
      throw InputError(where, "unknown joint '" + name + "' (skeleton '" + def.name + "')");
    }
  }
  for (int j = 0; j < def.joint_count(); ++j) {
    const auto it = joints.find(def.joints[j]);
    if (it == joints.end()) {
      throw InputError(where,
                       "joint '" + def.joints[j] + "' is missing (write null for an unseen joint)");
    }
    frame.joints[j] = JointFromJson(*it, where + " joint '" + def.joints[j] + "'");
  }
  return frame;
}

SkeletonSequence SkeletonSequenceFromJson(const nlohmann::json& json, const std::string& context) {
  if (!json.is_object()) throw InputError(context, "expected a JSON object");
  if (json.value("format", std::string()) != kFormat) {
    throw InputError(context, std::string("format: expected \"") + kFormat + "\"");
  }
  if (!json.contains("version") || !json["version"].is_number_integer() ||
      json["version"].get<int>() != 1) {
    throw InputError(context, "version: only version 1 is known");
  }
  SkeletonSequence sequence;
  sequence.skeleton = SkeletonDefFromJson(
      json.contains("skeleton") ? json["skeleton"] : nlohmann::json("human14"), context);
  sequence.clip = json.value("clip", std::string());
  if (json.contains("fps")) {
    if (!json["fps"].is_number() || json["fps"].get<double>() < 0) {
      throw InputError(context, "fps: expected a number >= 0");
    }
    sequence.fps = json["fps"].get<double>();
  }
  const auto frames_it = json.find("frames");
  if (frames_it == json.end() || !frames_it->is_array()) {
    throw InputError(context, "frames: expected an array");
  }
  const SkeletonDef& def = sequence.skeleton;
  int64_t previous = -1;
  for (size_t i = 0; i < frames_it->size(); ++i) {
    const auto& f = (*frames_it)[i];
    std::string where = context + ": frames[" + std::to_string(i) + "]";
    if (!f.is_object() || !f.contains("joints"))
      throw InputError(where, "expected {\"frame\", \"joints\"}");
    if (f.contains("frame") && !f["frame"].is_number_integer())
      throw InputError(where, "frame: expected an integer");
    const int64_t number =
        f.contains("frame") ? f["frame"].get<int64_t>() : static_cast<int64_t>(i);
    if (number <= previous) throw InputError(where, "frame numbers must increase");
    previous = number;
    where += " (frame " + std::to_string(number) + ")";
    SkeletonFrame frame = SkeletonFrameFromJson(f["joints"], def, where);
    frame.frame = number;
    if (const auto it = f.find("interpolated"); it != f.end()) {
      if (!it->is_array())
        throw InputError(where, "'interpolated' must be an array of joint names");
      for (const auto& name : *it) {
        const auto j = name.is_string() ? def.JointIndex(name.get<std::string>()) : std::nullopt;
        if (!j) throw InputError(where, "interpolated: unknown joint " + name.dump());
        frame.joints[*j].interpolated = true;
      }
    }
    sequence.frames.push_back(std::move(frame));
  }
  return sequence;
}

nlohmann::json SkeletonSequenceToJson(const SkeletonSequence& sequence) {
  const SkeletonDef& def = sequence.skeleton;
  nlohmann::json json;
  json["format"] = kFormat;
  json["version"] = 1;
  if (BuiltinSkeleton(def.name)) {
    json["skeleton"] = def.name;
  } else {
    json["skeleton"] = SkeletonDefToJson(def);
  }
  if (!sequence.clip.empty()) json["clip"] = sequence.clip;
  if (sequence.fps > 0) json["fps"] = sequence.fps;
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& frame : sequence.frames) {
    nlohmann::json joints = nlohmann::json::object();
    nlohmann::json interpolated = nlohmann::json::array();
    for (int j = 0; j < def.joint_count(); ++j) {
      const JointSample& s = frame.joints.at(j);
      if (!s.present) {
        joints[def.joints[j]] = nullptr;
        continue;
      }
      // Three decimals: a thousandth of a pixel is below any tracker's accuracy.
      auto round3 = [](float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0; };
      joints[def.joints[j]] = {round3(s.x_px), round3(s.y_px), round3(s.confidence)};
      if (s.interpolated) interpolated.push_back(def.joints[j]);
    }
    nlohmann::json f = {{"frame", frame.frame}, {"joints", joints}};
    if (!interpolated.empty()) f["interpolated"] = interpolated;
    frames.push_back(std::move(f));
  }
  json["frames"] = std::move(frames);
  return json;
}

SkeletonSequence ReadSkeletonSequence(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the skeleton sequence");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("not valid JSON: ") + e.what());
  }
  try {
    return SkeletonSequenceFromJson(json, path);
  } catch (const nlohmann::json::exception& e) {  // a field of the wrong type
    throw InputError(path, e.what());
  }
}

void WriteSkeletonSequence(const SkeletonSequence& sequence, const std::string& path) {
  std::ofstream out(path);
  out << SkeletonSequenceToJson(sequence).dump(1) << "\n";
  if (!out) throw WorkError(path, "cannot write the skeleton sequence");
}

}  // namespace ss
