#pragma once
// Store (seed 000 §2, made incremental): collects each clip's sprites as the
// pipeline makes them and hands them to the bank in batches, each batch one
// transaction. A clip is held back until it is `min_clip_frames` long (shorter
// clips give no transitions and are discarded, counted); after that it goes out
// every `batch_frames` frames, keeping back the last `velocity_half_window`
// frames whose velocity still needs frames to come. Every original sprite is
// followed by its horizontally mirrored copy. Floor sprites (seen from above) come with their
// body axis of either sign: the batcher turns each head first (ResolveHeadings) over the frames
// it holds, keeping back kHeadingLookahead frames that the next batch decides with more, and
// moves each one's place from its outline's centre to its body's thickest part by that offset's
// median over the frames around it.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/bank_records.h"
#include "pipeline/describe/sprite_description.h"
#include "pipeline/rectify/rectifier.h"

namespace ss {

struct ClipBatcherOptions {
  int min_clip_frames = 5;       // shorter clips are discarded
  int batch_frames = 60;         // sprites per batch once a clip is long enough
  int velocity_half_window = 2;  // frames each side for the velocity slope
  bool mirrors = true;           // store the mirrored copy of every sprite
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
  bool operator==(const ClipBatcherOptions&) const = default;
};

// One usable sprite of a clip, as the pipeline made it.
struct MadeSprite {
  int64_t frame = 0;  // device sequence number (consecutive within a clip)
  int64_t timestamp_ns = 0;
  cv::Rect bbox_in_image;
  Billboard billboard;
  SpriteDescription description;
  bool merged = false;       // two or more subjects in one blob: stored with the tag kMergedTag
  double matte_width_m = 0;  // the billboard matte's width (MatteLook), for MarkMerged
};

// One bank transaction: sprites of one clip, originals each followed by its mirror.
struct ClipBatch {
  ClipRecord clip;
  std::vector<SpriteRecord> sprites;
};

class ClipBatcher {
 public:
  // Floor sprites: frames kept back for the heading of those handed out to look ahead to.
  static constexpr size_t kHeadingLookahead = 15;

  ClipBatcher(int64_t camera_id, ClipBatcherOptions options);
  // Adds the next frame of clip `clip` (ClipCutter's id) of tracker subject `subject`.
  void Add(int64_t clip, int subject, MadeSprite sprite, std::vector<ClipBatch>* out);
  // The clip's subject is two subjects side by side, seen only now (SideBySide): each sprite of
  // the clip not yet handed out whose matte is at least `min_width_m` wide is tagged merged.
  // Those handed out stay as stored: a clip goes out batch_frames at a time, so a pair seen
  // split within its first batch is tagged whole. The clip stays marked until it closes.
  void MarkMerged(int64_t clip, double min_width_m);
  // Whether MarkMerged was called for the open clip `clip`.
  bool MarkedMerged(int64_t clip) const;
  // The clip ended: its rest goes out as the complete batch, or it is dropped when short.
  void Close(int64_t clip, std::vector<ClipBatch>* out);
  // Closes every open clip.
  void CloseAll(std::vector<ClipBatch>* out);

  // The bank camera of the clips to come (a new capture session); only with no open clip.
  void set_camera_id(int64_t camera_id);

  uint64_t short_clip_sprites() const {
    return short_clip_sprites_;
  }  // originals dropped in short clips
  uint64_t stored_originals() const {
    return stored_originals_;
  }  // originals handed out in batches
  uint64_t stored_merged_originals() const {
    return stored_merged_originals_;
  }  // of them, tagged kMergedTag
  uint64_t clips_completed() const { return clips_completed_; }
  size_t open_clips() const { return clips_.size(); }

 private:
  struct Open {
    int subject = 0;
    int64_t first_frame = 0;
    std::vector<int64_t> timestamps_ns;   // every frame of the clip so far
    std::vector<Eigen::Vector2d> points;  // their contact points
    std::vector<MadeSprite> pending;      // not yet handed out: the last pending.size() frames
    bool started = false;                 // a first batch went out
    bool marked_merged = false;           // MarkMerged: two side by side
    std::optional<double> last_heading;   // floor sprites: the last one handed out's heading
    // Floor sprites: Billboard::thickest_ahead_m of the last frames handed out (head first).
    std::vector<double> aheads;
  };
  // Hands out the first `count` pending sprites of `open`.
  void Emit(Open& open, size_t count, bool complete, std::vector<ClipBatch>* out);

  int64_t camera_id_;
  ClipBatcherOptions options_;
  std::map<int64_t, Open> clips_;
  uint64_t short_clip_sprites_ = 0;
  uint64_t stored_originals_ = 0;
  uint64_t stored_merged_originals_ = 0;
  uint64_t clips_completed_ = 0;
};

}  // namespace ss
