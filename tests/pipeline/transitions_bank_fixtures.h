#pragma once
// Synthetic sprites in a real sprite bank, shared by the transitions unit tests
// (tests/pipeline/transitions_bank_test.cc) and the `transitions` command tests
// (tests/e2e/transitions_cli_test.cc): the synthetic set, its clips, a bank filled with them
// and a session truth describing them.
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/bank.h"
#include "pipeline/transitions/synthetic.h"

namespace ss::testing {

// The bank record of a synthetic sprite at `frame` (33.3 ms apart, 1 mm further along x each),
// at the synthetic set's scale; a mirror carries no pixels of its own.
SpriteRecord Record(const SyntheticSprite& s, int64_t frame, bool mirrored);

// A synthetic set whose area survives the bank's round trip bit for bit.
std::vector<SyntheticSprite> Sprites(int frames, uint64_t seed);

// One synthetic clip (originals and their mirrors) as one bank clip.
struct ClipOfSprites {
  int64_t clip = 0;
  std::vector<const SyntheticSprite*> originals, mirrors;  // by frame
};
std::vector<ClipOfSprites> Clips(const std::vector<SyntheticSprite>& sprites);

// Writes clips into a bank, `batch` frames per transaction; `stored` is called with the
// ids of every batch (as the pipeline would hand them to the worker).
class BankFiller {
 public:
  explicit BankFiller(const std::string& path);
  // Stores one clip; fills bank_id for its sprites.
  void Add(const ClipOfSprites& c, int batch,
           const std::function<void(const std::vector<int64_t>&)>& stored = {});
  std::map<int64_t, int64_t> bank_id;  // synthetic id -> bank id
  // Synthetic ids of originals stored tagged merged (with their mirrors).
  std::set<int64_t> merged;

 private:
  BankWriter writer_;
  int64_t camera_ = 0;
  int64_t next_frame_ = 100;
};

// A session folder whose truth/subjects.csv describes the synthetic sprites as stored by
// BankFiller.
void WriteTruth(const std::string& session_dir, const std::vector<SyntheticSprite>& sprites);

}  // namespace ss::testing
