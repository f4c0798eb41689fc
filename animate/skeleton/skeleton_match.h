#pragma once
// The whole articulated-sprite match (seed 003 §2.2-2.3) in one call: descriptors of the
// target and of the source clips, the DP with and without penalties (Figure 2), and the
// refinement (Figure 3).
#include <cstdint>
#include <optional>
#include <vector>

#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/match_dp.h"
#include "animate/skeleton/refine.h"
#include "animate/skeleton/skeleton.h"

namespace ss {

struct SkeletonMatchOptions {
  DescriptorOptions descriptor;
  MatchOptions match;  // transitions index the source frames flat, clip after clip
  RefineOptions refine;
  bool refine_enabled = true;
  bool compare_without_penalties = true;  // also solve without the penalties (Figure 2a)
  // source frames with less of the pose terms' weight are never chosen
  float min_source_coverage = 0.5f;
  // False with "FIELD: reason" lines in `why` for values out of range; the parts' fields come out
  // under "descriptor.", "match.", "refine.".
  bool IsValid(std::string* why) const;
};

// A source frame as the caller knows it.
struct ClipFrame {
  int clip = 0;       // index into the source clips
  int index = 0;      // index into that clip's frames
  int64_t frame = 0;  // its frame number (SkeletonFrame::frame)
};

struct SkeletonMatchResult {
  std::vector<int> clip_starts;  // flat index of each clip's first frame
  MatchResult with_penalties;    // pass one
  std::optional<MatchResult> without_penalties;
  std::optional<RefineResult> refined;
  std::vector<int> source_frames;  // the final choice (refined when enabled), flat
  std::vector<ClipFrame> chosen;   // the same as clip frames
};

// Throws InputError when the skeletons differ or a sequence is empty.
SkeletonMatchResult MatchSkeletons(const SkeletonSequence& target,
                                   const std::vector<const SkeletonSequence*>& clips,
                                   const SkeletonMatchOptions& options = {});

}  // namespace ss
