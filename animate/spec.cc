#include "animate/spec.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "core/error.h"
#include "core/input_file.h"
#include "core/option_checks.h"
#include "core/options_binder.h"
#include "core/yaml_reader.h"

namespace ss {

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

namespace fs = std::filesystem;
using namespace yaml_text;

// A time as written: seconds, or `end`.
struct SpecTime {
  double seconds = 0;
  bool end = false;
};

// The `at`, `from` and `to` keys of a block with a window, as read.
struct WindowKeys {
  std::optional<SpecTime> at, from, to;
};

// A sprite's constraints, as an item of `constraints:` names them: "location:, path:, frames:"
// and each registered apart (animate/spec_term.h).
std::string ConstraintWords() {
  std::string words;
  for (const std::string& key : SpriteConstraintKeys())
    words += (words.empty() ? "" : ", ") + key + ":";
  return words;
}

// A number as written, without rounding to 6 digits ("10000000", not "1e+07").
std::string Exact(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", v);
  return text;
}

// Whether `file` lies under one of `roots`, both with symlinks followed as far as they exist
// (a link under a root to a file elsewhere is elsewhere). Nothing is opened.
bool UnderOneOf(const std::string& file, const std::vector<std::string>& roots) {
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (ec) return false;
  for (const std::string& root : roots) {
    const fs::path base = fs::weakly_canonical(root, ec);
    if (ec) continue;
    const auto rel = resolved.lexically_relative(base);
    if (!rel.empty() && *rel.begin() != "..") return true;
  }
  return false;
}

enum class OffsetAxes { kHeading, kGround };
constexpr EnumText<OffsetAxes> kOffsetAxesTexts[] = {{OffsetAxes::kHeading, "heading"},
                                                     {OffsetAxes::kGround, "ground"}};

// The optimizer's option fields (ReplacementOptions, BeamOptions) by the spec key that sets them,
// so that the optimizer's own limits are checked by the optimizer and named as the spec's keys.
const std::map<std::string, std::string> kReplacementKeys = {
    {"reach.set_size", "set_size"},
    {"reach.num_threads", "threads"},
    {"time_budget_seconds", "time_budget_s"},
    {"changes_per_turn", "changes_per_turn"},
    {"collision_pick_fraction", "collision_pick_fraction"},
    {"goal_fraction", "goal_pick_fraction"},
    {"beam.width", "beam_width"},
};
const std::map<std::string, std::string> kBeamKeys = {
    {"width", "beam_width"},
    {"time_budget_seconds", "time_budget_s"},
};

// Reads one spec with the station config's reader (core/yaml_reader.h): each block's keys are
// bound to the spec's fields (core/options_binder.h), values with a shape of their own (points,
// times, `free`, `all`) are read by this class, and every mistake of the file is collected with
// its line and field before the spec is refused.
class SpecReader : public SpecBlockReader {
 public:
  SpecReader(const std::string& origin, SpecFileRules files)
      : msg_(origin, lines_),
        r_(msg_, lines_,
           files.base_dir.empty() ? fs::path(origin).parent_path().string() : files.base_dir),
        files_(std::move(files)) {
    spec_.path = origin;
  }

  AnimationSpec Read(const YAML::Node& root);

  // SpecBlockReader, for the terms registered apart (animate/spec_term.h).
  bool Block(const OptionsBinder& keys, const YAML::Node& node, const std::string& path,
             YamlMap& view) override;
  void Required(const YamlMap& view, const std::string& key, const std::string& reason) override {
    if (view.Find(key) == nullptr) Error(view, key, reason);
  }

 private:
  using NodeRead = std::function<bool(const YAML::Node& node, const std::string& path)>;

  // --- values of one node at `path` (list items, and the values of shaped keys)
  bool Number(const YAML::Node& node, const std::string& path, double& out);
  bool WholeNumber(const YAML::Node& node, const std::string& path, int low, int64_t& out,
                   int64_t high = 1000000000);
  bool Text(const YAML::Node& node, const std::string& path, std::string& out);
  bool Point(const YAML::Node& node, const std::string& path, Eigen::Vector2d& out);
  bool Time(const YAML::Node& node, const std::string& path, SpecTime& out);
  // Why `seconds` lies past the animation's end (its steps beyond its longest sequence), or "".
  std::string PastTheEnd(double seconds) const;
  bool ExistingFile(const YAML::Node& node, const std::string& path, std::string& out);

  // A key whose value `read` takes from its node, once the key is there with a value.
  static OptionsBinder::ReadFn Shaped(NodeRead read) {
    return [read = std::move(read)](YamlReader& r, const YamlMap& view, const std::string& key) {
      const YAML::Node* node = r.Value(view, key);
      return node != nullptr && read(*node, Child(view.path(), key));
    };
  }
  // A key holding a block that `read` takes whole, reporting its own errors.
  static OptionsBinder::ReadFn BlockOf(
      std::function<void(const YAML::Node& node, const std::string& path)> read) {
    return Shaped([read = std::move(read)](const YAML::Node& n, const std::string& p) {
      read(n, p);
      return true;
    });
  }
  OptionsBinder::ReadFn PointInto(Eigen::Vector2d* out) {
    return Shaped(
        [this, out](const YAML::Node& n, const std::string& p) { return Point(n, p, *out); });
  }
  OptionsBinder::ReadFn FileInto(std::string* out) {
    return Shaped([this, out](const YAML::Node& n, const std::string& p) {
      return ExistingFile(n, p, *out);
    });
  }
  void BindWindow(OptionsBinder& keys, WindowKeys& window);

  // --- rules on what a block's keys hold, each reported on the key
  void Error(const YamlMap& view, const std::string& key, const std::string& reason) {
    msg_.Error(Child(view.path(), key), reason);
  }
  // Reports `reason` on `key` unless `good`, when the key was given and read without an error.
  void Check(const YamlMap& view, const std::string& key, bool good, const std::string& reason) {
    if (!good && view.Find(key) != nullptr && !msg_.Failed(Child(view.path(), key)))
      Error(view, key, reason);
  }
  // The window the keys give; `fallback` when none is given.
  StepWindow Window(const YamlMap& view, const WindowKeys& keys, StepWindow fallback);
  // An options struct's problems ("field: reason" lines), each on the spec key that sets it.
  void Report(const YamlMap& view, const std::string& why,
              const std::map<std::string, std::string>& keys);

  // --- the blocks
  void LengthTop(const YAML::Node& node);
  void Banks(const YAML::Node& node);
  void Optimizer(const YAML::Node& node);
  void Sprites(const YAML::Node& node);
  void Collisions(const YAML::Node& node);
  SpriteSpecEntry Sprite(const YAML::Node& node, const std::string& path);
  void Start(const YAML::Node& node, const std::string& path, SpriteSpecEntry& out);
  void Constraints(const YAML::Node& node, const std::string& path, SpriteSpecEntry& out);
  LengthSpec Length(const YAML::Node& node, const std::string& path);
  FastFrameSpec Fast(const YAML::Node& node, const std::string& path);
  LocationSpec Location(const YAML::Node& node, const std::string& path);
  PathSpec Path(const YAML::Node& node, const std::string& path);
  FrameSpec Frames(const YAML::Node& node, const std::string& path);
  CollisionSpec Collision(const YAML::Node& node, const std::string& path);
  // The references between sprites, once every name is known.
  void CheckReferences();

  std::map<std::string, int> lines_;  // before msg_ and r_, which keep references to it
  YamlMessages msg_;
  YamlReader r_;
  SpecFileRules files_;
  AnimationSpec spec_;
};

bool SpecReader::Number(const YAML::Node& node, const std::string& path, double& out) {
  double value = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    msg_.Error(path, "expected a number, got " + ShapeOf(node));
    return false;
  }
  if (!std::isfinite(value)) {
    msg_.Error(path, "expected a finite number");
    return false;
  }
  out = value;
  return true;
}

bool SpecReader::WholeNumber(const YAML::Node& node, const std::string& path, int low, int64_t& out,
                             int64_t high) {
  double value = 0;
  const bool number = node.IsScalar() && YAML::convert<double>::decode(node, value);
  if (!number || value != std::floor(value) || value < low) {
    msg_.Error(path,
               "expected a whole number >= " + std::to_string(low) + ", got " + ShapeOf(node));
    return false;
  }
  if (value > static_cast<double>(high)) {
    msg_.Error(path, "must be at most " + std::to_string(high) + ", got " + ShapeOf(node));
    return false;
  }
  out = static_cast<int64_t>(value);
  return true;
}

bool SpecReader::Text(const YAML::Node& node, const std::string& path, std::string& out) {
  if (!node.IsScalar()) {
    msg_.Error(path, "expected a name, got " + ShapeOf(node));
    return false;
  }
  out = node.Scalar();
  return true;
}

bool SpecReader::Point(const YAML::Node& node, const std::string& path, Eigen::Vector2d& out) {
  if (!node.IsSequence() || node.size() != 2) {
    msg_.Error(path, "expected [x, y] in metres");
    return false;
  }
  Eigen::Vector2d p;
  const bool x = Number(node[0], Index(path, 0), p.x());
  const bool y = Number(node[1], Index(path, 1), p.y());
  if (!x || !y) return false;
  out = p;
  return true;
}

bool SpecReader::Time(const YAML::Node& node, const std::string& path, SpecTime& out) {
  if (node.IsScalar() && node.Scalar() == "end") {
    out = {0, true};
    return true;
  }
  double seconds = 0;
  if (!Number(node, path, seconds)) return false;
  if (seconds < 0) {
    msg_.Error(path, "must be >= 0 (seconds) or end");
    return false;
  }
  if (const std::string past = PastTheEnd(seconds); !past.empty()) {
    msg_.Error(path, past);
    return false;
  }
  out = {seconds, false};
  return true;
}

std::string SpecReader::PastTheEnd(double seconds) const {
  // The animation's own extent: its longest sequence, or a spec's longest when it sets none.
  // A window may end one step past the last frame (at the end of a fixed length's time).
  const double steps = seconds * spec_.frame_rate;
  const int extent = spec_.max_frames > 0 ? spec_.max_frames : kMaxSpecFrames;
  if (!(steps <= extent + 0.5)) {
    return "past the animation's end: " + Exact(seconds) + " s is step " +
           Exact(std::round(steps)) + " at " + Exact(spec_.frame_rate) + " fps, and " +
           (spec_.max_frames > 0 ? "its sequences are at most "
                                 : "a spec's sequences are at most ") +
           std::to_string(extent) + " frames";
  }
  return "";
}

bool SpecReader::ExistingFile(const YAML::Node& node, const std::string& path, std::string& out) {
  if (!node.IsScalar() || node.Scalar().empty()) {
    msg_.Error(path, "expected a file name, got " + ShapeOf(node));
    return false;
  }
  const std::string file = r_.Resolve(node.Scalar());
  std::error_code ec;  // a name the file system refuses (too long, ...) is no such file either
  if (!files_.roots.empty() && !UnderOneOf(file, files_.roots)) {
    std::string roots;
    for (const std::string& root : files_.roots) roots += (roots.empty() ? "" : ", ") + root;
    msg_.Error(path, file + ": outside the station's folders (" + roots + "); not opened");
    return false;
  }
  if (!fs::exists(file, ec)) {
    msg_.Error(path, "no such file: " + file + (ec ? " (" + ec.message() + ")" : ""));
    return false;
  }
  // Absolute: the sequences file names these, and is read from anywhere (render, judge).
  out = fs::absolute(file, ec).lexically_normal().string();
  if (ec) out = file;
  return true;
}

void SpecReader::BindWindow(OptionsBinder& keys, WindowKeys& window) {
  for (const auto& bound : {std::pair{"at", &window.at}, std::pair{"from", &window.from},
                            std::pair{"to", &window.to}}) {
    std::optional<SpecTime>* field = bound.second;
    keys.AddRead(bound.first, "", "seconds or end",
                 Shaped([this, field](const YAML::Node& n, const std::string& p) {
                   SpecTime time;
                   if (!Time(n, p, time)) return false;
                   *field = time;
                   return true;
                 }));
  }
}

bool SpecReader::Block(const OptionsBinder& keys, const YAML::Node& node, const std::string& path,
                       YamlMap& view) {
  view = r_.Map(node, path);
  if (!node.IsMap()) {
    if (node.IsNull() && !path.empty()) msg_.Error(path, "expected a mapping of keys, got nothing");
    return false;
  }
  r_.Known(view, keys.Keys());
  keys.ReadKeys(r_, view);
  keys.CheckRules(msg_, view);  // each given number within its binding's rule
  return true;
}

StepWindow SpecReader::Window(const YamlMap& view, const WindowKeys& keys, StepWindow fallback) {
  const auto step = [&](const SpecTime& t) { return t.end ? 0 : spec_.Steps(t.seconds); };
  if (view.Find("at") != nullptr) {
    if (view.Find("from") != nullptr || view.Find("to") != nullptr)
      Error(view, "at", "give either at or from/to");
    if (!keys.at) return fallback;
    return {step(*keys.at), keys.at->end, step(*keys.at), keys.at->end};
  }
  if (!keys.from && !keys.to) return fallback;
  StepWindow window = StepWindow::All();
  if (keys.from) {
    window.first = step(*keys.from);
    window.first_from_end = keys.from->end;
  }
  if (keys.to) {
    window.last = step(*keys.to);
    window.last_from_end = keys.to->end;
  }
  Check(view, "to", window.first_from_end || window.last_from_end || window.last >= window.first,
        "ends before it starts");
  return window;
}

void SpecReader::Report(const YamlMap& view, const std::string& why,
                        const std::map<std::string, std::string>& keys) {
  for (const auto& [field, reason] : OptionProblems::Split(why)) {
    const auto key = keys.find(field);
    if (key == keys.end()) {
      // A field the spec does not set: cannot happen from a spec.
      msg_.Error(view.path(), field.empty() ? reason : field + ": " + reason);
    } else if (!msg_.Failed(Child(view.path(), key->second))) {
      Error(view, key->second, reason);
    }
  }
}

AnimationSpec SpecReader::Read(const YAML::Node& root) {
  OptionsBinder keys;
  keys.Add("version", &spec_.version, "a whole number", "the spec's version")
      .AddRead("frame_rate", "30", "playback frames per second",
               [this](YamlReader& r, const YamlMap& view, const std::string& key) {
                 double rate = 0;
                 if (!r.Number(view, key, rate)) return false;
                 if (!std::isfinite(rate) || rate <= 0) {
                   Error(view, key, "must be > 0");  // before any time is turned into steps
                   return false;
                 }
                 if (rate < kMinFrameRate || rate > kMaxFrameRate) {
                   Error(view, key,
                         "must be from " + Num(kMinFrameRate) + " to " + Num(kMaxFrameRate) +
                             " frames per second, got " + Num(rate));
                   return false;
                 }
                 spec_.frame_rate = rate;
                 return true;
               })
      .AddRead("length", "", "N, or {min_frames, max_frames, ...}",
               BlockOf([this](const YAML::Node& n, const std::string&) { LengthTop(n); }))
      .AddRead("camera", "", "the virtual camera's .cameramodel",
               Shaped([this](const YAML::Node& n, const std::string& p) {
                 spec_.camera_place = {LineOf(n), p};
                 return ExistingFile(n, p, spec_.camera_path);
               }))
      .AddRead("background", "", "an image of the camera's size", FileInto(&spec_.background_path))
      .AddRead("banks", "", "a list of sprite banks",
               BlockOf([this](const YAML::Node& n, const std::string&) { Banks(n); }))
      .AddRead(
          "fast_frames", "", "{reference_speed_m_s, strength}",
          BlockOf([this](const YAML::Node& n, const std::string& p) { spec_.fast = Fast(n, p); }))
      .AddRead("optimizer", "", "the optimizer's block",
               BlockOf([this](const YAML::Node& n, const std::string&) { Optimizer(n); }))
      .AddRead("sprites", "", "the list of sprites",
               BlockOf([this](const YAML::Node& n, const std::string&) { Sprites(n); }))
      .AddRead("collisions", "", "collision constraints",
               BlockOf([this](const YAML::Node& n, const std::string&) { Collisions(n); }));
  const std::vector<const SpecTermKind*> term_kinds = SpecTermKinds();
  for (const SpecTermKind* kind : term_kinds) {
    keys.AddRead(kind->key, "", kind->expected,
                 BlockOf([this, kind](const YAML::Node& n, const std::string& p) {
                   spec_.terms[kind->key] = kind->read(*this, n, p);
                 }));
  }
  YamlMap view;
  if (!Block(keys, root, "", view)) {
    if (root.IsNull()) msg_.Error("(top level)", "the spec is empty");
    throw InputError(Join(msg_.errors, "\n"));
  }
  Check(view, "version", spec_.version == kAnimationSpecVersion,
        "this build reads version " + std::to_string(kAnimationSpecVersion));
  Required(view, "length", "required: N frames, or {min_frames, max_frames}");
  Required(view, "camera", "required: the virtual camera's .cameramodel");
  Required(view, "banks", "required: a list of sprite banks");
  Required(view, "sprites", "required: a list of sprites");
  CheckReferences();
  if (!msg_.errors.empty()) throw InputError(Join(msg_.errors, "\n"));
  for (const SpecTermKind* kind : term_kinds) {
    if (spec_.terms.count(kind->key) == 0) {
      if (auto absent = kind->absent()) spec_.terms[kind->key] = std::move(absent);
    }
  }
  if (spec_.initial_frames == 0) {
    spec_.initial_frames = spec_.length ? spec_.length->min_frames : spec_.Steps(4.0);
    if (spec_.max_frames > 0)
      spec_.initial_frames = std::min(spec_.initial_frames, spec_.max_frames);
  }
  return std::move(spec_);
}

void SpecReader::LengthTop(const YAML::Node& node) {
  int fixed = 0, min_frames = 0, max_frames = 0, initial_frames = 0;
  std::optional<double> strength;
  if (node.IsScalar()) {
    int64_t frames = 0;
    if (!WholeNumber(node, "length", 1, frames, kMaxSpecFrames)) return;
    fixed = static_cast<int>(frames);
  } else {
    OptionsBinder keys;
    const std::string frames = "a whole number of frames 1.." + std::to_string(kMaxSpecFrames);
    keys.Add("frames", &fixed, frames, "every sequence is this long")
        .Rule(Between(1, kMaxSpecFrames))
        .Add("min_frames", &min_frames, frames, "sequences shorter are penalized")
        .Rule(Between(1, kMaxSpecFrames))
        .Add("max_frames", &max_frames, frames, "the longest sequence")
        .Rule(Between(1, kMaxSpecFrames))
        .Add("initial_frames", &initial_frames, frames, "length of random initial sequences")
        .Rule(Between(1, kMaxSpecFrames))
        .Add("strength", &strength, "a number >= 0", "weight of the length term")
        .Rule(AtLeast(0));
    YamlMap view;
    if (!Block(keys, node, "length", view)) return;
    if (view.Find("frames") != nullptr &&
        (view.Find("min_frames") != nullptr || view.Find("max_frames") != nullptr)) {
      Error(view, "frames", "give either frames (fixed) or min/max_frames");
    }
    spec_.max_frames = std::max(0, max_frames);
    if (initial_frames > 0) spec_.initial_frames = initial_frames;
    if (min_frames > 0) {
      spec_.length = LengthSpec{min_frames, strength.value_or(LengthSpec{}.strength)};
      Check(view, "max_frames", spec_.max_frames == 0 || spec_.max_frames >= min_frames,
            "is below length.min_frames");
    }
  }
  if (fixed > 0) {
    // A fixed length: sequences are cut at N and strongly held to N.
    spec_.fixed_frames = fixed;
    spec_.max_frames = fixed;
    spec_.initial_frames = fixed;
    spec_.length = LengthSpec{fixed, strength.value_or(LengthSpec{}.strength)};
  }
}

void SpecReader::Banks(const YAML::Node& node) {
  if (node.IsScalar()) {
    std::string file;
    if (ExistingFile(node, "banks", file)) spec_.bank_paths.push_back(file);
    return;
  }
  if (!node.IsSequence()) {
    msg_.Error("banks", "expected a list of banks, got " + ShapeOf(node));
    return;
  }
  if (node.size() == 0) {
    msg_.Error("banks", "expected at least one bank");
    return;
  }
  for (size_t i = 0; i < node.size(); ++i) {
    const std::string path = Index("banks", i);
    r_.Mark(path, node[i]);
    std::string file;
    if (ExistingFile(node[i], path, file)) spec_.bank_paths.push_back(file);
  }
}

void SpecReader::Optimizer(const YAML::Node& node) {
  OptimizerSpec& o = spec_.optimizer;
  ReplacementOptions& rep = o.replacement;
  int64_t seed = static_cast<int64_t>(rep.seed);
  OptionsBinder keys;
  keys.AddEnum("method", &o.method, kOptimizerMethodTexts, "replace or beam")
      .AddEnum("start", &rep.start, kSpecStartTexts,
               "replacement's start: sequential, random or beam")
      .Add("time_budget_s", &rep.time_budget_seconds, "a number", "seconds the optimizer may run")
      .Add("seed", &seed, "a whole number >= 0", "the random generator's seed")
      .Add("set_size", &rep.reach.set_size, "a whole number", "N of the F/B sets")
      .Add("threads", &rep.reach.num_threads, "a whole number", "worker threads")
      .Add("changes_per_turn", &rep.changes_per_turn, "a whole number", "picks per sprite turn")
      .Add("beam_width", &rep.beam.width, "a whole number", "the beam search's width")
      .Add("snapshot_every_s", &o.snapshot_every_s, "seconds >= 0",
           "> 0: keep the sequences every so many seconds")
      .Rule(AtLeast(0))
      .Add("collision_pick_fraction", &rep.collision_pick_fraction, "a number",
           "replacement's picks aimed at a collision, 0 to 1")
      .Add("goal_pick_fraction", &rep.goal_fraction, "a number",
           "replacement's end picks led into a frame constraint's set, 0 to 1");
  YamlMap view;
  if (!Block(keys, node, "optimizer", view)) return;
  Check(view, "seed", seed >= 0 && seed <= 1000000000, "expected a whole number >= 0");
  rep.seed = static_cast<uint64_t>(std::max<int64_t>(seed, 0));
  const double budget = rep.time_budget_seconds, every = o.snapshot_every_s;
  Check(view, "snapshot_every_s",
        !(every > 0) || !std::isfinite(budget) || every * kMaxSpecSnapshots >= budget,
        "keeps at most " + std::to_string(kMaxSpecSnapshots) +
            " snapshots: must be 0 or >= " + Num(budget / kMaxSpecSnapshots) +
            " (time_budget_s / " + std::to_string(kMaxSpecSnapshots) + "), got " + Num(every));
  // The optimizer's own limits, checked by the optimizer and named as the spec's keys.
  std::string why;
  if (!rep.IsValid(&why)) Report(view, why, kReplacementKeys);
  if (o.method == OptimizerMethod::kBeam && !o.Beam().IsValid(&why)) Report(view, why, kBeamKeys);
}

void SpecReader::Sprites(const YAML::Node& node) {
  if (!node.IsSequence()) {
    msg_.Error("sprites", "expected a list of sprites, got " + ShapeOf(node));
    return;
  }
  if (node.size() == 0) {
    msg_.Error("sprites", "expected at least one sprite");
    return;
  }
  if (node.size() > static_cast<size_t>(kMaxSpecSprites)) {
    msg_.Error("sprites", "expected at most " + std::to_string(kMaxSpecSprites) + " sprites, got " +
                              std::to_string(node.size()));
    return;
  }
  for (size_t i = 0; i < node.size(); ++i) {
    const std::string path = Index("sprites", i);
    r_.Mark(path, node[i]);
    SpriteSpecEntry entry = Sprite(node[i], path);
    if (!entry.name.empty() && spec_.SpriteIndex(entry.name) >= 0)
      msg_.Error(Child(path, "name"), "another sprite is named " + entry.name);
    spec_.sprites.push_back(std::move(entry));
  }
}

void SpecReader::Collisions(const YAML::Node& node) {
  if (!node.IsSequence()) {
    msg_.Error("collisions", "expected a list, got " + ShapeOf(node));
    return;
  }
  for (size_t i = 0; i < node.size(); ++i) {
    const std::string path = Index("collisions", i);
    r_.Mark(path, node[i]);
    spec_.collisions.push_back(Collision(node[i], path));
  }
}

SpriteSpecEntry SpecReader::Sprite(const YAML::Node& node, const std::string& path) {
  SpriteSpecEntry out;
  out.place = {LineOf(node), path};
  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  OptionsBinder keys;
  keys.Add("name", &out.name, "a name", "unique")
      .AddRead(
          "start", "", "[x, y], free or {guess: [x, y]}",
          BlockOf([this, &out](const YAML::Node& n, const std::string& p) { Start(n, p, out); }))
      .AddRead("end", "", "[x, y]: the last position is fixed", PointInto(&end))
      .Add("smoothness", &out.smoothness, "a number >= 0", "α")
      .Rule(AtLeast(0))
      .AddRead("constraints", "", ConstraintWords(),
               BlockOf([this, &out](const YAML::Node& n, const std::string& p) {
                 Constraints(n, p, out);
               }))
      .AddRead("length", "", "{min_frames, strength}",
               BlockOf([this, &out](const YAML::Node& n, const std::string& p) {
                 out.length = Length(n, p);
               }))
      .AddRead("fast_frames", "", "{reference_speed_m_s, strength}",
               BlockOf([this, &out](const YAML::Node& n, const std::string& p) {
                 out.fast = Fast(n, p);
               }));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  Required(view, "name", "required");
  Check(view, "name", !out.name.empty(), "must not be empty");
  if (view.Find("end") != nullptr) {
    if (view.Find("start") != nullptr) Error(view, "end", "give either start or end");
    out.anchor = Anchor::kEnd;
    out.anchor_m = end;
  } else if (view.Find("start") == nullptr) {
    Error(view, "start", "required: [x, y], free, or end: [x, y] instead");
  }
  return out;
}

void SpecReader::Start(const YAML::Node& node, const std::string& path, SpriteSpecEntry& out) {
  if (node.IsScalar() && node.Scalar() == "free") {
    out.anchor = Anchor::kFree;
  } else if (node.IsMap()) {
    out.anchor = Anchor::kFree;
    OptionsBinder keys;
    keys.AddRead("free", "", "(any value)",
                 [](YamlReader&, const YamlMap&, const std::string&) { return true; })
        .AddRead("guess", "", "[x, y]: the first guess", PointInto(&out.anchor_m));
    YamlMap view;
    Block(keys, node, path, view);
  } else {
    Point(node, path, out.anchor_m);
  }
}

void SpecReader::Constraints(const YAML::Node& node, const std::string& path,
                             SpriteSpecEntry& out) {
  if (!node.IsSequence()) {
    msg_.Error(path, "expected a list, got " + ShapeOf(node));
    return;
  }
  for (size_t i = 0; i < node.size(); ++i) {
    const std::string item_path = Index(path, i);
    const YAML::Node item = node[i];
    r_.Mark(item_path, item);
    if (!item.IsMap() || item.size() != 1 || !item.begin()->first.IsScalar()) {
      msg_.Error(item_path, "expected one of " + ConstraintWords());
      continue;
    }
    const std::string kind = item.begin()->first.Scalar();
    const YAML::Node body = item.begin()->second;
    const std::string body_path = Child(item_path, kind);
    if (kind == "location") {
      out.locations.push_back(Location(body, body_path));
    } else if (kind == "path") {
      if (out.path) {
        msg_.Error(body_path, "a sprite has at most one path");
        continue;
      }
      out.path = Path(body, body_path);
    } else if (kind == "frames") {
      out.frames.push_back(Frames(body, body_path));
    } else if (const SpriteConstraintKind* registered = FindSpriteConstraint(kind)) {
      if (auto constraint = registered->read(*this, body, body_path))
        out.constraints.push_back(std::move(constraint));
    } else {
      const std::vector<std::string> keys = SpriteConstraintKeys();
      std::string expected;  // "location, path or frames"
      for (size_t k = 0; k < keys.size(); ++k)
        expected += (k == 0 ? "" : k + 1 == keys.size() ? " or " : ", ") + keys[k];
      msg_.Error(body_path, "unknown constraint (expected " + expected + ")");
    }
  }
}

LengthSpec SpecReader::Length(const YAML::Node& node, const std::string& path) {
  LengthSpec out;
  OptionsBinder keys;
  keys.Add("min_frames", &out.min_frames,
           "a whole number of frames 1.." + std::to_string(kMaxSpecFrames), "sequences shorter pay")
      .Rule(Between(1, kMaxSpecFrames))
      .Add("strength", &out.strength, "a number >= 0", "per missing frame")
      .Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  Required(view, "min_frames", "required");
  return out;
}

FastFrameSpec SpecReader::Fast(const YAML::Node& node, const std::string& path) {
  FastFrameSpec out{0.0, 1.0};
  OptionsBinder keys;
  keys.Add("reference_speed_m_s", &out.reference_speed_m_s, "a speed > 0", "v_ref")
      .Rule(Positive())
      .Add("strength", &out.strength, "a number >= 0", "per (m/s) below v_ref, per step")
      .Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  Required(view, "reference_speed_m_s", "required");
  return out;
}

LocationSpec SpecReader::Location(const YAML::Node& node, const std::string& path) {
  LocationSpec out;
  out.place = {LineOf(node), path};
  OffsetAxes axes = OffsetAxes::kHeading;
  WindowKeys window;
  OptionsBinder keys;
  keys.AddRead("target", "", "[x, y] in metres", PointInto(&out.target_m))
      .Add("follow", &out.follow, "a sprite's name", "the leader")
      .AddRead("offset", "", "[along, left] in metres", PointInto(&out.target_m))
      .AddEnum("offset_axes", &axes, kOffsetAxesTexts, "the offset's axes");
  BindWindow(keys, window);
  keys.Add("strength", &out.strength, "a number >= 0", "γ").Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  if (view.Find("follow") != nullptr) {
    if (view.Find("target") != nullptr) Error(view, "target", "give either target or follow");
  } else {
    Required(view, "target", "required (or follow: SPRITE)");
    if (view.Find("offset") != nullptr) Error(view, "offset", "only with follow");
  }
  out.offset_in_heading = axes == OffsetAxes::kHeading;
  out.window = Window(view, window, StepWindow::All());
  return out;
}

PathSpec SpecReader::Path(const YAML::Node& node, const std::string& path) {
  PathSpec out;
  out.place = {LineOf(node), path};
  OptionsBinder keys;
  keys.AddRead("points", "", "[[x, y], ...]",
               Shaped([this, &out](const YAML::Node& n, const std::string& p) {
                 if (!n.IsSequence() || n.size() < 2) {
                   msg_.Error(p, "expected a list of at least two [x, y] points");
                   return false;
                 }
                 bool all = true;
                 for (size_t i = 0; i < n.size(); ++i) {
                   Eigen::Vector2d point;
                   all = Point(n[i], Index(p, i), point) && all;
                   out.points_m.push_back(point);
                 }
                 if (!all) return false;
                 try {
                   Polyline check(out.points_m, p);
                 } catch (const InputError&) {
                   msg_.Error(p, "needs two distinct points");
                   return false;
                 }
                 return true;
               }))
      .Add("direction_strength", &out.strengths.direction, "a number >= 0", "δ")
      .Rule(AtLeast(0))
      .Add("distance_strength", &out.strengths.distance, "a number >= 0", "φ")
      .Rule(AtLeast(0))
      .Add("unreached_strength", &out.strengths.unreached, "a number >= 0", "η")
      .Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  Required(view, "points", "required");
  return out;
}

FrameSpec SpecReader::Frames(const YAML::Node& node, const std::string& path) {
  FrameSpec out;
  out.place = {LineOf(node), path};
  double duration_s = 0;
  WindowKeys window;
  OptionsBinder keys;
  keys.Add("tag", &out.tag, "a tag", "G: the frames with this tag")
      .AddRead("sprites", "", "[ids]: G, these bank sprites",
               Shaped([this, &out](const YAML::Node& n, const std::string& p) {
                 if (!n.IsSequence() || n.size() == 0) {
                   msg_.Error(p, "expected a list of bank sprite ids");
                   return false;
                 }
                 for (size_t i = 0; i < n.size(); ++i) {
                   int64_t id = 0;
                   if (WholeNumber(n[i], Index(p, i), 1, id)) out.sprite_ids.push_back(id);
                 }
                 return true;
               }));
  BindWindow(keys, window);
  keys.Add("after_path", &out.after_path_of, "a sprite's name", "the window starts at its end")
      .Add("duration", &duration_s, "seconds > 0", "seconds, with after_path")
      .Rule(Positive())
      .Add("strength", &out.strength, "a number >= 0", "λ")
      .Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  const bool tag = view.Find("tag") != nullptr, ids = view.Find("sprites") != nullptr;
  if (tag && ids) msg_.Error(path, "give either tag or sprites");
  if (!tag && !ids) Error(view, "tag", "required (or sprites: [ids])");
  Check(view, "tag", !out.tag.empty(), "must not be empty");
  if (view.Find("after_path") != nullptr) {
    if (view.Find("at") != nullptr || view.Find("from") != nullptr || view.Find("to") != nullptr)
      Error(view, "after_path", "give either after_path or at/from/to");
    Required(view, "duration", "required with after_path");
    const std::string past = std::isfinite(duration_s) ? PastTheEnd(duration_s) : "";
    Check(view, "duration", past.empty(), past);
    if (std::isfinite(duration_s) && past.empty())
      out.duration_steps = std::max(1, spec_.Steps(duration_s));
  } else {
    if (view.Find("duration") != nullptr) Error(view, "duration", "only with after_path");
    out.window = Window(view, window, StepWindow::All());
  }
  return out;
}

CollisionSpec SpecReader::Collision(const YAML::Node& node, const std::string& path) {
  CollisionSpec out;
  out.place = {LineOf(node), path};
  OptionsBinder keys;
  keys.AddRead("sprites", "", "all, or a list of names",
               Shaped([this, &out](const YAML::Node& n, const std::string& p) {
                 if (n.IsScalar() && n.Scalar() == "all") {
                   if (spec_.sprites.size() < 2) msg_.Error(p, "needs two sprites or more");
                   return true;
                 }
                 if (!n.IsSequence() || n.size() < 2) {
                   msg_.Error(p, "expected all or a list of two sprite names or more");
                   return false;
                 }
                 for (size_t i = 0; i < n.size(); ++i) {
                   std::string name;
                   if (!Text(n[i], Index(p, i), name)) continue;
                   if (spec_.SpriteIndex(name) < 0)
                     msg_.Error(Index(p, i), "no sprite named " + name);
                   out.sprites.push_back(name);
                 }
                 return true;
               }))
      .Add("min_distance_m", &out.min_distance_m, "a distance > 0 in metres", "d_min")
      .Rule(Positive())
      .Add("strength", &out.strength, "a number >= 0", "µ")
      .Rule(AtLeast(0));
  YamlMap view;
  if (!Block(keys, node, path, view)) return out;
  Required(view, "sprites", "required: a list of names, or all");
  Required(view, "min_distance_m", "required");
  return out;
}

void SpecReader::CheckReferences() {
  for (size_t i = 0; i < spec_.sprites.size(); ++i) {
    const SpriteSpecEntry& s = spec_.sprites[i];
    for (const LocationSpec& l : s.locations) {
      if (l.follow.empty()) continue;
      const int leader = spec_.SpriteIndex(l.follow);
      if (leader < 0 || leader == static_cast<int>(i)) {
        msg_.Error(Child(l.place.field, "follow"),
                   leader < 0 ? "no sprite named " + l.follow : "a sprite cannot follow itself");
      }
    }
    for (const FrameSpec& f : s.frames) {
      if (f.after_path_of.empty()) continue;
      const int owner = spec_.SpriteIndex(f.after_path_of);
      if (owner < 0) {
        msg_.Error(Child(f.place.field, "after_path"), "no sprite named " + f.after_path_of);
      } else if (!spec_.sprites[owner].path) {
        msg_.Error(Child(f.place.field, "after_path"), f.after_path_of + " has no path constraint");
      }
    }
  }
}

}  // namespace

AnimationSpec ParseAnimationSpec(const std::string& yaml, const std::string& origin,
                                 const SpecFileRules& files) {
  const YAML::Node root = LoadOneDocument(yaml, origin);
  try {
    return SpecReader(origin, files).Read(root);
  } catch (const YAML::Exception& e) {
    // A shape the reader did not check for (found by tests/fuzz): still an error naming the line.
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1),
                     "cannot read this (" + e.msg + ")");
  }
}

CameraModel ReadSpecCamera(const AnimationSpec& spec) {
  try {
    return CameraModel::Read(spec.camera_path);
  } catch (const InputError& e) {
    throw InputError(spec.Where(spec.camera_place), e.what());
  }
}

AnimationSpec LoadAnimationSpec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the animation spec");
  return ParseAnimationSpec(ReadWithinLimit(in, path, "an animation spec"), path);
}

}  // namespace ss
