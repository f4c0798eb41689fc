#pragma once
// What the judge (judge/judge.h) finds: per constraint its outcome, the stutter, the visible
// jumps; as JSON (`judge --json`, `animate --json`'s "judge") and as a human report.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "animate/bank_graph.h"

namespace ss {

struct LengthOutcome {
  std::string sprite;
  int frames = 0;
  int min_frames = 0;  // the spec's length constraint; 0: none (or no spec)
};

struct PathOutcome {
  std::string sprite, field;  // field: the spec's, "sprites[0].constraints[1].path"
  double length_m = 0;
  double swept_share = 0;  // of the length, reached in order along the path (0..1)
  int finished_step = -1;  // the step it passes the path's end; -1 never
  double max_deviation_m = 0, median_deviation_m = 0;  // from the polyline, until finished
};

struct LocationOutcome {
  std::string sprite, field;
  std::string target;                // "[x, y]" or "follow NAME + [along, left]"
  int first_step = 0, end_step = 0;  // the window [first, end)
  // Distance to the target at the window's first and last steps, and over the window.
  double first_m = 0, last_m = 0, min_m = 0, median_m = 0, max_m = 0;
};

struct CollisionOutcome {
  std::string a, b;
  double min_distance_m = 0;  // the spec's d_min
  double closest_m = 0;       // closest approach
  int closest_step = 0;
  int steps_closer = 0;  // steps closer than d_min
};

struct FrameOutcome {
  std::string sprite, field;
  std::string set;  // "tag NAME" or "N sprites"
  int first_step = 0, end_step = 0;
  int steps_on = 0;     // steps of the window showing a frame of the set
  double on_share = 0;  // steps_on / window steps (1 for an empty window)
};

struct StutterFigures {
  int window_steps = 15;
  int steps = 0;        // all sprites' steps
  int still_steps = 0;  // of them, showing a frame tagged still (not counted)
  int repeats = 0;      // counted steps showing a frame shown in the window before
  double share = 0;     // repeats / (steps - still_steps)
  // Loops past the window: counted steps showing a frame the sprite showed at any step before
  // (a stride played again), and their share; a viewer may see the same motion come round.
  int replayed = 0;
  double replayed_share = 0;
};

// Sprites that move as one: a step is a clone step when another sprite shows the same bank
// frame within `lag_steps` of it (what a viewer sees as copies: 64 flies in lockstep).
struct CloneFigures {
  int lag_steps = 2;
  int steps = 0;           // all sprites' steps
  int cloned_steps = 0;    // of them, with another sprite showing the same frame within the lag
  double share = 0;        // cloned_steps / steps
  int sprites_cloned = 0;  // sprites with at least half of their steps cloned
};

// Floor sprites (filmed from above): how far the direction a sprite is drawn facing lies from the
// way it moves, over the steps it moves faster than min_speed_m_s (motion: the displacement from
// step t - half_window_steps to t + half_window_steps). A viewer sees a large angle as sliding
// sideways; the source footage's own angle is the floor for it.
struct FacingFigures {
  bool measured = false;  // false: no floor sprite shown
  double min_speed_m_s = 0.05;
  int half_window_steps = 3;
  int moving_steps = 0;  // steps of floor sprites moving faster than min_speed_m_s
  std::optional<double> median_deg, p90_deg;
};

struct TransitionJump {
  std::string sprite;
  int step = 0;  // the step showing `to`
  BankFrameRef from, to;
  std::optional<int64_t> natural;  // from's natural successor; none at a clip's end
  std::optional<double> jump;      // difference(to, natural) / the bank's median step
};

struct JumpFigures {
  bool measured = false;  // false: not asked for
  int transitions = 0;    // steps that are not a natural successor
  int unmeasured = 0;     // of them, leaving a clip's last frame (nothing replaced)
  std::optional<double> median, p95, max;
  std::vector<double> median_step_px;  // per bank; 0 for a bank never shown
  std::vector<TransitionJump> each;
};

struct Judgement {
  std::vector<LengthOutcome> lengths;
  std::vector<PathOutcome> paths;
  std::vector<LocationOutcome> locations;
  std::vector<CollisionOutcome> collisions;
  std::vector<FrameOutcome> frames;
  bool constraints_judged = false;  // false: no spec given
  StutterFigures stutter;
  CloneFigures clones;
  FacingFigures facing;
  JumpFigures jumps;
};

nlohmann::json JudgementJson(const Judgement& judgement);
// Several lines, one per outcome, then the stutter and the jumps.
std::string JudgementReport(const Judgement& judgement);

}  // namespace ss
