#pragma once
// The console's live state (`GET /api/events`, Server-Sent Events). Each connection is sent a
// snapshot, then JSON Merge Patches (RFC 7386) from the state it last received to the state now.
// A slow reader therefore never queues anything: it skips to the latest state, and nothing on
// the capture side ever waits for it.
//
// When the status is read: whoever changes something a viewer acts on (a session started, a
// camera's state, a job's phase, a wizard's step) calls Changed(), and the status is read and
// sent at once, at most 4 times a second; the figures that move all the time (counts, rates,
// frames per second) are sampled once a second, with the 300 last one-second chart samples.
// Nothing else wakes the thread: an idle station costs one read a second.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

namespace ss {

// The RFC 7386 merge patch that turns `from` into `to` (arrays are replaced whole; a
// member whose new value is null is sent as removed).
nlohmann::json MergePatch(const nlohmann::json& from, const nlohmann::json& to);

class ConsoleEvents {
 public:
  // `status` returns the station's status JSON (called on this object's thread, with none of
  // its locks held). A told change is read no sooner than `min_interval_s` after the last told
  // one; the figures are sampled every `sample_interval_s`.
  explicit ConsoleEvents(std::function<nlohmann::json()> status, double min_interval_s = 0.25,
                         double sample_interval_s = 1.0);
  ~ConsoleEvents();  // Stop()
  ConsoleEvents(const ConsoleEvents&) = delete;
  ConsoleEvents& operator=(const ConsoleEvents&) = delete;

  void Start();
  // Wakes every connection so it ends; idempotent.
  void Stop();
  // The status changed: read and send it now (or once min_interval_s has passed since the last
  // told read). Any thread; takes only this object's lock.
  void Changed();
  // Status reads so far (the first snapshot's included).
  uint64_t reads() const;

  // One connection's stream. Next() blocks until there is something to send (at most the
  // heartbeat interval) and returns the text of one or more events, "" once stopping.
  class Stream {
   public:
    explicit Stream(ConsoleEvents& events) : events_(events) {}
    ~Stream();
    Stream(const Stream&) = delete;
    Stream& operator=(const Stream&) = delete;
    std::string Next();

   private:
    ConsoleEvents& events_;
    bool snapshot_sent_ = false;
    nlohmann::json sent_;          // the status as this client holds it
    uint64_t status_version_ = 0;  // of sent_
    uint64_t samples_sent_ = 0;    // samples numbered from 1
    uint64_t next_id_ = 1;
  };

  uint64_t connections() const;
  static constexpr double kHeartbeatS = 5.0;
  static constexpr size_t kHistory = 300;

 private:
  friend class Stream;
  void Loop();
  nlohmann::json Sample(const nlohmann::json& status, double dt_s);

  std::function<nlohmann::json()> status_;
  double min_interval_s_, sample_interval_s_;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;  // the streams wait on it
  std::condition_variable wake_;     // the reading thread waits on it
  bool stopping_ = false;
  bool told_ = false;  // Changed() since the last read
  uint64_t reads_ = 0;
  nlohmann::json current_;              // the latest status
  uint64_t version_ = 0;                // bumped when current_ changes
  std::deque<nlohmann::json> history_;  // the last kHistory samples
  uint64_t samples_ = 0;                // samples made so far (the newest is number samples_)
  uint64_t connections_ = 0;
  // For per-second rates between samples.
  double last_dropped_ = -1;
};

}  // namespace ss
