#include "station/animation_jobs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include <malloc.h>

#include <opencv2/imgcodecs.hpp>

#include "animate/animate_run.h"
#include "animate/beam_search.h"
#include "animate/cost_plot.h"
#include "animate/playback.h"
#include "animate/renderer.h"
#include "animate/replacement.h"
#include "animate/scene.h"
#include "animate/sequence_io.h"
#include "animate/spec.h"
#include "animate/summary.h"
#include "capture/recording/video_file.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"
#include "core/replace_file.h"
#include "core/utc_time.h"
#include "judge/judge.h"

namespace ss {

namespace fs = std::filesystem;

namespace {

// The files of a job's folder the API serves, with the key a job's `files` lists each under
// (none for job.json: the job's own answer holds what it says).
constexpr std::pair<const char*, const char*> kFiles[] = {{"spec", "spec.yaml"},
                                                          {nullptr, "job.json"},
                                                          {"sequences", "sequences.json"},
                                                          {"cost_plot", "cost.png"},
                                                          {"render", "render.mp4"}};
constexpr double kTracksEverySeconds = 0.25;  // the live paths are copied this often at most
constexpr size_t kMaxTracePoints = 2000;      // the live cost curve keeps this many (thinned)

double Now() { return MonotonicSeconds(); }

std::string FolderName(int64_t id) {
  char name[32];
  std::snprintf(name, sizeof name, "%04lld", static_cast<long long>(id));
  return name;
}

std::string FrameName(int step) {
  char name[32];
  std::snprintf(name, sizeof name, "%05d.jpg", step);
  return name;
}

// Writes `text` to `path` whole (core/replace_file.h: a reader never sees half).
void WriteWhole(const fs::path& path, const std::string& text) {
  ReplaceFile(path.string(), text, "the job's " + path.filename().string());
}

std::string ReadWhole(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw NotFoundError(path.filename().string(), "not saved");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The files a job folder holds now, as URLs of the API (null for those not there).
nlohmann::json FileUrls(int64_t id, const fs::path& folder) {
  nlohmann::json files = nlohmann::json::object();
  const std::string base = "/api/animations/" + std::to_string(id) + "/files/";
  for (const auto& [key, name] : kFiles) {
    if (key == nullptr) continue;
    std::error_code ec;
    files[key] =
        fs::exists(folder / name, ec) ? nlohmann::json(base + name) : nlohmann::json(nullptr);
  }
  return files;
}

// Every other point once a curve holds kMaxTracePoints: its shape stays, its size is bounded.
template <typename Point>
void Thin(std::vector<Point>& curve) {
  if (curve.size() < kMaxTracePoints) return;
  for (size_t i = 0; i < curve.size() / 2; ++i) curve[i] = std::move(curve[2 * i]);
  curve.resize(curve.size() / 2);
}

// A cost, or null before the optimizer's first figure.
nlohmann::json Cost(bool none_yet, double cost) {
  return none_yet ? nlohmann::json(nullptr) : nlohmann::json(cost);
}

}  // namespace

const char* AnimationJobStateName(AnimationJobState state) {
  switch (state) {
    case AnimationJobState::kQueued:
      return "queued";
    case AnimationJobState::kRunning:
      return "running";
    case AnimationJobState::kRendering:
      return "rendering";
    case AnimationJobState::kDone:
      return "done";
    case AnimationJobState::kFailed:
      return "failed";
    case AnimationJobState::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

bool AnimationJobsOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(!folder.empty(), "folder", "required");
  check(!roots.empty(), "roots", "at least one folder a spec may name files under");
  check.Within(max_time_budget_s, AboveUpTo(0, kMaxTimeBudgetSeconds), "max_time_budget_s",
               "seconds in (0, " + OptionProblems::Num(kMaxTimeBudgetSeconds) + "]");
  check.Within(max_set_bytes, Positive(), "max_set_bytes", "a positive number of bytes");
  check.Within(threads, Between(1, 64), "threads", "1..64 threads");
  return check.ok();
}

// The job that runs (or ran last): what the job thread reports, under AnimationJobs::mu_.
struct AnimationJobs::Current {
  int64_t id = 0;
  fs::path folder;
  std::string name;     // the spec's sprites, "hamster, hamster2"
  std::string created;  // UTC, ISO 8601
  std::string spec_text;
  AnimationSpec spec;
  std::atomic<bool> cancel{false};
  // under mu_
  AnimationJobState state = AnimationJobState::kQueued;
  std::string error;
  double started = 0;  // monotonic seconds
  double seconds = 0;  // of the optimizer's run at the last figures
  double cost = 0, best_cost = 0;
  int64_t moves_kept = 0;
  int restarts = 0, turns = 0;
  int steps_rendered = 0, num_steps = 0;
  std::vector<std::pair<double, double>> trace;  // (seconds, best cost)
  // (seconds, the current sequences' cost by kind of term), as often as the tracks
  std::vector<std::pair<double, std::map<std::string, double>>> by_kind;
  nlohmann::json tracks = nlohmann::json::array();

  // The figures the status and the job's progress share (the cost is null before the first).
  nlohmann::json Figures() const {
    return {{"seconds", state == AnimationJobState::kRunning ? Now() - started : seconds},
            {"cost", Cost(trace.empty(), cost)},
            {"best_cost", Cost(trace.empty(), best_cost)},
            {"moves_kept", moves_kept},
            {"restarts", restarts},
            {"turns", turns},
            {"steps_rendered", steps_rendered},
            {"num_steps", num_steps}};
  }

  nlohmann::json Saved() const {  // job.json
    return {{"id", id},
            {"state", AnimationJobStateName(state)},
            {"name", name},
            {"created", created},
            {"error", error.empty() ? nlohmann::json(nullptr) : nlohmann::json(error)},
            {"seconds", seconds},
            {"frame_rate", spec.frame_rate}};
  }
};

AnimationJobs::AnimationJobs(AnimationJobsOptions options) : options_(std::move(options)) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("animation jobs", why);
  // A job that was queued or running when the station stopped never ends now.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(options_.folder, ec)) {
    const fs::path job = entry.path() / "job.json";
    if (!fs::exists(job, ec)) continue;
    try {
      nlohmann::json j = nlohmann::json::parse(ReadWhole(job));
      const std::string state = j.value("state", "");
      if (state == "queued" || state == "running" || state == "rendering") {
        j["state"] = "failed";
        j["error"] = "the station stopped while it ran";
        WriteWhole(job, j.dump(2));
      }
    } catch (const std::exception& e) {
      Log("station.animations")->warn("{}: {}", job.string(), e.what());
    }
  }
}

AnimationJobs::~AnimationJobs() { Stop(); }

void AnimationJobs::Stop() {
  std::thread thread;
  {
    std::lock_guard lock(mu_);
    if (current_) current_->cancel = true;
    thread = std::move(thread_);
  }
  if (thread.joinable()) thread.join();
}

std::string AnimationJobs::FolderOf(int64_t id) const {
  return (fs::path(options_.folder) / FolderName(id)).string();
}

int64_t AnimationJobs::Submit(const std::string& spec_text) {
  // Checked before anything is made: the spec with the station's file rules, then its budget.
  SpecFileRules rules;
  rules.base_dir = options_.base_dir;
  rules.roots = options_.roots;
  auto job = std::make_shared<Current>();
  job->spec = ParseAnimationSpec(spec_text, "spec", rules);
  const double budget = job->spec.optimizer.replacement.time_budget_seconds;
  if (budget > options_.max_time_budget_s) {
    throw InputError("spec: optimizer.time_budget_s",
                     "at most " + OptionProblems::Num(options_.max_time_budget_s) +
                         " s on this station, got " + OptionProblems::Num(budget));
  }
  if (std::string why; !AnimateRunOptions{job->spec.optimizer}.IsValid(&why)) {
    throw InputError("spec: optimizer", why);
  }
  (void)ReadSpecCamera(job->spec);  // "spec:LINE: camera: ..." when it is not a camera model
  job->spec_text = spec_text;
  for (const SpriteSpecEntry& s : job->spec.sprites) {
    job->name += (job->name.empty() ? "" : ", ") + s.name;
  }
  job->created = UtcNowIso();

  std::lock_guard lock(mu_);
  if (current_ && (current_->state == AnimationJobState::kQueued ||
                   current_->state == AnimationJobState::kRunning ||
                   current_->state == AnimationJobState::kRendering)) {
    throw ConflictError("animation", "job " + std::to_string(current_->id) + " is still " +
                                         AnimationJobStateName(current_->state) +
                                         " (one job at a time: cancel it or wait)");
  }
  if (thread_.joinable()) thread_.join();  // ended: its thread is leaving
  // A new folder, never one that exists: the next number after the highest saved.
  std::error_code ec;
  fs::create_directories(options_.folder, ec);
  if (ec) throw WorkError(options_.folder, "cannot make the animations folder: " + ec.message());
  int64_t id = 0;
  for (const auto& entry : fs::directory_iterator(options_.folder, ec)) {
    const std::string n = entry.path().filename().string();
    if (!n.empty() && std::all_of(n.begin(), n.end(), ::isdigit) && n.size() < 12) {
      id = std::max<int64_t>(id, std::stoll(n));
    }
  }
  for (++id; !fs::create_directory(FolderOf(id), ec); ++id) {
    if (ec) throw WorkError(FolderOf(id), "cannot make the job's folder: " + ec.message());
  }
  job->id = id;
  job->folder = FolderOf(id);
  WriteWhole(job->folder / "spec.yaml", spec_text);
  WriteWhole(job->folder / "job.json", job->Saved().dump(2));
  current_ = job;
  thread_ = std::thread([this, job] {
    Run(job);
    // The job's bank, F/B sets and frames were freed in this thread's malloc arena, which glibc
    // keeps mapped after the thread ends: its free pages go back to the system here, or the
    // station's RSS keeps each job's peak (bench/RESULTS.md, "soak").
    malloc_trim(0);
  });
  Log("station.animations")->info("job {}: {} ({} s budget)", id, job->name, budget);
  return id;
}

void AnimationJobs::Run(std::shared_ptr<Current> job) {
  SetThisThreadNice(kNiceBackground);  // below capture and the console (core/posix.h)
  auto set_state = [&](AnimationJobState state, const std::string& error = "") {
    nlohmann::json saved;
    {
      std::lock_guard lock(mu_);
      job->state = state;
      job->error = error;
      saved = job->Saved();
    }
    WriteWhole(job->folder / "job.json", saved.dump(2));
    if (options_.changed) options_.changed();
  };
  try {
    {
      std::lock_guard lock(mu_);
      job->state = AnimationJobState::kRunning;
      job->started = Now();
    }
    set_state(AnimationJobState::kRunning);
    const auto scene = Scene::Load(job->spec, &job->cancel);
    if (job->cancel) return set_state(AnimationJobState::kCancelled);

    AnimateRunOptions run{scene->spec().optimizer};
    run.optimizer.replacement.reach.num_threads = options_.threads;
    if (run.optimizer.method == OptimizerMethod::kReplace) {
      const int64_t bytes = ReplacementSets::EstimateBytes(
          scene->problem(), scene->MakeReplacementOptions(run.optimizer.replacement));
      if (bytes > options_.max_set_bytes) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the optimizer's F/B sets would take %.1f MiB, over this station's %.1f MiB "
                      "(a smaller optimizer.set_size, or fewer distinct frame constraints)",
                      static_cast<double>(bytes) / (1 << 20),
                      static_cast<double>(options_.max_set_bytes) / (1 << 20));
        throw InputError("memory", text);
      }
    }
    run.cancel = &job->cancel;
    // The figures of every kept move; the tracks and the cost by kind of term 4 times a second,
    // made before the lock is taken (a status reader never waits for them).
    double sampled_at = -1;
    const auto record = [&](const std::vector<Track>& tracks, const TracePoint& point,
                            bool always_sample) {
      const bool sample = always_sample || point.seconds - sampled_at >= kTracksEverySeconds;
      nlohmann::json tracks_json = nlohmann::json::array();
      std::map<std::string, double> by_kind;
      if (sample) {
        sampled_at = point.seconds;
        by_kind = scene->problem().Evaluate(tracks).by_kind;
        for (size_t s = 0; s < tracks.size(); ++s) {
          nlohmann::json positions = nlohmann::json::array();
          for (const Eigen::Vector2d& p : tracks[s].positions_m) {
            positions.push_back({p.x(), p.y()});
          }
          tracks_json.push_back(
              {{"name", scene->spec().sprites[s].name}, {"positions", std::move(positions)}});
        }
      }
      {
        std::lock_guard lock(mu_);
        job->seconds = point.seconds;
        job->cost = point.cost;
        job->best_cost = point.best_cost;
        job->moves_kept = point.moves_kept;
        job->restarts = point.restart;
        job->turns = point.turns;
        Thin(job->trace);
        job->trace.emplace_back(point.seconds, point.best_cost);
        if (!sample) return;
        Thin(job->by_kind);
        job->by_kind.emplace_back(point.seconds, std::move(by_kind));
        job->tracks = std::move(tracks_json);
      }
      if (options_.changed) options_.changed();  // the studio's chart, 4 times a second
    };
    run.on_improvement = [&](const std::vector<Track>& tracks, const TracePoint& point) {
      record(tracks, point, false);
    };
    {
      std::lock_guard lock(mu_);
      job->started = Now();  // the optimizer's clock from here (the trace's seconds)
    }
    const AnimateResult result = RunAnimation(*scene, run);
    if (job->cancel) return set_state(AnimationJobState::kCancelled);
    // The curve ends with the result's own figures, also when no move was kept (a slow machine's
    // whole budget can go to the start).
    if (!result.summary.trace.empty()) {
      TracePoint last = result.summary.trace.back();
      last.cost = last.best_cost;  // the result is the best sequences, maybe of an earlier restart
      record(result.tracks, last, true);
    }

    SequenceFile file = MakeSequenceFile(*scene, result);
    nlohmann::json judged = JudgementJson(JudgeSequences(file, file.bank_paths, scene.get()));
    judged["jumps"].erase("each");
    file.summary["judge"] = std::move(judged);
    WriteSequenceFile((job->folder / "sequences.json").string(), file);
    WriteCostPlot((job->folder / "cost.png").string(),
                  {{"replacement", result.summary.trace, cv::Scalar(200, 80, 0)}}, job->name);
    {
      std::lock_guard lock(mu_);
      job->num_steps = file.num_steps;
      job->seconds = result.summary.total_seconds;
      job->best_cost = result.summary.final_cost.total;
      job->restarts = result.summary.restarts;
      job->turns = result.summary.turns;
    }
    if (options_.render) {
      set_state(AnimationJobState::kRendering);
      const CameraModel camera = ReadSpecCamera(scene->spec());
      cv::Mat background;
      if (!file.background_path.empty()) {
        background = cv::imread(file.background_path, cv::IMREAD_UNCHANGED);
        if (background.empty()) {
          throw InputError(file.background_path, "cannot read the background image");
        }
      }
      SequencePlayer player(file.bank_paths, std::make_unique<SpriteRenderer>(camera, background));
      const fs::path frames = job->folder / "frames";
      fs::create_directory(frames);
      {
        VideoFileWriter video((job->folder / "render.mp4.partial.mp4").string(), camera.width(),
                              camera.height(), file.frame_rate, "h264");
        for (int t = 0; t < file.num_steps; ++t) {
          if (job->cancel) return set_state(AnimationJobState::kCancelled);
          const cv::Mat frame = player.RenderStep(file.sprites, t);
          video.Write(frame);
          cv::Mat bgr;
          if (frame.channels() == 4) {
            cv::Mat planes[4];
            cv::split(frame, planes);
            cv::merge(planes, 3, bgr);
          } else {
            bgr = frame;
          }
          if (!cv::imwrite((frames / FrameName(t)).string(), bgr, {cv::IMWRITE_JPEG_QUALITY, 88})) {
            throw WorkError((frames / FrameName(t)).string(), "cannot write");
          }
          std::lock_guard lock(mu_);
          job->steps_rendered = t + 1;
        }
        video.Close();
      }
      fs::rename(job->folder / "render.mp4.partial.mp4", job->folder / "render.mp4");
    }
    set_state(AnimationJobState::kDone);
    Log("station.animations")
        ->info("job {} done: cost {:.6g}, {} steps", job->id, result.summary.final_cost.total,
               file.num_steps);
  } catch (const std::exception& e) {
    // A cancel stops the banks' load and the F/B sets by throwing: cancelled, not failed.
    const bool cancelled = job->cancel.load();
    if (cancelled) {
      Log("station.animations")->info("job {}: cancelled ({})", job->id, e.what());
    } else {
      Log("station.animations")->error("job {}: {}", job->id, e.what());
    }
    try {
      if (cancelled) return set_state(AnimationJobState::kCancelled);
      set_state(AnimationJobState::kFailed, e.what());
    } catch (const std::exception& again) {
      Log("station.animations")->error("job {}: {}", job->id, again.what());
    }
  }
}

nlohmann::json AnimationJobs::Job(int64_t id) const {
  const fs::path folder = FolderOf(id);
  nlohmann::json j;
  {
    std::lock_guard lock(mu_);
    if (current_ && current_->id == id) {
      const Current& c = *current_;
      j = c.Saved();
      j["spec"] = c.spec_text;
      nlohmann::json trace = nlohmann::json::array();
      for (const auto& [s, cost] : c.trace) trace.push_back({s, cost});
      nlohmann::json by_kind = nlohmann::json::array();
      for (const auto& [s, costs] : c.by_kind) by_kind.push_back({s, costs});
      j["progress"] = c.Figures();
      j["progress"]["trace"] = std::move(trace);
      j["progress"]["by_kind"] = std::move(by_kind);
      j["tracks"] = c.tracks;
      j["num_steps"] = c.num_steps;
    }
  }
  std::error_code ec;
  if (j.is_null()) {  // a job of an earlier run, or one long ended
    if (!fs::exists(folder / "job.json", ec)) {
      throw NotFoundError("animation", "no job " + std::to_string(id));
    }
    j = nlohmann::json::parse(ReadWhole(folder / "job.json"));
    j["spec"] = ReadWhole(folder / "spec.yaml");
    j["progress"] = nullptr;
  }
  j["files"] = FileUrls(id, folder);
  if (j.value("state", "") == "done" || (j.value("state", "") == "rendering")) {
    if (fs::exists(folder / "sequences.json", ec)) {
      nlohmann::json sequences = nlohmann::json::parse(ReadWhole(folder / "sequences.json"));
      j["num_steps"] = sequences.value("num_steps", 0);
      j["frame_rate"] = sequences.value("frame_rate", 30.0);
      if (sequences.contains("summary") && sequences["summary"].contains("judge")) {
        j["judge"] = sequences["summary"]["judge"];
      }
      nlohmann::json tracks = nlohmann::json::array();
      for (const auto& s : sequences.value("sprites", nlohmann::json::array())) {
        nlohmann::json positions = nlohmann::json::array();
        for (const auto& step : s.value("steps", nlohmann::json::array())) {
          positions.push_back({step.at(2), step.at(3)});  // [bank, sprite, x, y]
        }
        tracks.push_back({{"name", s.value("name", "")}, {"positions", std::move(positions)}});
      }
      j["tracks"] = std::move(tracks);
      j["sequences"] = std::move(sequences);
    }
  }
  return j;
}

nlohmann::json AnimationJobs::List() const {
  nlohmann::json jobs = nlohmann::json::array();
  std::vector<int64_t> ids;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(options_.folder, ec)) {
    const std::string n = entry.path().filename().string();
    if (n.empty() || n.size() >= 12 || !std::all_of(n.begin(), n.end(), ::isdigit)) continue;
    if (fs::exists(entry.path() / "job.json", ec)) ids.push_back(std::stoll(n));
  }
  std::sort(ids.rbegin(), ids.rend());
  for (int64_t id : ids) {
    nlohmann::json j;
    {
      std::lock_guard lock(mu_);
      if (current_ && current_->id == id) j = current_->Saved();
    }
    if (j.is_null()) {
      try {
        j = nlohmann::json::parse(ReadWhole(fs::path(FolderOf(id)) / "job.json"));
      } catch (const std::exception& e) {
        j = {{"id", id}, {"state", "failed"}, {"error", e.what()}};
      }
    }
    jobs.push_back({{"id", id},
                    {"state", j.value("state", "failed")},
                    {"name", j.value("name", "")},
                    {"created", j.value("created", "")},
                    {"files", FileUrls(id, FolderOf(id))}});
  }
  return {{"jobs", std::move(jobs)}};
}

nlohmann::json AnimationJobs::Cancel(int64_t id) {
  {
    std::lock_guard lock(mu_);
    if (current_ && current_->id == id) current_->cancel = true;
  }
  return Job(id);  // NotFoundError for an unknown id
}

nlohmann::json AnimationJobs::Brief() const {
  std::lock_guard lock(mu_);
  if (!current_) return nullptr;
  const Current& c = *current_;
  nlohmann::json j = c.Figures();
  j["id"] = c.id;
  j["state"] = AnimationJobStateName(c.state);
  j["by_kind"] =
      c.by_kind.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.by_kind.back().second);
  return j;
}

std::string AnimationJobs::File(int64_t id, const std::string& name) const {
  if (std::none_of(std::begin(kFiles), std::end(kFiles),
                   [&](const auto& file) { return name == file.second; })) {
    throw NotFoundError("file",
                        "a job holds spec.yaml, job.json, sequences.json, cost.png and "
                        "render.mp4, not " +
                            name);
  }
  const fs::path path = fs::path(FolderOf(id)) / name;
  std::error_code ec;
  if (!fs::exists(fs::path(FolderOf(id)) / "job.json", ec)) {
    throw NotFoundError("animation", "no job " + std::to_string(id));
  }
  if (!fs::exists(path, ec)) {
    throw NotFoundError("file", "job " + std::to_string(id) + " has no " + name + " (yet)");
  }
  return path.string();
}

std::string AnimationJobs::Frame(int64_t id, int step) const {
  const fs::path path = fs::path(FolderOf(id)) / "frames" / FrameName(step);
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw NotFoundError(
        "frame", "job " + std::to_string(id) + " has no rendered step " + std::to_string(step));
  }
  return path.string();
}

}  // namespace ss
