#pragma once
// The judge of what a viewer sees (issue 33, docs/animation.md "Judging an animation"): for a
// sequences file (what `animate` writes) and its banks, each constraint's outcome (given the
// spec), the stutter, and the visible jump at each transition
// (pipeline/transitions/visible_jump.h). Reads the banks; optimizes nothing.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "animate/scene.h"
#include "animate/sequence_io.h"
#include "judge/judgement.h"
#include "pipeline/transitions/transition_jumps.h"  // Quantile
#include "pipeline/transitions/visible_jump.h"

namespace ss {

struct JudgeOptions {
  // A step stutters when it shows a frame already shown in this many steps before it.
  int stutter_window_steps = 15;
  // Steps showing a frame with one of these bank tags hold still on purpose: not counted.
  std::vector<std::string> still_tags = {"still"};
  // Two sprites showing the same frame this many steps apart or closer are copies.
  int clone_lag_steps = 2;
  // Facing: floor sprites' steps moving faster than this count, their motion taken over
  // +- this many steps.
  double facing_min_speed_m_s = 0.05;
  int facing_half_window_steps = 3;
  bool jumps = true;  // measure the visible jumps (reads billboards); false: skip them
  VisibleJumpOptions jump;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// Judges `file`'s final sequences. Banks are opened from `bank_paths` (the file's, or where they
// are now), index for index. `scene`: the spec the sequences were made for, built over the same
// banks, for the constraints' outcomes; null: lengths, stutter and jumps only. InputError naming
// the file's field for a sprite the banks do not hold or sprites the spec does not name.
Judgement JudgeSequences(const SequenceFile& file, const std::vector<std::string>& bank_paths,
                         const Scene* scene, const JudgeOptions& options = {});

// The stutter of some sprites' frames alone; `is_still` exempts a step showing that frame.
StutterFigures MeasureStutter(const std::vector<SpriteSequence>& sprites, int window_steps,
                              const std::function<bool(const BankFrameRef&)>& is_still);

// The angle between floor sprites' drawn headings and their motion (FacingFigures);
// `heading_of`: a frame's heading on the ground, none for an upright frame.
FacingFigures MeasureFacing(
    const std::vector<SpriteSequence>& sprites, double frame_rate, double min_speed_m_s,
    int half_window_steps,
    const std::function<std::optional<double>(const BankFrameRef&)>& heading_of);

// Which steps of `sprites` show a frame another sprite shows within `lag_steps`.
CloneFigures MeasureClones(const std::vector<SpriteSequence>& sprites, int lag_steps);

}  // namespace ss
