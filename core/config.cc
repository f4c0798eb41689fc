#include "core/config.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "core/error.h"
#include "core/input_file.h"
#include "core/sql_postgres.h"
#include "core/frame.h"
#include "core/log.h"
#include "core/recording_codecs.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kSources = {"replay", "v4l2", "aravis", "libcamera"};
const std::vector<std::string> kLogLevels = {"trace", "debug",    "info", "warn",
                                             "error", "critical", "off"};

// Camera keys and the sources they apply to (empty: every source).
const std::vector<std::pair<std::string, std::vector<std::string>>> kCameraKeys = {
    {"name", {}},
    {"source", {}},
    {"model", {}},
    {"session", {"replay"}},
    {"session_camera", {"replay"}},
    {"loop", {"replay"}},
    {"realtime", {"replay"}},
    {"device", {"v4l2"}},
    {"camera_id", {"aravis", "libcamera"}},
    {"address", {"aravis"}},
    {"packet_resend", {"aravis"}},
    {"packet_size", {"aravis"}},
    {"pixel_format", {"v4l2", "aravis", "libcamera"}},
    {"width", {"v4l2", "aravis", "libcamera"}},
    {"height", {"v4l2", "aravis", "libcamera"}},
    {"fps", {"v4l2", "aravis", "libcamera"}},
    {"exposure_us", {"v4l2", "aravis", "libcamera"}},
    {"gain_db", {"v4l2", "aravis", "libcamera"}},
    {"white_balance", {"v4l2", "aravis", "libcamera"}},
};

std::string Join(const std::vector<std::string>& items, const std::string& sep = ", ") {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

bool OneOf(const std::string& value, const std::vector<std::string>& options) {
  return std::find(options.begin(), options.end(), value) != options.end();
}

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

// Short form of a number for messages ("25", "0.5").
std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// " (did you mean "fps"?)" for a near miss, else "".
std::string Suggest(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = std::max<size_t>(2, key.size() / 3) + 1;
  for (const auto& k : known) {
    const size_t d = EditDistance(key, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best.empty() ? "" : " (did you mean " + Quoted(best) + "?)";
}

std::string Child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Errors and adjustments, each tied to a field path and its YAML line.
class Messages {
 public:
  Messages(std::string origin, const std::map<std::string, int>& lines)
      : origin_(std::move(origin)), lines_(lines) {}
  // `line_of` names the field whose line to show, when it is not `path` itself.
  void Error(const std::string& path, const std::string& reason, const std::string& line_of = "") {
    errors.push_back(Where(line_of.empty() ? path : line_of) + path + ": " + reason);
    failed.insert(path);
  }
  void Adjust(const std::string& path, const std::string& what) {
    adjustments.push_back(Where(path) + path + ": " + what);
  }
  bool Failed(const std::string& path) const { return failed.count(path) > 0; }

  std::vector<std::string> errors, adjustments;
  std::set<std::string> failed;  // paths that already have an error

 private:
  // "ORIGIN:LINE: " with the line of the field or, if it is absent, of its nearest parent.
  std::string Where(std::string path) const {
    while (!path.empty()) {
      const auto it = lines_.find(path);
      if (it != lines_.end()) return origin_ + ":" + std::to_string(it->second) + ": ";
      const size_t cut = path.find_last_of(".[");
      path = cut == std::string::npos ? "" : path.substr(0, cut);
    }
    return origin_ + ": ";
  }
  std::string origin_;
  const std::map<std::string, int>& lines_;
};

// ---------------------------------------------------------------- reading YAML

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

std::string ScalarText(const YAML::Node& node) {
  if (node.IsScalar()) return Quoted(node.Scalar());
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

// One YAML mapping: its entries by key, with unknown and duplicate keys reported.
class MapView {
 public:
  struct Entry {
    YAML::Node key, value;
  };
  MapView() = default;
  MapView(const YAML::Node& node, std::string path, Messages& msg,
          std::map<std::string, int>& lines)
      : path_(std::move(path)) {
    if (!node.IsMap()) {
      if (!node.IsNull()) {
        const std::string name = path_.empty() ? "(top level)" : path_;
        lines.emplace(name, LineOf(node));
        msg.Error(name, "expected a mapping of keys, got " + ScalarText(node));
      }
      return;
    }
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
      const std::string field = Child(path_, key);
      if (key.empty()) {
        const std::string name = path_.empty() ? "(top level)" : path_;
        lines.emplace(name, LineOf(it->first));
        msg.Error(name,
                  "a key at line " + std::to_string(LineOf(it->first)) + " is not a plain name");
        continue;
      }
      if (entries_.count(key)) {
        lines[field] = LineOf(it->first);
        msg.Error(field, "given twice (lines " + std::to_string(LineOf(entries_[key].key)) +
                             " and " + std::to_string(LineOf(it->first)) + ")");
        continue;
      }
      entries_[key] = {it->first, it->second};
      lines[field] = LineOf(it->first);
    }
  }
  const std::string& path() const { return path_; }
  const std::map<std::string, Entry>& entries() const { return entries_; }
  const YAML::Node* Find(const std::string& key) const {
    const auto it = entries_.find(key);
    return it == entries_.end() ? nullptr : &it->second.value;
  }

 private:
  std::string path_;
  std::map<std::string, Entry> entries_;
};

class Reader {
 public:
  Reader(Messages& msg, std::map<std::string, int>& lines, std::string base_dir)
      : msg_(msg), lines_(lines), base_dir_(std::move(base_dir)) {}

  MapView Map(const YAML::Node& node, const std::string& path) {
    return MapView(node, path, msg_, lines_);
  }

  // Reports every key of `view` not in `known`.
  void Known(const MapView& view, const std::vector<std::string>& known) {
    for (const auto& [key, entry] : view.entries()) {
      if (!OneOf(key, known))
        msg_.Error(Child(view.path(), key), "unknown key" + Suggest(key, known));
    }
  }

  // The value node of `key`, or nullptr when absent. An explicit null is an error.
  const YAML::Node* Value(const MapView& view, const std::string& key) {
    const YAML::Node* node = view.Find(key);
    if (node && node->IsNull()) {
      msg_.Error(Child(view.path(), key), "has no value (remove the key to use the default)");
      return nullptr;
    }
    return node;
  }

  template <typename T>
  bool Scalar(const MapView& view, const std::string& key, T& out, const std::string& expected) {
    const YAML::Node* node = Value(view, key);
    if (!node) return false;
    T value{};
    if (!node->IsScalar() || !YAML::convert<T>::decode(*node, value)) {
      msg_.Error(Child(view.path(), key), "expected " + expected + ", got " + ScalarText(*node));
      return false;
    }
    out = value;
    return true;
  }
  bool Number(const MapView& view, const std::string& key, double& out,
              const std::string& expected = "a number") {
    return Scalar(view, key, out, expected);
  }
  bool Int(const MapView& view, const std::string& key, int& out,
           const std::string& expected = "an integer") {
    return Scalar(view, key, out, expected);
  }
  bool Int64(const MapView& view, const std::string& key, int64_t& out,
             const std::string& expected) {
    long long v = 0;
    if (!Scalar(view, key, v, expected)) return false;
    out = v;
    return true;
  }
  bool Bool(const MapView& view, const std::string& key, bool& out) {
    return Scalar(view, key, out, "true or false");
  }
  bool String(const MapView& view, const std::string& key, std::string& out,
              const std::string& expected = "a string") {
    const YAML::Node* node = Value(view, key);
    if (!node) return false;
    if (!node->IsScalar()) {
      msg_.Error(Child(view.path(), key), "expected " + expected + ", got " + ScalarText(*node));
      return false;
    }
    out = node->Scalar();
    return true;
  }
  // One of a closed set's texts (core/config.h), into its enum value; an error naming the
  // field and every allowed text otherwise.
  template <typename E, size_t N>
  bool Enum(const MapView& view, const std::string& key, E& out, const EnumText<E> (&texts)[N]) {
    std::string text;
    if (!String(view, key, text)) return false;
    return ToEnum(text, texts, Child(view.path(), key), out);
  }
  template <typename E, size_t N>
  bool ToEnum(const std::string& text, const EnumText<E> (&texts)[N], const std::string& path, E& out) {
    std::vector<std::string> names;
    for (const EnumText<E>& t : texts) {
      if (text == t.text) {
        out = t.value;
        return true;
      }
      names.push_back(t.text);
    }
    msg_.Error(path, "expected one of " + Join(names) + ", got " + Quoted(text));
    return false;
  }
  // A path, resolved against the config file's folder.
  bool Path(const MapView& view, const std::string& key, std::string& out) {
    std::string raw;
    if (!String(view, key, raw, "a path")) return false;
    if (raw.empty()) {
      msg_.Error(Child(view.path(), key), "expected a path, got \"\"");
      return false;
    }
    out = Resolve(raw);
    return true;
  }
  std::string Resolve(const std::string& raw) const {
    fs::path p(raw);
    if (p.is_relative()) p = fs::path(base_dir_) / p;
    return p.lexically_normal().string();
  }

  Messages& msg() { return msg_; }
  // Records where a list item sits, for messages about it.
  void Mark(const std::string& path, const YAML::Node& node) { lines_[path] = LineOf(node); }

 private:
  Messages& msg_;
  std::map<std::string, int>& lines_;
  std::string base_dir_;
};

void ReadWhiteBalance(Reader& r, const YAML::Node& node, const std::string& path,
                      WhiteBalanceConfig& wb) {
  if (node.IsScalar()) {  // shorthand: `white_balance: once`
    r.Mark(Child(path, "mode"), node);
    r.ToEnum(node.Scalar(), kWhiteBalanceModeTexts, Child(path, "mode"), wb.mode);
    return;
  }
  const MapView view = r.Map(node, path);
  r.Known(view, {"mode", "red_gain", "blue_gain", "temperature_k"});
  r.Enum(view, "mode", wb.mode, kWhiteBalanceModeTexts);
  const bool red = r.Number(view, "red_gain", wb.red_gain, "a positive number");
  const bool blue = r.Number(view, "blue_gain", wb.blue_gain, "a positive number");
  const bool kelvin = r.Number(view, "temperature_k", wb.temperature_k, "a colour temperature in kelvin");
  if ((red || blue || kelvin) && wb.mode != WhiteBalanceMode::kManual) {
    r.msg().Error(Child(path, red ? "red_gain" : blue ? "blue_gain" : "temperature_k"), "only applies with mode: manual");
  }
  if (kelvin && (red || blue)) {
    r.msg().Error(Child(path, "temperature_k"), "give either the red/blue gains or a colour temperature, not both");
  }
}

void ReadCamera(Reader& r, const YAML::Node& node, const std::string& path, CameraConfig& cam) {
  const MapView view = r.Map(node, path);
  r.String(view, "name", cam.name);
  r.String(view, "source", cam.source);
  // Keys that belong to another source are named as such; others are unknown.
  std::vector<std::string> all;
  for (const auto& [key, sources] : kCameraKeys) all.push_back(key);
  for (const auto& item : view.entries()) {
    const std::string& key = item.first;  // (a structured binding cannot be captured before clang 16)
    const auto it = std::find_if(kCameraKeys.begin(), kCameraKeys.end(),
                                 [&](const auto& k) { return k.first == key; });
    if (it == kCameraKeys.end()) {
      r.msg().Error(Child(path, key), "unknown key" + Suggest(key, all));
    } else if (OneOf(cam.source, kSources) && !it->second.empty() &&
               !OneOf(cam.source, it->second)) {
      r.msg().Error(Child(path, key), "only for source " + Join(it->second, " or ") +
                                          " (this camera's source is " + cam.source + ")");
    }
  }
  r.Path(view, "model", cam.model);
  r.Path(view, "session", cam.session);
  r.String(view, "session_camera", cam.session_camera);
  r.Bool(view, "loop", cam.loop);
  r.Bool(view, "realtime", cam.realtime);
  r.String(view, "device", cam.device);
  r.String(view, "camera_id", cam.camera_id);
  r.String(view, "address", cam.address);
  r.Bool(view, "packet_resend", cam.packet_resend);
  r.Int(view, "packet_size", cam.packet_size, "a packet size in bytes");
  r.String(view, "pixel_format", cam.pixel_format);
  r.Int(view, "width", cam.width, "a width in pixels");
  r.Int(view, "height", cam.height, "a height in pixels");
  r.Number(view, "fps", cam.fps, "a positive number");
  double v = 0;
  if (r.Number(view, "exposure_us", v, "an exposure time in microseconds")) cam.exposure_us = v;
  if (r.Number(view, "gain_db", v, "a gain in dB")) cam.gain_db = v;
  if (const YAML::Node* wb = r.Value(view, "white_balance")) {
    ReadWhiteBalance(r, *wb, Child(path, "white_balance"), cam.white_balance);
  }
}

void ReadKeying(Reader& r, const YAML::Node& node, KeyingConfig& k) {
  const MapView view = r.Map(node, "keying");
  r.Known(view, {"method", "training_frames", "chroma", "clean_plate", "despill", "shadow"});
  r.Enum(view, "method", k.method, kKeyingMethodTexts);
  r.Int(view, "training_frames", k.training_frames, "a number of frames");
  if (const YAML::Node* n = r.Value(view, "chroma")) {
    const MapView c = r.Map(*n, "keying.chroma");
    r.Known(c, {"low", "high"});
    r.Number(c, "low", k.chroma_low, "a level 0..255");
    r.Number(c, "high", k.chroma_high, "a level 0..255");
  }
  if (const YAML::Node* n = r.Value(view, "clean_plate")) {
    const MapView c = r.Map(*n, "keying.clean_plate");
    r.Known(c, {"low_sigma", "high_sigma"});
    r.Number(c, "low_sigma", k.plate_low_sigma, "a number of noise sigmas");
    r.Number(c, "high_sigma", k.plate_high_sigma, "a number of noise sigmas");
  }
  if (const YAML::Node* n = r.Value(view, "despill")) {
    const MapView c = r.Map(*n, "keying.despill");
    r.Known(c, {"enabled", "strength"});
    r.Bool(c, "enabled", k.despill);
    r.Number(c, "strength", k.despill_strength, "a number 0..1");
  }
  if (const YAML::Node* n = r.Value(view, "shadow")) {
    const MapView c = r.Map(*n, "keying.shadow");
    r.Known(c, {"enabled", "min_darkening", "max_darkening", "reach_m"});
    r.Bool(c, "enabled", k.shadow);
    r.Number(c, "min_darkening", k.shadow_min_darkening, "a fraction 0..1");
    r.Number(c, "max_darkening", k.shadow_max_darkening, "a fraction 0..1");
    r.Number(c, "reach_m", k.shadow_reach_m, "a distance in metres");
  }
}

void ReadEnclosure(Reader& r, const YAML::Node& node, EnclosureConfig& e) {
  const MapView view = r.Map(node, "enclosure");
  r.Known(view, {"floor", "wall_height_m"});
  r.Number(view, "wall_height_m", e.wall_height_m, "a height in metres");
  const YAML::Node* floor = r.Value(view, "floor");
  if (!floor) return;
  if (!floor->IsSequence()) {
    r.msg().Error("enclosure.floor",
                  "expected a list of [x, y] points in metres, got " + ScalarText(*floor));
    return;
  }
  if (floor->size() > GroundPolygon::kMaxVertices) {
    r.msg().Error("enclosure.floor", std::to_string(floor->size()) + " points; a floor polygon has at most " +
                                         std::to_string(GroundPolygon::kMaxVertices));
    return;
  }
  std::vector<Eigen::Vector2d> vertices;
  for (size_t i = 0; i < floor->size(); ++i) {
    const YAML::Node p = (*floor)[i];
    const std::string path = Index("enclosure.floor", i);
    r.Mark(path, p);
    double x = 0, y = 0;
    if (!p.IsSequence() || p.size() != 2 || !YAML::convert<double>::decode(p[0], x) ||
        !YAML::convert<double>::decode(p[1], y)) {
      r.msg().Error(path,
                    "expected a point [x, y] in metres, got " +
                        (p.IsSequence() ? "a list of " + std::to_string(p.size()) : ScalarText(p)));
      continue;
    }
    vertices.emplace_back(x, y);
  }
  e.floor = GroundPolygon(std::move(vertices));
}

void ReadPipeline(Reader& r, const YAML::Node& node, PipelineConfig& p) {
  const MapView view = r.Map(node, "pipeline");
  r.Known(view, {"min_area_px", "border_margin_px", "floor_margin_px", "wall_margin_m",
                 "still_speed_m_per_s", "max_speed_m_per_s", "max_still_s", "min_clip_frames", "px_per_m", "workers",
                 "queue_frames", "noise_recover_solidity", "noise_thick_px", "noise_min_thick_share", "noise_min_solidity",
                 "noise_min_largest_share", "noise_min_mean_alpha"});
  r.Int(view, "min_area_px", p.min_area_px, "an area in pixels");
  r.Int(view, "border_margin_px", p.border_margin_px, "a number of pixels");
  r.Int(view, "floor_margin_px", p.floor_margin_px, "a number of pixels");
  r.Number(view, "wall_margin_m", p.wall_margin_m, "a distance in metres");
  r.Number(view, "still_speed_m_per_s", p.still_speed_m_per_s, "a speed in m/s");
  r.Number(view, "max_speed_m_per_s", p.max_speed_m_per_s, "a speed in m/s");
  r.Number(view, "max_still_s", p.max_still_s, "a duration in seconds");
  r.Int(view, "min_clip_frames", p.min_clip_frames, "a number of frames");
  r.Number(view, "noise_recover_solidity", p.noise_recover_solidity, "a share from 0 to 1");
  r.Number(view, "noise_thick_px", p.noise_thick_px, "a distance in pixels");
  r.Number(view, "noise_min_thick_share", p.noise_min_thick_share, "a share from 0 to 1");
  r.Number(view, "noise_min_solidity", p.noise_min_solidity, "a share from 0 to 1");
  r.Number(view, "noise_min_largest_share", p.noise_min_largest_share, "a share from 0 to 1");
  r.Number(view, "noise_min_mean_alpha", p.noise_min_mean_alpha, "a share from 0 to 1");
  // `auto` (stored as 0) or a positive number of pixels per metre.
  if (const YAML::Node* n = view.Find("px_per_m"); n && n->IsScalar() && n->Scalar() == "auto") {
    p.px_per_m = 0;
  } else {
    double v = 0;
    if (r.Number(view, "px_per_m", v, "auto or a positive number of pixels per metre")) {
      p.px_per_m = v;
      if (v == 0) r.msg().Error("pipeline.px_per_m", "expected auto or a positive number, got 0");
    }
  }
  r.Int(view, "workers", p.workers, "a number of threads");
  r.Int(view, "queue_frames", p.queue_frames, "a number of frames");
}

void ReadStorage(Reader& r, const YAML::Node& node, StorageConfig& s) {
  const MapView view = r.Map(node, "storage");
  r.Known(view, {"bank", "recording_dir", "recording", "recording_codec",
                 "stop_recording_below_mib", "stop_sprites_below_mib", "spool_dir", "spool_max_mib"});
  // A file (resolved against the config's folder) or a PostgreSQL server's address, kept as written.
  if (r.Path(view, "bank", s.bank)) {
    std::string raw;
    r.String(view, "bank", raw, "a path");
    if (sql::IsPostgresAddress(raw)) s.bank = raw;
  }
  r.Path(view, "recording_dir", s.recording_dir);
  r.Enum(view, "recording", s.recording, kRecordingModeTexts);
  r.String(view, "recording_codec", s.recording_codec);
  r.Int64(view, "stop_recording_below_mib", s.stop_recording_below_mib, "a size in MiB");
  r.Int64(view, "stop_sprites_below_mib", s.stop_sprites_below_mib, "a size in MiB");
  r.Path(view, "spool_dir", s.spool_dir);
  r.Int64(view, "spool_max_mib", s.spool_max_mib, "a size in MiB");
}

void ReadControl(Reader& r, const YAML::Node& node, ControlConfig& c) {
  const MapView view = r.Map(node, "control");
  r.Known(view, {"address", "port", "token", "token_file"});
  r.String(view, "address", c.address, "an IP address");
  r.Int(view, "port", c.port, "a port number 0..65535");
  r.String(view, "token", c.token);
  std::string token_file;
  if (r.Path(view, "token_file", token_file)) {
    if (view.Find("token")) {
      r.msg().Error("control.token_file", "give token or token_file, not both");
      return;
    }
    std::ifstream in(token_file);
    if (!in) {
      r.msg().Error("control.token_file",
                    token_file + ": cannot read the token: " + std::strerror(errno));
      return;
    }
    std::getline(in, c.token);
    while (!c.token.empty() && std::isspace(static_cast<unsigned char>(c.token.back())))
      c.token.pop_back();
    if (c.token.empty()) r.msg().Error("control.token_file", token_file + ": the file is empty");
  }
}

void ReadLogging(Reader& r, const YAML::Node& node, LoggingConfig& l) {
  const MapView view = r.Map(node, "logging");
  r.Known(view, {"level", "components"});
  r.String(view, "level", l.level, "a log level");
  if (const YAML::Node* n = r.Value(view, "components")) {
    const MapView c = r.Map(*n, "logging.components");
    for (const auto& [key, entry] : c.entries()) {
      std::string level;
      if (r.String(c, key, level, "a log level")) l.components[key] = level;
    }
  }
}

// ---------------------------------------------------------------- validation

bool IsIpAddress(const std::string& a) {
  unsigned char buf[16];
  return inet_pton(AF_INET, a.c_str(), buf) == 1 || inet_pton(AF_INET6, a.c_str(), buf) == 1;
}

bool ValidName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  }) && name[0] != '.';
}

class Validator {
 public:
  Validator(Messages& msg, const ConfigOptions& options) : msg_(msg), options_(options) {}

  // Each check reports only when the field has no error from reading already.
  void Check(bool ok, const std::string& path, const std::string& reason) {
    if (!ok && !msg_.Failed(path)) msg_.Error(path, reason);
  }
  void Finite(double v, const std::string& path) {
    Check(std::isfinite(v), path, "expected a finite number, got " + Num(v));
  }
  void Positive(double v, const std::string& path) {
    Check(std::isfinite(v) && v > 0, path, "expected a positive number, got " + Num(v));
  }
  void NonNegative(double v, const std::string& path) {
    Check(std::isfinite(v) && v >= 0, path, "expected a number >= 0, got " + Num(v));
  }
  void Range(double v, double lo, double hi, const std::string& path) {
    Check(std::isfinite(v) && v >= lo && v <= hi, path,
          "expected a number from " + Num(lo) + " to " + Num(hi) + ", got " + Num(v));
  }
  void Enum(const std::string& v, const std::vector<std::string>& options,
            const std::string& path) {
    Check(OneOf(v, options), path, "expected one of " + Join(options) + ", got " + Quoted(v));
  }
  void Exists(const std::string& file, const std::string& path, const std::string& what) {
    if (!options_.check_files || file.empty()) return;
    std::error_code ec;
    Check(fs::exists(file, ec), path, file + ": no such " + what);
  }

  void Camera(CameraConfig& c, const std::string& path) {
    Check(ValidName(c.name), Child(path, "name"),
          c.name.empty() ? "every camera needs a name"
                         : "expected letters, digits, '_', '-' or '.', got " + Quoted(c.name));
    if (c.source.empty()) {
      Check(false, Child(path, "source"),
            "every camera needs a source (one of " + Join(kSources) + ")");
      return;
    }
    Enum(c.source, kSources, Child(path, "source"));
    if (c.source == "replay") {
      Check(!c.session.empty(), Child(path, "session"),
            "a replay camera needs the session folder it replays");
      Exists(c.session.empty() ? "" : (fs::path(c.session) / "session.json").string(),
             Child(path, "session"), "recorded session (session.json)");
      if (c.session_camera.empty()) c.session_camera = c.name;
    } else if (c.source == "v4l2") {
      Check(!c.device.empty(), Child(path, "device"),
            "a v4l2 camera needs its device, e.g. /dev/video0");
    } else if (c.source == "aravis") {
      Check(!c.camera_id.empty() || !c.address.empty(), Child(path, "camera_id"),
            "an aravis camera needs camera_id or address");
      Check(c.camera_id.empty() || c.address.empty(), Child(path, "address"),
            "give camera_id or address, not both");
      if (!c.address.empty()) {
        Check(IsIpAddress(c.address), Child(path, "address"),
              "expected an IP address, got " + Quoted(c.address));
      }
      Check(c.packet_size == 0 || (c.packet_size >= 576 && c.packet_size <= 16384),
            Child(path, "packet_size"),
            "expected 0 (negotiate) or 576..16384 bytes, got " + std::to_string(c.packet_size));
    }
    if (!c.pixel_format.empty()) {
      Check(ParsePixelFormat(c.pixel_format).has_value(), Child(path, "pixel_format"),
            "expected one of mono8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8, rgb8, bgr8, yuyv, "
            "nv12, mjpeg, got " +
                Quoted(c.pixel_format));
    }
    Check(c.width >= 0, Child(path, "width"),
          "expected a width in pixels, got " + std::to_string(c.width));
    Check(c.height >= 0, Child(path, "height"),
          "expected a height in pixels, got " + std::to_string(c.height));
    Check((c.width > 0) == (c.height > 0), Child(path, c.width > 0 ? "height" : "width"),
          "give width and height together");
    // Chroma-subsampled formats carry whole 2-pixel groups: round odd sizes down.
    if ((c.pixel_format == "yuyv" || c.pixel_format == "nv12") && c.width % 2 == 1) {
      msg_.Adjust(Child(path, "width"), std::to_string(c.width) + " is odd, which " +
                                            c.pixel_format + " cannot carry; lowered to " +
                                            std::to_string(c.width - 1));
      --c.width;
    }
    if (c.pixel_format == "nv12" && c.height % 2 == 1) {
      msg_.Adjust(Child(path, "height"), std::to_string(c.height) +
                                             " is odd, which nv12 cannot carry; lowered to " +
                                             std::to_string(c.height - 1));
      --c.height;
    }
    Check(std::isfinite(c.fps) && c.fps >= 0, Child(path, "fps"),
          "expected a positive number, got " + Num(c.fps));
    if (c.exposure_us) Positive(*c.exposure_us, Child(path, "exposure_us"));
    if (c.gain_db) NonNegative(*c.gain_db, Child(path, "gain_db"));
    Positive(c.white_balance.red_gain, Child(path, "white_balance.red_gain"));
    Positive(c.white_balance.blue_gain, Child(path, "white_balance.blue_gain"));
    Check(c.white_balance.temperature_k == 0 ||
              (c.white_balance.temperature_k >= 1500 && c.white_balance.temperature_k <= 15000),
          Child(path, "white_balance.temperature_k"),
          "expected a colour temperature of 1500-15000 K, got " + Num(c.white_balance.temperature_k));
    // How each backend fixes white balance: V4L2 as a colour temperature, GenICam as ratios.
    if (c.white_balance.mode == WhiteBalanceMode::kManual && c.source == "v4l2") {
      Check(c.white_balance.temperature_k > 0, Child(path, "white_balance.temperature_k"),
            "V4L2 devices fix white balance as a colour temperature: give temperature_k");
    }
    if (c.source == "aravis") {
      Check(c.white_balance.temperature_k == 0, Child(path, "white_balance.temperature_k"),
            "GigE Vision cameras fix white balance as red/blue ratios: give red_gain and blue_gain");
    }
    Exists(c.model, Child(path, "model"), "camera model");
  }

  void Run(StationConfig& cfg) {
    Check(cfg.version == kConfigVersion, "version",
          cfg.version > kConfigVersion
              ? "written for a newer SpriteStation (config version " + std::to_string(cfg.version) +
                    "); this one reads version " + std::to_string(kConfigVersion)
              : "expected " + std::to_string(kConfigVersion) + ", got " +
                    std::to_string(cfg.version));
    std::map<std::string, size_t> names;
    for (size_t i = 0; i < cfg.cameras.size(); ++i) {
      const std::string path = Index("cameras", i);
      Camera(cfg.cameras[i], path);
      const auto [it, fresh] = names.emplace(cfg.cameras[i].name, i);
      if (!fresh && !cfg.cameras[i].name.empty()) {
        Check(false, Child(path, "name"),
              Quoted(cfg.cameras[i].name) + " is already the name of " +
                  Index("cameras", it->second));
      }
    }

    KeyingConfig& k = cfg.keying;
    Check(k.training_frames >= 1, "keying.training_frames",
          "expected at least 1 frame, got " + std::to_string(k.training_frames));
    Range(k.chroma_low, 0, 255, "keying.chroma.low");
    Range(k.chroma_high, 0, 255, "keying.chroma.high");
    Check(!(k.chroma_low >= k.chroma_high), "keying.chroma.high",
          "must be above keying.chroma.low (" + Num(k.chroma_low) + "), got " + Num(k.chroma_high));
    NonNegative(k.plate_low_sigma, "keying.clean_plate.low_sigma");
    NonNegative(k.plate_high_sigma, "keying.clean_plate.high_sigma");
    Check(!(k.plate_low_sigma >= k.plate_high_sigma), "keying.clean_plate.high_sigma",
          "must be above keying.clean_plate.low_sigma (" + Num(k.plate_low_sigma) + "), got " +
              Num(k.plate_high_sigma));
    Finite(k.despill_strength, "keying.despill.strength");
    if (std::isfinite(k.despill_strength) && (k.despill_strength < 0 || k.despill_strength > 1)) {
      const double clamped = std::clamp(k.despill_strength, 0.0, 1.0);
      msg_.Adjust("keying.despill.strength",
                  Num(k.despill_strength) + " is outside 0..1; clamped to " + Num(clamped));
      k.despill_strength = clamped;
    }
    Range(k.shadow_min_darkening, 0, 1, "keying.shadow.min_darkening");
    Range(k.shadow_max_darkening, 0, 1, "keying.shadow.max_darkening");
    Check(!(k.shadow_min_darkening >= k.shadow_max_darkening), "keying.shadow.max_darkening",
          "must be above keying.shadow.min_darkening (" + Num(k.shadow_min_darkening) + "), got " +
              Num(k.shadow_max_darkening));
    Positive(k.shadow_reach_m, "keying.shadow.reach_m");

    const auto& floor = cfg.enclosure.floor.vertices();
    if (!floor.empty() && !msg_.Failed("enclosure.floor")) {
      bool points_ok = true;
      for (size_t i = 0; i < floor.size(); ++i)
        points_ok = points_ok && !msg_.Failed(Index("enclosure.floor", i));
      if (points_ok) {
        Check(floor.size() >= 3, "enclosure.floor",
              "a floor polygon needs at least 3 points, got " + std::to_string(floor.size()));
        if (floor.size() >= 3) {
          Check(
              cfg.enclosure.floor.IsSimple(), "enclosure.floor",
              "the polygon crosses itself, repeats a point, has a non-finite point or has no area "
              "(list the corners in order around the floor)");
        }
      }
    }
    NonNegative(cfg.enclosure.wall_height_m, "enclosure.wall_height_m");

    PipelineConfig& p = cfg.pipeline;
    Check(p.min_area_px >= 1, "pipeline.min_area_px",
          "expected at least 1 pixel, got " + std::to_string(p.min_area_px));
    Check(p.border_margin_px >= 0, "pipeline.border_margin_px",
          "expected a number >= 0, got " + std::to_string(p.border_margin_px));
    Check(p.floor_margin_px >= 0, "pipeline.floor_margin_px",
          "expected a number >= 0, got " + std::to_string(p.floor_margin_px));
    NonNegative(p.wall_margin_m, "pipeline.wall_margin_m");
    Positive(p.still_speed_m_per_s, "pipeline.still_speed_m_per_s");
    Positive(p.max_speed_m_per_s, "pipeline.max_speed_m_per_s");
    Positive(p.max_still_s, "pipeline.max_still_s");
    Check(p.min_clip_frames >= 1, "pipeline.min_clip_frames",
          "expected at least 1 frame, got " + std::to_string(p.min_clip_frames));
    NonNegative(p.noise_thick_px, "pipeline.noise_thick_px");
    for (const auto& [v, key] : {std::pair{p.noise_recover_solidity, "noise_recover_solidity"},
                                 std::pair{p.noise_min_thick_share, "noise_min_thick_share"},
                                 std::pair{p.noise_min_solidity, "noise_min_solidity"},
                                 std::pair{p.noise_min_largest_share, "noise_min_largest_share"},
                                 std::pair{p.noise_min_mean_alpha, "noise_min_mean_alpha"}}) {
      Check(std::isfinite(v) && v >= 0 && v <= 1, std::string("pipeline.") + key,
            "expected a share from 0 to 1 (0 turns the test off), got " + Num(v));
    }
    Check(p.px_per_m == 0 || (std::isfinite(p.px_per_m) && p.px_per_m > 0), "pipeline.px_per_m",
          "expected auto or a positive number, got " + Num(p.px_per_m));
    Check(p.workers >= 0, "pipeline.workers",
          "expected 0 (one per core) or more, got " + std::to_string(p.workers));
    Check(p.queue_frames >= 1, "pipeline.queue_frames",
          "expected at least 1 frame, got " + std::to_string(p.queue_frames));
    constexpr int kMaxQueue = 1024;
    if (p.queue_frames > kMaxQueue) {
      msg_.Adjust("pipeline.queue_frames", std::to_string(p.queue_frames) +
                                               " would hold too many frames in memory; "
                                               "lowered to " +
                                               std::to_string(kMaxQueue));
      p.queue_frames = kMaxQueue;
    }

    StorageConfig& s = cfg.storage;
    Check(!s.bank.empty(), "storage.bank", "expected a path");
    Check(!s.recording_dir.empty(), "storage.recording_dir", "expected a path");
    {
      std::vector<std::string> codecs;
      for (const RecordingCodec& c : RecordingCodecs()) codecs.push_back(c.name);
      Enum(s.recording_codec, codecs, "storage.recording_codec");
    }
    Check(s.stop_recording_below_mib >= 0, "storage.stop_recording_below_mib",
          "expected a size >= 0, got " + std::to_string(s.stop_recording_below_mib));
    Check(s.spool_max_mib >= 1, "storage.spool_max_mib", "expected a size >= 1, got " + std::to_string(s.spool_max_mib));
    Check(s.stop_sprites_below_mib >= 0, "storage.stop_sprites_below_mib",
          "expected a size >= 0, got " + std::to_string(s.stop_sprites_below_mib));
    // Raw recording must stop first: its low-water mark is never below the sprites' one.
    if (s.stop_recording_below_mib < s.stop_sprites_below_mib && s.stop_recording_below_mib >= 0 &&
        !msg_.Failed("storage.stop_recording_below_mib") &&
        !msg_.Failed("storage.stop_sprites_below_mib")) {
      msg_.Adjust("storage.stop_recording_below_mib",
                  std::to_string(s.stop_recording_below_mib) +
                      " is below stop_sprites_below_mib; raised to " +
                      std::to_string(s.stop_sprites_below_mib) +
                      " so that raw recording stops before sprite storage");
      s.stop_recording_below_mib = s.stop_sprites_below_mib;
    }

    ControlConfig& c = cfg.control;
    Check(c.address == "localhost" || IsIpAddress(c.address), "control.address",
          "expected an IP address (or localhost), got " + Quoted(c.address));
    Check(c.port >= 0 && c.port <= 65535, "control.port",
          "expected a port number 0..65535, got " + std::to_string(c.port));
    if (!c.token.empty()) {
      Check(c.token.size() >= 16, "control.token",
            "too short: use at least 16 characters (got " + std::to_string(c.token.size()) + ")");
    } else if (!IsLoopbackAddress(c.address) && !msg_.Failed("control.address")) {
      msg_.Error("control.token",
                 "required when control.address (" + c.address +
                     ") is not loopback; set token or token_file",
                 "control.address");
    }

    LoggingConfig& l = cfg.logging;
    Enum(l.level, kLogLevels, "logging.level");
    for (const auto& [component, level] : l.components)
      Enum(level, kLogLevels, "logging.components." + component);
  }

 private:
  Messages& msg_;
  const ConfigOptions& options_;
};

ConfigReport MakeReport(const Messages& msg) {
  ConfigReport report;
  report.errors = msg.errors;
  report.adjustments = msg.adjustments;
  report.status = !msg.errors.empty()        ? ConfigStatus::kInvalid
                  : !msg.adjustments.empty() ? ConfigStatus::kAdjusted
                                             : ConfigStatus::kValid;
  return report;
}

// Throws on kInvalid; logs adjustments; hands the report back.
void Conclude(const ConfigReport& report, ConfigReport* out) {
  if (out) *out = report;
  if (report.status == ConfigStatus::kInvalid) throw InputError(Join(report.errors, "\n"));
  for (const auto& a : report.adjustments) Log("core.config")->warn("adjusted: {}", a);
}

}  // namespace

std::string ConfigReport::Summary() const {
  std::vector<std::string> lines = errors;
  for (const auto& a : adjustments) lines.push_back("adjusted: " + a);
  return Join(lines, "\n");
}

bool IsLoopbackAddress(const std::string& address) {
  if (address == "localhost" || address == "::1") return true;
  unsigned char buf[16];
  if (inet_pton(AF_INET, address.c_str(), buf) == 1) return buf[0] == 127;
  if (inet_pton(AF_INET6, address.c_str(), buf) == 1) {
    // ::ffff:127.x.y.z (IPv4-mapped loopback)
    static const unsigned char prefix[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
    return std::equal(prefix, prefix + 12, buf) && buf[12] == 127;
  }
  return false;
}

ConfigReport ValidateStationConfig(StationConfig& config, const std::string& origin,
                                   const std::map<std::string, int>& lines,
                                   const ConfigOptions& options) {
  Messages msg(origin, lines);
  Validator(msg, options).Run(config);
  return MakeReport(msg);
}

StationConfig ParseStationConfig(const std::string& yaml, const std::string& origin,
                                 const std::string& base_dir, ConfigReport* report,
                                 const ConfigOptions& options) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    const std::string where =
        e.mark.is_null() ? origin : origin + ":" + std::to_string(e.mark.line + 1);
    throw InputError(where, "not valid YAML: " + e.msg);
  }
  if (root.IsNull()) {
    throw InputError(origin,
                     "the config is empty (expected sections such as cameras, enclosure, storage)");
  }
  std::map<std::string, int> lines;
  Messages msg(origin, lines);
  Reader r(msg, lines, base_dir);

  StationConfig cfg;
  cfg.storage.bank = r.Resolve("station.bank");
  cfg.storage.recording_dir = r.Resolve("recordings");
  cfg.storage.spool_dir = r.Resolve("spool");
  const MapView top = r.Map(root, "");
  r.Known(top, {"version", "cameras", "keying", "enclosure", "pipeline", "storage", "control",
                "logging"});
  r.Int(top, "version", cfg.version, "a config version number");
  if (const YAML::Node* cams = r.Value(top, "cameras")) {
    if (!cams->IsSequence()) {
      msg.Error("cameras", "expected a list of cameras, got " + ScalarText(*cams));
    } else {
      for (size_t i = 0; i < cams->size(); ++i) {
        const std::string path = Index("cameras", i);
        r.Mark(path, (*cams)[i]);
        cfg.cameras.emplace_back();
        ReadCamera(r, (*cams)[i], path, cfg.cameras.back());
      }
    }
  }
  if (const YAML::Node* n = r.Value(top, "keying")) ReadKeying(r, *n, cfg.keying);
  if (const YAML::Node* n = r.Value(top, "enclosure")) ReadEnclosure(r, *n, cfg.enclosure);
  if (const YAML::Node* n = r.Value(top, "pipeline")) ReadPipeline(r, *n, cfg.pipeline);
  if (const YAML::Node* n = r.Value(top, "storage")) ReadStorage(r, *n, cfg.storage);
  if (const YAML::Node* n = r.Value(top, "control")) ReadControl(r, *n, cfg.control);
  if (const YAML::Node* n = r.Value(top, "logging")) ReadLogging(r, *n, cfg.logging);

  Validator(msg, options).Run(cfg);
  Conclude(MakeReport(msg), report);
  return cfg;
}

StationConfig LoadStationConfig(const std::string& path, ConfigReport* report,
                                const ConfigOptions& options) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a config file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open the config: ") + std::strerror(errno));
  const std::string text = ReadWithinLimit(in, path, "a config file");
  const fs::path base = fs::absolute(fs::path(path), ec).parent_path();
  return ParseStationConfig(text, path, base.string(), report, options);
}

namespace {

template <typename E, size_t N>
const char* TextOf(E value, const EnumText<E> (&texts)[N]) {
  for (const EnumText<E>& t : texts) {
    if (t.value == value) return t.text;
  }
  return "unknown";
}

}  // namespace

const char* ToText(WhiteBalanceMode mode) { return TextOf(mode, kWhiteBalanceModeTexts); }
const char* ToText(KeyingMethod method) { return TextOf(method, kKeyingMethodTexts); }
const char* ToText(RecordingMode mode) { return TextOf(mode, kRecordingModeTexts); }

}  // namespace ss
