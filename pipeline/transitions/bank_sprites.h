#pragma once
// Sprites of a sprite bank (core/bank.h) as the transition finder takes them. A bank
// clip holds originals and their mirrors; each (clip, mirrored) run of consecutive
// frames is one "segment" for C(i->j) (a frame gap starts a new segment), so the
// mirrored copy of a clip is a clip of its own and never links to the originals.
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/bank.h"
#include "pipeline/transitions/sprite_store.h"

namespace ss {

// Which stored sprites take part in transitions (docs/transitions.md): by default not those
// tagged kMergedTag (two or more subjects in one blob: a sprite that is neither of them).
struct SpriteChoice {
  bool include_merged = false;  // the config's transitions.include_merged, --include-merged
  bool Takes(const SpriteRecord& sprite) const;
  // The bank's meta key recording the choice its transition table was made with.
  static constexpr const char* kMetaKey = "transitions.include_merged";
  std::string MetaValue() const { return include_merged ? "true" : "false"; }
};

// The cheap features of a stored sprite: velocity, mean colour, eccentricity as stored;
// area_m2 = area_px / px_per_m^2. A floor sprite's velocity in its own axes (x ahead, y to its
// left), as its image faces: floor sprites compare whatever way they faced.
CheapFeatures CheapFromRecord(const SpriteRecord& sprite);

// The bank's billboard (BGRA, anchor in pixel-centre coordinates) as an RgbaBillboard;
// `floor` for a floor sprite (SpriteRecord::kind).
RgbaBillboard BillboardFromPixels(const SpritePixels& pixels, double anchor_x_px,
                                  double anchor_y_px, bool floor = false);

// Gives every sprite its segment key in arrival order: a sprite continues the segment of
// its (clip, mirrored) when its frame is the last one's + 1, else starts a new one.
class SegmentKeys {
 public:
  int64_t Key(int64_t clip_id, bool mirrored, int64_t frame);

 private:
  struct Last {
    int64_t key, frame;
  };
  std::map<std::pair<int64_t, bool>, Last> last_;
  int64_t next_key_ = 1;
};

// Sprites loaded from a bank, owning their billboards; inputs() views them.
struct BankSprites {
  std::vector<int64_t> ids;
  std::vector<SpriteInput> inputs;  // billboard pointers into `billboards`
  std::vector<RgbaBillboard> billboards;
  double px_per_m = 0;            // the bank's billboard scale (the same for all)
  int64_t clips = 0;              // complete clips they came from
  std::vector<int64_t> left_out;  // sprites loaded but not taken (SpriteChoice), in load order
};

// Loads the sprites of every complete clip that `choice` takes, ordered by (clip, mirrored,
// frame), their segments from `keys` (a sprite left out breaks its clip's segment there).
// InputError naming the bank when sprites disagree on px_per_m. `progress(done, total)` is
// called every few hundred sprites when given.
BankSprites LoadBankSprites(const Bank& bank, SegmentKeys* keys,
                            const std::function<void(size_t, size_t)>& progress = {},
                            const SpriteChoice& choice = {});

// Loads the named sprites (in that order) with `keys` giving their segments.
// InputError naming the bank and the sprite for an unknown id or another px_per_m
// (`px_per_m` 0 = take the first sprite's). With `choice`, only the sprites it takes (the rest
// go to left_out); without, every named sprite (labels name the sprites they judge).
BankSprites LoadBankSpritesById(const Bank& bank, std::span<const int64_t> ids, SegmentKeys* keys,
                                double px_per_m = 0, const SpriteChoice* choice = nullptr);

}  // namespace ss
