// End to end on real footage: OpenCV's sample video vtest.avi (Debian package opencv-doc,
// which scripts/install-deps.sh installs; Apache-2.0 / BSD-3-Clause): a fixed camera over a
// square, people walking, never empty. `import` with a rough camera model and the per-pixel
// median plate, then `ingest` with the clean-plate keyer, then the stored billboards judged
// as a person would (docs/import.md, "Real footage": what each clip holds, seen by eye). And
// OpenCV's chessboard views (left01..14.jpg, same package) through import and `calibrate`.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/camera_model.h"
#include "core/session.h"
#include "tests/support/test_support.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using testing::JsonInOutput;
using testing::RunSpritestation;
using testing::ScratchDir;

const char* kVtest = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";
// The rough camera: fitted by hand to five people of ~1.75 m at known image rows
// (docs/import.md); the first 30 s (300 frames at 10 fps).
const char* kImportArgs = " --camera-height 6.5 --tilt 22 --hfov 50 --range 0-30 --codec ffvhuff";

// What a stored billboard's matte holds: its parts (alpha > 1/2; parts closer than ~0.2 m are
// one, since a real matte has holes where a coat matches the floor and legs apart from the body),
// and how much of it is in parts shaped like people standing: 1.2-2.3 m tall, at most 1.6 m wide
// (two walking side by side are one part).
struct Silhouette {
  double people_share = 0;  // of the matte's pixels, in person-shaped parts
  int people = 0;           // person-shaped parts
  double tallest_m = 0;     // the tallest person-shaped part
};

Silhouette Measure(const std::string& png, double px_per_m) {
  const cv::Mat bgra = cv::imread(png, cv::IMREAD_UNCHANGED);
  Silhouette s;
  if (bgra.empty() || bgra.channels() != 4) return s;
  cv::Mat alpha;
  cv::extractChannel(bgra, alpha, 3);
  cv::Mat mask = alpha > 127;
  const int k = std::max(3, static_cast<int>(0.2 * px_per_m) | 1);
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int total = 0, people = 0;
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    const double h = stats.at<int>(i, cv::CC_STAT_HEIGHT) / px_per_m,
                 w = stats.at<int>(i, cv::CC_STAT_WIDTH) / px_per_m;
    total += area;
    if (h >= 1.2 && h <= 2.3 && w <= 1.6) {
      people += area;
      ++s.people;
      s.tallest_m = std::max(s.tallest_m, h);
    }
  }
  s.people_share = total > 0 ? static_cast<double>(people) / total : 0;
  return s;
}

// How many people a stored sprite shows, by eye (tests/data/vtest/people_0-30s.csv): rows of
// frame, image box and people.
struct PeopleRow {
  int64_t frame;
  cv::Rect box;
  int people;
};

std::vector<PeopleRow> ReadPeople() {
  std::ifstream in(testing::SourcePath("tests/data/vtest/people_0-30s.csv"));
  std::vector<PeopleRow> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("frame,", 0) == 0) continue;
    PeopleRow r{};
    char comma;
    std::istringstream(line) >> r.frame >> comma >> r.box.x >> comma >> r.box.y >> comma >>
        r.box.width >> comma >> r.box.height >> comma >> r.people;
    rows.push_back(r);
  }
  return rows;
}

// The row of the same frame whose box overlaps `box` most (intersection over union >= 1/2).
const PeopleRow* PeopleOf(const std::vector<PeopleRow>& rows, int64_t frame, const cv::Rect& box) {
  const PeopleRow* best = nullptr;
  double best_iou = 0.5;
  for (const PeopleRow& r : rows) {
    if (r.frame != frame) continue;
    const double inter = (r.box & box).area();
    const double iou = inter / (r.box.area() + box.area() - inter);
    if (iou >= best_iou) {
      best = &r;
      best_iou = iou;
    }
  }
  return best;
}

class ImportVtest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { dir_ = new ScratchDir(); }
  static void TearDownTestSuite() { delete dir_; }
  void SetUp() override {
    // Not a skip: install-deps installs opencv-doc, so its absence is a broken setup.
    ASSERT_TRUE(fs::exists(kVtest))
        << kVtest << " is missing: install the Debian package opencv-doc "
        << "(scripts/install-deps.sh does)";
  }
  static ScratchDir* dir_;
};
ScratchDir* ImportVtest::dir_ = nullptr;

TEST_F(ImportVtest, PeopleWalkingAreStoredAtTheirScaleWithLittleNoise) {
  const std::string session = *dir_ / "vtest";
  const auto imported = RunSpritestation(std::string("--log-level warn import ") + kVtest +
                                         " --out " + session + kImportArgs + " --json");
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const nlohmann::json ij = JsonInOutput(imported.output);
  EXPECT_EQ(ij["cameras"][0]["frames"], 300);
  EXPECT_EQ(ij["cameras"][0]["corrupt_frames"], 0);
  const std::vector<FrameRecord> rows = ReadFrameCsv(session + "/cam0.frames.csv");
  ASSERT_EQ(rows.size(), 330u);
  EXPECT_EQ(rows[30].timestamp_ns, 0);
  EXPECT_EQ(rows.back().timestamp_ns, 29'900'000'000);

  const std::string bank = *dir_ / "vtest.bank";
  const auto ingested =
      RunSpritestation("--log-level warn ingest " + session + " --bank " + bank + " --config " +
                       session + "/ingest.yaml --no-transitions --json");
  ASSERT_EQ(ingested.exit_code, 0) << ingested.output;
  const nlohmann::json j = JsonInOutput(ingested.output);
  EXPECT_EQ(j["cameras"][0]["training_frames"], 30);
  // Auto scale: people here are 60-110 px tall for ~1.75 m, seen obliquely; the rule (the median
  // resolution of the floor over the image, docs/pipeline.md) picks 44 px/m for this camera and
  // floor (its centre, 18 m off, is seen at 26 px/m).
  const double px_per_m = j["px_per_m"].get<double>();
  EXPECT_GE(px_per_m, 20) << j["px_per_m_why"];
  EXPECT_LE(px_per_m, 60) << j["px_per_m_why"];
  EXPECT_EQ(j["discards"]["too_large"], 0);
  const int kept = j["sprites_kept"].get<int>();
  // 110 measured (docs/import.md): 128 before the noise rule, which took the 11 that are no person
  // and 7 of people (5 carrying a streak of tape, 2 in clips the rule cut short).
  EXPECT_GE(kept, 100) << ingested.output;
  EXPECT_GE(j["discards"]["noise"].get<int>(), 20) << ingested.output;  // 121 candidates measured

  const std::string exported = *dir_ / "export";
  const auto ex = RunSpritestation("--log-level warn bank export " + bank + " --out " + exported +
                                   " --no-mirrors");
  ASSERT_EQ(ex.exit_code, 0) << ex.output;
  std::ifstream csv(exported + "/sprites.csv");
  std::string line;
  std::getline(csv, line);
  int sprites = 0, noise = 0;
  std::string judged;  // per sprite, shown when the judgement fails
  const std::vector<PeopleRow> people_rows = ReadPeople();
  ASSERT_EQ(people_rows.size(), 491u);
  // Sprites of two people (by eye) tagged merged, of one person tagged, and with no row.
  int pairs = 0, pairs_tagged = 0, ones = 0, ones_tagged = 0, unmatched = 0;
  std::vector<double> heights_m;
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    ASSERT_GE(f.size(), 29u) << line;  // one tag at most: no quoted commas
    const bool tagged = f[26].find("merged") != std::string::npos;
    const cv::Rect box(std::stoi(f[17]), std::stoi(f[18]), std::stoi(f[19]), std::stoi(f[20]));
    if (const PeopleRow* row = PeopleOf(people_rows, std::stoll(f[4]), box); !row) {
      ++unmatched;
    } else if (row->people >= 2) {
      ++pairs;
      pairs_tagged += tagged;
    } else {
      ++ones;
      ones_tagged += tagged;
    }
    const Silhouette s = Measure(exported + "/" + f[27], std::stod(f[23]));
    ++sprites;
    // People (one, or two walking side by side): most of the matte in person-shaped parts.
    const bool person = s.people_share >= 0.8;
    if (!person) {
      ++noise;
    } else {
      heights_m.push_back(s.tallest_m);
    }
    char row[160];
    std::snprintf(
        row, sizeof(row),
        "sprite %s clip %s: %s, %d person-shaped parts, %.2f of the matte, tallest %.2f m\n",
        f[0].c_str(), f[1].c_str(), person ? "people" : "NOISE", s.people, s.people_share,
        s.tallest_m);
    judged += row;
  }
  EXPECT_EQ(sprites, kept);
  ASSERT_FALSE(heights_m.empty());
  std::nth_element(heights_m.begin(), heights_m.begin() + heights_m.size() / 2, heights_m.end());
  const double median_height_m = heights_m[heights_m.size() / 2];
  const double noise_share = static_cast<double>(noise) / sprites;
  std::printf(
      "vtest.avi 0-30 s: %d sprites at %.0f px/m, %d judged noise (%.1f %%), median "
      "person height %.2f m\n",
      sprites, px_per_m, noise, 100 * noise_share, median_height_m);
  // The rough camera was fitted to people of ~1.75 m: the billboards must say so.
  EXPECT_GE(median_height_m, 1.5);
  EXPECT_LE(median_height_m, 2.0);
  // Measured: 12 of 110 (10.9 %) judged noise; by eye (docs/import.md) none of the 110 is noise:
  // the 12 are people whose matte broke (a pair keyed as two distant parts, a person behind the
  // lamp post), the judge's own error. Before the noise rule (issue 19): 20 of 128 judged, 11 of
  // 128 noise by eye. The bound catches the rule or the keyer getting worse (the first median
  // plate, which replaced moving background by the median, stored 33 of 120 noise by eye).
  EXPECT_LE(noise_share, 0.12) << judged;

  // Two people in one blob are tagged merged (issue 19), by the tracks when they meet in view
  // and by their looks (SideBySide) when they walk in together. Measured: 161 of the 169 sprites
  // of two people tagged, none of the 322 of one (before the looks: 2 of 169).
  std::printf("merged: %d of %d sprites of two people tagged, %d of %d of one; %d not in %s\n",
              pairs_tagged, pairs, ones_tagged, ones, unmatched, "people_0-30s.csv");
  EXPECT_LE(unmatched, sprites / 10) << "the stored sprites changed: look at them again";
  EXPECT_GE(pairs_tagged, 0.9 * pairs);
  EXPECT_LE(ones_tagged, 0.02 * ones);
}

// Board calibration from footage: OpenCV's own chessboard views (left01..14.jpg, 9x6 inner
// corners of 25 mm), imported as an image sequence with no model, then `calibrate intrinsics` on
// the session as on any recorded one. OpenCV's solution for these images (left_intrinsics.yml,
// fixed aspect ratio) has fx = fy = 535.9 px.
TEST_F(ImportVtest, BoardFootageImportsForCalibration) {
  const std::string session = *dir_ / "board";
  const auto imported = RunSpritestation(
      "--log-level warn import '/usr/share/doc/opencv-doc/examples/data/left[01]*.jpg' --out " +
      session + " --no-model --empty-frames 0 --fps 1 --json");
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  EXPECT_EQ(JsonInOutput(imported.output)["cameras"][0]["frames"], 13);
  EXPECT_EQ(JsonInOutput(imported.output)["name"], "left01");
  EXPECT_FALSE(fs::exists(session + "/ingest.yaml"));  // no empty scene: not for ingest
  const auto solved =
      RunSpritestation("--log-level warn calibrate intrinsics " + session +
                       " --board chessboard:10x7:0.025 --lensmodel LENSMODEL_OPENCV4 --every 1 "
                       "--min-views 8 --min-coverage 0 --out " +
                       *dir_ / "intrinsics" + " --json");
  ASSERT_EQ(solved.exit_code, 0) << solved.output;
  const CameraModel model = CameraModel::Read(*dir_ / "intrinsics/cam0.cameramodel");
  EXPECT_NEAR(model.intrinsics()[0], 535.9, 0.01 * 535.9);
  EXPECT_NEAR(model.intrinsics()[1], 535.9, 0.01 * 535.9);
  EXPECT_NEAR(model.intrinsics()[2], 342.3, 3);
  EXPECT_NEAR(model.intrinsics()[3], 235.6, 3);
}

}  // namespace
}  // namespace ss
