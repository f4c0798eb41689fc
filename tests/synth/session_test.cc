// Whole synthetic sessions: the truth against the images, determinism, and the
// session read back by the replay source like any recording.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/replay/replay_source.h"
#include "core/camera_model.h"
#include "core/frame.h"
#include "core/session.h"
#include "synth/studio_session.h"
#include "tests/support/test_support.h"
#include "tests/synth/synth_csv.h"

namespace ss::synth {
namespace {

namespace fs = std::filesystem;
using ss::testing::Num;
using ss::testing::ReadCsv;
using ss::testing::ScratchDir;

SynthOptions Small(const std::string& out, uint64_t seed) {
  SynthOptions o;
  o.out_dir = out;
  o.kind = SynthKind::kAnimal;
  o.seconds = 2.0;
  o.fps = 10.0;
  o.width = 320;
  o.height = 240;
  o.cameras = 2;
  o.subjects = 1;
  o.seed = seed;
  return o;
}

// Every frame of every camera, decoded (BGR), indexed [camera][frame].
std::vector<std::vector<cv::Mat>> Decode(const std::string& dir) {
  ReplaySource source(dir);
  std::vector<std::vector<cv::Mat>> frames(source.cameras().size());
  while (auto f = source.Next()) frames[static_cast<size_t>(f->camera)].push_back(ToBgr(*f));
  return frames;
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string Png(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return name;
}

TEST(SynthSession, MatteCoversExactlyTheRenderedSubject) {
  ScratchDir dir;
  // The same studio, cameras and seed without the animal: its frames are the clean plate.
  SynthOptions with = Small(dir / "with", 11), without = Small(dir / "without", 11);
  with.noise = without.noise = 0.0;
  without.subjects = 0;
  RenderStudioSession(with);
  RenderStudioSession(without);
  const auto a = Decode(with.out_dir), b = Decode(without.out_dir);
  ASSERT_EQ(a.size(), 2u);
  double matte_px = 0;
  for (size_t c = 0; c < a.size(); ++c) {
    ASSERT_EQ(a[c].size(), 20u);
    const std::string cam = "cam" + std::to_string(c);
    const auto views = ReadCsv((fs::path(with.out_dir) / "truth" / cam / "views.csv").string());
    ASSERT_EQ(views.size(), 20u);
    for (int f = 0; f < 20; ++f) {
      const cv::Mat alpha =
          cv::imread((fs::path(with.out_dir) / "truth" / cam / "alpha_s0" / Png(f)).string(),
                     cv::IMREAD_UNCHANGED);
      const cv::Mat shadow =
          cv::imread((fs::path(with.out_dir) / "truth" / cam / "shadow" / Png(f)).string(),
                     cv::IMREAD_UNCHANGED);
      ASSERT_EQ(alpha.type(), CV_8U);
      ASSERT_EQ(alpha.size(), a[c][f].size());
      cv::Mat diff;
      cv::absdiff(a[c][f], b[c][f], diff);
      cv::Mat changed(diff.size(), CV_8U);
      for (int y = 0; y < diff.rows; ++y) {
        for (int x = 0; x < diff.cols; ++x) {
          const cv::Vec3b d = diff.at<cv::Vec3b>(y, x);
          changed.at<uint8_t>(y, x) = std::max({d[0], d[1], d[2]}) > 12 ? 255 : 0;
        }
      }
      int solid = 0, solid_changed = 0, clear = 0, clear_changed = 0;
      for (int y = 0; y < diff.rows; ++y) {
        for (int x = 0; x < diff.cols; ++x) {
          const int al = alpha.at<uint8_t>(y, x), sh = shadow.at<uint8_t>(y, x);
          const bool ch = changed.at<uint8_t>(y, x) != 0;
          if (al >= 250) {
            ++solid;
            solid_changed += ch;
          } else if (al == 0 && sh <= 2) {
            ++clear;
            clear_changed += ch;
          }
        }
      }
      const double area = cv::sum(alpha)[0] / 255.0;
      matte_px += area;
      EXPECT_NEAR(area, Num(views[static_cast<size_t>(f)], "visible_px"), 0.01 * area + 1.0);
      // The subject's pixels are changed (it is not green), and nothing else is.
      if (solid > 0) {
        EXPECT_GE(solid_changed, 0.97 * solid) << cam << " frame " << f;
      }
      EXPECT_LE(clear_changed, 2) << cam << " frame " << f;
    }
  }
  EXPECT_GT(matte_px, 20 * 2 * 30.0);  // the animal was in view
}

TEST(SynthSession, LowestPointAndContactMatchTheMatte) {
  ScratchDir dir;
  SynthOptions o = Small(dir / "s", 21);
  o.seconds = 3.0;
  RenderStudioSession(o);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  const auto subjects = ReadCsv((truth / "subjects.csv").string());
  int checked = 0, contacts = 0;
  for (int c = 0; c < 2; ++c) {
    const std::string cam = "cam" + std::to_string(c);
    const CameraModel model = CameraModel::Read((truth / (cam + ".cameramodel")).string());
    const auto views = ReadCsv((truth / cam / "views.csv").string());
    for (const auto& v : views) {
      const int f = std::stoi(v.at("frame"));
      if (Num(v, "unoccluded_px") - Num(v, "visible_px") > 0.5) continue;  // partly hidden
      if (subjects[static_cast<size_t>(f)].at("touches_wall") == "1") continue;
      const cv::Mat alpha =
          cv::imread((truth / cam / "alpha_s0" / Png(f)).string(), cv::IMREAD_UNCHANGED);
      // The extractor's lowest point: the lowest row with alpha > 1/2, then where alpha falls
      // through 1/2.
      int row = -1;
      for (int y = alpha.rows - 1; y >= 0 && row < 0; --y) {
        for (int x = 0; x < alpha.cols; ++x) {
          if (alpha.at<uint8_t>(y, x) > 127) row = y;
        }
      }
      ASSERT_GE(row, 0);
      double sum_x = 0, n = 0, below = 0, here = 0, row_x0 = 1e9, row_x1 = -1e9;
      for (int x = 0; x < alpha.cols; ++x) {
        if (alpha.at<uint8_t>(row, x) > 127) {
          row_x0 = std::min<double>(row_x0, x);
          row_x1 = std::max<double>(row_x1, x);
          sum_x += x;
          ++n;
          here = std::max(here, static_cast<double>(alpha.at<uint8_t>(row, x)));
          if (row + 1 < alpha.rows)
            below = std::max(below, static_cast<double>(alpha.at<uint8_t>(row + 1, x)));
        }
      }
      const double low_y = row + (here - 127.5) / std::max(1.0, here - below);
      const Eigen::Vector2d matte_low(sum_x / n, low_y);
      const Eigen::Vector2d truth_low(Num(v, "lowest_x"), Num(v, "lowest_y"));
      EXPECT_NEAR(truth_low.y(), matte_low.y(), 1.5) << cam << " frame " << f;
      // Along a nearly level bottom edge x is ill-defined: the truth must lie on the matte's lowest
      // row.
      EXPECT_GE(truth_low.x(), row_x0 - 1.5) << cam << " frame " << f;
      EXPECT_LE(truth_low.x(), row_x1 + 1.5) << cam << " frame " << f;
      ++checked;
      // Where the lowest point is a paw on the floor, the true ground point under it
      // projects onto the sprite's lowest point.
      if (Num(v, "lowest_gz") < 0.001) {
        const Eigen::Vector2d px =
            model.ProjectGround({Num(v, "lowest_gx"), Num(v, "lowest_gy"), 0.0});
        EXPECT_NEAR(px.y(), matte_low.y(), 1.5) << cam << " frame " << f;
        EXPECT_GE(px.x(), row_x0 - 1.5) << cam << " frame " << f;
        EXPECT_LE(px.x(), row_x1 + 1.5) << cam << " frame " << f;
        ++contacts;
      }
      // The root (the floor under the body) projects inside the sprite's box.
      const Eigen::Vector2d root =
          model.ProjectGround({Num(subjects[static_cast<size_t>(f)], "x"),
                               Num(subjects[static_cast<size_t>(f)], "y"), 0.0});
      EXPECT_NEAR(root.x(), Num(v, "root_x"), 1e-3);
      EXPECT_GE(root.x(), Num(v, "box_x") - 1);
      EXPECT_LE(root.x(), Num(v, "box_x") + Num(v, "box_w") + 1);
      EXPECT_LE(root.y(), Num(v, "box_y") + Num(v, "box_h") + 1);
    }
  }
  EXPECT_GT(checked, 20);
  RecordProperty("contacts", contacts);
}

TEST(SynthSession, SameSeedSameBytesOtherSeedOtherSession) {
  ScratchDir dir;
  SynthOptions a = Small(dir / "a", 7), b = Small(dir / "b", 7), c = Small(dir / "c", 8);
  for (auto* o : {&a, &b, &c}) {
    o->seconds = 1.0;
    o->width = 160;
    o->height = 120;
    RenderStudioSession(*o);
  }
  // Every truth file is byte-identical for the same seed.
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(a.out_dir) / "truth")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), a.out_dir);
    ASSERT_EQ(ReadFile(e.path()), ReadFile(fs::path(b.out_dir) / rel)) << rel;
    ++files;
  }
  EXPECT_GT(files, 20);
  for (const char* f : {"cam0.frames.csv", "cam0.cameramodel", "cam1.cameramodel"}) {
    EXPECT_EQ(ReadFile(fs::path(a.out_dir) / f), ReadFile(fs::path(b.out_dir) / f)) << f;
  }
  const auto fa = Decode(a.out_dir), fb = Decode(b.out_dir), fc = Decode(c.out_dir);
  ASSERT_EQ(fa.size(), fb.size());
  for (size_t cam = 0; cam < fa.size(); ++cam) {
    ASSERT_EQ(fa[cam].size(), fb[cam].size());
    for (size_t i = 0; i < fa[cam].size(); ++i) {
      EXPECT_EQ(cv::norm(fa[cam][i], fb[cam][i], cv::NORM_INF), 0.0)
          << "camera " << cam << " frame " << i;
      EXPECT_GT(cv::norm(fa[cam][i], fc[cam][i], cv::NORM_L1), 0.0);
    }
  }
  EXPECT_NE(ReadFile(fs::path(a.out_dir) / "truth" / "subjects.csv"),
            ReadFile(fs::path(c.out_dir) / "truth" / "subjects.csv"));
  EXPECT_NE(ReadFile(fs::path(a.out_dir) / "cam0.cameramodel"),
            ReadFile(fs::path(c.out_dir) / "cam0.cameramodel"));
}

TEST(SynthSession, ReplaysLikeARecordingInItsPixelFormat) {
  ScratchDir dir;
  SynthOptions o = Small(dir / "s", 3);
  o.seconds = 1.0;
  o.width = 160;
  o.height = 120;
  o.cameras = 3;
  o.subjects = 2;
  o.pixel_format = PixelFormat::kBayerRG8;
  const SynthSummary summary = RenderStudioSession(o);
  EXPECT_EQ(summary.frames, 10);
  const SessionInfo info = ReadSessionInfo(o.out_dir);
  EXPECT_TRUE(info.synthetic);
  ASSERT_EQ(info.cameras.size(), 3u);
  const auto subjects = ReadCsv((fs::path(o.out_dir) / "truth" / "subjects.csv").string());
  ASSERT_EQ(subjects.size(), 20u);  // 10 frames x 2 subjects
  ReplaySource source(o.out_dir);
  std::vector<int> count(3, 0);
  while (auto f = source.Next()) {
    EXPECT_EQ(f->format, PixelFormat::kBayerRG8);
    EXPECT_EQ(f->width, 160);
    EXPECT_EQ(f->timestamp_ns, std::stoll(subjects[2 * f->sequence].at("timestamp_ns")));
    ++count[static_cast<size_t>(f->camera)];
  }
  EXPECT_EQ(count, std::vector<int>(3, 10));
  EXPECT_EQ(source.stats().errors, 0u);
  // The true models are the session's models; the floor polygon is in truth/.
  for (const auto& cam : info.cameras) {
    EXPECT_EQ(ReadFile(fs::path(o.out_dir) / cam.model),
              ReadFile(fs::path(o.out_dir) / "truth" / cam.model));
  }
  const auto floor = nlohmann::json::parse(ReadFile(fs::path(o.out_dir) / "truth" / "floor.json"));
  EXPECT_EQ(floor["polygon"].size(), 4u);
  const auto truth = nlohmann::json::parse(ReadFile(fs::path(o.out_dir) / "truth" / "truth.json"));
  EXPECT_EQ(truth["subjects"].size(), 2u);
  EXPECT_EQ(truth["frames"], 10);
}

// overlaps.csv (two subjects): one row per frame and pair, and `touching` is exactly whether the
// two true mattes overlap or are 8-neighbours somewhere.
TEST(SynthSession, OverlapsSayWhereTwoSilhouettesTouch) {
  ScratchDir dir;
  SynthOptions o = Small(dir / "s", 11);
  o.seconds = 3.0;
  o.cameras = 1;
  o.subjects = 2;
  RenderStudioSession(o);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  const auto cams = nlohmann::json::parse(ReadFile(truth / "truth.json"))["cameras"];
  ASSERT_EQ(cams.size(), 1u);
  const std::string cam = cams[0]["name"];
  const auto rows = ReadCsv((truth / cam / "overlaps.csv").string());
  ASSERT_EQ(rows.size(), 30u);  // 30 frames x 1 pair
  for (const auto& r : rows) {
    const int frame = std::stoi(r.at("frame"));
    ASSERT_EQ(r.at("subject_a"), "0");
    ASSERT_EQ(r.at("subject_b"), "1");
    const cv::Mat a =
        cv::imread((truth / cam / "alpha_s0" / Png(frame)).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat b =
        cv::imread((truth / cam / "alpha_s1" / Png(frame)).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    cv::Mat a_near;
    cv::dilate(a > 0, a_near, cv::Mat::ones(3, 3, CV_8U));
    const int shared = cv::countNonZero(a_near & (b > 0));
    EXPECT_EQ(std::stoi(r.at("shared_px")), shared) << "frame " << frame;
    EXPECT_EQ(r.at("touching"), shared > 0 ? "1" : "0") << "frame " << frame;
  }
  // One subject: no overlaps.csv.
  SynthOptions one = Small(dir / "one", 11);
  one.seconds = 0.5;
  one.cameras = 1;
  RenderStudioSession(one);
  EXPECT_FALSE(fs::exists(fs::path(one.out_dir) / "truth" / cam / "overlaps.csv"));
}

}  // namespace
}  // namespace ss::synth
