#pragma once
// The daemon's one running station, and test mode's replay of a recorded
// session in its place (the console's replay page): StartReplay stops the
// station of the config's cameras (its session stopped and stored) and starts
// one whose cameras replay a recorded session, with the same bank, keying,
// pipeline and storage; StopReplay goes back. Callers take the running
// station with current(); a replaced station is stopped before its successor
// starts, and stays valid for whoever still holds it. Who follows the running
// station (the calibration wizard's frame tap, a retrain waiting for the rebuild)
// adds a station change listener instead of asking current() again and again.
//
// Threads: the daemon's main thread calls Start and Stop; the API's threads (the
// replay routes, the calibration save) and the labels' retrain thread (UseWeights)
// switch stations; any thread reads current(), weights(), live_config(), ModeJson().
// Lock order: switch_mutex_ -> listeners_ (its lock) -> a listener's own locks -> mutex_.
// mutex_ is a leaf (held for a copy). A listener runs on the switching thread with
// switch_mutex_ and the listeners_ lock held: it may read the host (current() and the
// other getters) and the new station, but must not switch stations or add or remove
// listeners, and nobody may hold a lock a listener takes while switching stations.
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/listeners.h"
#include "core/session.h"
#include "station/station.h"

namespace ss {

// A recorded session found under a replay root.
struct RecordedSessionEntry {
  std::string path;  // absolute
  std::string root;
  SessionInfo info;
  double seconds = 0;  // the longest camera's frames / fps
  std::string error;   // why it cannot be read ("" when it can)
};
// Sessions (folders with a session.json) in each root, the root itself or up to two levels
// down, sorted by root then path. A root that does not exist is skipped.
std::vector<RecordedSessionEntry> FindRecordedSessions(const std::vector<std::string>& roots);
nlohmann::json RecordedSessionsToJson(const std::vector<std::string>& roots,
                                      const std::vector<RecordedSessionEntry>& sessions);

// The config of a station replaying session `dir` in place of `live`'s cameras.
StationConfig ReplayStationConfig(const StationConfig& live, const SessionInfo& session,
                                  const std::string& dir, bool paced, bool loop);

class StationHost {
 public:
  StationHost(StationOptions live, std::vector<std::string> replay_roots);
  ~StationHost();  // Stop()

  void Start();  // the live station
  void Stop();   // idempotent
  std::shared_ptr<Station> current() const;

  // InputError (field "path") for a path that is not a listed session, or whose
  // station cannot start (then the live station runs again).
  void StartReplay(const std::string& path, bool paced, bool loop);
  // InputError (field "replay") when no replay runs.
  void StopReplay();

  // The transition weights every station of this host runs with, and the file they came
  // from ("" for the shipped defaults).
  struct Weights {
    TransitionWeights weights;
    std::string path;
  };
  Weights weights() const;
  // Restarts the running station (live or replay, as it is) with new transition weights and
  // keeps them for every later station: its transition worker rebuilds the bank's table with
  // them at start (UpdateBankTransitions' rules), in the background. ConflictError (field
  // "session") while a capture session is active: a restart would end it, so the operator
  // stops it first. When the station cannot start with them, the previous weights run again
  // and the error is rethrown.
  void UseWeights(const TransitionWeights& weights, const std::string& path);
  // The live station's config (the daemon's, with what ApplyLiveConfig changed).
  StationConfig live_config() const;
  // A new config for the live station (the calibration wizard's models and floor): the live
  // station restarts with it at once (true), or, while a replay runs, when the replay stops
  // (false). When the new station cannot start, the previous config runs again and the
  // error is thrown.
  bool ApplyLiveConfig(const StationConfig& config);

  // Calls `listener` each time a new station has started and is current(): at Start, when a
  // replay starts or stops, after UseWeights and ApplyLiveConfig, and when a failed switch
  // starts the previous station again. It runs on the switching thread, one switch after the
  // other (see the lock order above); the mode (ModeJson) may still be the old one then. An
  // exception it throws is logged. Returns the id RemoveStationChangeListener takes.
  int AddStationChangeListener(std::function<void()> listener);
  // Once it returns, the listener is not running and is not called again.
  void RemoveStationChangeListener(int id);

  // Calls `listener` when the running station's status changes in a way a viewer acts on
  // (StationOptions::status_changed: on the station's threads, possibly under its locks) and
  // after each switch of stations. It must be short and call neither the host nor the station
  // (the console's events: ConsoleEvents::Changed). Returns the id RemoveStatusListener takes.
  int AddStatusListener(std::function<void()> listener);
  // Once it returns, the listener is not running and is not called again.
  void RemoveStatusListener(int id);

  // {"mode": "live" | "replay", "replay": {"path", "paced", "loop"} or null}
  nlohmann::json ModeJson() const;
  const std::vector<std::string>& replay_roots() const { return replay_roots_; }

 private:
  // Stops the running station and starts one from `options`. Under switch_mutex_.
  void Replace(StationOptions options);
  // Calls the station change listeners. Under switch_mutex_, after station_ is the new one.
  void NotifyStationChange();

  StationOptions
      live_;  // written under switch_mutex_ and mutex_ (weights(), live_config() read it)
  StationOptions running_;  // what the current station was started from; under switch_mutex_
  std::vector<std::string> replay_roots_;
  std::mutex switch_mutex_;   // one switch at a time
  mutable std::mutex mutex_;  // guards station_ and the mode below
  std::shared_ptr<Station> station_;
  bool replaying_ = false;
  std::string replay_path_;
  bool replay_paced_ = true, replay_loop_ = false;
  Listeners listeners_;  // its lock is held while they run (the lock order above)
  // The status listeners, shared with every station this host starts (a station may outlive
  // the host in whoever still holds it). A leaf: their lock is taken under any other.
  std::shared_ptr<Listeners> status_listeners_ = std::make_shared<Listeners>();
  // `options` with their status_changed telling status_listeners_.
  StationOptions Told(StationOptions options) const;
};

}  // namespace ss
