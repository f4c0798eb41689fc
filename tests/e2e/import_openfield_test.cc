// Issue 38 on real footage: DeepLabCut's example video of a mouse in an open-field arena, filmed
// from straight above (tests/data/openfield; LGPL-3.0). Its first 30 s go through `import` with
// the rough camera the issue reports (0.6 m up, tilted 89 degrees, 60 degrees across: the
// arena's median view is 68 degrees, so ingest stores floor sprites), `ingest` and `plate`,
// once for the file. Before floor sprites, the same import stored slivers: an upright billboard
// seen edge-on from above. The stored sprites must hold the whole body, and the mouse must run a
// circle and a straight line as a viewer would judge them (bench/RESULTS.md, "Real footage from
// above": the whole video, by eye and by the judge).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/test_support.h"
#include "tests/synth/synth_csv.h"

namespace ss {
namespace {

namespace fs = std::filesystem;

class OpenField : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<testing::ScratchDir>();
    const std::string session = *dir_ / "session";
    const testing::CommandResult imported = testing::RunSpritestation(
        "--log-level warn import " + testing::SourcePath("tests/data/openfield/m3v1mp4.mp4") +
        " --out " + session +
        " --camera-height 0.6 --tilt 89 --hfov 60 --range 0-30 --codec ffvhuff");
    import_output_ = imported.output;
    made_ =
        imported.exit_code == 0 &&
        testing::RunSpritestationOk("ingest " + session + " --bank " + (*dir_ / "mouse.ssbank") +
                                    " --config " + session + "/ingest.yaml") &&
        testing::RunSpritestationOk("plate " + session + " --camera cam0 --out " +
                                    (*dir_ / "floor.png"));
    if (made_) fs::copy_file(session + "/cam0.cameramodel", *dir_ / "virtual.cameramodel");
  }
  static void TearDownTestSuite() { dir_.reset(); }

  void SetUp() override {
    ASSERT_TRUE(made_) << "the open-field footage could not be imported and ingested\n"
                       << import_output_;
  }

  // The mouse from `start` along `path` (points in metres), judged: the judge's figures.
  // A turn limit, not a time, ends the run (with a time budget far beyond it): the same result on
  // any machine.
  static nlohmann::json Animate(const std::string& name, const std::string& start,
                                const std::string& path, int min_frames, int max_frames,
                                int max_turns) {
    const std::string spec = *dir_ / (name + ".yaml"), seq = *dir_ / (name + ".json");
    std::ofstream(spec) << "version: 1\nframe_rate: 30\nlength: {min_frames: " << min_frames
                        << ", max_frames: " << max_frames
                        << "}\ncamera: " << (*dir_ / "virtual.cameramodel")
                        << "\nbackground: " << (*dir_ / "floor.png") << "\nbanks: ["
                        << (*dir_ / "mouse.ssbank") << "]\nrepeats: {strength: 3}\n"
                        << "optimizer: {method: replace, time_budget_s: 300, seed: 1}\n"
                        << "sprites:\n  - name: mouse\n    start: " << start
                        << "\n    constraints:\n      - path:\n          points: " << path
                        << "\n          direction_strength: 0.5\n          distance_strength: 1000"
                        << "\n          unreached_strength: 3000\n";
    const testing::CommandResult r =
        testing::RunSpritestation("--log-level warn animate " + spec + " --out " + seq +
                                  " --max-turns " + std::to_string(max_turns) + " --json");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json report = testing::JsonInOutput(r.output);
    EXPECT_TRUE(report.contains("judge")) << r.output;
    if (r.exit_code == 0) {
      // It renders: the floor sprites laid on the floor, seen from the camera that filmed them.
      EXPECT_TRUE(
          testing::RunSpritestationOk("render " + seq + " --out " + (*dir_ / (name + ".mkv"))));
    }
    return report.value("judge", nlohmann::json::object());
  }

  static std::unique_ptr<testing::ScratchDir> dir_;
  static bool made_;
  static std::string import_output_;
};
std::unique_ptr<testing::ScratchDir> OpenField::dir_;
bool OpenField::made_ = false;
std::string OpenField::import_output_;

// Every stored sprite is a floor sprite and holds the mouse's whole body: no sliver. Looked at
// (the whole video, 1,528 sprites, 24 of them on a contact sheet): each is the body seen from
// above, the tail cut off (too thin to key), head or rump first; the matte's area in the image
// is 2,237-3,896 px (median 2,988: the smallest is 75 % of it).
// (One test, since CTest runs each in a process of its own, and each would import again.)
TEST_F(OpenField, TheMouseIsStoredWholeAsFloorSpritesAndRunsACircleAndALine) {
  EXPECT_NE(import_output_.find("films its floor from above"), std::string::npos) << import_output_;
  const std::string out = *dir_ / "export";
  ASSERT_TRUE(
      testing::RunSpritestationOk("bank export " + (*dir_ / "mouse.ssbank") + " --out " + out));
  const auto rows = testing::ReadCsv(out + "/sprites.csv");
  std::vector<double> areas;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("kind"), "floor") << "sprite " << row.at("id");
    if (row.at("mirrored") == "0") areas.push_back(std::stod(row.at("area_px")));
  }
  // The first 30 s: the mouse is in view and moving most of the time.
  ASSERT_GE(areas.size(), 400U);
  std::vector<double> sorted = areas;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  EXPECT_GT(median, 1500) << "a mouse ~0.1 m long seen from 0.6 m covers ~3,000 px";
  EXPECT_GE(sorted.front(), 0.5 * median) << "a sprite holds less than half the body";

  // Issue 38's goal on real footage: an overhead circle of radius 0.1 m completed (swept >= 98 %,
  // deviation <= 2 cm, stutter <= 1 %), and a straight run. The whole video's bank (1,528 sprites,
  // 600 turns, seeds 1-3) meets it: 0.7 / 1.7 / 1.4 cm with the facing term and the start facing
  // along the path (1.3-1.6 with neither), 100 %, 0 %. This 30 s cut has 429 sprites and strays
  // further where the circle turns: 600 turns, seed 1, 2.0 cm at most (median 0.7 cm; with
  // neither, seeds 1-3 strayed 2.8 / 2.8 / 2.1 cm), 100 % swept, no stutter; the line 300 turns,
  // 0.8 cm. The bars here are the cut's.
  const nlohmann::json circle =
      Animate("circle", "[0.1, 0.0]",
              "[[0.1, 0.0], [0.0707, 0.0707], [0.0, 0.1], [-0.0707, 0.0707], [-0.1, 0.0], "
              "[-0.0707, -0.0707], [0.0, -0.1], [0.0707, -0.0707], [0.1, 0.0]]",
              120, 600, 600);
  ASSERT_TRUE(circle.contains("paths")) << circle.dump();
  EXPECT_GE(circle["paths"][0]["swept_share"].get<double>(), 0.98) << circle.dump();
  EXPECT_LE(circle["paths"][0]["max_deviation_m"].get<double>(), 0.035) << circle.dump();
  EXPECT_LE(circle["stutter"]["share"].get<double>(), 0.01) << circle.dump();
  // The mouse faces the way it goes (the spec's default facing term, and the start facing along
  // the path): the footage's own frames move 32 degrees (median) off their heading. On this cut
  // with neither the circle's median is 27 degrees, now 21; on the whole video's bank 42-45
  // with neither, 29-34 now (seeds 1-3).
  EXPECT_LE(circle["facing"]["median_deg"].get<double>(), 25.0) << circle["facing"].dump();

  const nlohmann::json line =
      Animate("line", "[-0.15, 0.0]", "[[-0.15, 0.0], [0.15, 0.0]]", 60, 300, 300);
  ASSERT_TRUE(line.contains("paths")) << line.dump();
  EXPECT_GE(line["paths"][0]["swept_share"].get<double>(), 0.98) << line.dump();
  EXPECT_LE(line["paths"][0]["max_deviation_m"].get<double>(), 0.02) << line.dump();
  EXPECT_LE(line["stutter"]["share"].get<double>(), 0.01) << line.dump();
  // On the whole video's bank the line slid sideways at 55-57 degrees with neither, and keeps to
  // 5-7 now, in one clip of the mouse walking head first turned onto the line. This cut's line:
  // 25 degrees with neither, 27 with the facing term alone (its start frame faced off the line),
  // 18 now.
  EXPECT_LE(line["facing"]["median_deg"].get<double>(), 22.0) << line["facing"].dump();
}

}  // namespace
}  // namespace ss
