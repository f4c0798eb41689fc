#pragma once
// Callbacks told that something changed (the station host's station, a station's transitions
// start-up): who waits for the change waits on its own condition variable instead of polling.
// Add and Remove from any thread; Notify calls each listener in turn on the notifying thread,
// under the registry's lock, so once Remove returns its listener is not running and is not
// called again. A listener must not add or remove listeners; what it throws is logged.
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <utility>

#include "core/log.h"

namespace ss {

class Listeners {
 public:
  // The id Remove takes (never 0).
  int Add(std::function<void()> listener) {
    std::lock_guard lock(mutex_);
    const int id = next_id_++;
    listeners_.emplace(id, std::move(listener));
    return id;
  }
  void Remove(int id) {
    std::lock_guard lock(mutex_);
    listeners_.erase(id);
  }
  // `what` names the change in the log line of a listener that throws.
  void Notify(const char* what) {
    std::lock_guard lock(mutex_);
    for (const auto& [id, listener] : listeners_) {
      try {
        listener();
      } catch (const std::exception& e) {
        Log("station")->warn("a {} listener failed: {}", what, e.what());
      }
    }
  }

 private:
  std::mutex mutex_;  // held while the listeners run
  std::map<int, std::function<void()>> listeners_;
  int next_id_ = 1;
};

}  // namespace ss
