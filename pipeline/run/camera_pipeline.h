#pragma once
// One camera's live pipeline (docs/pipeline.md): every frame goes
//   key -> extract -> track -> filter -> rectify -> describe -> clip batches
// and what comes out are the batches the bank stores. One CameraPipeline
// belongs to one thread; several cameras run side by side, each its own.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/logger.h>
#include <opencv2/core.hpp>

#include "core/camera_model.h"
#include "core/frame.h"
#include "core/geometry.h"
#include "pipeline/extract/extractor.h"
#include "pipeline/filter/usability.h"
#include "pipeline/key/keyer.h"
#include "pipeline/key/keying_config.h"
#include "pipeline/key/matte.h"
#include "pipeline/rectify/floor_rectifier.h"
#include "pipeline/rectify/rectifier.h"
#include "pipeline/run/clip_batcher.h"
#include "pipeline/track/side_by_side.h"
#include "pipeline/track/tracker.h"

namespace ss {

// Everything a camera pipeline is tuned by: each stage's own options. The station config's
// keying and pipeline sections (and enclosure.wall_height_m) are these fields, bound key by key
// (config/config_keys.cc; its defaults where they differ: DefaultPipelineOptions in
// config/station_config.h). rectify.px_per_m 0 is `auto`: the caller sets the bank's scale
// (ChooseBankScale, bank_scale.h) before making a CameraPipeline.
struct CameraPipelineOptions {
  // The config's keying section: keying.method picks the keyer, which reads its own block
  // (pipeline/key/keyer_registry.h); keying.shadow.reach_m (> 0) becomes its grid's
  // shadow_reach_cells at the floor's centre. Unset: a chroma keyer with its own defaults.
  std::optional<KeyingConfig> keying;
  ExtractorOptions extract;           // blobs of the matte into candidates
  TrackerOptions track;               // candidates into subjects across frames
  UsabilityOptions usability;         // border, floor and wall tests
  NoiseOptions noise;                 // keyed background that is not a subject
  SideBySideOptions side_by_side;     // a pair in one blob by its looks (tagged merged)
  double still_speed_m_per_s = 0.05;  // slower than this counts as not moving (StillnessFilter)
  double max_still_s = 2.0;           // still periods longer than this are discarded
  RectifierOptions rectify;           // billboards and their scale
  ClipBatcherOptions batch;           // clips into the bank's batches
  // How the pipelines run, read by whoever runs them (the station, ingest), not by
  // CameraPipeline: OpenCV threads inside a frame's work (process-wide; 0 = OpenCV's
  // default), and frames queued between a camera's capture and its pipeline (the station).
  int workers = 0;
  int queue_frames = 8;

  // Empty-enclosure frames the keyer learns from before the first frame is keyed
  // (keying.training_frames; 30 when the keying block is unset), at least 1.
  int TrainingFrames() const {
    return std::max(1, keying ? keying->training_frames : KeyingConfig{}.training_frames);
  }
  // False with "FIELD: reason" lines in `why` (FIELD as "extract.min_area") for values out of
  // range; the keying block is the keyers' to check (they refuse what they cannot use).
  bool IsValid(std::string* why) const;
  bool operator==(const CameraPipelineOptions&) const = default;
};

struct CameraPipelineStats {
  uint64_t frames = 0;           // frames processed (training frames included)
  uint64_t training_frames = 0;  // of them, learnt as the empty enclosure
  uint64_t candidates = 0;       // blobs the extractor found above the noise size
  uint64_t sequence_gaps = 0;    // breaks in the sequence numbers (drops): open clips end there
  DiscardCounts
      discards{};  // by reason; [kNone] counts usable sprites (in clips long enough so far)
  uint64_t stored_sprites = 0;  // originals handed to the bank (mirrors not counted)
  uint64_t merged_sprites = 0;  // of them, tagged `merged`: two or more subjects in one blob
  uint64_t clips = 0;           // complete clips handed to the bank
  double seconds_key = 0, seconds_rest = 0;  // thread time in keying+extracting, in the rest
};

// What became of one candidate of the last processed frame (the console's sprites view).
struct CandidateVerdict {
  const Candidate* candidate = nullptr;  // the extractor's; valid until the next Process
  int track = -1;  // the tracker's subject id; -1 when its ray missed the floor
  std::optional<Eigen::Vector2d> ground;  // contact point on the floor, metres
  Discard reason = Discard::kNone;        // kNone: usable (it joins a clip)
  bool merged = false;  // the blob holds two or more subjects (MergeDetector, SideBySide)
};

class CameraPipeline {
 public:
  // `camera_id` is the bank's id of the camera. Throws InputError when the model
  // is missing or the options are invalid (rectify.px_per_m not chosen: <= 0).
  CameraPipeline(std::string name, int64_t camera_id, CameraModel model, const GroundPolygon& floor,
                 const CameraPipelineOptions& options);
  ~CameraPipeline();
  CameraPipeline(CameraPipeline&&) noexcept;

  // Learns the empty enclosure from BGR frames (InputError when they cannot be keyed).
  void Train(const std::vector<cv::Mat>& empty_bgr);
  bool trained() const;
  // One frame through every stage; appends the batches it completed to `out`.
  // A frame of another size than the model's: InputError naming the camera and frame.
  void Process(const Frame& frame, std::vector<ClipBatch>* out);
  // End of stream: every open clip is closed.
  void Finish(std::vector<ClipBatch>* out);
  // A new capture session (the daemon): closes every open clip into `out`, then
  // stores the clips to come under bank camera `camera_id`. The keyer stays trained.
  void Retarget(int64_t camera_id, std::vector<ClipBatch>* out);

  // The last processed frame's matte (previews; valid until the next Process).
  const Matte& last_matte() const { return matte_; }
  // Every candidate of the last processed frame with its verdict (valid until the next Process).
  const std::vector<CandidateVerdict>& last_verdicts() const { return verdicts_; }

  const std::string& name() const { return name_; }
  const CameraModel& model() const { return model_; }
  const CameraPipelineStats& stats() const { return stats_; }
  // Sprites that passed every filter so far, short clips included (grows by the frame's usable
  // ones).
  uint64_t usable_sprites() const { return usable_total_; }
  const FloorMask& floor_mask() const { return floor_mask_; }
  const Keyer& keyer() const { return *keyer_; }  // as configured (options.keying)

 private:
  std::string name_;
  int64_t camera_id_;
  CameraModel model_;
  CameraPipelineOptions options_;
  std::unique_ptr<Keyer> keyer_;
  FloorMask floor_mask_;
  Extractor extractor_;
  Tracker tracker_;
  MergeDetector merges_;
  SideBySide side_by_side_;
  StillnessFilter stillness_;
  NoiseFilter noise_;
  ClipCutter cutter_;
  Rectifier rectifier_;
  FloorRectifier floor_rectifier_;  // for a camera that films from above (FloorMask)
  ClipBatcher batcher_;
  cv::Mat bgr_scratch_;  // a frame converted for the keyer (formats it cannot key in place)
  Matte matte_;
  std::vector<CandidateVerdict> verdicts_;
  void UpdateClipStats();

  std::optional<uint64_t> last_sequence_;
  std::shared_ptr<spdlog::logger> log_;  // "pipeline.run": per-sprite decisions at trace level
  std::optional<std::chrono::steady_clock::time_point> last_too_large_log_;  // one warning per 10 s
  uint64_t usable_total_ = 0;  // sprites that passed the filters, short clips included
  CameraPipelineStats stats_;
};

}  // namespace ss
