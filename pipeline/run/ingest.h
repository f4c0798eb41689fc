#pragma once
// `spritestation ingest`: a recorded session through the live pipeline into a
// bank, as fast as the machine allows. The replay reads each camera on its own
// thread a few frames ahead of the pipeline, with one decoder thread per core
// decoding FFV1/ffvhuff frames in parallel; each camera's pipeline runs on its
// own thread; one writer thread stores the clip batches, so no stage waits on
// the disk. Ingesting the same session twice stores nothing new (the bank knows
// the session and its sprites).
// With `transitions` on, a TransitionWorker (pipeline/transitions/worker.h) is handed
// each stored batch's sprite ids and keeps the bank's transition table current; the
// ingest waits for it at the end.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/replay/replay_source.h"
#include "core/geometry.h"
#include "pipeline/run/camera_pipeline.h"
#include "pipeline/transitions/bank_sprites.h"

namespace ss {

struct IngestProgress {
  uint64_t frames_done = 0;
  uint64_t frames_total = 0;  // rows of the session's frame CSVs
  uint64_t sprites_stored = 0;
  double seconds = 0;
};

struct IngestOptions {
  std::string session_dir;  // the recorded session to ingest (a folder with session.json)
  std::string bank_path;    // the bank the sprites go into (made when missing)
  // What the station config sets (config/station_config.h: the sections named). The defaults
  // are the stages' own, not the config's: without a config file a caller passes a default
  // StationConfig's (DefaultPipelineOptions).
  CameraPipelineOptions pipeline;  // keying, pipeline; keying.training_frames train (30 unset)
  GroundPolygon floor;             // enclosure.floor; empty: the session's (FloorForSession)
  TableChoice transition_table;    // transitions.include_merged, transitions.max_per_sprite
  std::function<void(const IngestProgress&)>
      progress;                    // a few times a second, from the calling thread
  bool transitions = true;         // keep the transition table current (TransitionWorker)
  std::string transition_weights;  // weights file; empty: the shipped default weights
  // Decoder threads per camera (ReplayOptions::decode_threads): 0 = one per core, 1 = frames
  // decoded one after another on the replay thread. The bank is the same either way.
  int decode_threads = 0;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range
  // (the pipeline's as "pipeline.extract.min_area").
  bool IsValid(std::string* why) const;
};

struct IngestCamera {
  std::string name;
  int64_t bank_camera_id = 0;
  CameraPipelineStats stats;
  ReplayCameraStats
      replay;  // what its recording held: unreadable frames, each problem naming the file and frame
};

struct IngestSummary {
  std::string session_name;
  int64_t session_id = 0;
  std::vector<IngestCamera> cameras;
  uint64_t frames = 0;          // frames through the pipelines (training frames included)
  uint64_t sprites_kept = 0;    // usable originals handed to the bank
  uint64_t sprites_merged = 0;  // of them, tagged merged (two or more subjects in one blob)
  uint64_t rows_inserted = 0;   // new sprite rows (originals + mirrors); 0 on a re-ingest
  uint64_t batches = 0;
  double px_per_m = 0;       // the bank's billboard scale the sprites were made at
  std::string px_per_m_why;  // how it was chosen (ChooseBankScale)
  DiscardCounts discards{};  // summed over cameras
  SourceStats source;        // what the replay could not read
  double seconds = 0;
  double frames_per_second = 0;
  bool transitions = false;        // the transition worker ran
  int64_t transitions_stored = 0;  // transitions it wrote (its start-up table included)
  // The table at the end: fewer than written when the cap on transitions out of a sprite
  // (transitions.max_per_sprite) pruned some of them.
  int64_t transitions_in_table = 0;
  int64_t transition_sprites = 0;       // sprites it knows at the end
  double seconds_transitions_wait = 0;  // waiting for it after the last batch was stored
  std::string transitions_error;  // its last error ("" when none): the table may be incomplete
};

// The floor polygon for a session: `configured` (the config's `enclosure.floor`) when not
// empty, else the session's own `enclosure.json` or (synthetic sessions) `truth/floor.json`.
// InputError naming what was looked at when there is none.
GroundPolygon FloorForSession(const std::string& session_dir, const GroundPolygon& configured);

// Runs the whole ingest. InputError for bad input (session, models, config),
// WorkError when the work fails; batches stored before a failure stay stored.
IngestSummary IngestSession(const IngestOptions& options);

}  // namespace ss
