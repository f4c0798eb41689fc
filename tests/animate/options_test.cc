// The animation stages' options (issue 17): defaults valid, values out of range refused by
// IsValid naming the field (nested blocks under their prefix), and entry points refusing them.
#include <string>

#include <gtest/gtest.h>

#include "animate/animate_run.h"
#include "animate/reach_sets.h"
#include "animate/renderer.h"
#include "animate/replacement.h"
#include "animate/skeleton/refine.h"
#include "animate/skeleton/skeleton_match.h"
#include "tests/support/error_text.h"
#include "tests/support/option_problems.h"

namespace ss {
namespace {

using testing::InputErrorOf;
using testing::Problems;

TEST(AnimateOptions, DefaultsAreValid) {
  EXPECT_EQ(Problems(ReachOptions{}), "");
  EXPECT_EQ(Problems(RenderOptions{}), "");
  EXPECT_EQ(Problems(MovementOptions{}), "");
  EXPECT_EQ(Problems(RefineOptions{}), "");
  EXPECT_EQ(Problems(SkeletonMatchOptions{}), "");
  EXPECT_EQ(Problems(AnimateRunOptions{}), "");
}

TEST(AnimateOptions, EachProblemNamesItsField) {
  ReachOptions reach;
  reach.set_size = 0;
  reach.num_threads = 0;
  EXPECT_EQ(Problems(reach),
            "set_size: must be in 1..65535, got 0\nnum_threads: must be >= 1, got 0");
  RenderOptions render;
  render.shadow_opacity = 1.5;
  EXPECT_EQ(Problems(render), "shadow_opacity: must be within [0, 1], got 1.5");
  AnimateRunOptions run;
  run.max_turns = -1;
  EXPECT_EQ(Problems(run), "max_turns: must be >= 0 (0: the time budget alone), got -1");
  // The replacement optimizer's reach block comes out under "reach.".
  ReplacementOptions replace;
  replace.reach.step_cost = -1;
  EXPECT_EQ(Problems(replace), "reach.step_cost: must be finite and >= 0, got -1");
}

TEST(AnimateOptions, SkeletonMatchNamesItsNestedBlocks) {
  SkeletonMatchOptions o;
  o.refine.averaging_window = 0;
  o.refine.movements.lag_s = 0;
  o.min_source_coverage = 2;
  EXPECT_EQ(Problems(o),
            "refine.movements.lag_s: must be a positive number of seconds, got 0\n"
            "refine.averaging_window: must be >= 1, got 0\n"
            "min_source_coverage: must be within [0, 1], got 2");
  SkeletonSequence target;
  const std::string what = InputErrorOf([&] { MatchSkeletons(target, {&target}, o); });
  EXPECT_EQ(what.rfind("skeleton match options: refine.movements.lag_s: ", 0), 0u) << what;
}

TEST(AnimateOptions, ReachSetsRefuseBadOptions) {
  ReachOptions reach;
  reach.set_size = 70000;
  const std::string what =
      InputErrorOf([&] { ReachSets::Build(TransitionGraph{}, ReachDirection::kForward, reach); });
  EXPECT_EQ(what.rfind("reach options: set_size: must be in 1..65535, got 70000", 0), 0u) << what;
}

}  // namespace
}  // namespace ss
