#include "station/request_bodies.h"

#include <algorithm>
#include <cctype>
#include <sstream>

#include "core/error.h"

namespace ss::api {
namespace {

// An integer member; `at_least_one`: a sprite id (>= 1).
int64_t IdField(const nlohmann::json& body, const char* field, const char* missing,
                bool at_least_one) {
  if (!body.contains(field)) throw InputError(field, missing);
  const nlohmann::json& v = body[field];
  if (at_least_one) {
    if (!v.is_number_integer() || v.get<int64_t>() < 1) {
      throw InputError(field, "expected a sprite id (an integer >= 1), got " + Dump(v));
    }
  } else if (!v.is_number_integer()) {
    throw InputError(field, "expected an integer, got " + Dump(v));
  }
  return v.get<int64_t>();
}

}  // namespace

std::string Dump(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json ObjectBody(const std::string& text, std::initializer_list<const char*> fields) {
  if (text.empty()) return nlohmann::json::object();
  nlohmann::json body;
  // Refused while it is parsed: nlohmann::json writes and copies a value by recursion, so a body
  // of 1 MiB of brackets overflowed the HTTP thread's stack when an error message quoted it.
  const nlohmann::json::parser_callback_t limit_depth = [](int depth,
                                                           nlohmann::json::parse_event_t event,
                                                           nlohmann::json&) {
    if ((event == nlohmann::json::parse_event_t::object_start ||
         event == nlohmann::json::parse_event_t::array_start) &&
        depth >= kMaxBodyDepth) {
      throw InputError("body", "nested deeper than " + std::to_string(kMaxBodyDepth) + " levels");
    }
    return true;
  };
  try {
    body = nlohmann::json::parse(text, limit_depth);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("body", std::string("not valid JSON: ") + e.what());
  }
  if (!body.is_object()) throw InputError("body", "expected a JSON object");
  for (const auto& item : body.items()) {
    const std::string& key = item.key();  // (clang 14 cannot capture a structured binding)
    if (std::none_of(fields.begin(), fields.end(), [&](const char* f) { return key == f; })) {
      std::string list;
      for (const char* f : fields) list += std::string(list.empty() ? "" : ", ") + "\"" + f + "\"";
      throw InputError(key, "unknown field (the request takes " +
                                (list.empty() ? std::string("none") : list) + ")");
    }
  }
  return body;
}

std::string ParseSessionName(const nlohmann::json& body, bool required, bool sent_empty) {
  if (!body.contains("name")) {
    if (required)
      throw InputError(sent_empty ? "body" : "name", "missing (expected {\"name\": \"...\"})");
    return "";
  }
  if (!body["name"].is_string())
    throw InputError("name", "expected text, got " + Dump(body["name"]));
  return body["name"].get<std::string>();
}

ReplayStartRequest ParseReplayStart(const nlohmann::json& body) {
  if (!body.contains("path") || !body["path"].is_string())
    throw InputError("path", "expected the session's path (text)");
  for (const char* flag : {"paced", "loop"}) {
    if (body.contains(flag) && !body[flag].is_boolean())
      throw InputError(flag, "expected true or false");
  }
  return {body["path"].get<std::string>(), body.value("paced", true), body.value("loop", false)};
}

TagRequest ParseTag(const nlohmann::json& body) {
  if (!body.is_object()) throw InputError("body", "expected a JSON object");
  for (const auto& [key, value] : body.items()) {
    if (key != "tag" && key != "sprites" && key != "clip" && key != "first_frame" &&
        key != "last_frame") {
      throw InputError(key,
                       "unknown field (the request takes tag with sprites, or tag with clip, "
                       "first_frame, last_frame)");
    }
  }
  TagRequest r;
  if (!body.contains("tag") || !body["tag"].is_string()) throw InputError("tag", "expected text");
  r.tag = body["tag"].get<std::string>();
  if (r.tag.empty() || r.tag.size() > 64) throw InputError("tag", "a tag needs 1 to 64 characters");
  for (const char c : r.tag) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) {
      throw InputError("tag",
                       "\"" + r.tag + "\": only letters, digits, '-', '_' and '.' are allowed");
    }
  }
  if (body.contains("sprites")) {
    if (body.contains("clip"))
      throw InputError("clip", "give sprites or a clip's frames, not both");
    const nlohmann::json& list = body["sprites"];
    if (!list.is_array() || list.empty())
      throw InputError("sprites", "expected a non-empty list of sprite ids");
    if (list.size() > kMaxTagSprites)
      throw InputError("sprites", "at most 100000 sprites a request");
    for (const auto& v : list) {
      if (!v.is_number_integer())
        throw InputError("sprites", "expected integer ids, got " + Dump(v));
      r.sprites.push_back(v.get<int64_t>());
    }
  } else {
    r.clip = IdField(body, "clip", "missing", false);
    r.first_frame = IdField(body, "first_frame", "missing", false);
    r.last_frame = IdField(body, "last_frame", "missing", false);
    if (r.last_frame < r.first_frame) throw InputError("last_frame", "comes before first_frame");
  }
  return r;
}

LabelRequest ParseLabel(const nlohmann::json& body) {
  LabelRequest r = ParseLabelUndo(body);
  if (!body.contains("label"))
    throw InputError("label", "missing (expected \"yes\", \"no\" or \"skip\")");
  if (!body["label"].is_string())
    throw InputError("label", "expected \"yes\", \"no\" or \"skip\", got " + Dump(body["label"]));
  r.label = body["label"].get<std::string>();
  if (r.label != "yes" && r.label != "no" && r.label != "skip") {
    throw InputError("label", "expected \"yes\", \"no\" or \"skip\", got \"" + r.label + "\"");
  }
  if (r.from == r.to)
    throw InputError("to", "the same sprite as \"from\" (" + std::to_string(r.from) + ")");
  return r;
}

LabelRequest ParseLabelUndo(const nlohmann::json& body) {
  LabelRequest r;
  r.from = IdField(body, "from", "missing (expected a sprite id)", true);
  r.to = IdField(body, "to", "missing (expected a sprite id)", true);
  return r;
}

std::optional<std::string> ParseCameraName(const nlohmann::json& body, bool required) {
  if (!body.contains("camera")) {
    if (required) throw InputError("camera", "missing (the camera's name)");
    return std::nullopt;
  }
  if (!body["camera"].is_string())
    throw InputError("camera", "expected the camera's name, got " + Dump(body["camera"]));
  return body["camera"].get<std::string>();
}

CalibrationStartRequest ParseCalibrationStart(
    const nlohmann::json& body, const std::function<bool(const std::string&)>& known_camera) {
  if (!body.contains("board") || !body["board"].is_string()) {
    throw InputError("board", "expected the board's spec, e.g. \"chessboard:10x7:0.03\"");
  }
  CalibrationStartRequest r;
  r.board = calib::ParseBoardSpec(body["board"].get<std::string>(), "board");
  auto number = [&](const char* field, double lo, double hi) -> std::optional<double> {
    if (!body.contains(field)) return std::nullopt;
    if (!body[field].is_number())
      throw InputError(field, "expected a number, got " + Dump(body[field]));
    const double v = body[field].get<double>();
    if (!(v >= lo && v <= hi)) {
      std::ostringstream range;
      range << "expected " << lo << " to " << hi << ", got " << v;
      throw InputError(field, range.str());
    }
    return v;
  };
  r.min_views = number("min_views", 3, 200);
  r.max_views = number("max_views", 3, 500);
  r.min_coverage = number("min_coverage", 0, 1);
  r.max_rms_px = number("max_rms_px", 0.01, 100);
  r.still_s = number("still_s", 0, 10);
  r.floor_still_s = number("floor_still_s", 0, 60);
  if (body.contains("board_pose")) {
    const nlohmann::json& p = body["board_pose"];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() ||
        !p[2].is_number()) {
      throw InputError("board_pose", "expected [x_m, y_m, yaw_deg], got " + Dump(p));
    }
    for (int i = 0; i < 3; ++i) r.board_pose[i] = p[static_cast<size_t>(i)].get<double>();
  }
  r.board_thickness_m = number("board_thickness_m", 0, 0.1);
  if (body.contains("use_current_intrinsics")) {
    if (!body["use_current_intrinsics"].is_boolean())
      throw InputError("use_current_intrinsics", "expected true or false");
    r.use_current_intrinsics = body["use_current_intrinsics"].get<bool>();
  }
  if (body.contains("cameras")) {
    const nlohmann::json& c = body["cameras"];
    if (!c.is_array() || c.empty())
      throw InputError("cameras", "expected a list of camera names, got " + Dump(c));
    for (const auto& n : c) {
      if (!n.is_string()) throw InputError("cameras", "expected camera names, got " + Dump(n));
      const std::string name = n.get<std::string>();
      if (!known_camera(name))
        throw InputError("cameras", "no camera \"" + name + "\" in the station");
      if (std::find(r.cameras.begin(), r.cameras.end(), name) == r.cameras.end())
        r.cameras.push_back(name);
    }
  }
  return r;
}

CalibrationDropRequest ParseCalibrationDrop(const nlohmann::json& body) {
  CalibrationDropRequest r;
  r.which =
      body.value("which", nlohmann::json("last")).is_string() ? body.value("which", "last") : "";
  if (r.which != "last" && r.which != "worst") {
    throw InputError("which", "expected \"last\" or \"worst\", got " +
                                  Dump(body.value("which", nlohmann::json())));
  }
  r.camera = *ParseCameraName(body, true);
  return r;
}

CalibrationRedoRequest ParseCalibrationRedo(const nlohmann::json& body) {
  if (!body.contains("step")) throw InputError("step", "missing (intrinsics, ground or enclosure)");
  const nlohmann::json& v = body["step"];
  const std::string s = v.is_string() ? v.get<std::string>() : "";
  CalibrationRedoRequest r{calib::WizardStep::kIntrinsics, std::nullopt};
  if (s == "intrinsics") {
    r.step = calib::WizardStep::kIntrinsics;
  } else if (s == "ground") {
    r.step = calib::WizardStep::kGround;
  } else if (s == "enclosure") {
    r.step = calib::WizardStep::kEnclosure;
  } else {
    throw InputError("step",
                     "expected \"intrinsics\", \"ground\" or \"enclosure\", got " + Dump(v));
  }
  r.camera = ParseCameraName(body, false);
  return r;
}

CalibrationFloorRequest ParseCalibrationFloor(const nlohmann::json& body) {
  CalibrationFloorRequest r;
  if (body.contains("pixels")) {
    const nlohmann::json& p = body["pixels"];
    if (!p.is_array()) throw InputError("pixels", "expected [[x, y], ...] in the camera's pixels");
    for (const auto& q : p) {
      if (!q.is_array() || q.size() != 2 || !q[0].is_number() || !q[1].is_number()) {
        throw InputError("pixels", "expected [x, y] pairs, got " + Dump(q));
      }
      r.pixels.emplace_back(q[0].get<double>(), q[1].get<double>());
    }
  } else if (body.contains("detect") && !body["detect"].is_boolean()) {
    throw InputError("detect", "expected true or false, got " + Dump(body["detect"]));
  } else if (body.value("detect", false)) {
    r.detect = true;
  } else {
    throw InputError("body", "give \"detect\": true or \"pixels\": [[x, y], ...]");
  }
  return r;
}

}  // namespace ss::api
