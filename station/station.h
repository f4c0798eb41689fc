#pragma once
// The live station (`spritestation daemon`): every configured camera runs its
// own CameraRunner (capture thread + pipeline thread); their clip batches meet
// in one bank writer thread, which hands each stored sprite to the incremental
// TransitionWorker. Sprites are stored only during a capture session (started
// and stopped over the control API or at start); a session may also record the
// raw frames. The disk guard is asked before each write: below
// storage.stop_recording_below_mib raw recording stops, below
// storage.stop_sprites_below_mib sprite storage stops too (the bank stays whole).
// Threads: the station host's switching thread calls Start and Stop; the API's threads the
// rest; a frame watcher runs on a camera's pipeline thread, a transitions listener on the
// transitions worker's. Each lock and its order: station_impl.h.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "config/station_config.h"
#include "pipeline/transitions/weights.h"
#include "station/preview.h"
#include "station/station_status.h"

namespace ss {

struct StationOptions {
  // the station config, validated by the caller (ValidateStationConfig): not checked again here
  StationConfig config;
  std::optional<TransitionWeights> weights;  // unset: the shipped defaults; set: valid ones
  std::string weights_path;                  // the file `weights` came from (named in the status)
  bool transitions = true;                   // keep the bank's transitions current
  double offline_after_s = 3.0;  // a camera silent this long, seconds (> 0), is reopened
  // Opens each camera; unset: its configured backend (benchmarks replay from memory).
  std::function<std::unique_ptr<FrameSource>(const CameraConfig&, int camera_index)> open_source;
  // Called when what the status says changes in a way a viewer acts on: the station's state, a
  // session started, stopped or renamed, a camera's state, the storage state, the transitions'
  // start-up. Any of the station's threads calls it, possibly with station locks held: it must
  // be short and must not call the station (the console's events: ConsoleEvents::Changed).
  // Figures that move all the time (counts, rates) are not told; the console samples them.
  std::function<void()> status_changed;
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

// The enclosure's floor a station on `config` uses: enclosure.floor, else the floor of the first
// replayed session that has one (as ingest takes it), else empty.
GroundPolygon StationFloor(const StationConfig& config);

// What a station on `config` lacks to store sprites, one line each ("cam0: no camera model",
// "enclosure.floor: no floor polygon"): without it the camera (or every camera) streams for
// preview and recording and stores none. The daemon logs these at start; `config check` lists
// them. Camera model files that cannot be read count as missing.
std::vector<std::string> CalibrationGaps(const StationConfig& config);

// The cameras that see all of their floor from further above than pipeline.max_view_angle_deg,
// one line each ("cam0: sees all of its floor from 84 degrees ..."): every sprite they key is
// refused as view_too_steep (docs/pipeline.md). Cameras without a model or floor are left out.
std::vector<std::string> SteepViews(const StationConfig& config);

// What the station refuses to start on although the file is well formed (no camera at all):
// throws InputError naming the field. The daemon calls it at start and `config check` before
// it says valid, so both say the same words. (`ingest --config` may leave the cameras out: it
// takes the session's.)
void CheckStationConfig(const StationConfig& config);

class Station {
 public:
  // Checks what can be checked before anything starts (models, floor, bank):
  // InputError naming the field or file.
  explicit Station(StationOptions options);
  ~Station();  // Stop()
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  // Opens the bank and starts every camera and worker.
  void Start();
  // Stops the session (its clips stored, its recording finalized), the cameras and the
  // workers; the bank is committed. Idempotent.
  void Stop();

  // Capture sessions. StartSession: InputError when one is active or the name is bad.
  SessionStatus StartSession(const std::string& name);
  // Closes every open clip into the session, waits until the bank holds them, finalizes
  // the recording. InputError when no session is active.
  SessionStatus StopSession();
  SessionStatus RenameSession(const std::string& name);

  StationStatus Status() const;
  const std::string& bank_path() const;  // storage.bank (fixed for the station's life)
  // A camera's latest preview as JPEG, at most `max_width` wide; NotFoundError for an unknown
  // camera, nullopt before its first frame. Each snapshot (5 a second, 2 while a session runs)
  // is encoded once per view and width, for every caller, on the first caller's thread.
  struct PreviewImage {
    std::vector<uint8_t> jpeg;
    uint64_t sequence = 0;
    int64_t timestamp_ns = 0;
    int width = 0, height = 0;  // the camera's full size
  };
  std::optional<PreviewImage> Preview(const std::string& camera, PreviewView view,
                                      int max_width) const;
  // The sprites view (preview.h SpritesViewJson) as JSON text, made once per snapshot the same way.
  std::optional<std::string> SpritesView(const std::string& camera, int max_width) const;
  bool SessionActive() const;
  // Called with every frame of every camera (`camera`: its index in the config), on that
  // camera's pipeline thread after the pipeline has seen it: the calibration wizard's tap.
  // Keep it short (copy what is needed and return). An empty function removes it.
  using FrameWatcher = std::function<void(int camera, const Frame& frame)>;
  void SetFrameWatcher(FrameWatcher watcher);
  // Calls `listener` each time the transitions worker's start-up build moves on or ends (the
  // status' transitions_startup_stage / _done / _total and transitions_ready), on the worker's
  // thread: who waits for the rebuild waits on its own condition variable, not polling
  // Status(). Keep it short; it must not add or remove transitions listeners. Returns the id
  // RemoveTransitionsListener takes.
  int AddTransitionsListener(std::function<void()> listener);
  // Once it returns, the listener is not running and is not called again.
  void RemoveTransitionsListener(int id);
  // SIGHUP: applies what is safe to change live (logging, storage limits and recording
  // mode, from the next session on); returns one line per section that needs a restart.
  std::vector<std::string> Reload(const StationConfig& config);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
