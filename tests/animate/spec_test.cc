// The animation spec: every field read, bad specs refused with the line and the field.
#include "animate/spec.h"

#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>

#include "animate/basic_costs.h"
#include "animate/clone_cost.h"
#include "animate/problem.h"
#include "animate/scene.h"
#include "animate/spec_term.h"
#include "animate_test_bank.h"
#include "core/error.h"
#include "core/options_binder.h"
#include "core/yaml_reader.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

class SpecTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::WalkerBank::Write(dir_ / "walker.ssbank");
    testing::LookAtCamera(320, 240, 300, {0, -4, 3}, {0, 0, 0}).Write(dir_ / "virtual.cameramodel");
  }
  std::string Origin() const { return dir_ / "scene.yaml"; }
  // The message of the InputError the spec raises ("" if none).
  std::string ErrorOf(const std::string& yaml) const {
    try {
      ParseAnimationSpec(yaml, Origin());
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  ScratchDir dir_;
};

constexpr const char* kGood = R"(version: 1
frame_rate: 25
length: {min_frames: 100, max_frames: 300, strength: 2}
camera: virtual.cameramodel
banks: [walker.ssbank]
fast_frames: {reference_speed_m_s: 1.0, strength: 0.5}
optimizer: {method: replace, start: random, time_budget_s: 5, seed: 7, set_size: 50}
sprites:
  - name: lead
    start: [0, 0]
    constraints:
      - path: {points: [[0, 0], [1, 0], [1, 1]], direction_strength: 2, distance_strength: 3, unreached_strength: 4}
      - frames: {tag: standing, after_path: lead, duration: 2, strength: 5}
      - location: {target: [1, 1], at: 4, strength: 6}
  - name: follower
    start: free
    smoothness: 0.5
    constraints:
      - location: {follow: lead, offset: [-0.3, 0.2], from: 1, to: end, strength: 7}
      - frames: {sprites: [3, 4], from: 2, to: 3}
collisions:
  - {sprites: all, min_distance_m: 0.25, strength: 100}
)";

TEST_F(SpecTest, ReadsEveryField) {
  const AnimationSpec spec = ParseAnimationSpec(kGood, Origin());
  EXPECT_EQ(spec.frame_rate, 25);
  EXPECT_EQ(spec.fixed_frames, 0);
  EXPECT_EQ(spec.max_frames, 300);
  ASSERT_TRUE(spec.length);
  EXPECT_EQ(spec.length->min_frames, 100);
  EXPECT_EQ(spec.length->strength, 2);
  EXPECT_EQ(spec.camera_path, dir_ / "virtual.cameramodel");
  ASSERT_EQ(spec.bank_paths.size(), 1u);
  EXPECT_EQ(spec.optimizer.replacement.seed, 7u);
  EXPECT_EQ(spec.optimizer.replacement.start, StartMethod::kRandom);
  EXPECT_EQ(spec.optimizer.replacement.reach.set_size, 50);
  EXPECT_EQ(spec.optimizer.replacement.collision_pick_fraction, 0.25);  // the default
  EXPECT_EQ(spec.optimizer.replacement.time_budget_seconds, 5);
  EXPECT_EQ(OptimizerSpec().replacement.time_budget_seconds, 30);  // a spec's default
  ASSERT_EQ(spec.sprites.size(), 2u);
  const SpriteSpecEntry& lead = spec.sprites[0];
  EXPECT_EQ(lead.anchor, Anchor::kStart);
  ASSERT_TRUE(lead.path);
  EXPECT_EQ(lead.path->points_m.size(), 3u);
  EXPECT_EQ(lead.path->strengths.direction, 2);
  EXPECT_EQ(lead.path->strengths.distance, 3);
  EXPECT_EQ(lead.path->strengths.unreached, 4);
  ASSERT_EQ(lead.frames.size(), 1u);
  EXPECT_EQ(lead.frames[0].after_path_of, "lead");
  EXPECT_EQ(lead.frames[0].duration_steps, 50);  // 2 s at 25 fps
  ASSERT_EQ(lead.locations.size(), 1u);
  EXPECT_EQ(lead.locations[0].window.first, 100);  // 4 s
  EXPECT_EQ(lead.locations[0].window.last, 100);
  EXPECT_FALSE(lead.locations[0].window.last_from_end);
  EXPECT_EQ(lead.locations[0].place.line, 14);
  const SpriteSpecEntry& follower = spec.sprites[1];
  EXPECT_EQ(follower.anchor, Anchor::kFree);
  EXPECT_EQ(follower.smoothness, 0.5);
  EXPECT_EQ(follower.locations[0].follow, "lead");
  EXPECT_EQ(follower.locations[0].target_m, Eigen::Vector2d(-0.3, 0.2));
  EXPECT_EQ(follower.locations[0].window.first, 25);
  EXPECT_TRUE(follower.locations[0].window.last_from_end);
  EXPECT_EQ(follower.frames[0].sprite_ids, (std::vector<int64_t>{3, 4}));
  EXPECT_EQ(follower.frames[0].window.first, 50);
  EXPECT_EQ(follower.frames[0].window.last, 75);
  ASSERT_EQ(spec.collisions.size(), 1u);
  EXPECT_TRUE(spec.collisions[0].sprites.empty());  // all
  EXPECT_EQ(spec.collisions[0].min_distance_m, 0.25);
}

TEST_F(SpecTest, BuildsTheTermsOverTheBank) {
  const auto scene = Scene::Load(ParseAnimationSpec(kGood, Origin()));
  const Problem& p = scene->problem();
  EXPECT_EQ(p.num_sprites(), 2);
  std::map<std::string, int> kinds;
  for (int k = 0; k < p.num_terms(); ++k) ++kinds[p.term(k).kind()];
  EXPECT_EQ(kinds["smoothness"], 2);
  EXPECT_EQ(kinds["path"], 1);
  EXPECT_EQ(kinds["frame"], 2);
  EXPECT_EQ(kinds["location"], 2);
  EXPECT_EQ(kinds["collision"], 1);
  EXPECT_EQ(kinds["length"], 2);
  EXPECT_EQ(kinds["fast"], 2);
  EXPECT_GT(scene->MakeReplacementOptions().slow_frame_cost, 0);
}

TEST_F(SpecTest, FixedLengthHoldsEverySequenceToIt) {
  std::string yaml = kGood;
  yaml.replace(yaml.find("length: {min_frames: 100, max_frames: 300, strength: 2}"),
               std::string("length: {min_frames: 100, max_frames: 300, strength: 2}").size(),
               "length: 150");  // 6 s at 25 fps: every window of kGood lies within
  const AnimationSpec spec = ParseAnimationSpec(yaml, Origin());
  EXPECT_EQ(spec.fixed_frames, 150);
  EXPECT_EQ(spec.max_frames, 150);
  EXPECT_EQ(spec.initial_frames, 150);
  ASSERT_TRUE(spec.length);
  EXPECT_EQ(spec.length->min_frames, 150);
}

// Replaces the first occurrence of `from` in the good spec.
std::string Edit(const std::string& from, const std::string& to) {
  std::string yaml = kGood;
  const size_t at = yaml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return yaml.replace(at, from.size(), to);
}

// How many of the scene's terms are of `kind`.
int TermsOfKind(const Scene& scene, const std::string& kind) {
  int n = 0;
  for (int k = 0; k < scene.problem().num_terms(); ++k) n += scene.problem().term(k).kind() == kind;
  return n;
}

// Issue 33: the loiter's hamster replayed a few frames to hold its place (stutter 6-7 %).
TEST_F(SpecTest, RepeatsCostAFrameShownAgainWithinTheWindow) {
  const std::string fast = "fast_frames: {reference_speed_m_s: 1.0, strength: 0.5}";
  const AnimationSpec spec =
      ParseAnimationSpec(Edit(fast, "repeats: {strength: 3, window_steps: 10}"), Origin());
  const RepeatSpec* repeats = spec.Term<RepeatSpec>("repeats");
  ASSERT_NE(repeats, nullptr);
  EXPECT_EQ(repeats->strength, 3);
  EXPECT_EQ(repeats->window_steps, 10);
  EXPECT_EQ(repeats->still_tag, "still");
  EXPECT_EQ(ParseAnimationSpec(kGood, Origin()).Term<RepeatSpec>("repeats"), nullptr);  // off
  EXPECT_EQ(TermsOfKind(*Scene::Load(spec), "repeat"), 2);  // one a sprite
  const std::string o = Origin();
  EXPECT_EQ(ErrorOf(Edit(fast, "repeats: {strength: -1}")),
            o + ":6: repeats.strength: expected a number >= 0, got -1");
  EXPECT_EQ(ErrorOf(Edit(fast, "repeats: {strength: 1, window_steps: 0}")),
            o + ":6: repeats.window_steps: expected 1..1000 steps, got 0");
  EXPECT_EQ(ErrorOf(Edit(fast, "repeats: {window_steps: 5}")),
            o + ":6: repeats.strength: required");
}

// The flies of seed 000 §6.2 walked in lockstep, each given the same best sequence.
TEST_F(SpecTest, ClonesCostTwoSpritesShowingAFrameTogether) {
  const std::string fast = "fast_frames: {reference_speed_m_s: 1.0, strength: 0.5}";
  const AnimationSpec spec =
      ParseAnimationSpec(Edit(fast, "clones: {strength: 4, lag_steps: 3}"), Origin());
  const CloneSpec* clones = spec.Term<CloneSpec>("clones");
  ASSERT_NE(clones, nullptr);
  EXPECT_EQ(clones->strength, 4);
  EXPECT_EQ(clones->lag_steps, 3);
  EXPECT_EQ(ParseAnimationSpec(kGood, Origin()).Term<CloneSpec>("clones"), nullptr);  // off
  EXPECT_EQ(TermsOfKind(*Scene::Load(spec), "clone"), 1);                             // one a pair
  EXPECT_EQ(ErrorOf(Edit(fast, "clones: {strength: 1, lag_steps: 101}")),
            Origin() + ":6: clones.lag_steps: expected 0..100 steps, got 101");
}

TEST_F(SpecTest, FacingIsOnForFloorSpritesAlone) {
  const std::string fast = "fast_frames: {reference_speed_m_s: 1.0, strength: 0.5}";
  const AnimationSpec good = ParseAnimationSpec(kGood, Origin());
  ASSERT_NE(good.Term<FacingSpec>("facing"), nullptr);  // on unless set to 0
  EXPECT_EQ(good.Term<FacingSpec>("facing")->strength, 300);
  const AnimationSpec spec = ParseAnimationSpec(Edit(fast, "facing: {strength: 50}"), Origin());
  ASSERT_NE(spec.Term<FacingSpec>("facing"), nullptr);
  EXPECT_EQ(spec.Term<FacingSpec>("facing")->strength, 50);
  // The bank's sprites are upright: they carry no heading, and no facing term is built.
  EXPECT_EQ(TermsOfKind(*Scene::Load(spec), "facing"), 0);
  EXPECT_EQ(ErrorOf(Edit(fast, "facing: {strength: -1}")),
            Origin() + ":6: facing.strength: expected a number >= 0, got -1");
  EXPECT_NE(ErrorOf(Edit(fast, "facing: {strenght: 1}"))
                .find(":6: facing.strenght: unknown key (did you mean \"strength\"?)"),
            std::string::npos);
}

// A term of its own registered as the built-in ones are (animate/spec_term.h): its block is read
// with the spec's rules and names, and its terms join the scene, with nothing in the spec reader
// or the scene naming it (issue 36).
struct WobbleTerm : StepSumTerm {
  WobbleTerm(int sprite, double strength) : StepSumTerm("wobble", {sprite}, strength) {}
  std::pair<int, int> Steps(Tracks tracks, const EvalRequest& /*request*/) const override {
    return {0, tracks[sprites()[0]]->size()};
  }
  double StepCost(Tracks /*tracks*/, int /*t*/) const override { return strength(); }
};
struct WobbleSpec : SpecTerm {
  double strength = 0;
  void AddTerms(const TransitionGraph& /*graph*/, Problem& problem) const override {
    for (int id = 0; id < problem.num_sprites(); ++id)
      problem.AddTerm(std::make_unique<WobbleTerm>(id, strength));
  }
};

TEST_F(SpecTest, ATermRegisteredApartIsReadAndBuilt) {
  SpecTermKind wobble{
      "wobble", "{strength}",
      TermBlockReader<WobbleSpec>(
          [](OptionsBinder& keys, WobbleSpec& w) {
            keys.Add("strength", &w.strength, "a number >= 0", "per step").Rule(AtLeast(0));
          },
          {"strength"})};
  RegisterSpecTerm(wobble);
  EXPECT_THROW(RegisterSpecTerm(wobble), WorkError);
  const std::string fast = "fast_frames: {reference_speed_m_s: 1.0, strength: 0.5}";
  const AnimationSpec spec = ParseAnimationSpec(Edit(fast, "wobble: {strength: 2}"), Origin());
  ASSERT_NE(spec.Term<WobbleSpec>("wobble"), nullptr);
  EXPECT_EQ(spec.Term<WobbleSpec>("wobble")->strength, 2);
  EXPECT_EQ(ParseAnimationSpec(kGood, Origin()).Term<WobbleSpec>("wobble"), nullptr);  // off
  EXPECT_EQ(TermsOfKind(*Scene::Load(spec), "wobble"), 2);  // one a sprite
  EXPECT_EQ(ErrorOf(Edit(fast, "wobble: {strength: -1}")),
            Origin() + ":6: wobble.strength: expected a number >= 0, got -1");
  EXPECT_EQ(ErrorOf(Edit(fast, "wobble: {}")), Origin() + ":6: wobble.strength: required");
  EXPECT_NE(ErrorOf(Edit(fast, "wobbel: {strength: 1}"))
                .find(":6: wobbel: unknown key (did you mean \"wobble\"?)"),
            std::string::npos)
      << ErrorOf(Edit(fast, "wobbel: {strength: 1}"));
}

// A constraint of one sprite registered as a term is (animate/spec_term.h): read under the
// sprite's `constraints:` with the spec's rules and names, its terms added for that sprite alone,
// with nothing in the spec reader or the scene naming it (issue 36).
struct HoldSpec : SpriteConstraint {
  double strength = 0;
  void AddTerms(const TransitionGraph& /*graph*/, Problem& problem, int sprite) const override {
    problem.AddTerm(std::make_unique<WobbleTerm>(sprite, strength));
  }
};

TEST_F(SpecTest, AConstraintRegisteredApartIsReadAndBuiltForItsSprite) {
  SpriteConstraintKind hold{
      "hold", TermBlockReader<HoldSpec>(
                  [](OptionsBinder& keys, HoldSpec& h) {
                    keys.Add("strength", &h.strength, "a number >= 0", "per step").Rule(AtLeast(0));
                  },
                  {"strength"})};
  RegisterSpriteConstraint(hold);
  EXPECT_THROW(RegisterSpriteConstraint(hold), WorkError);
  EXPECT_THROW(RegisterSpriteConstraint({"path", hold.read}), WorkError) << "a typed one";
  const std::string item = "      - frames: {sprites: [3, 4], from: 2, to: 3}\n";
  const AnimationSpec spec =
      ParseAnimationSpec(Edit(item, item + "      - hold: {strength: 2}\n"), Origin());
  ASSERT_EQ(spec.sprites[1].constraints.size(), 1u);
  EXPECT_TRUE(spec.sprites[0].constraints.empty());
  const auto* read = dynamic_cast<const HoldSpec*>(spec.sprites[1].constraints[0].get());
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->strength, 2);
  const std::unique_ptr<Scene> scene = Scene::Load(spec);
  int wobbles = 0;
  for (int k = 0; k < scene->problem().num_terms(); ++k) {
    const CostTerm& term = scene->problem().term(k);
    if (term.kind() != "wobble") continue;
    ++wobbles;
    EXPECT_EQ(term.sprites(), std::vector<int>{1}) << "the follower's alone";
  }
  EXPECT_EQ(wobbles, 1);
  EXPECT_EQ(ErrorOf(Edit(item, item + "      - hold: {strength: -1}\n")),
            Origin() +
                ":21: sprites[1].constraints[2].hold.strength: expected a number >= 0, "
                "got -1");
  EXPECT_EQ(ErrorOf(Edit(item, item + "      - hold: {}\n")),
            Origin() + ":21: sprites[1].constraints[2].hold.strength: required");
  EXPECT_EQ(ErrorOf(Edit(item, item + "      - holt: {strength: 1}\n")),
            Origin() +
                ":21: sprites[1].constraints[2].holt: unknown constraint (expected "
                "location, path, frames or hold)");
}

// A spec a client sends the station may name files under the station's folders only: one
// elsewhere (by path, by "..", or through a link) is refused by its line before it is opened.
TEST_F(SpecTest, FilesOutsideTheRootsAreRefusedByLineUnopened) {
  const ScratchDir outside_dir;
  const fs::path& outside = outside_dir.path();
  fs::copy_file(dir_ / "walker.ssbank", outside / "walker.ssbank");
  fs::create_directory_symlink(outside, dir_ / "link");
  SpecFileRules rules;
  rules.roots = {dir_.path().string()};
  EXPECT_NO_THROW(ParseAnimationSpec(kGood, Origin(), rules));
  auto error_of = [&](const std::string& yaml) -> std::string {
    try {
      ParseAnimationSpec(yaml, Origin(), rules);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string o = Origin();
  const std::string why =
      ": outside the station's folders (" + dir_.path().string() + "); not opened";
  const std::string moved = (outside / "walker.ssbank").string();
  for (const auto& [bank, named] : std::vector<std::pair<std::string, std::string>>{
           {moved, moved},
           {"../" + outside.filename().string() + "/walker.ssbank", moved},  // resolved
           {"link/walker.ssbank", dir_ / "link/walker.ssbank"}}) {
    EXPECT_EQ(error_of(Edit("banks: [walker.ssbank]", "banks: [" + bank + "]")),
              o + ":5: banks[0]: " + named + why);
  }
  EXPECT_EQ(error_of(Edit("camera: virtual.cameramodel", "camera: /etc/passwd")),
            o + ":4: camera: /etc/passwd" + why);
  // relative names resolve in the rules' folder, not the origin's
  rules.base_dir = outside.string();
  rules.roots.push_back(outside.string());
  EXPECT_EQ(error_of(kGood),
            o + ":4: camera: no such file: " + (outside / "virtual.cameramodel").string());
}

TEST_F(SpecTest, BadSpecsNameTheLineAndTheField) {
  const std::string o = Origin();
  EXPECT_EQ(ErrorOf(Edit("frame_rate: 25", "frame_rate: fast")),
            o + ":2: frame_rate: expected a number, got \"fast\"");
  EXPECT_EQ(ErrorOf(Edit("frame_rate: 25", "frame_rate: -3")), o + ":2: frame_rate: must be > 0");
  EXPECT_EQ(ErrorOf(Edit("frame_rate: 25", "frame_rat: 25")),
            o + ":2: frame_rat: unknown key (did you mean \"frame_rate\"?)");
  EXPECT_EQ(ErrorOf(Edit("camera: virtual.cameramodel", "camera: nowhere.cameramodel")),
            o + ":4: camera: no such file: " + (dir_ / "nowhere.cameramodel"));
  EXPECT_EQ(
      ErrorOf(Edit("direction_strength: 2", "direction_strength: -2")),
      o + ":12: sprites[0].constraints[0].path.direction_strength: expected a number >= 0, got -2");
  EXPECT_EQ(ErrorOf(Edit("[1, 1]], direction", "[1]], direction")),
            o + ":12: sprites[0].constraints[0].path.points[2]: expected [x, y] in metres");
  EXPECT_EQ(ErrorOf(Edit("follow: lead", "follow: nobody")),
            o + ":19: sprites[1].constraints[0].location.follow: no sprite named nobody");
  EXPECT_EQ(ErrorOf(Edit("at: 4,", "at: 4, from: 1,")),
            o + ":14: sprites[0].constraints[2].location.at: give either at or from/to");
  EXPECT_EQ(ErrorOf(Edit("from: 2, to: 3", "from: 3, to: 2")),
            o + ":20: sprites[1].constraints[1].frames.to: ends before it starts");
  EXPECT_EQ(ErrorOf(Edit("    start: free\n", "")),
            o + ":15: sprites[1].start: required: [x, y], free, or end: [x, y] instead");
  // (A constraint another test of this process registered joins the list: the start is fixed.)
  EXPECT_EQ(ErrorOf(Edit("- location: {target: [1, 1]", "- loiter: {target: [1, 1]"))
                .rfind(o + ":14: sprites[0].constraints[2].loiter: unknown constraint (expected "
                           "location, path",
                       0),
            0u)
      << ErrorOf(Edit("- location: {target: [1, 1]", "- loiter: {target: [1, 1]"));
  EXPECT_EQ(ErrorOf(Edit("min_distance_m: 0.25", "min_distance_m: 0")),
            o + ":22: collisions[0].min_distance_m: expected a distance > 0 in metres, got 0");
  EXPECT_EQ(ErrorOf(Edit("name: follower", "name: lead")),
            o + ":15: sprites[1].name: another sprite is named lead");
  EXPECT_EQ(ErrorOf(Edit("start: random", "start: later")),
            o + ":7: optimizer.start: expected one of sequential, random, beam, got \"later\"");
  EXPECT_EQ(ErrorOf(Edit("start: random,", "start: random, collision_pick_fraction: 1.5,")),
            o + ":7: optimizer.collision_pick_fraction: expected a fraction 0..1, got 1.5");
  // The optimizer's own limits (ReplacementOptions::IsValid), named as the spec's fields.
  EXPECT_EQ(ErrorOf(Edit("set_size: 50", "set_size: 100000")),
            o + ":7: optimizer.set_size: expected 1..65535, got 100000");
  EXPECT_EQ(ErrorOf(Edit("set_size: 50", "set_size: 50, threads: 100000")),
            o + ":7: optimizer.threads: expected 1..256, got 100000");
  EXPECT_EQ(ErrorOf(Edit("method: replace", "method: beam, beam_width: 0")),
            o + ":7: optimizer.beam_width: expected at least 1, got 0");
  // A mapping as a key (found by tests/fuzz: yaml-cpp's exception escaped and aborted).
  EXPECT_EQ(ErrorOf(Edit("set_size: 50", "set_size: 50, {a: 1}: 2")),
            o + ":7: optimizer: a key at line 7 is not a plain name");
  // The optimizer's and length's keys are read as the station config's are (core/options_binder.h).
  EXPECT_EQ(ErrorOf(Edit("max_frames: 300", "max_frame: 300")),
            o + ":3: length.max_frame: unknown key (did you mean \"max_frames\"?)");
  EXPECT_EQ(ErrorOf(Edit("min_frames: 100, max_frames: 300", "min_frames: 200, max_frames: 150")),
            o + ":3: length.max_frames: is below length.min_frames");
  EXPECT_EQ(ErrorOf(Edit("min_frames: 100", "min_frames: 0")),
            o + ":3: length.min_frames: expected a whole number of frames 1..10000, got 0");
  EXPECT_EQ(ErrorOf(Edit("set_size: 50", "set_sise: 50")),
            o + ":7: optimizer.set_sise: unknown key (did you mean \"set_size\"?)");
  EXPECT_EQ(ErrorOf(Edit("set_size: 50", "set_size: 2.5")),
            o + ":7: optimizer.set_size: expected a whole number, got \"2.5\"");
  EXPECT_NE(ErrorOf("sprites: [\n").find(o + ":"), std::string::npos);  // YAML syntax: a line too
}

// Issue 39: every number of a spec that sizes work is bounded, by the animation's own extent (its
// longest sequence) or a stated bound (docs/animation.md, "Bounds"), and refused with its line
// (`from: 10000000` took 2.4 GB and 9 s, `time_budget_s: 1e300` ran until killed).
TEST_F(SpecTest, NumbersThatSizeWorkAreBounded) {
  const std::string o = Origin();
  // kGood: 25 fps, sequences of at most 300 frames: its end is 12 s.
  const std::string past = "past the animation's end: ";
  EXPECT_EQ(ErrorOf(Edit("from: 1, to: end", "from: 10000000, to: end")),
            o + ":19: sprites[1].constraints[0].location.from: " + past +
                "10000000 s is step 250000000 at 25 fps, and its sequences are at most 300 "
                "frames");
  EXPECT_EQ(ErrorOf(Edit("from: 1, to: end", "from: 1e15, to: end")),
            o + ":19: sprites[1].constraints[0].location.from: " + past +
                "1e+15 s is step 2.5e+16 at 25 fps, and its sequences are at most 300 frames");
  EXPECT_EQ(ErrorOf(Edit("from: 2, to: 3", "from: 2, to: 12.1")),
            o + ":20: sprites[1].constraints[1].frames.to: " + past +
                "12.1 s is step 303 at 25 fps, and its sequences are at most 300 frames");
  EXPECT_EQ(ErrorOf(Edit("at: 4,", "at: 12,")), "");  // step 300: the end of the longest
  EXPECT_EQ(ErrorOf(Edit("duration: 2", "duration: 1e9")),
            o + ":13: sprites[0].constraints[1].frames.duration: " + past +
                "1000000000 s is step 25000000000 at 25 fps, and its sequences are at most 300 "
                "frames");
  // Without max_frames, a spec's own bound.
  std::string free_length = Edit("max_frames: 300, ", "");
  EXPECT_EQ(ErrorOf(free_length), "");
  free_length.replace(free_length.find("at: 4,"), 6, "at: 401,");
  EXPECT_EQ(ErrorOf(free_length),
            o + ":14: sprites[0].constraints[2].location.at: " + past +
                "401 s is step 10025 at 25 fps, and a spec's sequences are at most 10000 frames");
  // Lengths.
  EXPECT_EQ(ErrorOf(Edit("max_frames: 300", "max_frames: 20000")),
            o + ":3: length.max_frames: expected a whole number of frames 1..10000, got 20000");
  EXPECT_EQ(ErrorOf(Edit("max_frames: 300", "max_frames: 300, initial_frames: 10001")),
            o + ":3: length.initial_frames: expected a whole number of frames 1..10000, got 10001");
  EXPECT_EQ(
      ErrorOf(Edit("length: {min_frames: 100, max_frames: 300, strength: 2}", "length: 20000")),
      o + ":3: length: must be at most 10000, got \"20000\"");
  // The frame rate, 1..1000 frames per second.
  EXPECT_EQ(ErrorOf(Edit("frame_rate: 25", "frame_rate: 1e300")),
            o + ":2: frame_rate: must be from 1 to 1000 frames per second, got 1e+300");
  EXPECT_EQ(ErrorOf(Edit("frame_rate: 25", "frame_rate: 1e-300")),
            o + ":2: frame_rate: must be from 1 to 1000 frames per second, got 1e-300");
  // The time budget: a day at most; snapshots: a thousand at most.
  EXPECT_EQ(ErrorOf(Edit("time_budget_s: 5", "time_budget_s: 1e300")),
            o + ":7: optimizer.time_budget_s: must be at most 86400 seconds (a day), got 1e+300");
  EXPECT_EQ(ErrorOf(Edit("method: replace, start: random, time_budget_s: 5",
                         "method: beam, time_budget_s: 86401")),
            o + ":7: optimizer.time_budget_s: must be at most 86400 seconds (a day), got 86401");
  EXPECT_EQ(ErrorOf(Edit("time_budget_s: 5", "time_budget_s: 5, snapshot_every_s: 0.001")),
            o + ":7: optimizer.snapshot_every_s: keeps at most 1000 snapshots: must be 0 or >= "
                "0.005 (time_budget_s / 1000), got 0.001");
  // Lists that must not be empty, or too long.
  EXPECT_EQ(ErrorOf(Edit("banks: [walker.ssbank]", "banks: []")),
            o + ":5: banks: expected at least one bank");
  std::string no_sprites = kGood;
  no_sprites = no_sprites.substr(0, no_sprites.find("sprites:\n")) + "sprites: []\n";
  EXPECT_EQ(ErrorOf(no_sprites), o + ":8: sprites: expected at least one sprite");
  std::string many = kGood;
  many = many.substr(0, many.find("sprites:\n")) + "sprites:\n";
  for (int i = 0; i < 257; ++i) many += "  - {name: s" + std::to_string(i) + ", start: free}\n";
  EXPECT_EQ(ErrorOf(many), o + ":8: sprites: expected at most 256 sprites, got 257");
}

// Issue 39: one YAML document, nested no deeper than yaml-cpp reads, each said so (a second
// document was dropped without a word; deep nesting was "bad file").
TEST_F(SpecTest, OneDocumentOfBoundedDepth) {
  const std::string o = Origin();
  EXPECT_EQ(ErrorOf(std::string(kGood) + "---\nversion: 2\n"),
            o + ":23: a second YAML document (---) starts here; the file must hold one document");
  EXPECT_EQ(ErrorOf(Edit("smoothness: 0.5",
                         "smoothness: " + std::string(600, '[') + std::string(600, ']'))),
            o + ":17: nested deeper than 499 levels");
}

// The whole file is read before it is refused: every mistake, each with its line and field, in
// the order of the file (the station config's reader, core/yaml_reader.h).
TEST_F(SpecTest, EveryMistakeOfTheFileIsReported) {
  const std::string o = Origin();
  std::string yaml = Edit("frame_rate: 25", "frame_rate: -3");
  yaml.replace(yaml.find("time_budget_s: 5"), 16, "time_budget_s: 0");
  yaml.replace(yaml.find("smoothness: 0.5"), 15, "smoothness: -1");
  yaml.replace(yaml.find("[1, 1]], direction"), 18, "[1]], direction");
  yaml.replace(yaml.find("follow: lead"), 12, "follow: nobody");
  yaml.replace(yaml.find("min_distance_m: 0.25"), 20, "min_distanse_m: 0.25");
  EXPECT_EQ(ErrorOf(yaml),
            o + ":2: frame_rate: must be > 0\n" +  //
                o + ":7: optimizer.time_budget_s: expected a positive number of seconds, got 0\n" +
                o + ":12: sprites[0].constraints[0].path.points[2]: expected [x, y] in metres\n" +
                o + ":17: sprites[1].smoothness: expected a number >= 0, got -1\n" +  //
                o +
                ":22: collisions[0].min_distanse_m: unknown key (did you mean "  //
                "\"min_distance_m\"?)\n" +                                       //
                o +
                ":22: collisions[0].min_distance_m: required\n" +  //
                o + ":19: sprites[1].constraints[0].location.follow: no sprite named nobody");
}

// A key given without a value, a block that is not a mapping: named, not thrown by yaml-cpp.
TEST_F(SpecTest, EmptyValuesAndWrongShapesAreNamed) {
  const std::string o = Origin();
  EXPECT_EQ(ErrorOf(Edit("smoothness: 0.5", "smoothness:")),
            o + ":17: sprites[1].smoothness: has no value (remove the key to use the default)");
  std::string listed = Edit("- location: {follow", "- location: [{follow");
  listed.replace(listed.find("strength: 7}"), 12, "strength: 7}]");
  EXPECT_EQ(ErrorOf(listed),
            o + ":19: sprites[1].constraints[0].location: expected a mapping of keys, got a list");
  EXPECT_EQ(ErrorOf(Edit("optimizer: {method: replace, start: random, time_budget_s: 5, seed: 7, "
                         "set_size: 50}",
                         "optimizer: [replace]")),
            o + ":7: optimizer: expected a mapping of keys, got a list");
  EXPECT_EQ(ErrorOf(""), o + ": (top level): the spec is empty");
}

TEST_F(SpecTest, ConstraintsTheBankCannotMeetNameTheirLine) {
  try {
    Scene::Load(ParseAnimationSpec(Edit("tag: standing", "tag: sitting"), Origin()));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), Origin() +
                                         ":13: sprites[0].constraints[1].frames.tag: no sprite "
                                         "of the banks carries the tag sitting");
  }
}

TEST_F(SpecTest, LoadsAFileAndRefusesAMissingOne) {
  {
    std::ofstream out(Origin());
    out << kGood;
  }
  EXPECT_EQ(LoadAnimationSpec(Origin()).sprites.size(), 2u);
  EXPECT_THROW(LoadAnimationSpec(dir_ / "missing.yaml"), InputError);
}

// Issue 20: yaml-cpp parses a whole file first. A sparse 250 MB spec is refused from its size,
// naming the file, its size and the limit, before a byte of it is read.
TEST_F(SpecTest, AFileOverTheLimitIsRefusedBeforeItIsRead) {
  std::ofstream(Origin()) << kGood;
  std::filesystem::resize_file(Origin(), 250'000'000);
  try {
    LoadAnimationSpec(Origin());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              Origin() +
                  ": 238.4 MiB (250000000 bytes): larger than the 16 MiB an animation spec may be");
  }
}

// Every example in docs/examples parses, with stand-ins for the bank, plate and camera it names
// where scripts/reference-banks.sh makes them (recordings/reference/, relative to the spec).
TEST_F(SpecTest, TheDocumentedExamplesAreValid) {
  const fs::path examples = fs::path(ss::testing::SourcePath("docs/examples"));
  const fs::path copies = fs::path(dir_.path()) / "docs" / "examples";
  fs::create_directories(copies);
  for (const char* set : {"hamster", "hamster-60s", "flies"}) {
    const fs::path reference = fs::path(dir_.path()) / "recordings" / "reference" / set;
    fs::create_directories(reference);
    for (const char* name : {"hamster.ssbank", "fly.ssbank", "floor.png", "virtual.cameramodel"})
      std::ofstream(reference / name) << "x";
  }
  int count = 0;
  for (const auto& entry : fs::directory_iterator(examples)) {
    if (entry.path().extension() != ".yaml") continue;
    const fs::path copy = copies / entry.path().filename();
    fs::copy_file(entry.path(), copy, fs::copy_options::overwrite_existing);
    EXPECT_NO_THROW(LoadAnimationSpec(copy.string())) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 5);
}

}  // namespace
}  // namespace ss
