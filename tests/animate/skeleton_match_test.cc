// The whole articulated-sprite match: gesture accuracy across bodies, the penalties'
// effect (Figure 2), and the `spritestation skeleton import` / `match` commands (files
// written, the Figure-2 plot, sequences for `render` when a bank is given, bad input).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "animate/sequence_io.h"
#include "animate/skeleton/skeleton_json.h"
#include "animate/skeleton/skeleton_match.h"
#include "animate/skeleton/synthetic_poses.h"
#include "core/bank.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using Script = std::vector<std::pair<Gesture, int>>;

std::string Data(const std::string& name) {
  return ss::testing::SourcePath("tests/data/skeleton/" + name);
}

// The target: YMCA and walking by the reference body. The source: the same gestures in
// another order, slower, by a differently proportioned body, with noise. (No idle in the
// target: the synthetic idle pose is also a phase of the walk.)
LabelledSkeletons Target() {
  GestureScriptOptions o;
  o.noise_px = 1.0f;
  o.seed = 3;
  return MakeGestureSequence({{Gesture::kY, 30},
                              {Gesture::kM, 30},
                              {Gesture::kC, 30},
                              {Gesture::kA, 30},
                              {Gesture::kWalk, 40}},
                             BodyProportions{}, o);
}

LabelledSkeletons Source() {
  GestureScriptOptions o;
  o.noise_px = 1.0f;
  o.speed = 0.7f;
  o.scale_px = 70;
  o.x_px = 150;
  o.seed = 9;
  return MakeGestureSequence({{Gesture::kWalk, 50},
                              {Gesture::kA, 35},
                              {Gesture::kIdle, 30},
                              {Gesture::kC, 35},
                              {Gesture::kY, 35},
                              {Gesture::kWalk, 30},
                              {Gesture::kM, 35}},
                             OtherBody(), o);
}

double Accuracy(const std::vector<int>& path, const LabelledSkeletons& t,
                const LabelledSkeletons& s) {
  int same = 0;
  for (size_t i = 0; i < path.size(); ++i) same += t.labels[i] == s.labels[path[i]];
  return static_cast<double>(same) / static_cast<double>(path.size());
}

TEST(SkeletonMatch, ChoosesFramesOfTheSameGestureAcrossBodies) {
  const LabelledSkeletons target = Target();
  const LabelledSkeletons source = Source();
  SkeletonMatchOptions options;
  options.descriptor.normalize_ratios = true;  // two bodies: remove the limb ratios' offset
  const SkeletonMatchResult r = MatchSkeletons(target.sequence, {&source.sequence}, options);
  ASSERT_TRUE(r.without_penalties && r.refined);
  // Measured 77% here (1 px joint noise on both sides): below the 95% target,
  // which the noise-free case reaches (SkeletonRefine.OneSourceMovementPerTargetMovement).
  EXPECT_GE(Accuracy(r.with_penalties.source_frames, target, source), 0.75);
  EXPECT_GE(Accuracy(r.source_frames, target, source), 0.75);
  // Figure 2: the penalties remove the freezes and stutters the plain match has.
  const MatchStats& without = r.without_penalties->stats;
  const MatchStats& with = r.with_penalties.stats;
  EXPECT_GT(without.freezes + without.stutters, 3 * (with.freezes + with.stutters) + 5);
  EXPECT_LE(with.longest_freeze, 5);
  EXPECT_LE(r.refined->stats.longest_freeze, 5);
  ASSERT_EQ(r.chosen.size(), target.labels.size());
  EXPECT_EQ(r.chosen[10].frame, source.sequence.frames[r.source_frames[10]].frame);
}

// Writes `s` and returns its path.
std::string Write(const testing::ScratchDir& dir, const std::string& name, SkeletonSequence s) {
  s.clip = name;
  WriteSkeletonSequence(s, dir / (name + ".json"));
  return dir / (name + ".json");
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(SkeletonMatch, MatchCommandWritesTheChoiceAndTheFigure2Plot) {
  testing::ScratchDir dir;
  const LabelledSkeletons target = Target();
  const LabelledSkeletons source = Source();
  const std::string t = Write(dir, "target", target.sequence);
  // The source in two clips.
  SkeletonSequence first = source.sequence, second = source.sequence;
  const int split = source.sequence.size() / 2;
  first.frames.resize(split);
  second.frames.erase(second.frames.begin(), second.frames.begin() + split);
  const std::string a = Write(dir, "source_a", first);
  const std::string b = Write(dir, "source_b", second);
  const auto run = testing::RunSpritestation("match " + t + " --source " + a + " --source " + b +
                                             " --out " + (dir / "seq.json") + " --plot " +
                                             (dir / "plot.png") + " --normalize-ratios --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  EXPECT_EQ(report["target_frames"], target.sequence.size());
  EXPECT_GT(report["without_penalties"]["freezes"].get<int>(),
            report["with_penalties"]["freezes"].get<int>());
  const nlohmann::json seq = ReadJson(dir / "seq.json");
  EXPECT_EQ(seq["format"], "spritestation.skeleton_match");
  EXPECT_EQ(seq["version"], 1);
  ASSERT_EQ(seq["frames"].size(), target.labels.size());
  int same = 0;
  for (size_t i = 0; i < seq["frames"].size(); ++i) {
    const auto& f = seq["frames"][i];
    EXPECT_EQ(f["target_frame"], target.sequence.frames[i].frame);
    const int clip = f["clip"].get<int>();
    const int64_t frame = f["frame"].get<int64_t>();  // frame numbers of the source clip
    ASSERT_TRUE(clip == 0 || clip == 1);
    same += target.labels[i] == source.labels[frame];
  }
  EXPECT_GE(same, static_cast<int>(target.labels.size()) * 75 / 100);  // as above: 77% measured
  ASSERT_TRUE(seq["passes"].contains("without_penalties"));
  EXPECT_EQ(seq["passes"]["without_penalties"]["frames"].size(), target.labels.size());
  const cv::Mat plot = cv::imread(dir / "plot.png");
  ASSERT_FALSE(plot.empty());
  EXPECT_EQ(plot.cols, 3 * 640);  // without, with penalties, refined
  EXPECT_EQ(plot.rows, 480);
}

// A bank holding the source clip's frames as sprites of camera "cam0" of session "studio".
std::vector<int64_t> MakeBank(const std::string& path, int frames) {
  BankWriter w(path);
  const int64_t session =
      w.AddSession({0, "studio@test", "studio", "2026-11-23T10:00:00Z", "test"});
  CameraRecord camera;
  camera.name = "cam0";
  camera.width = 640;
  camera.height = 480;
  const int64_t cam = w.AddCamera(session, camera);
  std::vector<SpriteRecord> sprites;
  for (int f = 0; f < frames; ++f) {
    if (f == 5) continue;  // this frame was not usable
    SpriteRecord s;
    s.frame = f;
    s.timestamp_ns = f * 33'333'333LL;
    s.ground_x_m = 1.5;
    s.ground_y_m = -0.5;
    s.billboard_width_px = 8;
    s.billboard_height_px = 8;
    s.px_per_m = 100;
    s.anchor_x_px = 4;
    s.anchor_y_px = 7;
    s.bbox_in_image = cv::Rect(0, 0, 8, 8);
    s.pixels.bgra = cv::Mat(8, 8, CV_8UC4, cv::Scalar(10, 20, 30, 255));
    s.pixels.shadow = cv::Mat(8, 8, CV_8UC1, cv::Scalar(0));
    sprites.push_back(s);
  }
  ClipRecord clip;
  clip.camera_id = cam;
  clip.track_id = 1;
  clip.first_frame = 0;
  clip.last_frame = frames - 1;
  clip.complete = true;
  w.AppendClipBatch(clip, sprites);
  std::vector<int64_t> ids(frames, 0);
  for (const auto& f : w.LoadFeatures()) ids[f.frame] = f.id;
  return ids;
}

TEST(SkeletonMatch, MatchCommandWithABankWritesRenderableSequences) {
  testing::ScratchDir dir;
  const LabelledSkeletons target = Target();
  const LabelledSkeletons source = Source();
  SkeletonSequence s = source.sequence;
  s.clip = "studio/cam0";
  WriteSkeletonSequence(s, dir / "source.json");
  const std::string t = Write(dir, "target", target.sequence);
  const std::vector<int64_t> ids = MakeBank(dir / "bank.sqlite", s.size());
  const auto run =
      testing::RunSpritestation("match " + t + " --source " + (dir / "source.json") + " --bank " +
                                (dir / "bank.sqlite") + " --out " + (dir / "seq.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const SequenceFile file = ReadSequenceFile(dir / "seq.json");
  ASSERT_EQ(file.sprites.size(), 1u);
  ASSERT_EQ(file.bank_paths.size(), 1u);
  const auto& steps = file.sprites[0].frames;
  ASSERT_EQ(steps.size(), target.labels.size());
  const nlohmann::json match = file.summary["skeleton_match"];
  for (size_t i = 0; i < steps.size(); ++i) {
    const int64_t frame = match["frames"][i]["frame"].get<int64_t>();
    EXPECT_NE(frame, 5);                        // no sprite: never chosen
    EXPECT_EQ(steps[i].sprite_id, ids[frame]);  // the sprite of the chosen frame
    EXPECT_NEAR(file.sprites[0].positions_m[i].x(), 1.5, 1e-9);
  }
  // A clip the bank does not hold.
  s.clip = "other/cam3";
  WriteSkeletonSequence(s, dir / "other.json");
  {  // with two cameras in the bank the clip's name must resolve
    BankWriter w(dir / "bank.sqlite");
    const int64_t other_session = w.AddSession({0, "b@x", "b", "", ""});
    w.AddCamera(other_session, CameraRecord{0, 0, "cam1", "", 640, 480});
  }
  const auto bad =
      testing::RunSpritestation("match " + t + " --source " + (dir / "other.json") + " --bank " +
                                (dir / "bank.sqlite") + " --out " + (dir / "x.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("other/cam3"), std::string::npos) << bad.output;
}

TEST(SkeletonMatch, MatchCommandRefusesBadInput) {
  testing::ScratchDir dir;
  const std::string t = Write(dir, "target", Target().sequence);
  // A source whose frame lacks a joint.
  nlohmann::json broken = SkeletonSequenceToJson(Source().sequence);
  broken["frames"][3]["joints"].erase("knee_l");
  std::ofstream(dir / "broken.json") << broken.dump();
  const auto r = testing::RunSpritestation("match " + t + " --source " + (dir / "broken.json") +
                                           " --out " + (dir / "x.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("broken.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'knee_l' is missing"), std::string::npos) << r.output;
  // A source on another skeleton.
  const auto q = testing::RunSpritestation(
      "skeleton import --format deeplabcut " + Data("dlc_mouse.csv") + " --mapping " +
      Data("mouse_mapping.json") + " --out " + (dir / "m.json"));
  ASSERT_EQ(q.exit_code, 0) << q.output;
  const auto m = testing::RunSpritestation("match " + t + " --source " + (dir / "m.json") +
                                           " --out " + (dir / "x.json"));
  EXPECT_EQ(m.exit_code, 2) << m.output;
  EXPECT_NE(m.output.find("skeleton differs"), std::string::npos) << m.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}

TEST(SkeletonMatch, ImportCommandReadsEachFormat) {
  testing::ScratchDir dir;
  auto import = [&](const std::string& args) {
    const auto r = testing::RunSpritestation("skeleton import " + args + " --out " +
                                             (dir / "s.json") + " --json");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return ReadSkeletonSequence(dir / "s.json");
  };
  const SkeletonSequence d = import("--format deeplabcut " + Data("dlc_mouse.csv") + " --mapping " +
                                    Data("mouse_mapping.json"));
  EXPECT_EQ(d.skeleton.name, "mouse5");
  EXPECT_EQ(d.size(), 4);
  const SkeletonSequence o = import("--format openpose " + Data("openpose_ymca"));
  EXPECT_EQ(o.size(), 3);
  EXPECT_NEAR(o.frames[0].joints[*o.skeleton.JointIndex("wrist_l")].x_px, 395.0f, 1e-3);
  const SkeletonSequence c =
      import("--format coco " + Data("coco_person_keypoints.json") + " --min-confidence 0.9");
  EXPECT_EQ(c.frames[1].frame, 8);
  EXPECT_FALSE(c.frames[1].joints[*c.skeleton.JointIndex("wrist_l")].present);  // hidden, below 0.9
  // DeepLabCut needs a mapping; unknown formats are usage errors.
  const auto no_mapping =
      testing::RunSpritestation("skeleton import --format deeplabcut " + Data("dlc_mouse.csv") +
                                " --out " + (dir / "x.json"));
  EXPECT_EQ(no_mapping.exit_code, 2);
  EXPECT_NE(no_mapping.output.find("--mapping"), std::string::npos) << no_mapping.output;
  EXPECT_EQ(testing::RunSpritestation("skeleton import --format bvh x --out y").exit_code, 2);
}

}  // namespace
}  // namespace ss
