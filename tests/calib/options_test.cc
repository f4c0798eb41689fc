// The calibration stages' options (issue 17): defaults valid, values out of range refused by
// IsValid naming the field, and the entry points refusing them with InputError.
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/detect.h"
#include "calib/enclosure.h"
#include "calib/inputs.h"
#include "calib/report.h"
#include "calib/solve.h"
#include "calib/wizard.h"
#include "calib/wizard_run.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"

namespace ss::calib {
namespace {

using ss::testing::InputErrorOf;
using ss::testing::Names;
using ss::testing::Problems;

TEST(CalibOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(DetectOptions{}), "");
  EXPECT_EQ(Problems(SampleOptions{}), "");
  EXPECT_EQ(Problems(GreenFloorOptions{}), "");
  EXPECT_EQ(Problems(VerdictOptions{}), "");
  EXPECT_EQ(Problems(WizardOptions{}), "");
  EXPECT_EQ(Problems(WizardRunOptions{}), "");
  EXPECT_EQ(Problems(SolveOptions{}), "");
}

TEST(CalibOptions, EachProblemNamesItsField) {
  DetectOptions d;
  d.min_corners = 3;
  d.min_area_fraction = 1.5;
  EXPECT_EQ(Problems(d),
            "min_corners: expected at least 4 (a board pose needs 4 corners), got 3\n"
            "min_area_fraction: expected a fraction 0..1, got 1.5");
  SampleOptions s;
  s.max_views = 0;
  EXPECT_EQ(Problems(s), "max_views: expected at least 1 view, got 0");
  GreenFloorOptions g;
  g.min_green_excess = 300;
  EXPECT_EQ(Problems(g), "min_green_excess: expected 8-bit levels 0..255, got 300");
  VerdictOptions v;
  v.grid_y = 0;
  EXPECT_EQ(Problems(v), "grid_y: expected at least 1 cell, got 0");
  WizardRunOptions r;
  r.silent_s = 0;
  EXPECT_EQ(Problems(r), "silent_s: expected a positive number of seconds, got 0");
  SolveOptions solve;
  solve.lensmodel = "LENSMODEL_NOPE";
  EXPECT_EQ(Problems(solve),
            "lensmodel: unknown mrcal lens model \"LENSMODEL_NOPE\" (e.g. LENSMODEL_OPENCV8)");
  solve.lensmodel = "";
  EXPECT_TRUE(Names(Problems(solve), "lensmodel"));
  // Any model mrcal knows with an fx fy cx cy core will do.
  solve.lensmodel = "LENSMODEL_PINHOLE";
  EXPECT_EQ(Problems(solve), "");
}

// The wizard's options hold the detector's, the verdict's and the solve's: their fields come out
// under detect., verdict. and solve.
TEST(CalibOptions, TheWizardNamesItsNestedBlocks) {
  WizardOptions w;
  w.detect.max_edge_width_px = -1;
  w.verdict.min_coverage = 2;
  w.solve.lensmodel = "LENSMODEL_NOPE";
  w.still_frames = 0;
  EXPECT_EQ(
      Problems(w),
      "detect.max_edge_width_px: expected a positive number of pixels, got -1\n"
      "verdict.min_coverage: expected a fraction 0..1, got 2\n"
      "solve.lensmodel: unknown mrcal lens model \"LENSMODEL_NOPE\" (e.g. LENSMODEL_OPENCV8)\n"
      "still_frames: expected at least 1 frame, got 0");
  const std::string what = InputErrorOf([&] { CalibrationWizard wizard("cam0", 640, 480, w); });
  EXPECT_EQ(what.rfind("calibration wizard options: detect.max_edge_width_px: ", 0), 0u) << what;
}

TEST(CalibOptions, EntryPointsRefuseBadOptions) {
  DetectOptions d;
  d.min_corners = 0;
  const cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(128));
  EXPECT_EQ(InputErrorOf([&] {
              DetectBoard(BoardSpec{}, grey, d);
            }).rfind("board detection options: min_corners: ", 0),
            0u);
  // With good options an image without a board is no error: the view comes back rejected.
  EXPECT_FALSE(DetectBoard(BoardSpec{}, grey).accepted);
  GreenFloorOptions g;
  g.simplify_m = -0.1;
  const cv::Mat green(48, 64, CV_8UC3, cv::Scalar(0, 200, 0));
  EXPECT_EQ(InputErrorOf([&] {
              FindGreenFloor(CameraModel{}, green, g);
            }).rfind("green floor options: simplify_m: ", 0),
            0u);
  // The solve refuses a lens model it does not know before it looks at the views.
  SolveOptions solve;
  solve.lensmodel = "LENSMODEL_NOPE";
  EXPECT_EQ(InputErrorOf([&] {
              SolveBoards(BoardSpec{}, {{"cam0", 640, 480}}, {}, solve);
            }).rfind("calibration solve options: lensmodel: unknown mrcal lens model", 0),
            0u);
}

}  // namespace
}  // namespace ss::calib
