// Calibration sessions: OpenCV finds the chessboard and ChArUco corners in the
// rendered frames where the truth says they are.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>

#include <Eigen/Core>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/replay/replay_source.h"
#include "synth/studio_session.h"
#include "tests/support/test_support.h"
#include "tests/synth/synth_csv.h"

namespace ss::synth {
namespace {

namespace fs = std::filesystem;
using ss::testing::Num;

struct Corner {
  Eigen::Vector2d px;
  bool in_view = false;
};

// corners[frame][board] -> inner corners in truth order.
std::map<int, std::map<int, std::vector<Corner>>> ReadCorners(const fs::path& csv) {
  std::map<int, std::map<int, std::vector<Corner>>> out;
  for (const auto& row : ss::testing::ReadCsv(csv.string())) {
    Corner c;
    c.px = {Num(row, "x"), Num(row, "y")};
    c.in_view = row.at("in_view") == "1";
    out[std::stoi(row.at("frame"))][std::stoi(row.at("board"))].push_back(c);
  }
  return out;
}

// A calibration session of seed 5 to render in `dir`/s.
SynthOptions CalibrationOptions(const ss::testing::ScratchDir& dir, int cameras, double seconds,
                                double fps, int width, int height) {
  SynthOptions o;
  o.out_dir = dir / "s";
  o.kind = SynthKind::kCalibration;
  o.seconds = seconds;
  o.fps = fps;
  o.width = width;
  o.height = height;
  o.cameras = cameras;
  o.seed = 5;
  return o;
}

TEST(CalibrationSession, BoardCornersAreWhereOpenCvFindsThem) {
  ss::testing::ScratchDir dir;
  SynthOptions o = CalibrationOptions(dir, 1, 6.0, 3.0, 640, 480);
  o.noise = 0.5;
  RenderStudioSession(o);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  ASSERT_TRUE(fs::exists(truth / "boards.json"));
  const auto poses = ss::testing::ReadCsv((truth / "board_poses.csv").string());
  ASSERT_GE(poses.size(), 18u);
  EXPECT_EQ(poses.back().at("placement"), "floor");
  auto corners = ReadCorners(truth / "cam0" / "corners.csv");

  auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  auto charuco = cv::aruco::CharucoBoard::create(7, 5, 0.04f, 0.03f, dict);
  ReplaySource source(o.out_dir);
  int chess_found = 0, charuco_found = 0, charuco_corners = 0, charuco_outliers = 0;
  double worst = 0;
  while (auto f = source.Next()) {
    const int frame = static_cast<int>(f->sequence);
    cv::Mat gray;
    cv::cvtColor(ToBgr(*f), gray, cv::COLOR_BGR2GRAY);
    for (const auto& [board, truth_corners] : corners[frame]) {
      bool all_in = true;
      for (const auto& c : truth_corners) all_in = all_in && c.in_view;
      if (board == 0 && all_in) {
        std::vector<cv::Point2f> found;
        if (!cv::findChessboardCorners(gray, cv::Size(9, 6), found)) continue;
        cv::cornerSubPix(
            gray, found, cv::Size(4, 4), cv::Size(-1, -1),
            cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.01));
        ++chess_found;
        for (const auto& p : found) {  // OpenCV may start from either end: match by nearest
          double best = 1e9;
          for (const auto& c : truth_corners)
            best = std::min(best, (c.px - Eigen::Vector2d(p.x, p.y)).norm());
          worst = std::max(worst, best);
          EXPECT_LT(best, 0.5) << "frame " << frame;
        }
      } else if (board == 1) {
        std::vector<std::vector<cv::Point2f>> markers;
        std::vector<int> ids;
        cv::aruco::detectMarkers(gray, dict, markers, ids);
        if (ids.size() < 4) continue;
        std::vector<cv::Point2f> found;
        std::vector<int> found_ids;
        cv::aruco::interpolateCornersCharuco(markers, ids, gray, charuco, found, found_ids);
        if (found_ids.size() < 6) continue;
        // The same saddle-point refinement as for the chessboard.
        cv::cornerSubPix(
            gray, found, cv::Size(3, 3), cv::Size(-1, -1),
            cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.01));
        ++charuco_found;
        double sum = 0;
        for (size_t i = 0; i < found.size(); ++i) {
          const Corner& c = truth_corners.at(static_cast<size_t>(found_ids[i]));
          const double err = (c.px - Eigen::Vector2d(found[i].x, found[i].y)).norm();
          worst = std::max(worst, err);
          sum += err;
          ++charuco_corners;
          charuco_outliers += err > 1.0;  // a marker corner can capture the 3x3 refinement
        }
        EXPECT_LT(sum / static_cast<double>(found.size()), 0.5) << "frame " << frame;
      }
    }
  }
  EXPECT_GE(chess_found, 3);
  EXPECT_GE(charuco_found, 3);
  EXPECT_LE(charuco_outliers, charuco_corners / 20);
  RecordProperty("worst_corner_error_px", std::to_string(worst));
}

// With two cameras, the chessboard is also held where both see it whole (the joint solve's
// shared instants, calib/joint.h): poses held still for 0.9 s, in distinct places, every corner
// in view of both cameras in every frame of the segment; each camera's own poses go round the
// image's nine regions.
TEST(CalibrationSession, TwoCamerasShareASegmentOfTheBoardInViewOfBoth) {
  ss::testing::ScratchDir dir;
  SynthOptions o = CalibrationOptions(dir, 2, 30.0, 8.0, 320, 240);
  o.write_mattes = false;
  RenderStudioSession(o);
  const fs::path truth = fs::path(o.out_dir) / "truth";
  std::map<int, std::string> placement;
  std::map<int, std::vector<double>> rig_pose;  // frame -> rt
  for (const auto& row : ss::testing::ReadCsv((truth / "board_poses.csv").string())) {
    const int frame = std::stoi(row.at("frame"));
    placement[frame] = row.at("placement");
    if (row.at("board") != "0") continue;
    if (row.at("placement") == "rig") {
      for (const char* k : {"rx", "ry", "rz", "tx", "ty", "tz"})
        rig_pose[frame].push_back(Num(row, k));
    }
  }
  // 30 s: 3 s on the floor at the end, before it 27 s in 6 parts: 4 camera segments of 4.5 s,
  // then the shared one of 9 s (frames 144..215 at 8 fps).
  ASSERT_EQ(rig_pose.size(), 72u);
  EXPECT_EQ(placement[rig_pose.begin()->first - 1], "camera:cam1");
  EXPECT_EQ(placement[rig_pose.rbegin()->first + 1], "floor");
  for (const char* cam : {"cam0", "cam1"}) {
    auto corners = ReadCorners(truth / cam / "corners.csv");
    for (const auto& [frame, rt] : rig_pose) {
      const auto& board = corners[frame][0];
      ASSERT_EQ(board.size(), 54u) << cam << " frame " << frame;
      for (const auto& c : board) EXPECT_TRUE(c.in_view) << cam << " frame " << frame;
    }
  }
  // Still spans: runs of frames with the same pose, at least 0.75 s (6 frames at 8 fps) each,
  // in 6 distinct places (9 s at 1.6 s a pose, 40 % of it moving: 0.9 s held).
  int places = 0, run = 1;
  std::vector<double> last;
  for (const auto& [frame, rt] : rig_pose) {
    const bool same =
        !last.empty() &&
        std::abs(rt[3] - last[3]) + std::abs(rt[4] - last[4]) + std::abs(rt[5] - last[5]) < 1e-9;
    run = same ? run + 1 : 1;
    if (run == 6) ++places;
    last = rt;
  }
  EXPECT_GE(places, 6);
}

}  // namespace
}  // namespace ss::synth
