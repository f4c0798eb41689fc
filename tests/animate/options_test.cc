// The animation stages' options (issue 17): defaults valid, values out of range refused by
// IsValid naming the field (nested blocks under their prefix), and entry points refusing them.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "animate/animate_run.h"
#include "animate/beam_search.h"
#include "animate/problem.h"
#include "animate/reach_sets.h"
#include "animate/renderer.h"
#include "animate/replacement.h"
#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/importers.h"
#include "animate/skeleton/lk_tracker.h"
#include "animate/skeleton/match_dp.h"
#include "animate/skeleton/match_plot.h"
#include "animate/skeleton/refine.h"
#include "animate/skeleton/skeleton_match.h"
#include "animate/skeleton/synthetic_poses.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"

namespace ss {
namespace {

using testing::InputErrorOf;
using testing::Names;
using testing::Problems;

TEST(AnimateOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(ReachOptions{}), "");
  EXPECT_EQ(Problems(RenderOptions{}), "");
  EXPECT_EQ(Problems(MovementOptions{}), "");
  EXPECT_EQ(Problems(RefineOptions{}), "");
  EXPECT_EQ(Problems(SkeletonMatchOptions{}), "");
  EXPECT_EQ(Problems(AnimateRunOptions{}), "");
  EXPECT_EQ(Problems(ReplacementOptions{}), "");
  EXPECT_EQ(Problems(BeamOptions{}), "");
  EXPECT_EQ(Problems(SkeletonImportOptions{}), "");
  EXPECT_EQ(Problems(DescriptorOptions{}), "");
  EXPECT_EQ(Problems(MatchOptions{}), "");
  EXPECT_EQ(Problems(LkOptions{}), "");
  EXPECT_EQ(Problems(GestureScriptOptions{}), "");
  EXPECT_EQ(Problems(PlotOptions{}), "");
}

TEST(AnimateOptions, EachProblemNamesItsField) {
  ReachOptions reach;
  reach.set_size = 0;
  reach.num_threads = 0;
  EXPECT_EQ(Problems(reach),
            "set_size: expected 1..65535, got 0\nnum_threads: expected 1..256, got 0");
  RenderOptions render;
  render.shadow_opacity = 1.5;
  EXPECT_EQ(Problems(render), "shadow_opacity: expected a fraction 0..1, got 1.5");
  AnimateRunOptions run;
  run.max_turns = -1;
  EXPECT_EQ(Problems(run), "max_turns: expected at least 0 (0: the time budget alone), got -1");
  run.max_turns = 0;
  run.optimizer.replacement.time_budget_seconds = 0;
  EXPECT_EQ(Problems(run),
            "optimizer.replacement.time_budget_seconds: must be a positive number of seconds, "
            "got 0");
  // Issue 39: a day at most (1e300 ran until killed), and at most 1000 snapshots.
  run.optimizer.replacement.time_budget_seconds = 1e300;
  EXPECT_EQ(Problems(run),
            "optimizer.replacement.time_budget_seconds: must be at most 86400 seconds (a day), "
            "got 1e+300");
  run.optimizer.replacement.time_budget_seconds = 60;
  run.optimizer.snapshot_every_s = 0.01;
  EXPECT_EQ(Problems(run),
            "optimizer.snapshot_every_s: must be 0 or >= 0.06 s (the time budget / 1000), got "
            "0.01");
  run.optimizer.snapshot_every_s = 0;
  // The replacement optimizer's reach block comes out under "reach.".
  ReplacementOptions replace;
  replace.reach.step_cost = -1;
  EXPECT_EQ(Problems(replace), "reach.step_cost: expected a finite number >= 0, got -1");
}

// The replacement optimizer reports every problem, not the first; the beam block counts only when
// the replacement starts with a beam search, and comes out under "beam.".
TEST(AnimateOptions, ReplacementNamesEveryField) {
  ReplacementOptions o;
  o.reach.set_size = 0;
  o.step_cost_fraction = -0.1;
  o.slow_frame_cost = -1;
  o.reference_speed_m = -1;
  o.time_budget_seconds = 0;
  o.max_tries = 0;
  o.changes_per_turn = 0;
  o.max_turns = -1;
  o.sequential_fraction = 1.5;
  o.middle_fraction = -0.5;
  o.begin_fraction = -0.5;
  o.max_span = -1;
  o.collision_pick_fraction = 2;
  o.max_candidates = -1;
  o.progress_seconds = -1;
  EXPECT_EQ(Problems(o),
            "reach.set_size: expected 1..65535, got 0\n"
            "step_cost_fraction: expected a finite number >= 0, got -0.1\n"
            "slow_frame_cost: expected at least 0, got -1\n"
            "reference_speed_m: expected metres >= 0, got -1\n"
            "time_budget_seconds: expected a positive number of seconds, got 0\n"
            "max_tries: expected at least 1, got 0\n"
            "changes_per_turn: expected at least 1, got 0\n"
            "max_turns: expected at least 0 (0: no limit), got -1\n"
            "sequential_fraction: expected a fraction 0..1, got 1.5\n"
            "middle_fraction: expected at least 0, got -0.5\n"
            "begin_fraction: expected at least 0, got -0.5\n"
            "max_span: expected at least 0 (0: the whole sequence), got -1\n"
            "collision_pick_fraction: expected a fraction 0..1, got 2\n"
            "max_candidates: expected at least 0 (0: all of them), got -1\n"
            "progress_seconds: expected seconds >= 0 (0: never), got -1");
  ReplacementOptions split;
  split.middle_fraction = 0.7;
  split.begin_fraction = 0.4;
  EXPECT_EQ(Problems(split),
            "begin_fraction: must leave middle_fraction + begin_fraction <= 1, got 1.1");
  ReplacementOptions beam;
  beam.beam.width = 0;
  EXPECT_EQ(Problems(beam), "");  // a sequential start never reads the beam block
  beam.start = StartMethod::kBeam;
  EXPECT_EQ(Problems(beam), "beam.width: expected at least 1, got 0");
}

TEST(AnimateOptions, BeamNamesEveryField) {
  BeamOptions o;
  o.width = 0;
  o.length = -1;
  o.start_frames = -1;
  o.time_budget_seconds = -1;
  EXPECT_EQ(Problems(o),
            "width: expected at least 1, got 0\n"
            "length: expected at least 0 (0: the sprite's own), got -1\n"
            "start_frames: expected at least 0 (0: every frame), got -1\n"
            "time_budget_seconds: expected seconds >= 0 (0: one pass), got -1");
  o = {};
  o.time_budget_seconds = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(Names(Problems(o), "time_budget_seconds"));
  o.time_budget_seconds = 86401;  // issue 39: a day at most
  EXPECT_EQ(Problems(o), "time_budget_seconds: must be at most 86400 seconds (a day), got 86401");
}

TEST(AnimateOptions, OptimizersRefuseBadOptions) {
  const TransitionGraph graph;
  Problem problem(graph);
  Summary summary;
  BeamOptions beam;
  beam.width = 0;
  beam.length = -2;
  EXPECT_EQ(InputErrorOf([&] { BeamSearch(problem, beam, &summary); }),
            "beam options: width: expected at least 1, got 0\n"
            "length: expected at least 0 (0: the sprite's own), got -2");
  ReplacementOptions replace;
  replace.max_tries = 0;
  replace.time_budget_seconds = -1;
  const std::string what = InputErrorOf([&] { OptimizeSequences(problem, replace, &summary); });
  EXPECT_EQ(what,
            "replacement options: time_budget_seconds: expected a positive number of seconds, got "
            "-1\nmax_tries: expected at least 1, got 0");
  EXPECT_EQ(InputErrorOf([&] { ReplacementSets::Build(problem, replace); }), what);
}

TEST(AnimateOptions, SkeletonMatchNamesItsNestedBlocks) {
  SkeletonMatchOptions o;
  o.refine.averaging_window = 0;
  o.refine.movements.lag_s = 0;
  o.min_source_coverage = 2;
  EXPECT_EQ(Problems(o),
            "refine.movements.lag_s: expected a positive number of seconds, got 0\n"
            "refine.averaging_window: expected at least 1, got 0\n"
            "min_source_coverage: expected a fraction 0..1, got 2");
  SkeletonSequence target;
  const std::string what = InputErrorOf([&] { MatchSkeletons(target, {&target}, o); });
  EXPECT_EQ(what.rfind("skeleton match options: refine.movements.lag_s: ", 0), 0u) << what;
}

TEST(AnimateOptions, ReachSetsRefuseBadOptions) {
  ReachOptions reach;
  reach.set_size = 70000;
  const std::string what =
      InputErrorOf([&] { ReachSets::Build(TransitionGraph{}, ReachDirection::kForward, reach); });
  EXPECT_EQ(what.rfind("reach options: set_size: expected 1..65535, got 70000", 0), 0u) << what;
}

TEST(AnimateOptions, SkeletonImportNamesEveryField) {
  SkeletonImportOptions o;
  o.min_confidence = 1.5f;
  o.person = -1;
  o.category_id = -2;
  EXPECT_EQ(Problems(o),
            "min_confidence: must be within [0, 1] (or unset: the mapping's or the format's), "
            "got 1.5\n"
            "person: expected an index >= 0, got -1\n"
            "category_id: must be a category id >= 0 (or -1: the first with keypoints), got -2");
  o = {};
  o.min_confidence = 0;
  o.category_id = 3;
  EXPECT_EQ(Problems(o), "");
  // Each importer refuses bad options before it opens the file.
  o.person = -1;
  const JointMapping mapping = IdentityMapping(HumanSkeleton());
  for (const auto& import : std::vector<std::function<void()>>{
           [&] { ImportDeepLabCutCsv("/nonexistent.csv", mapping, o); },
           [&] { ImportOpenPoseJson("/nonexistent", mapping, o); },
           [&] { ImportCocoKeypoints("/nonexistent.json", mapping, o); },
           [&] { ImportSynthTruth("/nonexistent", "", mapping, o); }}) {
    EXPECT_EQ(InputErrorOf(import),
              "skeleton import options: person: expected an index >= 0, got -1");
  }
}

TEST(AnimateOptions, GestureScriptNamesEveryField) {
  GestureScriptOptions o;
  o.transition_frames = -1;
  o.speed = 0;
  o.noise_px = -1;
  o.scale_px = 0;
  o.x_px = std::numeric_limits<float>::quiet_NaN();
  o.y_px = std::numeric_limits<float>::infinity();
  EXPECT_EQ(Problems(o),
            "transition_frames: expected frames >= 0, got -1\n"
            "speed: expected a positive factor, got 0\n"
            "noise_px: expected pixels >= 0, got -1\n"
            "scale_px: expected a positive number of pixels per body unit, got 0\n"
            "x_px: must be a finite pixel position, got nan\n"
            "y_px: must be a finite pixel position, got inf");
  GestureScriptOptions slow;
  slow.speed = -2;
  EXPECT_EQ(InputErrorOf([&] {
              MakeGestureSequence({{Gesture::kY, 5}}, BodyProportions{}, slow);
            }),
            "gesture script options: speed: expected a positive factor, got -2");
}

TEST(AnimateOptions, PlotNamesEveryField) {
  PlotOptions o;
  o.panel_size = {100, 480};
  o.stutter_window = -1;
  EXPECT_EQ(Problems(o),
            "panel_size: must be at least 120 x 100 pixels, got 100 x 480\n"
            "stutter_window: expected frames >= 0, got -1");
  const std::vector<PlotPanel> panels = {{"a", {0, 1, 1, 0}}};
  EXPECT_EQ(InputErrorOf([&] { PlotMatch(panels, 2, o); }).rfind("plot options: panel_size: ", 0),
            0u);
  EXPECT_EQ(InputErrorOf([&] { PlotMatch({}, 2); }), "plot: needs at least one panel");
  EXPECT_EQ(PlotMatch(panels, 2).cols, 640);
}

// The skeleton matcher's inner blocks report every bad field, not the first only.
TEST(AnimateOptions, SkeletonBlocksNameEveryField) {
  DescriptorOptions d;
  d.ratio_weight = -1;
  d.motion_weight = 1;
  d.motion_window_s = 0;
  d.default_fps = 0;
  std::string why = Problems(d);
  for (const char* field : {"ratio_weight", "motion_window_s", "default_fps"})
    EXPECT_TRUE(Names(why, field)) << field << " in " << why;
  MatchOptions m;
  m.jump_cost = -1;
  m.freeze_levels = 9;
  m.transitions.push_back({});
  m.transitions.back().cost = std::numeric_limits<float>::infinity();
  why = Problems(m);
  for (const char* field : {"jump_cost", "freeze_levels", "transitions[0].cost"})
    EXPECT_TRUE(Names(why, field)) << field << " in " << why;
  LkOptions lk;
  lk.window_px = 3;
  lk.epsilon = 0;
  why = Problems(lk);
  EXPECT_TRUE(Names(why, "window_px")) << why;
  EXPECT_TRUE(Names(why, "epsilon")) << why;
  SkeletonMatchOptions o;
  o.descriptor.default_fps = 0;
  o.match.stutter_window = -1;
  why = Problems(o);
  EXPECT_TRUE(Names(why, "descriptor.default_fps")) << why;
  EXPECT_TRUE(Names(why, "match.stutter_window")) << why;
}

}  // namespace
}  // namespace ss
