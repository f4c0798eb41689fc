#include "animate/skeleton/skeleton_match.h"

#include <algorithm>

#include "animate/skeleton/cost_rows.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss {

bool SkeletonMatchOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(descriptor.IsValid(&part), "descriptor.", part);
  check.Nested(match.IsValid(&part), "match.", part);
  check.Nested(refine.IsValid(&part), "refine.", part);
  check.Within(min_source_coverage, Between(0, 1), "min_source_coverage", "a fraction 0..1");
  return check.ok();
}

SkeletonMatchResult MatchSkeletons(const SkeletonSequence& target,
                                   const std::vector<const SkeletonSequence*>& clips,
                                   const SkeletonMatchOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("skeleton match options", why);
  if (clips.empty()) throw InputError("sources", "no source clip");
  SkeletonMatchResult result;
  int flat = 0;
  for (const auto* clip : clips) {
    if (clip->frames.empty())
      throw InputError(clip->clip.empty() ? "sources" : clip->clip, "a clip without frames");
    result.clip_starts.push_back(flat);
    flat += clip->size();
  }
  const PoseDescriptors sources = ComputeDescriptors(clips, options.descriptor);
  const PoseDescriptors targets = ComputeDescriptors(target, options.descriptor);
  if (targets.layout.dim != sources.layout.dim) {
    throw InputError(target.clip.empty() ? "target" : target.clip,
                     "the target's skeleton differs from the sources'");
  }
  const DescriptorCostRows costs(targets, sources, options.min_source_coverage);
  if (costs.usable_sources() == 0) {
    throw InputError("sources", "no source frame has enough joints to be matched");
  }
  result.with_penalties = SolveMatch(costs, result.clip_starts, options.match);
  if (options.compare_without_penalties) {
    result.without_penalties =
        SolveMatch(costs, result.clip_starts, options.match.WithoutPenalties());
  }
  result.source_frames = result.with_penalties.source_frames;
  if (options.refine_enabled) {
    result.refined = RefineMatch(costs, targets, sources, result.clip_starts, options.match,
                                 options.refine, &result.with_penalties.source_frames);
    result.source_frames = result.refined->source_frames;
  }
  for (int s : result.source_frames) {
    int c =
        static_cast<int>(std::upper_bound(result.clip_starts.begin(), result.clip_starts.end(), s) -
                         result.clip_starts.begin()) -
        1;
    const int index = s - result.clip_starts[c];
    result.chosen.push_back({c, index, clips[c]->frames[index].frame});
  }
  Log("animate.match")
      ->info("matched {} target frames to {} source frames in {} clips: {}", target.size(), flat,
             clips.size(), result.with_penalties.Summary());
  return result;
}

}  // namespace ss
