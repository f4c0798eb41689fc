#pragma once
// The visible jump of a transition (docs/animation.md, "Judging an animation"): how much the
// picture changes where a sequence shows sprite `to` instead of the natural successor n of
// sprite `from` (the next frame of from's clip, same mirrored flag), against how much it
// changes from one frame of a clip to the next. One implementation for the judge, the
// classifier's bench and `transitions --json`.
//
//   Difference_px(a, b): the two billboards at full resolution laid on each other with their
//     contact points on one pixel (the offset rounded to whole pixels), summed over the union
//     of their extents (transparent outside each):
//       sum (|dR'| + |dG'| + |dB'| + |dA|) / (4 * 255),   R' = R * A / 255 (premultiplied)
//     in px: the area of fully changed pixels it equals. 0 for the same pixels.
//   MedianStep_px: the median Difference_px(i, next(i)) over the bank's clips (originals).
//   Jump(from -> to) = Difference_px(to, n) / MedianStep_px: 1.0 is no more visible than an
//     ordinary frame step, 0 the natural successor itself.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/bank.h"
#include "pipeline/transitions/billboard.h"

namespace ss {

// Contact-aligned RGBA difference of two billboards of one scale (straight colour: BGRA or
// RGBA alike), in px as above. Throws InputError("billboard", ...) for a malformed one.
double ContactAlignedDifference_px(const RgbaBillboard& a, const RgbaBillboard& b);

struct VisibleJumpOptions {
  // The median step is taken over at most this many consecutive pairs, spread evenly over
  // the bank's clips (every pair when it has fewer).
  int max_pairs = 2000;
  // A bank whose frames never change (median 0) is measured against this step instead.
  double min_step_px = 1.0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// One sprite of the clip structure a meter reads.
struct JumpFrame {
  int64_t id = 0;
  int64_t clip = 0;
  bool mirrored = false;
  std::optional<int64_t> next;  // the next frame's id (same mirrored flag); none at a clip's end
};

// A sprite's billboard at full resolution (straight colour), by id; InputError if unknown.
using BillboardLoader = std::function<RgbaBillboard(int64_t id)>;

// How a transition from -> to leaves its clip: to another frame of the same clip, to another
// clip, or between an original and a mirrored copy.
enum class TransitionKind { kWithinClip, kJoiningClips, kOriginalMirror };

// The visible jumps of one bank, or of any set of sprites with clips. Reads the clip structure
// (no pixels) on construction and billboards on demand (a few hundred kept). One thread.
class VisibleJumpMeter {
 public:
  // Borrows `bank` for the meter's lifetime. InputError for invalid options or a bank that
  // cannot be read.
  explicit VisibleJumpMeter(const Bank& bank, VisibleJumpOptions options = {});
  // Sprites held elsewhere (the bench's synthetic sets). `cache_key` names the set for
  // MedianStep_px's process-wide cache ("": not cached). InputError for invalid options.
  VisibleJumpMeter(const std::vector<JumpFrame>& frames, BillboardLoader load,
                   const std::string& cache_key, VisibleJumpOptions options = {});

  // The next frame of `id`'s clip with the same mirrored flag; nullopt at the clip's end or
  // for a sprite outside the bank's complete clips.
  std::optional<int64_t> NaturalSuccessor(int64_t id) const;
  // The kind of the transition from -> to; nullopt when either is not one of the sprites.
  std::optional<TransitionKind> KindOf(int64_t from, int64_t to) const;
  // Contact-aligned difference of two of the bank's sprites, px. InputError for an unknown id.
  double Difference_px(int64_t a, int64_t b);
  // The median consecutive-frame difference of the bank's clips, px (>= min_step_px).
  // Computed once per bank (path and sprite count) and options in this process.
  double MedianStep_px();
  // Jump of showing `shown` where `natural` was due: Difference_px / MedianStep_px.
  double JumpBetween(int64_t shown, int64_t natural);
  // Jump of the transition from -> to; nullopt when `from` ends its clip (nothing replaced).
  std::optional<double> Jump(int64_t from, int64_t to);

 private:
  const RgbaBillboard& Billboard(int64_t id);

  void Index(const std::vector<JumpFrame>& frames);

  BillboardLoader load_;
  VisibleJumpOptions options_;
  std::unordered_map<int64_t, int64_t> next_;  // sprite id -> its natural successor's id
  std::unordered_map<int64_t, std::pair<int64_t, bool>> clip_of_;  // id -> (clip, mirrored)
  std::vector<int64_t> originals_with_next_;                       // in (clip, frame) order
  std::string cache_key_;                 // "": MedianStep_px is not cached process-wide
  std::optional<double> median_step_px_;  // once computed or read from the cache
  std::map<int64_t, RgbaBillboard> billboards_;
};

}  // namespace ss
