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

// What a bank's transition table holds (docs/transitions.md): which stored sprites take part
// (by default not those tagged kMergedTag: two or more subjects in one blob, a sprite that is
// neither of them), and at most how many transitions leave each sprite (its cheapest).
struct TableChoice {
  // At most this many transitions out of a sprite by default. From above a walking animal's
  // frames look alike once turned to one heading, a third of all pairs pass, and an uncapped
  // table grows with the square of the session (2,044 a sprite after 60 s, bench/RESULTS.md).
  static constexpr int kDefaultMaxPerSprite = 100;
  bool include_merged = false;  // the config's transitions.include_merged, --include-merged
  // The config's transitions.max_per_sprite, --max-per-sprite; 0 keeps every transition.
  int max_per_sprite = kDefaultMaxPerSprite;
  bool Takes(const SpriteRecord& sprite) const;
  // The bank's meta keys recording the choice its transition table was made with.
  static constexpr const char* kMetaKey = "transitions.include_merged";
  static constexpr const char* kCapMetaKey = "transitions.max_per_sprite";
  std::string MetaValue() const { return include_merged ? "true" : "false"; }
  std::string CapMetaValue() const { return std::to_string(max_per_sprite); }
  // The choice `bank`'s table was made with, as its meta keys record it (the defaults for what
  // they do not say): what a rebuild that is not told otherwise keeps.
  static TableChoice RecordedIn(const Bank& bank);
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
  std::vector<int64_t> left_out;  // sprites loaded but not taken (TableChoice), in load order
};

// Loads the sprites of every complete clip that `choice` takes, ordered by (clip, mirrored,
// frame), their segments from `keys` (a sprite left out breaks its clip's segment there).
// InputError naming the bank when sprites disagree on px_per_m. `progress(done, total)` is
// called every few hundred sprites when given.
BankSprites LoadBankSprites(const Bank& bank, SegmentKeys* keys,
                            const std::function<void(size_t, size_t)>& progress = {},
                            const TableChoice& choice = {});

// Loads the named sprites (in that order) with `keys` giving their segments.
// InputError naming the bank and the sprite for an unknown id or another px_per_m
// (`px_per_m` 0 = take the first sprite's). With `choice`, only the sprites it takes (the rest
// go to left_out); without, every named sprite (labels name the sprites they judge).
BankSprites LoadBankSpritesById(const Bank& bank, std::span<const int64_t> ids, SegmentKeys* keys,
                                double px_per_m = 0, const TableChoice* choice = nullptr);

}  // namespace ss
