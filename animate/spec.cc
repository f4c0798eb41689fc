#include "animate/spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "core/error.h"
#include "core/input_file.h"
#include "core/options_binder.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.line >= 0 ? mark.line + 1 : 0;
}

// Reads nodes of one spec, naming the file, line and field in every error.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& field,
                         const std::string& why) const {
    throw InputError(origin_ + ":" + std::to_string(LineOf(node)) + ": " + field, why);
  }
  SpecPlace Place(const YAML::Node& node, const std::string& field) const {
    return {LineOf(node), field};
  }

  // `node` must be a map holding only `known` keys.
  void Map(const YAML::Node& node, const std::string& field,
           std::initializer_list<const char*> known) const {
    if (!node.IsMap()) Fail(node, field, "expected a map");
    for (const auto& item : node) {
      if (!item.first.IsScalar()) Fail(item.first, field, "a key that is not a plain name");
      const std::string key = item.first.as<std::string>();
      bool ok = false;
      std::string list;
      for (const char* k : known) {
        ok = ok || key == k;
        list += (list.empty() ? "" : ", ") + std::string(k);
      }
      if (!ok) Fail(item.first, Join(field, key), "unknown field (expected one of: " + list + ")");
    }
  }
  static std::string Join(const std::string& field, const std::string& key) {
    return field.empty() ? key : field + "." + key;
  }
  static std::string Index(const std::string& field, size_t i) {
    return field + "[" + std::to_string(i) + "]";
  }

  std::string Text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) Fail(node, field, "expected a string");
    return node.Scalar();
  }
  double Number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) Fail(node, field, "expected a number");
    try {
      const double value = node.as<double>();
      if (!std::isfinite(value)) Fail(node, field, "expected a finite number");
      return value;
    } catch (const YAML::Exception&) {
      Fail(node, field, "expected a number, got \"" + node.Scalar() + "\"");
    }
  }
  double AtLeast(const YAML::Node& node, const std::string& field, double low) const {
    const double value = Number(node, field);
    if (value < low) Fail(node, field, "must be >= " + Num(low));
    return value;
  }
  double Positive(const YAML::Node& node, const std::string& field) const {
    const double value = Number(node, field);
    if (value <= 0) Fail(node, field, "must be > 0");
    return value;
  }
  int Integer(const YAML::Node& node, const std::string& field, int low) const {
    const double value = Number(node, field);
    if (value != std::floor(value) || value < low || value > 1e9) {
      Fail(node, field, "expected a whole number >= " + std::to_string(low));
    }
    return static_cast<int>(value);
  }
  // A whole number in [low, high]; `high` is a limit of the optimizer, named in the message.
  int IntegerIn(const YAML::Node& node, const std::string& field, int low, int high) const {
    const int value = Integer(node, field, low);
    if (value > high)
      Fail(node, field,
           "expected at most " + std::to_string(high) + ", got " + std::to_string(value));
    return value;
  }
  Eigen::Vector2d Point(const YAML::Node& node, const std::string& field) const {
    if (!node.IsSequence() || node.size() != 2) Fail(node, field, "expected [x, y] in metres");
    return {Number(node[0], Index(field, 0)), Number(node[1], Index(field, 1))};
  }
  std::string Path(const YAML::Node& node, const std::string& field, bool must_exist) const {
    std::string text = Text(node, field);
    if (text.empty()) Fail(node, field, "expected a file name");
    fs::path p(text);
    if (p.is_relative()) p = fs::path(origin_).parent_path() / p;
    p = p.lexically_normal();
    std::error_code ec;  // a name the file system refuses (too long, ...) is no such file either
    if (must_exist && !fs::exists(p, ec)) {
      Fail(node, field, "no such file: " + p.string() + (ec ? " (" + ec.message() + ")" : ""));
    }
    return p.string();
  }
  const std::string& origin() const { return origin_; }

 private:
  static std::string Num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  std::string origin_;
};

// A time in seconds or "end": (step, counts back from the end).
std::pair<int, bool> ReadTime(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                              const std::string& field) {
  if (node.IsScalar() && node.Scalar() == "end") return {0, true};
  return {spec.Steps(r.AtLeast(node, field, 0.0)), false};
}

// `at: T | end` or `from: T` / `to: T | end`; `fallback` when none is given.
StepWindow ReadWindow(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                      const std::string& field, StepWindow fallback) {
  if (node["at"]) {
    if (node["from"] || node["to"]) r.Fail(node, field + ".at", "give either at or from/to");
    const auto [step, from_end] = ReadTime(r, spec, node["at"], field + ".at");
    return {step, from_end, step, from_end};
  }
  if (!node["from"] && !node["to"]) return fallback;
  StepWindow window = StepWindow::All();
  if (node["from"]) {
    const auto [step, from_end] = ReadTime(r, spec, node["from"], field + ".from");
    window.first = step;
    window.first_from_end = from_end;
  }
  if (node["to"]) {
    const auto [step, from_end] = ReadTime(r, spec, node["to"], field + ".to");
    window.last = step;
    window.last_from_end = from_end;
  }
  if (!window.first_from_end && !window.last_from_end && window.last < window.first) {
    r.Fail(node["to"], field + ".to", "ends before it starts");
  }
  return window;
}

double ReadStrength(const Reader& r, const YAML::Node& node, const std::string& field,
                    double fallback) {
  return node["strength"] ? r.AtLeast(node["strength"], field + ".strength", 0.0) : fallback;
}

LengthSpec ReadLength(const Reader& r, const YAML::Node& node, const std::string& field) {
  r.Map(node, field, {"min_frames", "strength"});
  if (!node["min_frames"]) r.Fail(node, field + ".min_frames", "required");
  return {r.Integer(node["min_frames"], field + ".min_frames", 1),
          ReadStrength(r, node, field, 1.0)};
}

FastFrameSpec ReadFast(const Reader& r, const YAML::Node& node, const std::string& field) {
  r.Map(node, field, {"reference_speed_m_s", "strength"});
  if (!node["reference_speed_m_s"]) r.Fail(node, field + ".reference_speed_m_s", "required");
  return {r.Positive(node["reference_speed_m_s"], field + ".reference_speed_m_s"),
          ReadStrength(r, node, field, 1.0)};
}

LocationSpec ReadLocation(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                          const std::string& field) {
  r.Map(node, field, {"target", "follow", "offset", "offset_axes", "at", "from", "to", "strength"});
  LocationSpec out;
  out.place = r.Place(node, field);
  if (node["follow"]) {
    if (node["target"]) r.Fail(node["target"], field + ".target", "give either target or follow");
    out.follow = r.Text(node["follow"], field + ".follow");
    out.target_m =
        node["offset"] ? r.Point(node["offset"], field + ".offset") : Eigen::Vector2d::Zero();
    if (node["offset_axes"]) {
      const std::string axes = r.Text(node["offset_axes"], field + ".offset_axes");
      if (axes != "heading" && axes != "ground") {
        r.Fail(node["offset_axes"], field + ".offset_axes", "expected heading or ground");
      }
      out.offset_in_heading = axes == "heading";
    }
  } else {
    if (!node["target"]) r.Fail(node, field + ".target", "required (or follow: SPRITE)");
    if (node["offset"]) r.Fail(node["offset"], field + ".offset", "only with follow");
    out.target_m = r.Point(node["target"], field + ".target");
  }
  out.window = ReadWindow(r, spec, node, field, StepWindow::All());
  out.strength = ReadStrength(r, node, field, 1.0);
  return out;
}

PathSpec ReadPath(const Reader& r, const YAML::Node& node, const std::string& field) {
  r.Map(node, field, {"points", "direction_strength", "distance_strength", "unreached_strength"});
  PathSpec out;
  out.place = r.Place(node, field);
  const YAML::Node points = node["points"];
  if (!points) r.Fail(node, field + ".points", "required");
  if (!points.IsSequence() || points.size() < 2) {
    r.Fail(points, field + ".points", "expected a list of at least two [x, y] points");
  }
  for (size_t i = 0; i < points.size(); ++i) {
    out.points_m.push_back(r.Point(points[i], Reader::Index(field + ".points", i)));
  }
  try {
    Polyline check(out.points_m, field + ".points");
  } catch (const InputError&) {
    r.Fail(points, field + ".points", "needs two distinct points");
  }
  if (node["direction_strength"]) {
    out.strengths.direction =
        r.AtLeast(node["direction_strength"], field + ".direction_strength", 0);
  }
  if (node["distance_strength"]) {
    out.strengths.distance = r.AtLeast(node["distance_strength"], field + ".distance_strength", 0);
  }
  if (node["unreached_strength"]) {
    out.strengths.unreached =
        r.AtLeast(node["unreached_strength"], field + ".unreached_strength", 0);
  }
  return out;
}

FrameSpec ReadFrames(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                     const std::string& field) {
  r.Map(node, field, {"tag", "sprites", "at", "from", "to", "after_path", "duration", "strength"});
  FrameSpec out;
  out.place = r.Place(node, field);
  if (node["tag"] && node["sprites"]) r.Fail(node, field, "give either tag or sprites");
  if (node["tag"]) {
    out.tag = r.Text(node["tag"], field + ".tag");
    if (out.tag.empty()) r.Fail(node["tag"], field + ".tag", "must not be empty");
  } else if (node["sprites"]) {
    const YAML::Node ids = node["sprites"];
    if (!ids.IsSequence() || ids.size() == 0) {
      r.Fail(ids, field + ".sprites", "expected a list of bank sprite ids");
    }
    for (size_t i = 0; i < ids.size(); ++i) {
      out.sprite_ids.push_back(r.Integer(ids[i], Reader::Index(field + ".sprites", i), 1));
    }
  } else {
    r.Fail(node, field + ".tag", "required (or sprites: [ids])");
  }
  if (node["after_path"]) {
    if (node["at"] || node["from"] || node["to"]) {
      r.Fail(node["after_path"], field + ".after_path", "give either after_path or at/from/to");
    }
    out.after_path_of = r.Text(node["after_path"], field + ".after_path");
    if (!node["duration"]) r.Fail(node, field + ".duration", "required with after_path");
    out.duration_steps = std::max(1, spec.Steps(r.Positive(node["duration"], field + ".duration")));
  } else {
    if (node["duration"]) r.Fail(node["duration"], field + ".duration", "only with after_path");
    out.window = ReadWindow(r, spec, node, field, StepWindow::All());
  }
  out.strength = ReadStrength(r, node, field, 1.0);
  return out;
}

SpriteSpecEntry ReadSprite(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                           const std::string& field) {
  r.Map(node, field,
        {"name", "start", "end", "smoothness", "constraints", "length", "fast_frames"});
  SpriteSpecEntry out;
  out.place = r.Place(node, field);
  if (!node["name"]) r.Fail(node, field + ".name", "required");
  out.name = r.Text(node["name"], field + ".name");
  if (out.name.empty()) r.Fail(node["name"], field + ".name", "must not be empty");
  if (node["start"] && node["end"]) r.Fail(node["end"], field + ".end", "give either start or end");
  if (node["end"]) {
    out.anchor = Anchor::kEnd;
    out.anchor_m = r.Point(node["end"], field + ".end");
  } else if (node["start"]) {
    const YAML::Node start = node["start"];
    if (start.IsScalar() && start.Scalar() == "free") {
      out.anchor = Anchor::kFree;
    } else if (start.IsMap()) {
      r.Map(start, field + ".start", {"free", "guess"});
      out.anchor = Anchor::kFree;
      if (start["guess"]) out.anchor_m = r.Point(start["guess"], field + ".start.guess");
    } else {
      out.anchor_m = r.Point(start, field + ".start");
    }
  } else {
    r.Fail(node, field + ".start", "required: [x, y], free, or end: [x, y] instead");
  }
  if (node["smoothness"]) out.smoothness = r.AtLeast(node["smoothness"], field + ".smoothness", 0);
  if (node["length"]) out.length = ReadLength(r, node["length"], field + ".length");
  if (node["fast_frames"]) out.fast = ReadFast(r, node["fast_frames"], field + ".fast_frames");
  if (const YAML::Node list = node["constraints"]) {
    const std::string lfield = field + ".constraints";
    if (!list.IsSequence()) r.Fail(list, lfield, "expected a list");
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string cfield = Reader::Index(lfield, i);
      const YAML::Node item = list[i];
      if (!item.IsMap() || item.size() != 1) {
        r.Fail(item, cfield, "expected one of location:, path:, frames:");
      }
      if (!item.begin()->first.IsScalar())
        r.Fail(item, cfield, "expected one of location:, path:, frames:");
      const std::string kind = item.begin()->first.as<std::string>();
      const YAML::Node body = item.begin()->second;
      if (kind == "location") {
        out.locations.push_back(ReadLocation(r, spec, body, cfield + ".location"));
      } else if (kind == "path") {
        if (out.path) r.Fail(item, cfield + ".path", "a sprite has at most one path");
        out.path = ReadPath(r, body, cfield + ".path");
      } else if (kind == "frames") {
        out.frames.push_back(ReadFrames(r, spec, body, cfield + ".frames"));
      } else {
        r.Fail(item, cfield + "." + kind, "unknown constraint (expected location, path or frames)");
      }
    }
  }
  return out;
}

CollisionSpec ReadCollision(const Reader& r, const AnimationSpec& spec, const YAML::Node& node,
                            const std::string& field) {
  r.Map(node, field, {"sprites", "min_distance_m", "strength"});
  CollisionSpec out;
  out.place = r.Place(node, field);
  const YAML::Node sprites = node["sprites"];
  if (!sprites) r.Fail(node, field + ".sprites", "required: a list of names, or all");
  if (sprites.IsScalar() && sprites.Scalar() == "all") {
    if (spec.sprites.size() < 2) r.Fail(sprites, field + ".sprites", "needs two sprites or more");
  } else {
    if (!sprites.IsSequence() || sprites.size() < 2) {
      r.Fail(sprites, field + ".sprites", "expected all or a list of two sprite names or more");
    }
    for (size_t i = 0; i < sprites.size(); ++i) {
      const std::string f = Reader::Index(field + ".sprites", i);
      const std::string name = r.Text(sprites[i], f);
      if (spec.SpriteIndex(name) < 0) r.Fail(sprites[i], f, "no sprite named " + name);
      out.sprites.push_back(name);
    }
  }
  if (!node["min_distance_m"]) r.Fail(node, field + ".min_distance_m", "required");
  out.min_distance_m = r.Positive(node["min_distance_m"], field + ".min_distance_m");
  out.strength = ReadStrength(r, node, field, 1.0);
  return out;
}

// Reads `node` as the block `field` with `keys` (the station config's reader,
// core/options_binder.h: types, unknown keys) and throws its first mistake: a spec stops there.
void ReadBound(const Reader& r, const OptionsBinder& keys, const YAML::Node& node,
               const std::string& field) {
  std::map<std::string, int> lines;
  YamlMessages msg(r.origin(), lines);
  YamlReader reader(msg, lines, fs::path(r.origin()).parent_path().string());
  if (!node.IsMap()) r.Fail(node, field, "expected a map");
  keys.Read(reader, node, field);
  if (!msg.errors.empty()) throw InputError(msg.errors.front());
}

void ReadOptimizer(const Reader& r, const YAML::Node& node, OptimizerSpec& o) {
  const std::string f = "optimizer";
  ReplacementOptions& rep = o.replacement;
  int64_t seed = static_cast<int64_t>(rep.seed);
  OptionsBinder keys;
  keys.AddEnum("method", &o.method, kOptimizerMethodTexts, "replace or beam")
      .AddEnum("start", &rep.start, kSpecStartTexts,
               "replacement's start: sequential, random or beam")
      .Add("time_budget_s", &rep.time_budget_seconds, "a number", "seconds the optimizer may run")
      .Add("seed", &seed, "a whole number >= 0", "the random generator's seed")
      .Add("set_size", &rep.reach.set_size, "a whole number >= 2", "N of the F/B sets")
      .Add("threads", &rep.reach.num_threads, "a whole number >= 1", "worker threads")
      .Add("changes_per_turn", &rep.changes_per_turn, "a whole number >= 1",
           "picks per sprite turn")
      .Add("beam_width", &rep.beam.width, "a whole number >= 1", "the beam search's width")
      .Add("snapshot_every_s", &o.snapshot_every_s, "a number",
           "> 0: keep the sequences every so many seconds")
      .Add("collision_pick_fraction", &rep.collision_pick_fraction, "a number",
           "replacement's picks aimed at a collision, 0 to 1");
  ReadBound(r, keys, node, f);
  // The bounds; those of the optimizer (ReplacementOptions::IsValid, beam search) are checked
  // here so that the message names the spec's file, line and field rather than the optimizer's.
  const auto fail = [&](const char* key, const std::string& why) {
    r.Fail(node[key], f + "." + key, why);
  };
  const auto whole = [&](const char* key, int value, int low, int high) {
    if (!node[key]) return;
    if (value < low) fail(key, "expected a whole number >= " + std::to_string(low));
    if (value > high)
      fail(key, "expected at most " + std::to_string(high) + ", got " + std::to_string(value));
  };
  const auto positive = [&](const char* key, double value) {
    if (!node[key]) return;
    if (!std::isfinite(value)) fail(key, "expected a finite number");
    if (value <= 0) fail(key, "must be > 0");
  };
  positive("time_budget_s", rep.time_budget_seconds);
  if (node["seed"] && (seed < 0 || seed > 1000000000)) fail("seed", "expected a whole number >= 0");
  rep.seed = static_cast<uint64_t>(seed);
  whole("set_size", rep.reach.set_size, 2, 65535);
  whole("threads", rep.reach.num_threads, 1, 256);
  whole("changes_per_turn", rep.changes_per_turn, 1, 1000000000);
  whole("beam_width", rep.beam.width, 1, 65535);
  if (node["collision_pick_fraction"]) {
    const double fraction = rep.collision_pick_fraction;
    if (!std::isfinite(fraction)) fail("collision_pick_fraction", "expected a finite number");
    if (fraction < 0) fail("collision_pick_fraction", "must be >= 0");
    if (fraction > 1) fail("collision_pick_fraction", "expected 0 to 1");
  }
  positive("snapshot_every_s", o.snapshot_every_s);
}

void ReadLengthTop(const Reader& r, const YAML::Node& node, AnimationSpec& spec) {
  int fixed = 0, min_frames = 0, max_frames = 0, initial_frames = 0;
  std::optional<double> strength;
  if (node.IsScalar()) {
    fixed = r.Integer(node, "length", 1);
  } else {
    OptionsBinder keys;
    keys.Add("frames", &fixed, "a whole number >= 1", "every sequence is this long")
        .Add("min_frames", &min_frames, "a whole number >= 1", "sequences shorter are penalized")
        .Add("max_frames", &max_frames, "a whole number >= 1", "the longest sequence")
        .Add("initial_frames", &initial_frames, "a whole number >= 1",
             "length of random initial sequences")
        .Add("strength", &strength, "a number", "weight of the length term");
    ReadBound(r, keys, node, "length");
    for (const auto& [key, value] :
         {std::pair{"frames", fixed}, std::pair{"min_frames", min_frames},
          std::pair{"max_frames", max_frames}, std::pair{"initial_frames", initial_frames}}) {
      if (node[key] && value < 1)
        r.Fail(node[key], std::string("length.") + key, "expected a whole number >= 1");
    }
    if (strength && (!std::isfinite(*strength) || *strength < 0)) {
      r.Fail(node["strength"], "length.strength",
             std::isfinite(*strength) ? "must be >= 0" : "expected a finite number");
    }
    if (node["frames"] && (node["min_frames"] || node["max_frames"])) {
      r.Fail(node["frames"], "length.frames", "give either frames (fixed) or min/max_frames");
    }
    spec.max_frames = max_frames;
    if (initial_frames > 0) spec.initial_frames = initial_frames;
    if (min_frames > 0) {
      spec.length = LengthSpec{min_frames, strength.value_or(1.0)};
      if (spec.max_frames > 0 && spec.max_frames < min_frames) {
        r.Fail(node["max_frames"], "length.max_frames", "is below length.min_frames");
      }
    }
  }
  if (fixed > 0) {
    // A fixed length: sequences are cut at N and strongly held to N.
    spec.fixed_frames = fixed;
    spec.max_frames = fixed;
    spec.initial_frames = fixed;
    spec.length = LengthSpec{fixed, strength.value_or(100.0)};
  }
}

}  // namespace

int AnimationSpec::Steps(double seconds) const {
  return static_cast<int>(std::lround(seconds * frame_rate));
}

int AnimationSpec::SpriteIndex(const std::string& name) const {
  for (size_t i = 0; i < sprites.size(); ++i) {
    if (sprites[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::string AnimationSpec::Where(const SpecPlace& place) const {
  return path + ":" + std::to_string(place.line) + ": " + place.field;
}

namespace {

AnimationSpec ParseSpecRoot(const YAML::Node& root, const std::string& origin) {
  const Reader r(origin);
  AnimationSpec spec;
  spec.path = origin;
  r.Map(root, "",
        {"version", "frame_rate", "length", "camera", "background", "banks", "sprites",
         "collisions", "fast_frames", "optimizer"});
  if (root["version"]) {
    spec.version = r.Integer(root["version"], "version", 1);
    if (spec.version != kAnimationSpecVersion) {
      r.Fail(root["version"], "version",
             "this build reads version " + std::to_string(kAnimationSpecVersion));
    }
  }
  if (root["frame_rate"]) spec.frame_rate = r.Positive(root["frame_rate"], "frame_rate");
  if (!root["length"]) r.Fail(root, "length", "required: N frames, or {min_frames, max_frames}");
  ReadLengthTop(r, root["length"], spec);
  if (!root["camera"]) r.Fail(root, "camera", "required: the virtual camera's .cameramodel");
  spec.camera_path = r.Path(root["camera"], "camera", true);
  if (root["background"]) spec.background_path = r.Path(root["background"], "background", true);
  const YAML::Node banks = root["banks"];
  if (!banks) r.Fail(root, "banks", "required: a list of sprite banks");
  if (banks.IsScalar()) {
    spec.bank_paths.push_back(r.Path(banks, "banks", true));
  } else {
    if (!banks.IsSequence() || banks.size() == 0)
      r.Fail(banks, "banks", "expected a list of banks");
    for (size_t i = 0; i < banks.size(); ++i) {
      spec.bank_paths.push_back(r.Path(banks[i], Reader::Index("banks", i), true));
    }
  }
  if (root["fast_frames"]) spec.fast = ReadFast(r, root["fast_frames"], "fast_frames");
  if (root["optimizer"]) ReadOptimizer(r, root["optimizer"], spec.optimizer);

  const YAML::Node sprites = root["sprites"];
  if (!sprites) r.Fail(root, "sprites", "required: a list of sprites");
  if (!sprites.IsSequence() || sprites.size() == 0) r.Fail(sprites, "sprites", "expected a list");
  for (size_t i = 0; i < sprites.size(); ++i) {
    const std::string field = Reader::Index("sprites", i);
    SpriteSpecEntry entry = ReadSprite(r, spec, sprites[i], field);
    if (spec.SpriteIndex(entry.name) >= 0) {
      r.Fail(sprites[i]["name"], field + ".name", "another sprite is named " + entry.name);
    }
    spec.sprites.push_back(std::move(entry));
  }
  // References between sprites, now that every name is known.
  for (size_t i = 0; i < sprites.size(); ++i) {
    const SpriteSpecEntry& s = spec.sprites[i];
    for (const LocationSpec& l : s.locations) {
      if (l.follow.empty()) continue;
      const int leader = spec.SpriteIndex(l.follow);
      if (leader < 0 || leader == static_cast<int>(i)) {
        throw InputError(spec.Where(l.place) + ".follow", leader < 0
                                                              ? "no sprite named " + l.follow
                                                              : "a sprite cannot follow itself");
      }
    }
    for (const FrameSpec& f : s.frames) {
      if (f.after_path_of.empty()) continue;
      const int owner = spec.SpriteIndex(f.after_path_of);
      if (owner < 0)
        throw InputError(spec.Where(f.place) + ".after_path", "no sprite named " + f.after_path_of);
      if (!spec.sprites[owner].path) {
        throw InputError(spec.Where(f.place) + ".after_path",
                         f.after_path_of + " has no path constraint");
      }
    }
  }
  if (const YAML::Node list = root["collisions"]) {
    if (!list.IsSequence()) r.Fail(list, "collisions", "expected a list");
    for (size_t i = 0; i < list.size(); ++i) {
      spec.collisions.push_back(ReadCollision(r, spec, list[i], Reader::Index("collisions", i)));
    }
  }
  if (spec.initial_frames == 0) {
    spec.initial_frames = spec.length ? spec.length->min_frames : spec.Steps(4.0);
    if (spec.max_frames > 0) spec.initial_frames = std::min(spec.initial_frames, spec.max_frames);
  }
  return spec;
}

}  // namespace

AnimationSpec ParseAnimationSpec(const std::string& yaml, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1), "not valid YAML: " + e.msg);
  }
  try {
    return ParseSpecRoot(root, origin);
  } catch (const YAML::Exception& e) {
    // A shape the reader did not check for (found by tests/fuzz): still an error naming the line.
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1),
                     "cannot read this (" + e.msg + ")");
  }
}

AnimationSpec LoadAnimationSpec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the animation spec");
  return ParseAnimationSpec(ReadWithinLimit(in, path, "an animation spec"), path);
}

}  // namespace ss
