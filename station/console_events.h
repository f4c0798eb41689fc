#pragma once
// The console's live state (`GET /api/events`, Server-Sent Events). One thread
// samples the station's status 4 times a second and keeps the last 300
// one-second chart samples; each connection is sent a snapshot, then JSON
// Merge Patches (RFC 7386) from the state it last received to the state now.
// A slow reader therefore never queues anything: it skips to the latest state,
// and nothing on the capture side ever waits for it.
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
  // `status` returns the station's status JSON (called on this object's thread).
  explicit ConsoleEvents(std::function<nlohmann::json()> status, double tick_s = 0.25);
  ~ConsoleEvents();  // Stop()
  ConsoleEvents(const ConsoleEvents&) = delete;
  ConsoleEvents& operator=(const ConsoleEvents&) = delete;

  void Start();
  // Wakes every connection so it ends; idempotent.
  void Stop();

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
  double tick_s_;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool stopping_ = false;
  nlohmann::json current_;              // the latest status
  uint64_t version_ = 0;                // bumped when current_ changes
  std::deque<nlohmann::json> history_;  // the last kHistory samples
  uint64_t samples_ = 0;                // samples made so far (the newest is number samples_)
  uint64_t connections_ = 0;
  // For per-second rates between samples.
  double last_dropped_ = -1;
};

}  // namespace ss
