#include "station/console_events.h"

#include <chrono>

#include "core/log.h"

namespace ss {

nlohmann::json MergePatch(const nlohmann::json& from, const nlohmann::json& to) {
  if (!from.is_object() || !to.is_object()) return to;
  nlohmann::json patch = nlohmann::json::object();
  for (auto it = from.begin(); it != from.end(); ++it) {
    if (!to.contains(it.key())) patch[it.key()] = nullptr;
  }
  for (auto it = to.begin(); it != to.end(); ++it) {
    const auto old = from.find(it.key());
    if (old == from.end()) {
      patch[it.key()] = it.value();
    } else if (*old != it.value()) {
      patch[it.key()] =
          old->is_object() && it.value().is_object() ? MergePatch(*old, it.value()) : it.value();
    }
  }
  return patch;
}

ConsoleEvents::ConsoleEvents(std::function<nlohmann::json()> status, double min_interval_s,
                             double sample_interval_s)
    : status_(std::move(status)),
      min_interval_s_(min_interval_s),
      sample_interval_s_(sample_interval_s) {}

ConsoleEvents::~ConsoleEvents() { Stop(); }

void ConsoleEvents::Start() {
  if (thread_.joinable()) return;
  // The first snapshot; a status that cannot be read yet (no station runs) is an object that
  // says so, replaced by the first one the loop reads.
  nlohmann::json first;
  try {
    first = status_();
  } catch (const std::exception& e) {
    first = {{"error", e.what()}};
  }
  {
    std::lock_guard lock(mutex_);
    current_ = std::move(first);
    version_ = 1;
    ++reads_;
  }
  thread_ = std::thread([this] { Loop(); });
}

void ConsoleEvents::Stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ConsoleEvents::Changed() {
  {
    std::lock_guard lock(mutex_);
    told_ = true;
  }
  wake_.notify_one();
}

uint64_t ConsoleEvents::reads() const {
  std::lock_guard lock(mutex_);
  return reads_;
}

uint64_t ConsoleEvents::connections() const {
  std::lock_guard lock(mutex_);
  return connections_;
}

nlohmann::json ConsoleEvents::Sample(const nlohmann::json& status, double dt_s) {
  // A member the status lacks (no station runs) reads as 0.
  const auto member = [](const nlohmann::json& j, const char* key) {
    return j.is_object() ? j.value(key, nlohmann::json::object()) : nlohmann::json::object();
  };
  double dropped = 0;
  nlohmann::json fps = nlohmann::json::object();
  for (const auto& c : status.value("cameras", nlohmann::json::array())) {
    dropped += member(c, "dropped").value("total", 0.0);
    fps[c.value("name", "")] = c.value("fps", 0.0);
  }
  const double dropped_per_s =
      last_dropped_ >= 0 && dt_s > 0 ? std::max(0.0, dropped - last_dropped_) / dt_s : 0;
  last_dropped_ = dropped;
  const nlohmann::json bank = member(status, "bank");
  const nlohmann::json latency = member(bank, "latency_ms");
  return {
      {"t",
       std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count()},
      {"sprites_per_s", bank.value("sprites_per_second", 0.0)},
      {"latency_p50_ms", latency.value("p50", 0.0)},
      {"latency_p99_ms", latency.value("p99", 0.0)},
      {"transitions_pending", member(status, "transitions").value("pending", 0)},
      {"dropped_per_s", dropped_per_s},
      {"fps", fps}};
}

void ConsoleEvents::Loop() {
  using Clock = std::chrono::steady_clock;
  const auto sample_interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(sample_interval_s_));
  const auto min_interval =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(min_interval_s_));
  auto last_sample = Clock::now();
  auto next_sample = last_sample + sample_interval;
  auto earliest = last_sample;  // a told change's read, at the soonest
  auto log = Log("station.console");
  while (true) {
    bool told = false;
    {
      std::unique_lock lock(mutex_);
      // Until something is told or the figures are due. A told change is read no sooner than
      // the interval after the last told one (a burst of them is one read); the samples' reads
      // do not delay it.
      wake_.wait_until(lock, next_sample, [&] { return stopping_ || told_; });
      told = told_;
      if (!stopping_ && told && Clock::now() < earliest) {
        wake_.wait_until(lock, std::min(earliest, next_sample), [&] { return stopping_; });
      }
      if (stopping_) return;
      told_ = false;
      ++reads_;
    }
    nlohmann::json status;
    bool read = true;
    try {
      status = status_();
    } catch (const std::exception& e) {
      log->warn("events: the status could not be read: {}", e.what());
      read = false;
    }
    const auto now = Clock::now();
    if (told) earliest = now + min_interval;
    nlohmann::json sample;
    if (now >= next_sample) {
      if (read) sample = Sample(status, std::chrono::duration<double>(now - last_sample).count());
      last_sample = now;
      // On the second's beat, or a second from now when a read ran late.
      next_sample += sample_interval;
      if (next_sample <= now) next_sample = now + sample_interval;
    }
    bool notify = false;
    {
      std::lock_guard lock(mutex_);
      if (read && status != current_) {
        current_ = std::move(status);
        ++version_;
        notify = true;
      }
      if (!sample.is_null()) {
        history_.push_back(std::move(sample));
        while (history_.size() > kHistory) history_.pop_front();
        ++samples_;
        notify = true;
      }
    }
    if (notify) changed_.notify_all();
  }
}

namespace {

std::string Event(uint64_t id, const char* name, const nlohmann::json& data) {
  return "id: " + std::to_string(id) + "\nevent: " + name + "\ndata: " + data.dump() + "\n\n";
}

}  // namespace

ConsoleEvents::Stream::~Stream() {
  if (!snapshot_sent_) return;
  std::lock_guard lock(events_.mutex_);
  --events_.connections_;
}

std::string ConsoleEvents::Stream::Next() {
  ConsoleEvents& e = events_;
  std::unique_lock lock(e.mutex_);
  if (e.stopping_) return "";
  if (!snapshot_sent_) {
    snapshot_sent_ = true;
    ++e.connections_;
    sent_ = e.current_;
    status_version_ = e.version_;
    samples_sent_ = e.samples_;
    nlohmann::json history = nlohmann::json::array();
    for (const auto& s : e.history_) history.push_back(s);
    return Event(next_id_++, "snapshot", {{"status", sent_}, {"history", history}});
  }
  while (true) {
    const bool woke = e.changed_.wait_for(lock, std::chrono::duration<double>(kHeartbeatS), [&] {
      return e.stopping_ || e.version_ != status_version_ || e.samples_ != samples_sent_;
    });
    if (e.stopping_) return "";
    if (!woke) {
      return Event(
          next_id_++, "heartbeat",
          {{"t", std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
                     .count()}});
    }
    std::string out;
    if (e.version_ != status_version_) {
      const nlohmann::json patch = MergePatch(sent_, e.current_);
      sent_ = e.current_;
      status_version_ = e.version_;
      if (!patch.empty()) out += Event(next_id_++, "patch", patch);
    }
    // Samples this client has not had yet (at most the kept history).
    const uint64_t missed = std::min<uint64_t>(e.samples_ - samples_sent_, e.history_.size());
    for (size_t k = e.history_.size() - missed; k < e.history_.size(); ++k) {
      out += Event(next_id_++, "sample", e.history_[k]);
    }
    samples_sent_ = e.samples_;
    if (!out.empty()) return out;
  }
}

}  // namespace ss
