// The `spritestation skeleton import`, `skeleton track` and `match` commands on small inputs:
// each import format, tracking a folder of rendered frames, the match's files (the choice,
// the Figure-2 plot, sequences for `render` when a bank is given) and bad input. The clips
// come from tests/animate/skeleton_fixtures.h; the whole chain on synthetic sessions is
// skeleton_e2e_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "animate/sequence_io.h"
#include "animate/skeleton/skeleton_json.h"
#include "animate/skeleton/synthetic_poses.h"
#include "core/bank.h"
#include "tests/animate/skeleton_fixtures.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::Error;
using testing::kFrames;
using testing::kOccludedFrom;
using testing::kOccludedTo;
using testing::RenderClip;
using testing::Source;
using testing::Target;
using testing::Truth;

std::string Data(const std::string& name) {
  return ss::testing::SourcePath("tests/data/skeleton/" + name);
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

TEST(SkeletonTracking, TrackCommandOnAFolderOfFrames) {
  // `spritestation skeleton track` on PNG frames, the user's joints for frame 0 and the
  // occluded frames marked on the command line.
  const SkeletonSequence truth = Truth();
  const std::vector<cv::Mat> images = RenderClip(truth, true);
  testing::ScratchDir dir;
  std::filesystem::create_directories(dir / "frames");
  for (size_t f = 0; f < images.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "frames/%04zu.png", f);
    ASSERT_TRUE(cv::imwrite(dir / name, images[f]));
  }
  nlohmann::json joints = nlohmann::json::object();
  for (size_t j = 0; j < truth.frames[0].joints.size(); ++j) {
    joints[HumanSkeleton().joints[j]] = {truth.frames[0].joints[j].x_px,
                                         truth.frames[0].joints[j].y_px};
  }
  std::ofstream(dir / "init.json")
      << nlohmann::json{{"skeleton", "human14"}, {"joints", joints}}.dump();
  const auto run = testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                             (dir / "init.json") + " --out " + (dir / "skel.json") +
                                             " --occluded " + std::to_string(kOccludedFrom) + "-" +
                                             std::to_string(kOccludedTo) + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  EXPECT_EQ(report["frames"], kFrames);
  EXPECT_EQ(report["failures"].size(), 0u);
  EXPECT_EQ(report["interpolated_joints"], 15 * (kOccludedTo - kOccludedFrom + 1));
  const SkeletonSequence s = ReadSkeletonSequence(dir / "skel.json");
  EXPECT_EQ(s.clip, "frames");
  ASSERT_EQ(s.size(), kFrames);
  float worst = 0;
  for (int f = 0; f < kFrames; ++f) {
    for (size_t j = 0; j < s.frames[f].joints.size(); ++j) {
      ASSERT_TRUE(s.frames[f].joints[j].present);
      EXPECT_EQ(s.frames[f].joints[j].interpolated, f >= kOccludedFrom && f <= kOccludedTo);
      worst = std::max(worst, Error(s.frames[f].joints[j], truth.frames[f].joints[j]));
    }
  }
  EXPECT_LT(worst, 3.0f);
  // Bad input: an occluded frame past the clip, a missing initial joint.
  const auto past = testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                              (dir / "init.json") + " --out " + (dir / "x.json") +
                                              " --occluded 100");
  EXPECT_EQ(past.exit_code, 2) << past.output;
  joints.erase("wrist_r");
  std::ofstream(dir / "bad_init.json") << nlohmann::json{{"joints", joints}}.dump();
  const auto bad =
      testing::RunSpritestation("skeleton track " + (dir / "frames") + " --init " +
                                (dir / "bad_init.json") + " --out " + (dir / "x.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("'wrist_r' is missing"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace ss
