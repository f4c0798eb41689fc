#include "station/station_status.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/filter/usability.h"

namespace ss {
namespace {

// Prometheus label values escape backslash, double quote and newline.
std::string PromLabel(const std::string& value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

class Metrics {
 public:
  // One metric family: HELP and TYPE once, then its samples.
  void Family(const std::string& name, const char* type, const std::string& help) {
    out_ << "# HELP spritestation_" << name << " " << help << "\n# TYPE spritestation_" << name
         << " " << type << "\n";
    name_ = name;
  }
  void Sample(double value, const std::string& labels = "") {
    out_ << "spritestation_" << name_ << (labels.empty() ? "" : "{" + labels + "}") << " " << value
         << "\n";
  }
  // A sample of the family's `name_SUFFIX` series (a summary's _sum and _count).
  void SampleSuffix(const std::string& suffix, double value) {
    out_ << "spritestation_" << name_ << suffix << " " << value << "\n";
  }
  std::string str() const { return out_.str(); }

 private:
  // 12 significant digits: counters stay exact integers to 10^12 (the default 6 wrote
  // 1234567 frames as 1.23457e+06).
  std::ostringstream out_ = [] {
    std::ostringstream o;
    o.precision(12);
    return o;
  }();
  std::string name_;
};

}  // namespace

nlohmann::json SessionToJson(const SessionStatus& s) {
  return {{"active", s.active},
          {"name", s.name},
          {"bank_session_id", s.bank_session_id},
          {"started", s.started},
          {"seconds", s.seconds},
          {"sprites_stored", s.sprites_stored},
          {"recording_dir", s.recording_dir},
          {"revision", s.revision}};
}

const char* StationStateName(StationState state) {
  switch (state) {
    case StationState::kStarting:
      return "starting";
    case StationState::kRunning:
      return "running";
    case StationState::kStopping:
      return "stopping";
    case StationState::kStopped:
      return "stopped";
  }
  return "unknown";
}

const char* StorageStateName(StorageState state) {
  switch (state) {
    case StorageState::kOk:
      return "ok";
    case StorageState::kRecordingStopped:
      return "recording_stopped";
    case StorageState::kSpritesStopped:
      return "sprites_stopped";
    case StorageState::kWritesFailing:
      return "writes_failing";
  }
  return "unknown";
}

nlohmann::json StatusToJson(const StationStatus& st) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const CameraStatus& c : st.cameras) {
    nlohmann::json discards = nlohmann::json::object();
    for (size_t r = 1; r < c.pipeline.discards.size(); ++r) {
      discards[DiscardName(static_cast<Discard>(r))] = c.pipeline.discards[r];
    }
    cameras.push_back({{"name", c.name},
                       {"source", c.source},
                       {"state", CameraStateName(c.state)},
                       {"message", c.message},
                       {"width", c.width},
                       {"height", c.height},
                       {"pixel_format", c.pixel_format},
                       {"fps", c.fps},
                       {"frames_captured", c.frames_captured},
                       {"frames_processed", c.frames_processed},
                       {"dropped",
                        {{"queue_full", c.dropped_queue_full},
                         {"at_source", c.dropped_at_source},
                         {"total", c.dropped_queue_full + c.dropped_at_source}}},
                       {"source_errors", c.source_errors},
                       {"frames_rejected", c.frames_rejected},
                       {"frames_while_learning", c.frames_while_learning},
                       {"learnt_from",
                        {{"frames", c.learnt_from.frames},
                         {"first_sequence", c.learnt_from.first_sequence},
                         {"last_sequence", c.learnt_from.last_sequence},
                         {"first_timestamp_ns", c.learnt_from.first_timestamp_ns},
                         {"last_timestamp_ns", c.learnt_from.last_timestamp_ns}}},
                       {"queue_depth", c.queue_depth},
                       {"queue_capacity", c.queue_capacity},
                       {"reopens", c.reopens},
                       {"has_model", c.has_model},
                       {"has_floor", c.has_floor},
                       {"usable_sprites", c.pipeline.discards[static_cast<size_t>(Discard::kNone)]},
                       {"sprites_stored", c.sprites_to_bank},
                       {"sprites_merged", c.merged_to_bank},
                       {"clips", c.pipeline.clips},
                       {"sequence_gaps", c.pipeline.sequence_gaps},
                       {"batches_unstored", c.batches_unstored},
                       {"discards", discards},
                       {"exposure", ExposureToJson(c.exposure)}});
  }
  return {{"state", StationStateName(st.state)},
          {"uptime_s", st.uptime_s},
          {"session", SessionToJson(st.session)},
          {"cameras", cameras},
          {"bank",
           {{"path", st.bank_path},
            {"sprites", st.bank_sprites},
            {"sprites_stored", st.sprites_stored},
            {"sprites_per_second", st.sprites_per_second},
            {"batches_stored", st.batches_stored},
            {"batches_failed", st.batches_failed},
            {"batches_retried", st.batches_retried},
            {"batches_spooled", st.batches_spooled},
            {"spool", {{"batches", st.spool_batches}, {"bytes", st.spool_bytes}}},
            {"batches_refused", st.batches_refused},
            {"writer_queue", st.writer_queue},
            {"latency_ms", {{"p50", st.latency_p50_ms}, {"p99", st.latency_p99_ms}}},
            {"error", st.bank_error}}},
          {"transitions",
           {{"enabled", st.transitions_enabled},
            {"ready", st.transitions_ready},
            {"pending", st.transitions_pending},
            {"stored", st.transitions_stored},
            {"failed_rounds", st.transition_rounds_failed},
            {"last_round_ms", st.transitions_last_round_ms},
            {"error", st.transitions_error},
            {"startup",
             {{"stage", st.transitions_startup_stage},
              {"done", st.transitions_startup_done},
              {"total", st.transitions_startup_total}}}}},
          {"storage",
           {{"state", StorageStateName(st.storage_state)},
            {"disk_free_mib", st.disk_free_mib},
            {"stop_recording_below_mib", st.stop_recording_below_mib},
            {"stop_sprites_below_mib", st.stop_sprites_below_mib},
            {"recording", st.recording_mode},
            {"frames_recorded", st.frames_recorded},
            {"frames_record_dropped", st.frames_record_dropped},
            {"recording_error", st.recording_error},
            {"recording_stopped", st.recording_stopped}}},
          {"control",
           {{"url", st.control_url},
            {"connections_open", st.control_connections_open},
            {"connections_refused", st.control_connections_refused},
            {"requests_timed_out", st.control_requests_timed_out}}}};
}

std::string StatusToPrometheus(const StationStatus& st) {
  Metrics m;
  m.Family("up", "gauge", "1 while the station runs");
  m.Sample(st.state == StationState::kRunning ? 1 : 0);
  m.Family("uptime_seconds", "gauge", "seconds since the daemon started");
  m.Sample(st.uptime_s);
  m.Family("session_active", "gauge", "1 while a capture session runs");
  m.Sample(st.session.active ? 1 : 0);

  const auto per_camera = [&](const std::string& name, const char* type, const std::string& help,
                              auto value) {
    m.Family(name, type, help);
    for (const CameraStatus& c : st.cameras)
      m.Sample(static_cast<double>(value(c)), "camera=\"" + PromLabel(c.name) + "\"");
  };
  per_camera("camera_up", "gauge", "1 while the camera delivers frames (training or live)",
             [](const CameraStatus& c) {
               return c.state == CameraState::kLive || c.state == CameraState::kTraining;
             });
  per_camera("camera_fps", "gauge", "frames delivered per second over the last 2 s",
             [](const CameraStatus& c) { return c.fps; });
  per_camera("frames_captured_total", "counter", "frames delivered by the camera",
             [](const CameraStatus& c) { return c.frames_captured; });
  per_camera("frames_processed_total", "counter", "frames through the pipeline",
             [](const CameraStatus& c) { return c.frames_processed; });
  m.Family("frames_dropped_total", "counter", "frames lost, by cause");
  for (const CameraStatus& c : st.cameras) {
    m.Sample(static_cast<double>(c.dropped_queue_full),
             "camera=\"" + PromLabel(c.name) + "\",cause=\"queue_full\"");
    m.Sample(static_cast<double>(c.dropped_at_source),
             "camera=\"" + PromLabel(c.name) + "\",cause=\"at_source\"");
  }
  per_camera("source_errors_total", "counter",
             "recoverable source problems (timeouts, corrupt frames)",
             [](const CameraStatus& c) { return c.source_errors; });
  per_camera("frames_rejected_total", "counter",
             "frames the pipeline refused (corrupt, another size)",
             [](const CameraStatus& c) { return c.frames_rejected; });
  per_camera("queue_depth", "gauge", "frames waiting for the pipeline",
             [](const CameraStatus& c) { return c.queue_depth; });
  per_camera("camera_reopens_total", "counter", "times the camera was reopened after going offline",
             [](const CameraStatus& c) { return c.reopens; });
  m.Family("sprite_discards_total", "counter", "sprites not kept, by reason");
  for (const CameraStatus& c : st.cameras) {
    for (size_t r = 1; r < c.pipeline.discards.size(); ++r) {
      m.Sample(static_cast<double>(c.pipeline.discards[r]),
               "camera=\"" + PromLabel(c.name) + "\",reason=\"" +
                   DiscardName(static_cast<Discard>(r)) + "\"");
    }
  }
  per_camera("sprites_merged_total", "counter",
             "original sprites stored tagged merged (two or more subjects in one blob)",
             [](const CameraStatus& c) { return c.merged_to_bank; });
  m.Family("sprites_stored_total", "counter", "original sprites stored in the bank since start");
  m.Sample(static_cast<double>(st.sprites_stored));
  m.Family("sprites_per_second", "gauge", "sprites stored per second over the last 5 s");
  m.Sample(st.sprites_per_second);
  m.Family("bank_sprites", "gauge", "sprite rows in the bank (originals and mirrors)");
  m.Sample(static_cast<double>(st.bank_sprites));
  m.Family("bank_batches_failed_total", "counter", "clip batches the bank could not store");
  m.Sample(static_cast<double>(st.batches_failed));
  m.Family("bank_batches_retried_total", "counter",
           "clip batch appends tried again because another writer held the bank's lock past its "
           "busy timeout");
  m.Sample(static_cast<double>(st.batches_retried));
  m.Family("bank_batches_spooled_total", "counter",
           "clip batches kept on disk because the bank could not take them");
  m.Sample(static_cast<double>(st.batches_spooled));
  m.Family("bank_spool_batches", "gauge", "clip batches waiting in the spool for the bank");
  m.Sample(static_cast<double>(st.spool_batches));
  m.Family("bank_batches_refused_total", "counter",
           "clip batches not stored because the disk is nearly full");
  m.Sample(static_cast<double>(st.batches_refused));
  // A summary: quantiles over the last 10,000 sprites, _sum and _count over every sprite since
  // start.
  m.Family("sprite_latency_seconds", "summary",
           "frame arrival to sprite committed (quantiles over the last 10,000 sprites)");
  m.Sample(st.latency_p50_ms / 1e3, "quantile=\"0.5\"");
  m.Sample(st.latency_p99_ms / 1e3, "quantile=\"0.99\"");
  m.SampleSuffix("_sum", st.latency_sum_s);
  m.SampleSuffix("_count", static_cast<double>(st.latency_count));
  m.Family("transitions_pending", "gauge", "stored sprites whose transitions are not found yet");
  m.Sample(static_cast<double>(st.transitions_pending));
  m.Family("transitions_stored_total", "counter", "transitions stored since start");
  m.Sample(static_cast<double>(st.transitions_stored));
  m.Family("disk_free_mib", "gauge", "free MiB on the bank's (or recordings') file system");
  m.Sample(static_cast<double>(st.disk_free_mib));
  m.Family("storage_stopped", "gauge", "what the disk guard stopped, by what");
  m.Sample(st.storage_state == StorageState::kRecordingStopped ||
                   st.storage_state == StorageState::kSpritesStopped
               ? 1
               : 0,
           "what=\"recording\"");
  m.Sample(st.storage_state == StorageState::kSpritesStopped ? 1 : 0, "what=\"sprites\"");
  m.Family("bank_writes_failing", "gauge",
           "1 while the bank's last append failed (with disk space above both thresholds)");
  m.Sample(st.storage_state == StorageState::kWritesFailing ? 1 : 0);
  m.Family("frames_recorded_total", "counter", "raw frames written to the session recording");
  m.Sample(static_cast<double>(st.frames_recorded));
  m.Family("frames_record_dropped_total", "counter",
           "raw frames the recorder could not keep up with");
  m.Sample(static_cast<double>(st.frames_record_dropped));
  m.Family("http_connections", "gauge", "connections the control API serves now");
  m.Sample(static_cast<double>(st.control_connections_open));
  m.Family("http_connections_refused_total", "counter",
           "connections refused: too many open from the same address");
  m.Sample(static_cast<double>(st.control_connections_refused));
  m.Family("http_requests_timed_out_total", "counter",
           "requests not received whole by the request deadline");
  m.Sample(static_cast<double>(st.control_requests_timed_out));
  return m.str();
}

}  // namespace ss
