#pragma once
// `spritestation import`: videos FFmpeg reads -> an ordinary recorded session
// (docs/formats.md), ready for `ingest` with the clean-plate keyer. Per video
// one camera: its frames as bgr8 in the session's codec, each frame's time
// from the container (variable frame rates kept), preceded by the empty scene
// the keyer learns from (from a time range, a separate clip, or a per-pixel
// median). Beside the session's own files: enclosure.json (the floor),
// ingest.yaml (the keying the session needs), import.json (where it came from).
// docs/import.md.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "import/rough_camera.h"

namespace ss {

// Seconds on a video's own clock (0 = its first frame), [start_s, end_s).
struct TimeRange {
  double start_s = 0;
  double end_s = std::numeric_limits<double>::infinity();
  bool whole() const { return start_s <= 0 && end_s == std::numeric_limits<double>::infinity(); }
};
// "12.5-30", "12.5-" (to the end), "-30" (from the start). InputError naming `flag`.
TimeRange ParseTimeRange(const std::string& text, const std::string& flag);

enum class EmptySceneSource { kMedian, kTimeRange, kClip };

struct ImportOptions {
  std::vector<std::string> videos;  // one camera each, in this order
  std::string out_dir;              // the session folder to make
  bool force = false;               // replace an existing session folder at out_dir
  std::string name;                 // session name; "" = the first video's file stem
  TimeRange range;                  // the part of every video imported
  double image_sequence_fps = 25;   // frame rate of an image-sequence pattern (`%04d.png`)
  std::string codec = "ffv1";       // the session's video codec (core/recording_codecs.h)

  // Camera models: a .cameramodel per video, or (one video) a rough camera, or
  // none (footage of a calibration board, for `spritestation calibrate`).
  std::vector<std::string> model_paths;
  bool use_rough = false;
  RoughCamera rough;
  bool no_model = false;

  // The empty scene: `empty_frames` frames (= the ingest's keying.training_frames;
  // 0: none, for footage that is not to be ingested).
  EmptySceneSource empty_source = EmptySceneSource::kMedian;
  TimeRange empty_range;                 // kTimeRange: of each video
  std::vector<std::string> empty_clips;  // kClip: one per video, the same size
  int empty_frames = 30;
  int median_samples = 31;      // kMedian: frames (at least) the median is taken over
  double winsor_spreads = 2.5;  // kMedian: values pulled to within this many spreads of the median

  // The floor: a JSON file ({"floor": [[x, y], ...]}), or what the (first) camera sees.
  std::string floor_path;
  double floor_max_range_m = 0;  // 0: 5 x the camera's height

  std::function<void(const std::string&)> progress;  // a line now and then

  // False with the option (flag) at fault and what was expected in `why`.
  bool IsValid(std::string* why) const;
};

struct ImportedCamera {
  std::string name;
  std::string video;  // the source
  std::string codec;  // the source's codec
  int width = 0, height = 0;
  int rotation_deg = 0;        // the display rotation applied (clockwise): a phone's portrait video
  double fps = 0;              // nominal, as the container says (0: unknown)
  int64_t frames = 0;          // imported from the range (the empty scene not counted)
  int64_t empty_frames = 0;    // written before them
  int64_t corrupt_frames = 0;  // the decoder reported damaged and that were skipped
  std::string last_problem;
  int64_t first_timestamp_ns = 0, last_timestamp_ns = 0;  // of the imported frames
  // kMedian: share of the sampled values within the spreads kept
  double median_background_share = 0;
  std::string model_source;  // the file, or "rough: ..."
};

struct ImportSummary {
  std::string session_dir;
  std::string name;
  std::string empty_source;  // "median", "range 0-5", "clip FILE"
  std::string floor_source;
  std::vector<ImportedCamera> cameras;
  double seconds = 0;
};

// Runs the import. The session is written to a temporary sibling folder and
// moved to out_dir only when complete, so a failed import leaves nothing
// behind and an existing session is replaced (with `force`) only by a whole
// one. InputError for bad input (naming the file or flag), WorkError when the
// work fails.
ImportSummary ImportVideos(const ImportOptions& options);

}  // namespace ss
