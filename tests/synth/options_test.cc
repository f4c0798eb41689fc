// The synthetic studio's options (issue 17): defaults valid, values out of range refused by
// IsValid naming the field, and the entry points (the directors, the session) refusing them.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "synth/directors.h"
#include "synth/studio_session.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"
#include "tests/support/test_support.h"

namespace ss::synth {
namespace {

using ss::testing::InputErrorOf;
using ss::testing::Names;
using ss::testing::Problems;

// The session needs a folder to render into; with one, the defaults are valid.
SynthOptions WithFolder() {
  SynthOptions o;
  o.out_dir = "/nonexistent/session";
  return o;
}

TEST(SynthOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(DirectorOptions{}), "");
  EXPECT_EQ(Problems(WithFolder()), "");
  EXPECT_EQ(Problems(SynthOptions{}), "out_dir: a session folder is needed");
}

TEST(SynthOptions, EachDirectorProblemNamesItsField) {
  DirectorOptions d;
  d.subjects = -1;
  d.fps = 0;
  d.figure_variant = 2;
  EXPECT_EQ(Problems(d),
            "subjects: expected 0..64 (the renderer draws at most 64), got -1\n"
            "fps: expected a positive number of frames per second, got 0\n"
            "figure_variant: expected 0 (the reference figure) or 1 (the other build), got 2");
  d = {};
  d.subjects = 64;
  d.fps = 1000;
  EXPECT_EQ(Problems(d), "");
}

// Every problem of a session at once; the director's fields are the session's own (it extends
// the director's options), named once each: by the director's range where that refuses the
// value, else by the session's narrower one.
TEST(SynthOptions, EachSessionProblemNamesItsField) {
  SynthOptions o = WithFolder();
  o.subjects = 9;
  o.fps = 0.5;
  o.seconds = 0;
  o.width = 12;
  o.height = 5000;
  o.cameras = 0;
  o.noise = -1;
  o.threads = 65;
  o.kind = SynthKind::kAnimal;
  o.studio = StudioKind::kStage;
  o.codec = "vp9";
  o.empty_lead_in_s = -1;
  EXPECT_EQ(Problems(o),
            "subjects: a session renders at most 8 subjects, got 9\n"
            "fps: a session runs at 1..240 frames per second, got 0.5\n"
            "seconds: expected 0 < seconds <= 3600, got 0\n"
            "width: expected 64..4096 pixels, got 12\n"
            "height: expected 48..4096 pixels, got 5000\n"
            "cameras: expected 1..8, got 0\n"
            "noise: expected 0..10, got -1\n"
            "threads: expected 1..64, got 65\n"
            "studio: animals live in the enclosure\n"
            "codec: unknown codec 'vp9' (expected ffv1, ffvhuff, mjpeg or h264)\n"
            "empty_lead_in_s: expected seconds >= 0, got -1");
  o = WithFolder();
  o.subjects = 100;  // out of the director's range: its message alone
  o.figure_variant = -1;
  EXPECT_EQ(Problems(o),
            "subjects: expected 0..64 (the renderer draws at most 64), got 100\n"
            "figure_variant: expected 0 (the reference figure) or 1 (the other build), got -1");
  o = WithFolder();
  o.pixel_format = PixelFormat::kBayerRG8;
  o.width = 641;
  EXPECT_EQ(Problems(o), "width: bayer_rg8 needs an even width, got 641");
  o.pixel_format = PixelFormat::kNV12;
  o.width = 640;
  EXPECT_TRUE(Names(Problems(o), "pixel_format"));
  o = WithFolder();
  o.kind = SynthKind::kFigure;
  o.studio = StudioKind::kEnclosure;
  EXPECT_EQ(Problems(o), "studio: figures perform on the stage");
  o = WithFolder();
  o.kind = SynthKind::kFigure;
  o.view = CameraView::kOverhead;
  EXPECT_EQ(Problems(o), "view: cameras look down from overhead in the enclosure only");
}

// Overhead cameras look down from 82-90 degrees above the floor, through the oblique view's
// lenses, and see the whole floor.
TEST(SynthOptions, OverheadCamerasLookStraightDownThroughTheSameLenses) {
  const Studio studio = MakeStudio(StudioKind::kEnclosure, 6);
  const auto oblique = MakeCameras(studio, 3, 320, 240, 6);
  const auto overhead = MakeCameras(studio, 3, 320, 240, 6, CameraView::kOverhead);
  ASSERT_EQ(overhead.size(), 3u);
  for (size_t k = 0; k < overhead.size(); ++k) {
    EXPECT_EQ(overhead[k].intrinsics, oblique[k].intrinsics);
    // The optical axis (camera z) in the ground frame, against straight down.
    const Eigen::Vector3d axis = overhead[k].cam_from_ground.rotation.row(2).transpose();
    const double below_horizon = std::asin(-axis.z()) * 180 / M_PI;
    EXPECT_GE(below_horizon, 80.0) << overhead[k].name;
    const double oblique_below =
        std::asin(-oblique[k].cam_from_ground.rotation.row(2).z()) * 180 / M_PI;
    EXPECT_LE(oblique_below, 65.0) << oblique[k].name;
    for (const double sx : {-1.0, 1.0}) {
      for (const double sy : {-1.0, 1.0}) {
        const Eigen::Vector2d px =
            overhead[k].ProjectGround({sx * studio.half_x, sy * studio.half_y, 0.0});
        EXPECT_TRUE(px.x() > 0 && px.y() > 0 && px.x() < 319 && px.y() < 239) << px.transpose();
      }
    }
  }
}

TEST(SynthOptions, EntryPointsRefuseBadOptions) {
  const Studio studio = MakeStudio(StudioKind::kStage, 4);
  const auto cameras = MakeCameras(studio, 1, 160, 120, 4);
  DirectorOptions d;
  d.figure_variant = 3;
  const std::string figure = InputErrorOf([&] { MakeFigureDirector(studio, cameras, d); });
  EXPECT_EQ(figure.rfind("director options: figure_variant: ", 0), 0u) << figure;
  d = {};
  d.fps = -1;
  const std::string boards = InputErrorOf([&] { MakeCalibrationDirector(studio, cameras, d, 1); });
  EXPECT_EQ(boards.rfind("director options: fps: ", 0), 0u) << boards;

  // The session refuses before it makes its folder.
  ss::testing::ScratchDir dir;
  SynthOptions o;
  o.out_dir = dir / "s";
  o.threads = 0;
  o.cameras = 9;
  const std::string what = InputErrorOf([&] { RenderStudioSession(o); });
  EXPECT_EQ(what,
            "synth options: cameras: expected 1..8, got 9\n"
            "threads: expected 1..64, got 0");
  EXPECT_FALSE(std::filesystem::exists(o.out_dir));
}

}  // namespace
}  // namespace ss::synth
