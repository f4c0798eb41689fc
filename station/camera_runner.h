#pragma once
// One station camera, frame by frame from the device to the bank writer:
//   capture thread:  source->Next() -> bounded queue (full: the frame is dropped
//                    and counted; capture never waits on processing)
//   pipeline thread: queue -> learn the empty enclosure -> CameraPipeline::Process
//                    -> clip batches -> the station's sink (the bank writer)
// A camera that stops delivering frames is marked offline and reopened with
// backoff; nothing else in the station notices. The pipeline thread sleeps on the
// queue until a frame comes, the capture ends, the station retargets the bank
// camera or the state changes (each wakes it), or the camera has been silent
// for offline_after_s: it never wakes up only to look.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "capture/camera_config.h"
#include "capture/frame_source.h"
#include "core/camera_model.h"
#include "core/frame.h"
#include "core/geometry.h"
#include "pipeline/run/camera_pipeline.h"
#include "station/preview.h"

namespace ss {

using SteadyTime = std::chrono::steady_clock::time_point;

// A clip batch on its way to the bank, with when each sprite's frame arrived.
struct StationBatch {
  int camera = 0;  // runner index
  ClipBatch batch;
  std::vector<SteadyTime> received;  // one per sprite of the batch
};

enum class CameraState { kStarting, kTraining, kLive, kOffline, kFinished, kError };
const char* CameraStateName(CameraState state);

struct CameraStatus {
  std::string name;
  std::string source;  // replay | v4l2 | aravis | libcamera
  CameraState state = CameraState::kStarting;
  std::string message;  // why it is offline / in error; the last source problem
  int width = 0, height = 0;
  std::string pixel_format;
  double fps = 0;                   // frames delivered per second over the last ~2 s
  uint64_t frames_captured = 0;     // delivered by the source
  uint64_t frames_processed = 0;    // through the pipeline (training frames included)
  uint64_t dropped_queue_full = 0;  // the pipeline queue was full
  // lost before delivery: incomplete frames, sequence gaps, unreadable
  uint64_t dropped_at_source = 0;
  uint64_t source_errors = 0;  // recoverable source problems (timeouts, corrupt frames)
  // arrived while the keyer learnt the empty enclosure (preview only)
  uint64_t frames_while_learning = 0;
  // The frames collected for the keyer to learn the empty enclosure from (set when the set is
  // complete and learning starts): how many, and the first and last one's sequence number and
  // timestamp (-1: none collected yet).
  struct LearntFrom {
    uint64_t frames = 0;
    int64_t first_sequence = -1, last_sequence = -1;
    int64_t first_timestamp_ns = -1, last_timestamp_ns = -1;
  } learnt_from;
  uint64_t frames_rejected = 0;  // frames the pipeline refused (corrupt, another size); see message
  uint64_t batches_unstored = 0;  // batches made with no capture session (not stored)
  // Original sprites of the batches handed to the bank writer (a session ran; mirrors not
  // counted), and of them those tagged `merged`. The pipeline's own counts include the batches
  // made with no session, which are not stored.
  uint64_t sprites_to_bank = 0, merged_to_bank = 0;
  size_t queue_depth = 0, queue_capacity = 0;
  uint64_t reopens = 0;    // times the camera was opened again after going offline
  bool has_model = false;  // without one no sprite is stored (preview and recording only)
  bool has_floor = false;  // the same without the enclosure's floor
  CameraPipelineStats pipeline;
  ExposureFigures exposure;  // how the green screen is lit (latest preview, measured once a second)
};

struct CameraRunnerOptions {
  CameraConfig camera;               // the config's camera (validated with the config)
  std::optional<CameraModel> model;  // unset: no sprites, only previews and recording
  GroundPolygon floor;               // the enclosure's floor, metres (empty: as without a model)
  // The pipeline's options; its TrainingFrames() and queue_frames also say how many frames the
  // keyer learns from and how many wait between capture and the pipeline.
  CameraPipelineOptions pipeline;
  // no frame for this long, seconds (> 0): offline, closed and reopened
  double offline_after_s = 3.0;
  double backoff_min_s = 0.5;  // first reopen delay, seconds (> 0), doubled up to backoff_max_s
  double backoff_max_s = 8.0;  // longest reopen delay, seconds (>= backoff_min_s)
  // a preview snapshot this often, seconds (>= 0; set_preview_interval changes it)
  double preview_interval_s = 0.2;
  // Opens the camera; unset: OpenCameraSource (benchmarks put frames from memory here).
  std::function<std::unique_ptr<FrameSource>(const CameraConfig&, int camera_index)> open_source;
  // Called after the camera's state or its message changes (on the runner's threads, with none
  // of its locks held): the console shows it at once. Keep it short.
  std::function<void()> state_changed;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range
  // (the pipeline's as "pipeline.extract.min_area").
  bool IsValid(std::string* why) const;
};

// Sources are closed on threads of their own (a dead device takes seconds to close):
// waits until every close is done; false after `timeout_s` (then the process may end
// without them: nothing of the station's data depends on them). Any thread may call it (the
// daemon's main thread at exit, the tests'); it sleeps on a condition variable that each close
// thread notifies as it ends (a leaf lock: held only for the count).
bool WaitForCameraCloses(double timeout_s);

class CameraRunner {
 public:
  // Called on the pipeline thread for every batch made while a bank camera is set.
  using BatchSink = std::function<void(StationBatch)>;
  // Called on the pipeline thread for every frame (the recorder); `usable`: it gave a usable
  // sprite.
  using FrameTap =
      std::function<void(int camera, const Frame& frame, uint64_t drops_before, bool usable)>;

  CameraRunner(int index, CameraRunnerOptions options, BatchSink sink, FrameTap tap);
  ~CameraRunner();  // Stop()
  CameraRunner(const CameraRunner&) = delete;
  CameraRunner& operator=(const CameraRunner&) = delete;

  void Start();
  // Asks the threads to stop and returns at once (to stop many cameras side by side).
  void RequestStop();
  // RequestStop(), then waits: queued frames are processed and open clips closed into the sink.
  void Stop();
  // Clips from now on go to bank camera `camera_id` (0: none, batches are not stored);
  // open clips are closed first, under the previous camera. Returns once applied.
  void SetBankCamera(int64_t camera_id);

  CameraStatus status() const;
  // The latest preview snapshot (preview.h); nullptr before the first frame.
  std::shared_ptr<const PreviewFrame> preview() const;
  // Snapshots are taken every `seconds` (the station takes fewer while a session stores).
  void set_preview_interval(double seconds);
  const std::string& name() const;
  const std::optional<CameraModel>& model() const;
  // The source's description once opened (size, format), for the recorder.
  std::optional<SourceCamera> source_camera() const;

 private:
  CameraStatus StatusWithoutExposure() const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
