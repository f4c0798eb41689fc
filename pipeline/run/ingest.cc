#include "pipeline/run/ingest.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <utility>

#include "capture/replay/replay_source.h"
#include "core/bank.h"
#include "core/bank_verify.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/run/bank_scale.h"
#include "pipeline/run/bounded_queue.h"
#include "pipeline/transitions/worker.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Reads {"floor": [[x, y], ...]} (ground metres).
std::optional<GroundPolygon> ReadFloorJson(const fs::path& path) {
  if (!fs::exists(path)) return std::nullopt;
  std::ifstream in(path);
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string(), std::string("not valid JSON: ") + e.what());
  }
  const nlohmann::json* floor = nullptr;
  for (const char* key : {"floor", "floor_polygon", "polygon"}) {
    if (j.is_object() && j.contains(key)) {
      floor = &j[key];
      break;
    }
  }
  if (floor != nullptr && floor->is_object() && floor->contains("vertices"))
    floor = &(*floor)["vertices"];
  if (floor == nullptr || !floor->is_array())
    throw InputError(path.string(), "expected a \"floor\" list of [x, y] points");
  if (floor->size() > GroundPolygon::kMaxVertices) {
    throw InputError(path.string(), "floor: " + std::to_string(floor->size()) +
                                        " points; a floor polygon has at most " +
                                        std::to_string(GroundPolygon::kMaxVertices));
  }
  std::vector<Eigen::Vector2d> vertices;
  for (const auto& p : *floor) {
    if (p.is_array() && p.size() >= 2 && p[0].is_number() && p[1].is_number()) {
      vertices.emplace_back(p[0].get<double>(), p[1].get<double>());
    } else if (p.is_object() && p.contains("x") && p.contains("y")) {
      vertices.emplace_back(p["x"].get<double>(), p["y"].get<double>());
    } else {
      throw InputError(path.string(), "floor: every point must be [x, y] in metres");
    }
  }
  GroundPolygon polygon(std::move(vertices));
  if (!polygon.IsSimple())
    throw InputError(path.string(), "floor: not a simple polygon of at least 3 points");
  return polygon;
}

struct CameraWork {
  std::string name;
  int64_t camera_id = 0;
  std::unique_ptr<CameraPipeline> pipeline;
  std::unique_ptr<BoundedQueue<Frame>> frames;
  std::thread thread;
};

}  // namespace

GroundPolygon FloorForSession(const std::string& session_dir, const GroundPolygon& configured) {
  if (!configured.empty()) return configured;
  const fs::path dir(session_dir);
  for (const fs::path& candidate : {dir / "enclosure.json", dir / "truth" / "floor.json"}) {
    if (auto polygon = ReadFloorJson(candidate)) return *polygon;
  }
  throw InputError(session_dir,
                   "no floor polygon: give enclosure.floor in the config (--config), or put "
                   "enclosure.json in the session");
}

bool IngestOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(pipeline.IsValid(&part), "pipeline.", part);
  check.Within(decode_threads, AtLeast(0), "decode_threads", "0 (one per core) or more");
  return check.ok();
}

IngestSummary IngestSession(const IngestOptions& options) {
  const auto start = Clock::now();
  if (std::string why; !options.IsValid(&why)) throw InputError("ingest options", why);
  if (options.pipeline.workers > 0) cv::setNumThreads(options.pipeline.workers);  // process-wide
  ReplayOptions replay_options;
  replay_options.realtime = false;
  replay_options.frames_ahead = 6;
  replay_options.decode_threads = options.decode_threads;
  ReplaySource source(options.session_dir, replay_options);
  const SessionInfo& info = source.session();
  const GroundPolygon floor = FloorForSession(options.session_dir, options.floor);

  // Everything that can be refused is checked before the bank is touched.
  std::vector<CameraModel> models;
  for (const SessionCamera& cam : info.cameras) {
    if (cam.model.empty()) {
      throw InputError(
          options.session_dir + "/session.json",
          "camera " + cam.name + " has no camera model; the pipeline needs it to find the ground");
    }
    models.push_back(CameraModel::Read((fs::path(options.session_dir) / cam.model).string()));
    if (models.back().width() != cam.width || models.back().height() != cam.height) {
      throw InputError((fs::path(options.session_dir) / cam.model).string(),
                       "the model is for " + std::to_string(models.back().width()) + "x" +
                           std::to_string(models.back().height()) + " images but camera " +
                           cam.name + " records " + std::to_string(cam.width) + "x" +
                           std::to_string(cam.height));
    }
  }
  CameraPipelineOptions pipeline_options = options.pipeline;
  const TransitionWeights transition_weights = options.transition_weights.empty()
                                                   ? DefaultWeights()
                                                   : LoadWeights(options.transition_weights);

  RefuseDamagedBank(options.bank_path);  // before anything is written
  BankWriter bank(options.bank_path);
  IngestSummary summary;
  // The bank's one billboard scale: its own when it holds sprites, else the config's or auto.
  BankScaleInputs scale_inputs;
  scale_inputs.configured = options.pipeline.rectify.px_per_m;
  scale_inputs.bank_path = options.bank_path;
  for (const CameraModel& m : models) scale_inputs.models.push_back(&m);
  scale_inputs.floor = floor;
  scale_inputs.max_side_px = pipeline_options.rectify.max_side_px;
  scale_inputs.margin_m = pipeline_options.rectify.margin_m;
  const BankScale scale = ChooseAndKeepBankScale(bank, scale_inputs);
  pipeline_options.rectify.px_per_m = scale.px_per_m;
  summary.px_per_m = scale.px_per_m;
  summary.px_per_m_why = scale.why;
  Log("pipeline.ingest")->info("billboard scale {} px/m: {}", scale.px_per_m, scale.why);
  summary.session_name = info.name;
  SessionRecord session_record;
  session_record.uid = info.name + "@" + info.created;
  session_record.name = info.name;
  session_record.created = info.created;
  session_record.source = fs::absolute(options.session_dir).lexically_normal().string();
  summary.session_id = bank.AddSession(session_record);

  std::vector<CameraWork> cameras(info.cameras.size());
  for (size_t c = 0; c < info.cameras.size(); ++c) {
    const SessionCamera& cam = info.cameras[c];
    CameraRecord record;
    record.name = cam.name;
    record.cameramodel = models[c].ToText();
    record.width = cam.width;
    record.height = cam.height;
    cameras[c].name = cam.name;
    cameras[c].camera_id = bank.AddCamera(summary.session_id, record);
    cameras[c].pipeline = std::make_unique<CameraPipeline>(cam.name, cameras[c].camera_id,
                                                           models[c], floor, pipeline_options);
    cameras[c].frames = std::make_unique<BoundedQueue<Frame>>(4);
  }

  // Failures: the first one stops everything; batches already stored stay stored.
  std::mutex failure_mutex;
  std::exception_ptr failure;
  std::atomic<bool> failed{false};
  BoundedQueue<ClipBatch> batches(64);
  const auto fail = [&](std::exception_ptr e) {
    {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::move(e);
    }
    failed = true;
    source.Stop();
    batches.Close();
    for (CameraWork& w : cameras) w.frames->Close();
  };

  // The transition worker reads and writes the bank through its own connections; the
  // writer thread only queues each batch's ids with it.
  std::unique_ptr<TransitionWorker> transitions;
  if (options.transitions)
    transitions = std::make_unique<TransitionWorker>(options.bank_path, transition_weights, 1,
                                                     options.transition_table);

  std::atomic<uint64_t> frames_done{0}, rows_inserted{0}, batch_count{0}, stored{0};
  std::thread writer([&] {
    try {
      while (auto batch = batches.Pop()) {
        if (failed) break;
        const AppendResult r = bank.AppendClipBatch(batch->clip, batch->sprites);
        if (transitions) transitions->Submit(r.sprite_ids);
        rows_inserted += static_cast<uint64_t>(r.inserted);
        ++batch_count;
        for (const SpriteRecord& s : batch->sprites) stored += s.mirrored ? 0 : 1;
      }
    } catch (...) {
      fail(std::current_exception());
    }
  });

  const int training_frames = options.pipeline.TrainingFrames();
  for (CameraWork& w : cameras) {
    w.thread = std::thread([&, &w = w] {
      try {
        std::vector<cv::Mat> empty;
        std::vector<ClipBatch> out;
        while (auto frame = w.frames->Pop()) {
          if (!w.pipeline->trained()) {
            empty.push_back(ToBgr(*frame));
            ++frames_done;
            if (static_cast<int>(empty.size()) == training_frames) {
              w.pipeline->Train(empty);
              empty.clear();
            }
            continue;
          }
          w.pipeline->Process(*frame, &out);
          ++frames_done;
          for (ClipBatch& b : out) batches.Push(std::move(b));
          out.clear();
        }
        if (failed) return;
        if (!w.pipeline->trained() && !empty.empty()) w.pipeline->Train(empty);
        w.pipeline->Finish(&out);
        for (ClipBatch& b : out) batches.Push(std::move(b));
      } catch (...) {
        fail(std::current_exception());
      }
    });
  }

  // This thread reads the replay and hands each frame to its camera.
  uint64_t frames_total = 0;
  for (const ReplayCameraStats& s : source.camera_stats()) frames_total += s.frames_in_csv;
  auto last_progress = Clock::now();
  try {
    while (!failed) {
      std::optional<Frame> frame = source.Next();
      if (!frame) break;
      if (frame->camera < 0 || static_cast<size_t>(frame->camera) >= cameras.size()) {
        throw WorkError(options.session_dir, "replay delivered a frame of an unknown camera");
      }
      cameras[frame->camera].frames->Push(std::move(*frame));
      if (options.progress && Clock::now() - last_progress > std::chrono::milliseconds(250)) {
        last_progress = Clock::now();
        options.progress({frames_done.load(), frames_total, stored.load(),
                          std::chrono::duration<double>(last_progress - start).count()});
      }
    }
  } catch (...) {
    fail(std::current_exception());
  }
  for (CameraWork& w : cameras) w.frames->Close();
  for (CameraWork& w : cameras) w.thread.join();
  batches.Close();
  writer.join();
  if (failure) std::rethrow_exception(failure);  // ~TransitionWorker stops it
  if (transitions) {
    const auto wait_start = Clock::now();
    transitions->WaitIdle();
    const TransitionWorkerStats t = transitions->stats();
    transitions->Stop();
    summary.transitions = true;
    summary.transitions_stored = t.transitions_stored;
    summary.transitions_in_table = Bank(options.bank_path).TransitionCount();
    summary.transition_sprites = t.sprites;
    summary.transitions_error = t.last_error;
    summary.seconds_transitions_wait =
        std::chrono::duration<double>(Clock::now() - wait_start).count();
    if (!t.last_error.empty()) {
      Log("pipeline.ingest")
          ->error(
              "{}: the transition table may be incomplete ({}); run 'spritestation transitions "
              "{}' to rebuild it",
              options.bank_path, t.last_error, options.bank_path);
    }
  }

  summary.source = source.stats();
  const std::vector<ReplayCameraStats> replay_stats = source.camera_stats();
  for (size_t c = 0; c < cameras.size(); ++c) {
    CameraWork& w = cameras[c];
    const CameraPipelineStats& s = w.pipeline->stats();
    summary.cameras.push_back(
        {w.name, w.camera_id, s, c < replay_stats.size() ? replay_stats[c] : ReplayCameraStats{}});
    summary.frames += s.frames;
    summary.sprites_kept += s.stored_sprites;
    summary.sprites_merged += s.merged_sprites;
    for (size_t r = 0; r < summary.discards.size(); ++r) summary.discards[r] += s.discards[r];
  }
  summary.rows_inserted = rows_inserted;
  summary.batches = batch_count;
  summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  summary.frames_per_second = summary.seconds > 0 ? summary.frames / summary.seconds : 0;
  if (options.progress)
    options.progress({frames_done.load(), frames_total, stored.load(), summary.seconds});
  return summary;
}

}  // namespace ss
