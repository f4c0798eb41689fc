#include "calib/mrcal_corners.h"

#include <gtest/gtest.h>

#include <sstream>

namespace ss::calib {
namespace {

TEST(MrcalCornersVnl, OneFullGridPerAcceptedViewWithMissingCornersMarked) {
  const BoardSpec board = ParseBoardSpec("charuco:4x3:0.04:0.03");  // 3 x 2 inner corners
  CameraViews cam;
  cam.name = "cam1";
  cam.width = 640;
  cam.height = 480;
  BoardView partial;
  partial.accepted = true;
  partial.ids = {0, 2, 5};
  partial.pixels = {{10.5, 20.25}, {30, 40}, {50, 60.125}};
  BoardView rejected;
  rejected.rejection = "blurred";
  cam.views = {partial, rejected};
  cam.frames = {7, 8};
  const std::string vnl = MrcalCornersVnl(board, {cam});
  std::istringstream in(vnl);
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 1u + 6u) << vnl;  // legend, then 3 x 2 rows of the one accepted view
  EXPECT_EQ(lines[0], "# filename x y level");
  EXPECT_EQ(lines[1], "cam1-frame000007.png 10.5 20.25 0");
  EXPECT_EQ(lines[2], "cam1-frame000007.png - - -");
  EXPECT_EQ(lines[3], "cam1-frame000007.png 30 40 0");
  EXPECT_EQ(lines[4], "cam1-frame000007.png - - -");
  EXPECT_EQ(lines[6], "cam1-frame000007.png 50 60.125 0");
  EXPECT_EQ(MrcalViewName("cam1", 8), "cam1-frame000008.png");

  const std::string cmd =
      MrcalCalibrateCommand(board, {cam}, "/d/corners.vnl", "/d/mrcal", "LENSMODEL_OPENCV8", 500);
  for (const char* part :
       {"--object-width-n 3", "--object-height-n 2", "--object-spacing 0.04",
        "--imagersize 640 480", "'cam1-frame*.png'", "--corners-cache '/d/corners.vnl'"}) {
    EXPECT_NE(cmd.find(part), std::string::npos) << part << " in " << cmd;
  }
}

}  // namespace
}  // namespace ss::calib
