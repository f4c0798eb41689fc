// End to end (seed 003): two synthetic figure sessions (docs/synth.md) — a source figure
// and a differently proportioned target figure with another timeline — through
// `spritestation skeleton import --format synth` (the joint truth), `skeleton track`
// (Lucas-Kanade from the truth's first frame) and `spritestation match`, scored against
// the truth's gesture labels (subjects.csv `pose`).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"

namespace ss {
namespace {

using testing::JsonInOutput;
using testing::RunSpritestation;
using testing::ScratchDir;

// frame -> pose label of subject 0, from <session>/truth/subjects.csv.
std::map<int, std::string> PoseLabels(const std::string& session) {
  std::ifstream in(session + "/truth/subjects.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
  const auto col = [&](const std::string& n) {
    return std::find(header.begin(), header.end(), n) - header.begin();
  };
  const size_t c_frame = col("frame"), c_subject = col("subject"), c_pose = col("pose");
  std::map<int, std::string> labels;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
    if (cells.size() <= std::max({c_frame, c_subject, c_pose}) || cells[c_subject] != "0") continue;
    labels[std::stoi(cells[c_frame])] = cells[c_pose];
  }
  return labels;
}

nlohmann::json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Per frame number: the joints in definition order (x, y; NaN when missing).
std::map<int, std::vector<std::pair<double, double>>> Joints(const nlohmann::json& sequence) {
  std::map<int, std::vector<std::pair<double, double>>> out;
  const double nan = std::nan("");
  for (const auto& f : sequence["frames"]) {
    auto& joints = out[f["frame"].get<int>()];
    for (const auto& j : f["joints"]) {  // an array, or an object in definition order
      joints.push_back(j.is_array() ? std::make_pair(j[0].get<double>(), j[1].get<double>())
                                    : std::make_pair(nan, nan));
    }
  }
  return out;
}

class SkeletonEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    // Source: the reference figure, seed 3 (one full round: idle, turn, walk, Y M C A).
    // Target: the other build (--figure-variant 1) with seed 5, so another timeline.
    // 480x360 at 10 fps keeps the rendering near 15 s on the shared machine (640x480: ~30 s).
    for (const auto& [name, args] : std::vector<std::pair<std::string, std::string>>{
             {"source", "--seed 3 --seconds 15"},
             {"target", "--seed 5 --figure-variant 1 --seconds 12"}}) {
      const auto r = RunSpritestation(
          "--log-level warn synth --out " + *dir_ / name +
          " --kind figure --size 480x360 --fps 10 --cameras 1 --no-mattes --threads 2 " + args);
      ASSERT_EQ(r.exit_code, 0) << r.output;
      const auto i =
          RunSpritestation("--log-level warn skeleton import --format synth " + *dir_ / name +
                           " --out " + *dir_ / (name + ".skel.json") + " --json");
      ASSERT_EQ(i.exit_code, 0) << i.output;
    }
  }
  static void TearDownTestSuite() { delete dir_; }
  static ScratchDir* dir_;
};
ScratchDir* SkeletonEndToEnd::dir_ = nullptr;

TEST_F(SkeletonEndToEnd, ImportedTruthMatchesGesturesWithoutLongFreezes) {
  const std::string out = *dir_ / "match.json";
  const auto r =
      RunSpritestation("--log-level warn match " + *dir_ / "target.skel.json" + " --source " +
                       *dir_ / "source.skel.json" + " --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json m = ReadJsonFile(out);
  const auto target_labels = PoseLabels(*dir_ / "target");
  const auto source_labels = PoseLabels(*dir_ / "source");
  const auto target_joints = Joints(ReadJsonFile(*dir_ / "target.skel.json"));

  struct Score {
    int frames = 0, same = 0, arm_frames = 0, arm_same = 0, moving_frames = 0, moving_same = 0;
    double all() const { return static_cast<double>(same) / frames; }
    double arms() const { return static_cast<double>(arm_same) / arm_frames; }
    double moving() const { return static_cast<double>(moving_same) / moving_frames; }
  };
  auto score = [&](const nlohmann::json& frames) {
    Score s;
    for (const auto& f : frames) {
      const std::string& want = target_labels.at(f["target_frame"].get<int>());
      const bool same = want == source_labels.at(f["frame"].get<int>());
      ++s.frames;
      s.same += same;
      if (want == "Y" || want == "M" || want == "C" || want == "A") {
        ++s.arm_frames;
        s.arm_same += same;
      }
      if (want == "turn" || want == "walk") {
        ++s.moving_frames;
        s.moving_same += same;
      }
    }
    return s;
  };
  const Score with = score(m["passes"]["with_penalties"]["frames"]);
  const Score without = score(m["passes"]["without_penalties"]["frames"]);
  const Score refined = score(m["frames"]);
  std::printf(
      "gesture accuracy without / with penalties / refined: %.3f / %.3f / %.3f (arm gestures Y M C "
      "A: "
      "%.3f / %.3f / %.3f; turn and walk: %.3f / %.3f / %.3f)\n",
      without.all(), with.all(), refined.all(), without.arms(), with.arms(), refined.arms(),
      without.moving(), with.moving(), refined.moving());
  ASSERT_EQ(with.frames, static_cast<int>(target_labels.size()));
  ASSERT_GT(with.arm_frames, 40);
  ASSERT_GT(with.moving_frames, 20);  // turn 17, walk 8 (frames 20-35 and 111-119)
  // The arm gestures are matched (measured: 1.0 / 0.98 / 1.0).
  EXPECT_GE(with.arms(), 0.95);
  EXPECT_GE(refined.arms(), 0.95);
  // Over every frame, measured 0.892 without penalties, 0.958 with them, 0.975 refined
  // (before the motion term: 0.850 / 0.883 / 0.833). The target's turn and slow walk away
  // from the camera are nearly the idle pose in 2D; the motion term (limb-pair rates and
  // the root's image speed) sends them to moving source frames: turn and walk measured
  // 0.48 / 0.84 / 0.88 (before: 0.28 / 0.48 / 0.32). The refined walk used to be 0/8 (0.917
  // over all): locomotion has no peak of pose change, so idle, turn and walk were one target
  // movement held to one source movement; now target movements are also cut where the
  // first pass changes source movement (SplitByFirstPass).
  EXPECT_GE(without.all(), 0.875);
  EXPECT_GE(with.all(), 0.95);
  EXPECT_GE(refined.all(), 0.95);
  EXPECT_GE(with.moving(), 0.80);
  EXPECT_GE(refined.moving(), 0.80);

  // With penalties: no freeze longer than 5 frames while the target moves (a joint moves
  // more than 1 px from the previous target frame).
  const auto& chosen = m["passes"]["with_penalties"]["frames"];
  int run = 0, longest = 0;
  for (size_t t = 1; t < chosen.size(); ++t) {
    const bool repeat =
        chosen[t]["clip"] == chosen[t - 1]["clip"] && chosen[t]["frame"] == chosen[t - 1]["frame"];
    const auto& a = target_joints.at(chosen[t - 1]["target_frame"].get<int>());
    const auto& b = target_joints.at(chosen[t]["target_frame"].get<int>());
    double moved = 0;
    for (size_t j = 0; j < a.size(); ++j)
      moved = std::max(moved, std::hypot(a[j].first - b[j].first, a[j].second - b[j].second));
    run = repeat && moved > 1.0 ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  EXPECT_LE(longest, 5);
  EXPECT_LE(m["passes"]["with_penalties"]["stats"]["longest_freeze"].get<int>(),
            m["passes"]["without_penalties"]["stats"]["longest_freeze"].get<int>());
}

TEST_F(SkeletonEndToEnd, LucasKanadeTrackingAgainstTruth) {
  // The user's joints in frame 0 = the truth's frame 0.
  nlohmann::json init = ReadJsonFile(*dir_ / "target.skel.json");
  init["frames"] = nlohmann::json::array({init["frames"][0]});
  std::ofstream(*dir_ / "init.json") << init.dump();
  const auto r =
      RunSpritestation("--log-level warn skeleton track " + *dir_ / "target" + " --init " +
                       *dir_ / "init.json" + " --out " + *dir_ / "tracked.json" + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto truth = Joints(ReadJsonFile(*dir_ / "target.skel.json"));
  const auto tracked = Joints(ReadJsonFile(*dir_ / "tracked.json"));
  std::vector<double> errors;
  int missing = 0, total = 0;
  for (const auto& [frame, joints] : tracked) {
    const auto& want = truth.at(frame);
    for (size_t j = 0; j < joints.size(); ++j) {
      ++total;
      if (std::isnan(joints[j].first)) {
        ++missing;
        continue;
      }
      errors.push_back(
          std::hypot(joints[j].first - want[j].first, joints[j].second - want[j].second));
    }
  }
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  std::printf(
      "Lucas-Kanade vs truth: median %.2f px, 90th percentile %.2f px over %zu tracked joints; %d "
      "of %d "
      "joint-frames lost (%.0f%%)\n",
      median, p90, errors.size(), missing, total, 100.0 * missing / total);
  // Measured at 480x360: 0.70 px median, 12.3 px p90, 31 % lost; at 640x480 (same seeds,
  // bench/RESULTS.md): 0.52 / 1.97 px, 36 % lost. Limbs crossing the body in the turns and
  // the fast arm moves at 10 fps fail the forward-backward check or drift.
  EXPECT_LT(median, 1.0);
  EXPECT_LT(p90, 20.0);
  EXPECT_LT(missing, total / 2);
}

}  // namespace
}  // namespace ss
