#include "station/console_calibration.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "calib/board.h"
#include "calib/enclosure.h"
#include "calib/joint.h"
#include "calib/report.h"
#include "calib/wizard.h"
#include "capture/camera_source.h"
#include "config/station_save.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/frame.h"
#include "core/log.h"
#include "core/utc_time.h"
#include "station/preview.h"
#include "station/station.h"
#include "station/station_host.h"
#include "station/station_status.h"

#include <httplib.h>  // after Eigen (resolv.h's _res)

namespace ss {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using calib::WizardStep;

constexpr size_t kQueueFrames = 4;  // frames waiting for a camera's wizard; more: the oldest goes
constexpr int kGrid = 10;           // the coverage map's cells a side
constexpr double kPublishS = 0.1;   // a camera's state and live view are refreshed this often
constexpr double kGridStepM = 0.1;  // the floor grid drawn over a posed camera's view
// a view's rays above the horizon end this far away on the plan
constexpr double kPlanReachM = 8.0;
// The joint solve (issue 41): a camera keeps its last still board views (with their timestamps)
// for it; of the instants two cameras saw, one is kept per board place (the board moved this far
// in the first camera's image since every kept one), at most kJointInstants of them.
constexpr size_t kTimedViews = 900;
constexpr double kJointMovePx = 10.0;
constexpr size_t kJointInstants = 40;
constexpr size_t kMinJointInstants = 3;

nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json Points(const std::vector<Eigen::Vector2d>& points) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : points) out.push_back({p.x(), p.y()});
  return out;
}

// The 10 cm floor grid seen by a posed camera, as polylines in its pixels: lines across the
// part of the floor it sees (within `reach` of the floor point below the image centre), cut
// where they leave the image or pass behind the camera.
std::vector<std::vector<Eigen::Vector2d>> FloorGrid(const CameraModel& posed,
                                                    const std::vector<Eigen::Vector2d>& fov) {
  std::vector<std::vector<Eigen::Vector2d>> lines;
  if (fov.size() < 3) return lines;
  Eigen::Vector2d lo = fov.front(), hi = lo;
  for (const auto& p : fov) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  lo = (lo / kGridStepM).array().floor().matrix() * kGridStepM;
  hi = (hi / kGridStepM).array().ceil().matrix() * kGridStepM;
  const double w = posed.width(), h = posed.height();
  const Rigid3& cam_from_ground = posed.cam_from_ground();
  auto add_line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int steps = std::max(1, static_cast<int>(std::lround((b - a).norm() / (kGridStepM / 2))));
    std::vector<Eigen::Vector2d> run;
    for (int i = 0; i <= steps; ++i) {
      const Eigen::Vector2d g = a + (b - a) * (static_cast<double>(i) / steps);
      const Eigen::Vector3d in_cam = cam_from_ground * Eigen::Vector3d(g.x(), g.y(), 0.0);
      bool inside = in_cam.z() > 0.05;
      Eigen::Vector2d px;
      if (inside) {
        px = posed.Project(in_cam);
        inside = std::isfinite(px.x()) && std::isfinite(px.y()) && px.x() >= -0.1 * w &&
                 px.x() <= 1.1 * w && px.y() >= -0.1 * h && px.y() <= 1.1 * h;
      }
      if (inside) {
        run.push_back(px);
      } else {
        if (run.size() >= 2) lines.push_back(run);
        run.clear();
      }
    }
    if (run.size() >= 2) lines.push_back(run);
  };
  for (double x = lo.x(); x <= hi.x() + 1e-9; x += kGridStepM) add_line({x, lo.y()}, {x, hi.y()});
  for (double y = lo.y(); y <= hi.y() + 1e-9; y += kGridStepM) add_line({lo.x(), y}, {hi.x(), y});
  return lines;
}

// The floor a posed camera sees, in ground metres: the image's border carried onto the
// floor; a ray above the horizon ends kPlanReachM away, level with the floor.
std::vector<Eigen::Vector2d> FloorOfView(const CameraModel& posed) {
  std::vector<Eigen::Vector2d> border;
  const double w = posed.width() - 1, h = posed.height() - 1;
  constexpr int kPerEdge = 12;
  border.reserve(kPerEdge);
  for (int i = 0; i < kPerEdge; ++i) border.emplace_back(w * i / kPerEdge, 0);
  for (int i = 0; i < kPerEdge; ++i) border.emplace_back(w, h * i / kPerEdge);
  for (int i = 0; i < kPerEdge; ++i) border.emplace_back(w - w * i / kPerEdge, h);
  for (int i = 0; i < kPerEdge; ++i) border.emplace_back(0, h - h * i / kPerEdge);
  const Eigen::Vector3d centre = posed.CentreInGround();
  std::vector<Eigen::Vector2d> out;
  for (const auto& px : border) {
    const Ray ray = posed.RayInGround(px);
    const auto hit = IntersectGround(ray);
    Eigen::Vector2d p;
    if (hit && (hit->head<2>() - centre.head<2>()).norm() <= kPlanReachM) {
      p = hit->head<2>();
    } else {
      Eigen::Vector2d d = ray.direction.head<2>();
      if (d.norm() < 1e-9) continue;
      p = centre.head<2>() + d.normalized() * kPlanReachM;
    }
    out.push_back(p);
  }
  return out;
}

// What the live view shows of a camera's last processed frame.
struct LiveView {
  cv::Mat bgr;  // replaced, never written into: readers keep their copy
  uint64_t sequence = 0;
  bool detected = false, still = false;
  std::vector<Eigen::Vector2d> corners;
  std::vector<std::vector<Eigen::Vector2d>> grid;
  std::vector<Eigen::Vector2d> floor;
};

// What a camera's wizard has for the joint solve, copied (CameraWork::Joined).
struct JointInput {
  std::string name;
  int width = 0, height = 0;
  bool intrinsics_good = false;
  std::vector<calib::BoardView> captured;  // the intrinsics step's views
  std::vector<calib::TimedView> timed;     // still board views with their time (camera 0)
  double frame_interval_s = NAN;           // median time between frames of consecutive sequence
};

struct WizardSettings {
  calib::WizardOptions options;
  double still_s = 0.2, floor_still_s = 1.0;
  int run = 0;
  std::string work_dir;  // the solve's plots
  // Called after a camera's state is published (on its threads, no lock held): the console's
  // events send it (api::Context::status_changed).
  std::function<void()> published;
};

// One camera's wizard, on a thread of its own.
// Threads: Offer is called on the station's pipeline thread (the frame watcher), Run,
// StartSolve and the getters on the API's threads; the camera's thread (Loop) feeds the
// wizard, runs the posted commands and publishes the state. It sleeps on queue_cv_ until a
// frame, a command or the stop comes (each notified where it is queued). A solve runs on a
// thread of its own (solver_) on the views captured when it began, and posts its result to the
// camera's thread: the wizard goes on capturing views meanwhile (a solve on the camera's thread
// blinded it for the solve's seconds, and a rig's camera missed the places held before it).
// Locks: queue_mutex_ and state_mutex_ are leaves (held for a copy or a push, never together).
class CameraWork {
 public:
  // `solved`: called on the camera's thread after each intrinsics solve and when its ground step
  // poses it (the joint solve may start, or start again with the views seen since).
  CameraWork(std::string name, int index, const WizardSettings& settings,
             std::atomic<uint64_t>* floor_counter, std::function<void()> solved = {})
      : name_(std::move(name)),
        index_(index),
        settings_(settings),
        floor_counter_(floor_counter),
        solved_(std::move(solved)) {
    settings_.options.solve.progress = [this](const std::string& stage, double fraction) {
      SetBusy(stage, fraction);
    };
    Publish(true);
    thread_ = std::thread([this] { Loop(); });
  }
  ~CameraWork() {
    {
      std::lock_guard lock(queue_mutex_);
      stop_ = true;
    }
    queue_cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (solver_.joinable()) solver_.join();  // its result, posted, is never run
  }
  CameraWork(const CameraWork&) = delete;
  CameraWork& operator=(const CameraWork&) = delete;

  const std::string& name() const { return name_; }
  int index() const { return index_; }

  // From the station's pipeline thread: a copy of the frame, queued.
  void Offer(const Frame& frame) {
    Frame copy = Frame::Owned(frame.format, frame.width, frame.height,
                              std::vector<uint8_t>(frame.data, frame.data + frame.size));
    copy.camera = frame.camera;
    copy.sequence = frame.sequence;
    copy.timestamp_ns = frame.timestamp_ns;
    {
      std::lock_guard lock(queue_mutex_);
      if (frames_.size() >= kQueueFrames) frames_.pop_front();
      frames_.push_back(std::move(copy));
    }
    queue_cv_.notify_one();
  }

  // Runs `f(wizard)` on the camera's thread between two frames and returns what it returns;
  // ConflictError before the camera's first frame or while a solve runs.
  template <typename F>
  auto Run(F f) -> decltype(f(std::declval<calib::CalibrationWizard&>())) {
    using R = decltype(f(std::declval<calib::CalibrationWizard&>()));
    if (busy_.load()) throw ConflictError(name_, "a solve is running; wait for it to end");
    auto task = std::make_shared<std::packaged_task<R()>>([this, f]() mutable -> R {
      if (!wizard_) throw ConflictError(name_, "has delivered no frame to the wizard yet");
      return f(*wizard_);
    });
    std::future<R> done = task->get_future();
    Post([task] { (*task)(); });
    return done.get();
  }

  // Starts the solve of the views captured so far on the solver's thread; returns at once.
  void StartSolve() {
    // The wizard says why it cannot solve now (past the step, too few views, solving): each a
    // state of the run, 409.
    auto solve = Run([](calib::CalibrationWizard& w) {
      try {
        return std::make_shared<calib::IntrinsicsSolve>(w.BeginSolve());
      } catch (const InputError& e) {
        throw ConflictError(e.what());
      }
    });
    busy_.store(true);
    SetBusy("starting", 0.0);
    if (solver_.joinable()) solver_.join();  // the last solve's thread, ended
    solver_ = std::thread([this, solve] { SolveApart(solve); });
  }

  nlohmann::json Snapshot() const {
    std::lock_guard lock(state_mutex_);
    return state_;
  }
  std::optional<nlohmann::json> Busy() const {
    std::lock_guard lock(state_mutex_);
    return busy_json_;
  }
  LiveView Live() const {
    std::lock_guard lock(state_mutex_);
    return live_;
  }
  uint64_t floor_order() const { return floor_order_.load(); }
  std::string PlotPath(const char* kind) const {
    return (fs::path(settings_.work_dir) / (name_ + "." + kind + ".png")).string();
  }
  int solves() const { return solves_.load(); }
  bool intrinsics_good() const { return intrinsics_good_.load(); }
  bool posed() const {
    std::lock_guard lock(state_mutex_);
    return ground_pose_.has_value();
  }

  JointInput Joined() const {
    std::lock_guard lock(state_mutex_);
    JointInput in;
    in.name = name_;
    in.width = bgr_width_;
    in.height = bgr_height_;
    in.intrinsics_good = intrinsics_good_.load();
    in.captured = captured_;
    in.timed.assign(timed_.begin(), timed_.end());
    if (!intervals_.empty()) {
      std::vector<double> v(intervals_.begin(), intervals_.end());
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      in.frame_interval_s = v[v.size() / 2];
    }
    return in;
  }
  // The camera's own floor-board pose (nullopt before its ground step ends).
  std::optional<Rigid3> GroundPose() const {
    std::lock_guard lock(state_mutex_);
    return ground_pose_;
  }
  // The floor board's view that pose was solved from (nullopt before its ground step ends).
  std::optional<calib::BoardView> FloorView() const {
    std::lock_guard lock(state_mutex_);
    return floor_view_;
  }

 private:
  void Post(std::function<void()> command) {
    {
      std::lock_guard lock(queue_mutex_);
      commands_.push_back(std::move(command));
    }
    queue_cv_.notify_one();
  }

  void SetBusy(const std::string& stage, double fraction) {
    {
      std::lock_guard lock(state_mutex_);
      busy_json_ = nlohmann::json{
          {"what", "solve"}, {"camera", name_}, {"stage", stage}, {"progress", fraction}};
    }
    Told();
  }

  void Told() const {
    if (settings_.published) settings_.published();
  }

  void Loop() {
    for (;;) {
      std::function<void()> command;
      std::optional<Frame> frame;
      {
        std::unique_lock lock(queue_mutex_);
        // Every change of these is notified (Offer, Post, the destructor): no timeout needed.
        queue_cv_.wait(lock, [&] { return stop_ || !commands_.empty() || !frames_.empty(); });
        if (stop_) return;
        if (!commands_.empty()) {
          command = std::move(commands_.front());
          commands_.pop_front();
        } else if (!frames_.empty()) {
          frame = std::move(frames_.front());
          frames_.pop_front();
        }
      }
      if (command) {
        command();
        Publish(true);
      } else if (frame) {
        Process(*frame);
      }
    }
  }

  void Process(const Frame& frame) {
    try {
      ToBgr(frame, bgr_);
      if (!wizard_) {
        calib::WizardOptions o = settings_.options;
        // Both still spans by the frames' timestamps (issue 41): the view's was a count of
        // frames from the camera's measured rate, or 30 fps before one was measured, so a
        // slower camera's board had to stand still several times longer. The floor board's
        // after the operator's word that it lies on the floor.
        o.still_frames = 2;
        o.still_s = settings_.still_s;
        o.floor_still_s = settings_.floor_still_s;
        o.floor_needs_word = true;
        o.detect_when_done = true;  // the joint solve's views, from every step
        o.floor_word_s = std::max(o.floor_word_s, o.floor_still_s + 5.0);
        wizard_ = std::make_unique<calib::CalibrationWizard>(name_, bgr_.cols, bgr_.rows, o);
      }
      const calib::WizardFrame out = wizard_->Feed(
          bgr_, static_cast<int>(frame.sequence),
          frame.timestamp_ns > 0 ? static_cast<double>(frame.timestamp_ns) * 1e-9 : NAN);
      guidance_ = out.guidance;
      // A still board, in any step: a view for the joint solve, if another camera saw it still
      // at the same time (a camera posed early goes on adding the places held before it and
      // another; the floor board, which one camera sees, pairs with none). Still since the
      // run's first frame: the frame processed before the one that made it still.
      const double t =
          frame.timestamp_ns > 0 ? static_cast<double>(frame.timestamp_ns) * 1e-9 : NAN;
      const bool still = out.detected && out.still;
      if (frames_fed_ > 0 && frame.sequence == last_sequence_ + 1 && std::isfinite(t) &&
          std::isfinite(last_time_s_) && t > last_time_s_) {
        std::lock_guard lock(state_mutex_);
        intervals_.push_back(t - last_time_s_);
        if (intervals_.size() > 31) intervals_.pop_front();
      }
      if (still && !was_still_) still_since_s_ = last_time_s_;
      was_still_ = still;
      last_time_s_ = t;
      if (still && std::isfinite(t)) {
        std::lock_guard lock(state_mutex_);
        timed_.push_back({0, t, wizard_->last_view(), still_since_s_});
        if (timed_.size() > kTimedViews) timed_.pop_front();
      }
      ++frames_fed_;
      message_.clear();
    } catch (const std::exception& e) {
      message_ = e.what();
      Log("station.calibration")->warn("{}: {}", name_, e.what());
    }
    last_sequence_ = frame.sequence;
    // Posed by this frame: published at once (the joint solve counts the cameras posed from
    // what is published), then the joint solve may start again.
    const bool posed = wizard_ && wizard_->ground().has_value();
    const bool newly_posed = posed && !posed_told_;
    posed_told_ = posed;
    Publish(newly_posed);
    if (newly_posed && solved_) solved_();
  }

  // On the solver's thread: the solve and its plots, then its result to the camera's thread.
  void SolveApart(const std::shared_ptr<calib::IntrinsicsSolve>& solve) {
    std::string failed;
    try {
      solve->Run();
      SetBusy("plots", 0.95);
      if (solve->solution) {
        std::error_code ec;
        fs::create_directories(settings_.work_dir, ec);
        calib::WriteResidualPlot(PlotPath("residuals"), *solve->solution, 0);
        const double distance = solve->report && solve->report->working_distance_m > 0
                                    ? solve->report->working_distance_m
                                    : 1.0;
        calib::WriteUncertaintyMap(PlotPath("uncertainty"), *solve->solution,
                                   settings_.options.board, 0, distance);
      }
    } catch (const std::exception& e) {
      failed = e.what();
    }
    Post([this, solve, failed] { EndSolve(std::move(*solve), failed); });
  }

  // On the camera's thread: the solve's result into the wizard (`failed`: why its run threw).
  void EndSolve(calib::IntrinsicsSolve solved, const std::string& failed) {
    try {
      if (!failed.empty()) throw std::runtime_error(failed);
      wizard_->EndSolve(std::move(solved), -1);
      ++solves_;
      message_.clear();
    } catch (const std::exception& e) {
      if (wizard_->solve_out()) wizard_->AbandonSolve(e.what());
      message_ = std::string("solve failed: ") + e.what();
      Log("station.calibration")->warn("{}: {}", name_, message_);
    }
    {
      std::lock_guard lock(state_mutex_);
      busy_json_.reset();
    }
    busy_.store(false);
    Publish(true);  // before `solved_`: the joint solve reads what it publishes
    if (solved_) solved_();
  }

  nlohmann::json Checklist(const calib::CalibrationWizard& w) const {
    const calib::VerdictOptions& v = settings_.options.verdict;
    char buf[96];
    nlohmann::json list = nlohmann::json::array();
    auto item = [&](const char* id, const std::string& label, nlohmann::json met,
                    nlohmann::json value) {
      list.push_back(
          {{"id", id}, {"label", label}, {"met", std::move(met)}, {"value", std::move(value)}});
    };
    item("views", "views ≥ " + std::to_string(v.min_views), w.views() >= v.min_views,
         std::to_string(w.views()));
    std::snprintf(buf, sizeof buf, "coverage ≥ %.0f %%", v.min_coverage * 100);
    const std::vector<std::string> empty = calib::EmptyRegions(w.coverage());
    char value[64];
    std::snprintf(value, sizeof value, "%.0f %%", w.coverage_fraction() * 100);
    item("coverage", buf, w.coverage_fraction() >= v.min_coverage && empty.empty(),
         empty.empty() ? std::string(value) : std::string(value) + ", " + empty.front() + " empty");
    std::snprintf(buf, sizeof buf, "a view tilted ≥ %.0f°", v.min_tilt_deg);
    std::snprintf(value, sizeof value, "%.0f°", w.max_tilt_deg());
    item("tilt", buf, w.max_tilt_deg() >= v.min_tilt_deg, value);
    const auto& report = w.report();
    const bool solved = report && !report->intrinsics.empty();
    std::snprintf(buf, sizeof buf, "RMS < %.2g px", v.max_rms_px);
    if (solved) {
      std::snprintf(value, sizeof value, "%.3f px", report->rms_px);
      item("rms", buf, report->rms_px < v.max_rms_px, value);
    } else {
      item("rms", buf, nullptr, nullptr);
    }
    const char* names[4] = {"fx", "fy", "cx", "cy"};
    for (size_t i = 0; i < 4; ++i) {
      std::snprintf(buf, sizeof buf, "%s known to ≤ %.2g %% (1.96 σ)", names[i],
                    v.max_stdev_percent);
      if (solved && i < report->intrinsics_stdev.size() &&
          std::isfinite(report->intrinsics_stdev[i])) {
        const double percent =
            1.96 * report->intrinsics_stdev[i] / std::abs(report->intrinsics[i]) * 100;
        std::snprintf(value, sizeof value, "%.3f %%", percent);
        item(names[i], buf, percent <= v.max_stdev_percent, value);
      } else {
        item(names[i], buf, nullptr, nullptr);
      }
    }
    return list;
  }

  nlohmann::json SolveJson(const calib::CalibrationWizard& w) const {
    const auto& report = w.report();
    if (!report) return nullptr;
    nlohmann::json j = {{"verdict", report->good ? "good" : "rejected"},
                        {"reasons", report->reasons},
                        {"rms_px", Num(report->rms_px)},
                        {"worst_px", Num(report->worst_px)},
                        {"views", report->views_accepted}};
    if (report->intrinsics.size() >= 4) {
      const char* names[4] = {"fx", "fy", "cx", "cy"};
      nlohmann::json in, pct;
      for (size_t i = 0; i < 4; ++i) {
        in[names[i]] = report->intrinsics[i];
        pct[names[i]] =
            i < report->intrinsics_stdev.size()
                ? Num(1.96 * report->intrinsics_stdev[i] / std::abs(report->intrinsics[i]) * 100)
                : nlohmann::json(nullptr);
      }
      j["intrinsics"] = in;
      j["uncertainty_percent"] = pct;
      j["lensmodel"] = w.intrinsics_model() ? w.intrinsics_model()->lensmodel() : "";
      j["projection_stdev_px"] = {{"centre", Num(report->projection_stdev_centre_px)},
                                  {"worst", Num(report->projection_stdev_worst_px)}};
    }
    if (w.solution()) {
      const std::string query =
          "?run=" + std::to_string(settings_.run) + "&solve=" + std::to_string(solves_.load());
      j["residuals_png"] = "/api/calibration/cameras/" + name_ + "/residuals.png" + query;
      j["uncertainty_png"] = "/api/calibration/cameras/" + name_ + "/uncertainty.png" + query;
    }
    return j;
  }

  // The camera's state and live view, at most every kPublishS unless `force`.
  void Publish(bool force) {
    const auto now = Clock::now();
    if (!force && std::chrono::duration<double>(now - last_publish_).count() < kPublishS) return;
    last_publish_ = now;
    nlohmann::json j;
    j["name"] = name_;
    j["frames"] = frames_fed_;
    j["message"] = message_;
    if (!wizard_) {
      j.update({{"width", nullptr},
                {"height", nullptr},
                {"step", settings_.options.intrinsics ? "ground" : "intrinsics"},
                {"detected", false},
                {"still", false},
                {"guidance", {"waiting for the camera's first frame"}},
                {"views", 0},
                {"coverage", {{"grid", nlohmann::json::array()}, {"fraction", 0}}},
                {"diversity", {{"x", 0}, {"y", 0}, {"size", 0}, {"skew", 0}}},
                {"checklist", nlohmann::json::array()},
                {"solve", nullptr},
                {"ground", nullptr},
                {"ground_word_needed", settings_.options.intrinsics.has_value()},
                {"ground_check", nullptr},
                {"enclosure", nullptr},
                {"plan", nullptr}});
      {
        std::lock_guard lock(state_mutex_);
        state_ = std::move(j);
      }
      Told();
      return;
    }
    const calib::CalibrationWizard& w = *wizard_;
    const calib::BoardView& view = w.last_view();
    j["width"] = bgr_.cols;
    j["height"] = bgr_.rows;
    j["step"] = calib::WizardStepName(w.step());
    j["detected"] = !w.done() && view.accepted;
    j["still"] = !w.done() && w.last_still();
    j["guidance"] = guidance_;
    j["views"] = w.views();
    nlohmann::json grid = nlohmann::json::array();
    for (int y = 0; y < w.coverage().rows; ++y) {
      nlohmann::json row = nlohmann::json::array();
      for (int x = 0; x < w.coverage().cols; ++x)
        row.push_back(static_cast<int>(w.coverage().at<float>(y, x)));
      grid.push_back(row);
    }
    j["coverage"] = {{"grid", grid}, {"fraction", w.coverage_fraction()}};
    const calib::ViewDiversity d = w.diversity();
    j["diversity"] = {{"x", d.x}, {"y", d.y}, {"size", d.size}, {"skew", d.skew}};
    j["checklist"] = Checklist(w);
    j["solve"] = SolveJson(w);
    const std::optional<CameraModel> posed = w.posed_model();
    if (posed && w.ground()) {
      const calib::GroundResult& g = *w.ground();
      j["ground"] = {
          {"height_m", g.height_m},
          {"tilt_deg", g.optical_axis_down_deg},
          {"centre_m", {g.centre_in_ground.x(), g.centre_in_ground.y(), g.centre_in_ground.z()}},
          {"rms_px", Num(g.rms_px)}};
      if (fov_.empty()) {
        fov_ = FloorOfView(*posed);
        grid_ = FloorGrid(*posed, fov_);
      }
      j["plan"] = {
          {"position_m", {g.centre_in_ground.x(), g.centre_in_ground.y(), g.centre_in_ground.z()}},
          {"fov_m", Points(fov_)}};
    } else {
      fov_.clear();
      grid_.clear();
      j["ground"] = nullptr;
      j["plan"] = nullptr;
    }
    // The ground step: waiting for the operator's word, and what the last floor board's checks
    // found (a doubtful pose is not taken; `doubt` says why).
    j["ground_word_needed"] = w.waiting_for_word();
    if (const auto& c = w.ground_check()) {
      j["ground_check"] = {
          {"doubt", c->doubt.empty() ? nlohmann::json(nullptr) : nlohmann::json(c->doubt)},
          {"frame", c->frame},
          {"ring_green", Num(c->ring_green)},
          {"height_m", Num(c->height_m)},
          {"axis_down_deg", Num(c->axis_down_deg)},
          {"spread_mm", Num(c->spread_mm)},
          {"spread_deg", Num(c->spread_deg)},
          {"frames", c->frames},
          {"still_s", Num(c->still_s)}};
    } else {
      j["ground_check"] = nullptr;
    }
    std::vector<Eigen::Vector2d> floor_px;
    if (w.floor()) {
      j["enclosure"] = {{"polygon_m", Points(w.floor()->vertices())},
                        {"area_m2", w.floor()->Area()},
                        {"from", w.floor_from()}};
      if (!had_floor_ || w.floor()->vertices() != last_floor_)
        floor_order_.store(++*floor_counter_);
      last_floor_ = w.floor()->vertices();
      if (posed) {
        for (const auto& v : w.floor()->vertices()) {
          const Eigen::Vector3d in_cam =
              posed->cam_from_ground() * Eigen::Vector3d(v.x(), v.y(), 0.0);
          if (in_cam.z() > 0.05) floor_px.push_back(posed->Project(in_cam));
        }
      }
    } else {
      j["enclosure"] = nullptr;
    }
    had_floor_ = w.floor().has_value();
    LiveView live;
    live.bgr = bgr_.clone();
    live.sequence = last_sequence_;
    // A finished wizard searches no more frames: its last detection is not of this image.
    const bool searched = !w.done();
    live.detected = searched && view.accepted;
    live.still = searched && w.last_still();
    if (live.detected) live.corners = view.pixels;
    live.grid = grid_;
    live.floor = std::move(floor_px);
    intrinsics_good_.store(w.intrinsics_good());
    {
      std::lock_guard lock(state_mutex_);
      state_ = std::move(j);
      live_ = std::move(live);
      bgr_width_ = bgr_.cols;
      bgr_height_ = bgr_.rows;
      if (force || captured_.size() != w.captured().size()) captured_ = w.captured();
      ground_pose_.reset();
      floor_view_.reset();
      if (w.ground()) {
        ground_pose_ = w.ground()->cam_from_ground;
        floor_view_ = w.floor_view();
      }
    }
    Told();
  }

  const std::string name_;
  const int index_;
  WizardSettings settings_;
  std::atomic<uint64_t>* floor_counter_;
  std::function<void()> solved_;

  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Frame> frames_;
  std::deque<std::function<void()>> commands_;
  bool stop_ = false;

  // The camera thread's own.
  std::unique_ptr<calib::CalibrationWizard> wizard_;
  cv::Mat bgr_;
  uint64_t frames_fed_ = 0, last_sequence_ = 0;
  std::vector<std::string> guidance_;
  std::string message_;
  bool was_still_ = false;   // the last frame's board was still
  bool posed_told_ = false;  // the wizard was posed at the last frame
  double last_time_s_ = NAN, still_since_s_ = NAN;
  Clock::time_point last_publish_{};
  std::vector<Eigen::Vector2d> fov_;
  std::vector<std::vector<Eigen::Vector2d>> grid_;
  bool had_floor_ = false;
  std::vector<Eigen::Vector2d> last_floor_;

  std::atomic<bool> busy_{false};
  std::thread solver_;  // the last solve's (joined before the next starts, and at the end)
  std::atomic<int> solves_{0};
  std::atomic<uint64_t> floor_order_{0};
  mutable std::mutex state_mutex_;
  nlohmann::json state_;
  std::optional<nlohmann::json> busy_json_;
  LiveView live_;
  // For the joint solve.
  int bgr_width_ = 0, bgr_height_ = 0;
  std::vector<calib::BoardView> captured_;
  std::deque<calib::TimedView> timed_;
  std::deque<double> intervals_;  // between frames of consecutive sequence numbers, seconds
  std::optional<Rigid3> ground_pose_;
  std::optional<calib::BoardView> floor_view_;  // the floor board's, ground_pose_ solved from it
  std::atomic<bool> intrinsics_good_{false};

  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace

struct ConsoleCalibration::Impl {
  api::Context context;
  std::shared_ptr<spdlog::logger> log = Log("station.calibration");

  mutable std::mutex mutex;  // the run below
  bool active = false;
  int run = 0;
  std::string board;
  nlohmann::json options = nlohmann::json::object();
  std::vector<std::string> warnings;
  std::string error;
  nlohmann::json saved;
  bool saving = false;
  std::string work_dir;
  std::atomic<uint64_t> floor_counter{0};
  std::vector<std::shared_ptr<CameraWork>> works;
  // The joint solve of the cameras (issue 41), under `mutex`: started once every camera's
  // intrinsics are trusted, again when a camera is posed after it (the board is laid on the
  // floor after it was held where the cameras all see it: those views came since), or by POST
  // /api/calibration/joint; on joint_thread.
  calib::WizardOptions wizard_options;  // the run's board and solve options
  struct Joint {
    int run = 0;
    bool solving = false;
    std::string stage, error, at;
    double progress = 0;
    std::vector<std::string> names;  // the rig's cameras, in the solve's order
    std::optional<calib::JointRig> rig;
    std::vector<std::string> doubts;  // why the rig is not trusted (not saved); empty: trusted
  } joint;
  int joint_posed = -1;  // cameras posed when the last joint solve started (-1: none started)
  std::mutex joint_thread_mutex;  // joint_thread
  std::thread joint_thread;

  // The station whose frames the wizard takes (re-tapped when the host replaces it).
  std::mutex tap_mutex;
  std::shared_ptr<Station> tapped;
  int station_listener = 0;  // the host's id for OnStationChange (0: none)

  ~Impl() {
    JoinJoint();
    if (!work_dir.empty()) {
      std::error_code ec;
      fs::remove_all(work_dir, ec);
    }
  }

  std::shared_ptr<CameraWork> Work(const std::string& name) const {
    std::lock_guard lock(mutex);
    for (const auto& w : works) {
      if (w->name() == name) return w;
    }
    throw NotFoundError("camera", "\"" + name + "\" is not in the calibration wizard");
  }

  std::vector<std::shared_ptr<CameraWork>> Works() const {
    std::lock_guard lock(mutex);
    return works;
  }

  // The camera a request names (api::ParseCameraName), or every camera of the wizard when it names
  // none.
  std::vector<std::shared_ptr<CameraWork>> Chosen(const std::optional<std::string>& camera) const {
    if (!camera) {
      std::vector<std::shared_ptr<CameraWork>> all = Works();
      if (all.empty()) throw ConflictError("calibration", "no wizard is running: start one");
      return all;
    }
    return {Work(*camera)};
  }

  // `camera`, or without one every camera in `step` ("intrinsics", "ground"): ConflictError
  // naming `what` when none is.
  std::vector<std::shared_ptr<CameraWork>> ChosenInStep(const std::optional<std::string>& camera,
                                                        const std::string& step,
                                                        const std::string& what) const {
    std::vector<std::shared_ptr<CameraWork>> chosen = Chosen(camera);
    if (camera) return chosen;
    std::vector<std::shared_ptr<CameraWork>> in_step;
    for (const auto& w : chosen) {
      if (w->Snapshot().value("step", "") == step) in_step.push_back(w);
    }
    if (in_step.empty()) throw ConflictError(what, "no camera is in the " + step + " step");
    return in_step;
  }

  void RequireActive() const {
    std::lock_guard lock(mutex);
    if (!active) throw ConflictError("calibration", "no wizard is running: start one");
  }

  // Taps the host's current station when it changed (a replay started or stopped, a save
  // restarted it); called by the host's station change listener and after a start.
  void Retap() {
    // tap_mutex first: the station and the run read below are still the latest when they are
    // applied (a start's Retap and the listener's may run at once; the later one wins).
    std::lock_guard tap_lock(tap_mutex);
    std::shared_ptr<Station> current = context.host->current();
    std::vector<std::shared_ptr<CameraWork>> routed;
    bool on = false;
    {
      std::lock_guard lock(mutex);
      on = active;
      routed = works;
    }
    if (!on) {
      if (tapped) tapped->SetFrameWatcher({});
      tapped.reset();
      return;
    }
    if (current == tapped && current) return;
    if (tapped) tapped->SetFrameWatcher({});
    tapped = current;
    if (!current) return;
    // Camera index (the station's config order) -> the wizard's camera of that name.
    const StationStatus status = current->Status();
    auto by_index =
        std::make_shared<std::vector<std::shared_ptr<CameraWork>>>(status.cameras.size());
    for (size_t i = 0; i < status.cameras.size(); ++i) {
      for (const auto& w : routed) {
        if (w->name() == status.cameras[i].name) (*by_index)[i] = w;
      }
    }
    current->SetFrameWatcher([by_index](int camera, const Frame& frame) {
      if (camera < 0 || static_cast<size_t>(camera) >= by_index->size()) return;
      if (const auto& w = (*by_index)[static_cast<size_t>(camera)]) w->Offer(frame);
    });
  }

  void Untap() {
    std::lock_guard lock(tap_mutex);
    if (tapped) tapped->SetFrameWatcher({});
    tapped.reset();
  }

  // The host's station change listener: on the switching thread, once the new station runs.
  void OnStationChange() {
    try {
      Retap();
    } catch (const std::exception& e) {
      log->warn("calibration: cannot take the station's frames: {}", e.what());
    }
  }

  nlohmann::json Start(const nlohmann::json& body) {
    const std::shared_ptr<Station> station = context.station();
    if (station->SessionActive()) {
      throw ConflictError(
          "session",
          "a capture session is running: stop it before calibrating (the board would be "
          "stored as sprites)");
    }
    const StationStatus status = station->Status();
    const api::CalibrationStartRequest r =
        api::ParseCalibrationStart(body, [&](const std::string& name) {
          return std::any_of(status.cameras.begin(), status.cameras.end(),
                             [&](const CameraStatus& c) { return c.name == name; });
        });
    WizardSettings settings;
    calib::WizardOptions& o = settings.options;
    o.board = r.board;
    o.auto_solve = false;
    o.detect.exhaustive = false;  // a frame without a board must stay cheap
    o.verdict.grid_x = o.verdict.grid_y = kGrid;
    o.verdict.max_stdev_percent = 0.5;
    o.verdict.min_views = static_cast<int>(r.min_views.value_or(o.verdict.min_views));
    o.max_views = std::max(o.verdict.min_views, static_cast<int>(r.max_views.value_or(30)));
    o.verdict.min_coverage = r.min_coverage.value_or(o.verdict.min_coverage);
    o.verdict.max_rms_px = r.max_rms_px.value_or(o.verdict.max_rms_px);
    settings.still_s = r.still_s.value_or(0.2);
    settings.floor_still_s = r.floor_still_s.value_or(1.0);
    const double* pose = r.board_pose;
    o.ground_from_board =
        calib::FloorBoardPose(pose[0], pose[1], pose[2], r.board_thickness_m.value_or(0));
    const bool use_current = r.use_current_intrinsics;
    std::vector<std::string> names = r.cameras;
    if (names.empty()) {
      for (const auto& c : status.cameras) names.push_back(c.name);
    }
    std::vector<std::optional<CameraModel>> current(names.size());
    const StationConfig config = context.host->live_config();
    if (use_current) {
      for (size_t i = 0; i < names.size(); ++i) {
        std::optional<CameraModel> model;
        for (const auto& c : config.cameras) {
          if (c.name == names[i]) model = ModelForCamera(c);
        }
        if (!model)
          throw InputError("use_current_intrinsics",
                           names[i] + " has no camera model yet: solve its intrinsics");
        current[i] = model;
      }
    }
    std::vector<std::string> warnings;
    if (o.board.kind == calib::BoardKind::kChessboard) {
      if (o.board.squares_x == o.board.squares_y) {
        warnings.push_back(
            "the board is square (" + std::to_string(o.board.squares_x) + "x" +
            std::to_string(o.board.squares_y) +
            " squares): its orientation is ambiguous, so views "
            "may be matched the wrong way round; use a board with an even and an odd side");
      } else if (o.board.squares_x % 2 == o.board.squares_y % 2) {
        warnings.push_back("the board's sides (" + std::to_string(o.board.squares_x) + "x" +
                           std::to_string(o.board.squares_y) + " squares) are both " +
                           (o.board.squares_x % 2 ? "odd" : "even") +
                           ": it looks the same turned half round; "
                           "use a board with an even and an odd side");
      }
    }

    Stop();  // the previous run's cameras
    std::lock_guard lock(mutex);
    ++run;
    if (work_dir.empty()) {
      work_dir =
          (fs::temp_directory_path() / ("spritestation-calibration-" + std::to_string(::getpid())))
              .string();
    }
    settings.run = run;
    wizard_options = settings.options;
    joint = Joint{};
    joint_posed = -1;
    settings.work_dir = (fs::path(work_dir) / std::to_string(run)).string();
    settings.published = context.status_changed;
    for (size_t i = 0; i < names.size(); ++i) {
      WizardSettings s = settings;
      s.options.intrinsics = current[i];
      int index = 0;
      for (size_t k = 0; k < status.cameras.size(); ++k) {
        if (status.cameras[k].name == names[i]) index = static_cast<int>(k);
      }
      works.push_back(std::make_shared<CameraWork>(names[i], index, s, &floor_counter,
                                                   [this] { StartJoint(false); }));
    }
    active = true;
    board = o.board.ToString();
    this->warnings = warnings;
    error.clear();
    saved = nullptr;
    options = {{"min_views", o.verdict.min_views},
               {"max_views", o.max_views},
               {"min_coverage", o.verdict.min_coverage},
               {"max_rms_px", o.verdict.max_rms_px},
               {"max_stdev_percent", o.verdict.max_stdev_percent},
               {"min_tilt_deg", o.verdict.min_tilt_deg},
               {"board_pose", {pose[0], pose[1], pose[2]}},
               {"use_current_intrinsics", use_current}};
    log->info("calibration wizard started on {} camera(s), board {}", works.size(), board);
    return nullptr;
  }

  // Ends the run: the taps go first, then the cameras' threads.
  void Stop() {
    std::vector<std::shared_ptr<CameraWork>> done;
    {
      std::lock_guard lock(mutex);
      active = false;
      done.swap(works);
    }
    Untap();
    JoinJoint();
    done.clear();
  }

  void JoinJoint() {
    std::lock_guard lock(joint_thread_mutex);
    if (joint_thread.joinable()) joint_thread.join();
  }

  // Starts the joint solve of the cameras whose intrinsics are trusted, on joint_thread: by the
  // operator (`asked`: ConflictError when it cannot start), or after a camera's solve when every
  // camera's intrinsics are trusted and the run has no joint solve yet.
  void StartJoint(bool asked) {
    std::lock_guard thread_lock(joint_thread_mutex);
    std::vector<std::shared_ptr<CameraWork>> chosen;
    int run_id = 0;
    {
      std::lock_guard lock(mutex);
      if (!active) {
        if (asked) throw ConflictError("calibration", "no wizard is running: start one");
        return;
      }
      if (joint.solving) {
        if (asked) throw ConflictError("joint", "a joint solve is running");
        return;
      }
      int posed = 0;
      for (const auto& w : works) {
        if (w->intrinsics_good()) chosen.push_back(w);
        posed += w->posed() ? 1 : 0;
      }
      const bool tried = joint.rig || !joint.error.empty();
      if (!asked && (chosen.size() != works.size() || (tried && posed <= joint_posed))) return;
      if (chosen.size() < 2) {
        if (asked)
          throw ConflictError("joint", std::to_string(chosen.size()) +
                                           " camera(s) have trusted intrinsics; the joint solve "
                                           "needs two or more: solve them first");
        return;
      }
      joint_posed = posed;
      joint.solving = true;
      joint.stage = "starting";
      joint.progress = 0;
      joint.error.clear();
      run_id = run;
    }
    if (joint_thread.joinable()) joint_thread.join();  // the last one, finished
    joint_thread = std::thread([this, chosen, run_id] { SolveJoint(chosen, run_id); });
  }

  // On joint_thread: the instants two or more cameras saw the board, thinned to one per board
  // place, and each camera's captured views, in one solve.
  void SolveJoint(const std::vector<std::shared_ptr<CameraWork>>& chosen, int run_id) {
    calib::WizardOptions o;
    {
      std::lock_guard lock(mutex);
      o = wizard_options;
    }
    Joint result;
    result.run = run_id;
    try {
      std::vector<JointInput> inputs;
      inputs.reserve(chosen.size());
      for (const auto& w : chosen) inputs.push_back(w->Joined());
      std::vector<calib::TimedView> timed;
      std::vector<calib::SolveCamera> cameras;
      std::vector<std::vector<calib::BoardView>> own;
      double interval = NAN;  // the shortest camera's frame interval (none measured: 30 fps)
      for (size_t c = 0; c < inputs.size(); ++c) {
        result.names.push_back(inputs[c].name);
        cameras.push_back({inputs[c].name, inputs[c].width, inputs[c].height});
        own.push_back(inputs[c].captured);
        for (calib::TimedView v : inputs[c].timed) {
          v.camera = static_cast<int>(c);
          timed.push_back(std::move(v));
        }
        if (std::isfinite(inputs[c].frame_interval_s) && !(inputs[c].frame_interval_s >= interval))
          interval = inputs[c].frame_interval_s;
      }
      if (!std::isfinite(interval)) interval = 1.0 / 30;
      const std::vector<calib::BoardObservation> all =
          calib::SimultaneousObservations(timed, 0.5 * interval);
      // One instant per board place: the first camera's view moved kJointMovePx since every
      // kept one (a board held still gives an instant per frame). Views meet when the spans the
      // board stood still in them come within half a frame interval.
      std::vector<calib::BoardObservation> kept;
      std::vector<const calib::BoardObservation*> firsts;
      for (size_t i = 0; i < all.size();) {
        size_t j = i;
        while (j < all.size() && all[j].frame == all[i].frame) ++j;
        const calib::BoardObservation& first = all[i];
        const bool novel = std::none_of(firsts.begin(), firsts.end(), [&](const auto* k) {
          if (k->camera != first.camera || k->ids != first.ids) return false;
          double worst = 0;
          for (size_t p = 0; p < first.pixels.size(); ++p)
            worst = std::max(worst, (first.pixels[p] - k->pixels[p]).norm());
          return worst < kJointMovePx;
        });
        if (novel && firsts.size() < kJointInstants) {
          firsts.push_back(&first);
          kept.insert(kept.end(), all.begin() + static_cast<std::ptrdiff_t>(i),
                      all.begin() + static_cast<std::ptrdiff_t>(j));
        }
        i = j;
      }
      std::string counts;
      for (const auto& in : inputs) counts += " " + in.name + " " + std::to_string(in.timed.size());
      log->info("calibration: joint solve: still views{}; {} matched within {:.3f} s, {} kept",
                counts, all.size(), 0.5 * interval, kept.size());
      if (firsts.size() < kMinJointInstants) {
        throw InputError("joint", std::to_string(firsts.size()) +
                                      " board places seen still by two cameras at once (need " +
                                      std::to_string(kMinJointInstants) +
                                      "): hold the board where both see it, still for a moment, "
                                      "in several places");
      }
      calib::SolveOptions so = o.solve;
      // Between the solve's stages: its figures for the page, and the end of the run (cancel,
      // or a new run) ends it there, so that Stop waits for one stage at most, not the solve.
      so.progress = [this, run_id](const std::string& stage, double fraction) {
        std::lock_guard lock(mutex);
        if (!active || run != run_id)
          throw WorkError("joint", "cancelled: the calibration run ended");
        joint.stage = stage;
        joint.progress = fraction;
      };
      result.rig = calib::SolveJointRig(o.board, cameras, own, kept, so);
      result.at = UtcNowIso();
      // Saved instead of the cameras' own models only when trusted as their own solves are.
      const calib::SolveSummary& sol = result.rig->solution;
      for (size_t c = 0; c < cameras.size(); ++c) {
        const double percent = result.rig->focal_stdev_percent[c];
        if (!(percent <= o.verdict.max_stdev_percent)) {
          result.doubts.push_back(cameras[c].name + ": focal length known to " +
                                  (std::isfinite(percent) ? std::to_string(percent) : "?") +
                                  " % (1.96 sigma), need " +
                                  std::to_string(o.verdict.max_stdev_percent) + " %");
        }
        if (!(sol.rms_px[c] <= o.verdict.max_rms_px)) {
          result.doubts.push_back(cameras[c].name + ": RMS " + std::to_string(sol.rms_px[c]) +
                                  " px, need " + std::to_string(o.verdict.max_rms_px));
        }
      }
      log->info("calibration: joint solve of {} cameras, {} shared instants: {}", cameras.size(),
                result.rig->shared_frames, result.rig->solution.summary);
    } catch (const std::exception& e) {
      result.error = std::string("joint solve failed: ") + e.what();
      log->warn("calibration: {}", result.error);
    }
    std::lock_guard lock(mutex);
    if (run != run_id) return;  // a new run started meanwhile
    joint = std::move(result);
  }

  // The joint solve's state for the page: per camera its uncertainty, per camera pair the
  // relative pose and where it disagrees with the two cameras' own floor-board poses.
  nlohmann::json JointJson() const {
    Joint j;
    {
      std::lock_guard lock(mutex);
      if (joint.solving) {
        return {{"state", "solving"}, {"stage", joint.stage}, {"progress", joint.progress}};
      }
      j = joint;
    }
    if (!j.error.empty()) return {{"state", "failed"}, {"error", j.error}};
    if (!j.rig) return nullptr;
    const calib::JointRig& rig = *j.rig;
    const calib::SolveSummary& s = rig.solution;
    std::vector<std::optional<Rigid3>> ground;
    for (const auto& name : j.names) {
      std::optional<Rigid3> pose;
      try {
        pose = Work(name)->GroundPose();
      } catch (const NotFoundError&) {
      }
      ground.push_back(pose);
    }
    nlohmann::json out = {{"state", "solved"},
                          {"at", j.at},
                          {"trusted", j.doubts.empty()},
                          {"doubts", j.doubts},
                          {"shared_instants", rig.shared_frames},
                          {"rms_px", s.mrcal_rms_px},
                          {"posed_from", nullptr},
                          {"cameras", nlohmann::json::array()},
                          {"pairs", nlohmann::json::array()}};
    for (size_t c = 0; c < j.names.size(); ++c) {
      if (ground[c] && out["posed_from"].is_null()) out["posed_from"] = j.names[c];
      nlohmann::json cam = {{"name", j.names[c]},
                            {"views", rig.views[c]},
                            {"rms_px", Num(s.rms_px[c])},
                            {"distance_m", Num(rig.distance_m[c])},
                            {"stdev_centre_px", Num(rig.stdev_px[c])},
                            {"stdev_worst_px", Num(rig.stdev_worst[c])},
                            {"focal_stdev_percent", Num(rig.focal_stdev_percent[c])}};
      out["cameras"].push_back(std::move(cam));
    }
    for (size_t a = 0; a < j.names.size(); ++a) {
      for (size_t b = a + 1; b < j.names.size(); ++b) {
        // b_from_a = b_from_0 * a_from_0^-1
        const Rigid3 b_from_a =
            s.models[b].cam_from_ground() * s.models[a].cam_from_ground().Inverse();
        nlohmann::json pair = {{"a", j.names[a]},
                               {"b", j.names[b]},
                               {"baseline_m", b_from_a.translation.norm()},
                               {"translation_mm", nullptr},
                               {"rotation_deg", nullptr},
                               {"floor_point_mm", nullptr}};
        if (ground[a] && ground[b]) {
          const calib::PairDisagreement d =
              calib::CompareRelativePose(b_from_a, *ground[a], *ground[b]);
          pair["translation_mm"] = Num(d.translation_mm);
          pair["rotation_deg"] = Num(d.rotation_deg);
          pair["floor_point_mm"] = Num(d.floor_point_mm);
        }
        out["pairs"].push_back(std::move(pair));
      }
    }
    return out;
  }

  // The joint models to save: each rig camera's joint intrinsics, posed through the rig from the
  // first camera with a floor-board pose (none posed: the intrinsics alone). That camera's pose is
  // solved again from its floor board's view with its joint intrinsics (the wizard's was solved
  // with its own, which the joint model saved does not share); the wizard's pose when that fails.
  // Empty without a joint solve.
  std::vector<std::pair<std::string, CameraModel>> JointModels() const {
    Joint j;
    calib::WizardOptions o;
    {
      std::lock_guard lock(mutex);
      if (!joint.rig || !joint.doubts.empty()) return {};
      j = joint;
      o = wizard_options;
    }
    std::vector<std::pair<std::string, CameraModel>> out;
    std::vector<Rigid3> poses;
    for (size_t c = 0; c < j.names.size() && poses.empty(); ++c) {
      std::optional<Rigid3> g;
      std::optional<calib::BoardView> view;
      try {
        const auto work = Work(j.names[c]);
        g = work->GroundPose();
        view = work->FloorView();
      } catch (const NotFoundError&) {
      }
      if (!g) continue;
      if (view && view->accepted) {
        try {
          poses = calib::PoseRigFromFloorView(*j.rig, static_cast<int>(c), o.board, *view,
                                              o.ground_from_board, j.names[c]);
          continue;
        } catch (const std::runtime_error& e) {
          Log("station.calibration")
              ->warn("{}: the floor pose with the joint intrinsics: {}; the wizard's kept",
                     j.names[c], e.what());
        }
      }
      poses = calib::PoseRigFrom(*j.rig, static_cast<int>(c), *g);
    }
    for (size_t c = 0; c < j.names.size(); ++c) {
      CameraModel m = j.rig->solution.models[c];
      m.set_cam_from_ground(poses.empty() ? Rigid3{} : poses[c]);
      out.emplace_back(j.names[c], m);
    }
    return out;
  }

  nlohmann::json Save() {
    RequireActive();
    {
      std::lock_guard lock(mutex);
      if (saving) throw ConflictError("save", "a save is running");
      saving = true;
    }
    // (before the checks below: a refused save is not left "saving")
    struct Unbusy {
      Impl* s;
      ~Unbusy() {
        std::lock_guard lock(s->mutex);
        s->saving = false;
      }
    } unbusy{this};
    for (const auto& w : Works()) {
      if (w->Busy()) throw ConflictError("save", w->name() + " is solving; save when it is done");
    }
    {
      std::lock_guard lock(mutex);
      if (joint.solving)
        throw ConflictError("save", "the joint solve is running; save when it is done");
    }
    calib::StationSaveRequest request;
    uint64_t floor_order = 0;
    for (const auto& w : Works()) {
      std::optional<CameraModel> model;
      std::optional<GroundPolygon> floor;
      try {
        std::tie(model, floor) = w->Run([](calib::CalibrationWizard& wiz) {
          std::optional<CameraModel> m = wiz.posed_model();
          if (!m && wiz.intrinsics_good() && wiz.intrinsics_model()) m = wiz.intrinsics_model();
          return std::make_pair(m, wiz.floor());
        });
      } catch (const ConflictError&) {
        continue;  // no frame yet: nothing of it to save
      }
      if (model) request.models.emplace_back(w->name(), *model);
      if (floor && w->floor_order() >= floor_order)
        floor_order = w->floor_order(), request.floor = floor;
    }
    // The rig's cameras: their joint models (intrinsics, and the poses relative to each other)
    // instead of each one's own.
    for (auto& joint_model : JointModels()) {
      auto it = std::find_if(request.models.begin(), request.models.end(),
                             [&](const auto& m) { return m.first == joint_model.first; });
      if (it == request.models.end()) {
        request.models.push_back(std::move(joint_model));
      } else {
        it->second = std::move(joint_model.second);
      }
    }
    if (request.models.empty()) {
      throw ConflictError("save", "no camera has trusted intrinsics yet: solve first");
    }
    const StationConfig config = context.host->live_config();
    fs::path dir = context.config_path.empty() ? fs::path(config.storage.bank).parent_path()
                                               : fs::path(context.config_path).parent_path();
    request.config_path = context.config_path;
    request.calibration_dir = (dir / "calibration").string();
    request.stamp = UtcNowStamp();
    calib::StationSaveResult result;
    try {
      result = calib::SaveStationCalibration(config, request);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      error = std::string("not saved: ") + e.what() + " (nothing already saved was changed)";
      throw;
    }
    nlohmann::json j = {
        {"at", UtcNowIso()},
        {"files", result.files},
        {"previous", result.previous},
        {"config", context.config_path.empty() ? nlohmann::json(nullptr)
                                               : nlohmann::json(context.config_path)},
        {"cameras", nlohmann::json::array()},
        {"station_restarted", false}};
    for (const auto& [name, model] : request.models) j["cameras"].push_back(name);
    {
      std::lock_guard lock(mutex);
      saved = j;
      error.clear();
    }
    log->info("calibration saved: {}", api::Dump(result.files));
    // The live station restarts with them (a replay keeps running; the live station uses them when
    // it stops).
    try {
      const bool restarted = context.host->ApplyLiveConfig(result.config);
      j["station_restarted"] = restarted;
      if (!restarted) j["note"] = "a replay is running: the live station uses them when it stops";
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      error = std::string("saved, but the station could not start with them: ") + e.what();
      saved = j;
      throw WorkError("station", error);
    }
    // A restarted station is tapped already (OnStationChange ran before ApplyLiveConfig returned).
    std::lock_guard lock(mutex);
    saved = j;
    return j;
  }

  nlohmann::json State() const {
    nlohmann::json joint_json = JointJson();  // takes `mutex` itself
    std::lock_guard lock(mutex);
    nlohmann::json j;
    j["joint"] = std::move(joint_json);
    j["active"] = active;
    j["run"] = run;
    j["board"] = board;
    j["warnings"] = warnings;
    j["options"] = options;
    j["error"] = error.empty() ? nlohmann::json(nullptr) : nlohmann::json(error);
    j["saved"] = saved;
    j["busy"] = nullptr;
    if (joint.solving) {
      j["busy"] = {{"what", "joint solve"},
                   {"camera", nullptr},
                   {"stage", joint.stage},
                   {"progress", joint.progress}};
    }
    if (saving)
      j["busy"] = {
          {"what", "save"}, {"camera", nullptr}, {"stage", "writing the files"}, {"progress", 0.5}};
    j["cameras"] = nlohmann::json::array();
    int least = 3;
    for (const auto& w : works) {
      nlohmann::json c = w->Snapshot();
      if (const auto busy = w->Busy()) j["busy"] = *busy;
      const std::string step = c.value("step", "intrinsics");
      least = std::min(least, step == "intrinsics"  ? 0
                              : step == "ground"    ? 1
                              : step == "enclosure" ? 2
                                                    : 3);
      j["cameras"].push_back(std::move(c));
    }
    if (!active) {
      j["step"] = saved.is_null() ? "idle" : "saved";
    } else if (works.empty()) {
      j["step"] = "idle";
    } else {
      static const char* kSteps[] = {"intrinsics", "ground", "enclosure", "save"};
      j["step"] = kSteps[least];
      if (least == 3 && !saved.is_null()) j["step"] = "saved";
    }
    return j;
  }
};

ConsoleCalibration::ConsoleCalibration(api::Context context) : impl_(std::make_unique<Impl>()) {
  impl_->context = std::move(context);
  if (impl_->context.host) {
    impl_->station_listener =
        impl_->context.host->AddStationChangeListener([s = impl_.get()] { s->OnStationChange(); });
  }
}

ConsoleCalibration::~ConsoleCalibration() { Stop(); }

void ConsoleCalibration::Stop() {
  Impl& s = *impl_;
  if (s.station_listener != 0) {
    s.context.host->RemoveStationChangeListener(s.station_listener);  // not running after this
    s.station_listener = 0;
  }
  s.Stop();
}

nlohmann::json ConsoleCalibration::State() const { return impl_->State(); }

nlohmann::json ConsoleCalibration::StateWithCameras() const {
  nlohmann::json status;
  try {
    status = StatusToJson(impl_->context.station()->Status());
  } catch (const std::exception&) {
    status = nlohmann::json::object();  // no station: no camera is online
  }
  AddStatus(status);
  return status["calibration"];
}

void ConsoleCalibration::AddStatus(nlohmann::json& status) const {
  nlohmann::json calibration = State();
  // Whether each camera delivers, as the station sees it.
  std::string offline;
  if (status.contains("cameras") && status["cameras"].is_array()) {
    for (auto& c : calibration["cameras"]) {
      bool online = false;
      std::string message;
      for (const auto& s : status["cameras"]) {
        if (s.value("name", "") != c.value("name", "")) continue;
        const std::string state = s.value("state", "");
        // A camera in error whose frames still come (its keyer failed: it streams for preview
        // and recording) delivers to the wizard: not offline, its live view kept.
        online = state == "live" || state == "training" || state == "starting" ||
                 (state == "error" && s.value("fps", 0.0) > 0);
        if (!online)
          message = state + (s.value("message", "").empty() ? "" : ": " + s.value("message", ""));
      }
      c["online"] = online;
      if (!online && calibration.value("active", false)) {
        if (c.value("message", "").empty()) c["message"] = message;
        if (offline.empty()) {
          offline = c.value("name", "") + " delivers no frames (" +
                    (message.empty() ? "not in the station" : message) +
                    "); the views captured so far are kept";
        }
      }
    }
  }
  if (calibration["error"].is_null() && !offline.empty()) calibration["error"] = offline;
  status["calibration"] = std::move(calibration);
}

std::vector<api::Route> ConsoleCalibration::Routes() {
  Impl* s = impl_.get();
  using httplib::Request;
  using httplib::Response;
  auto state_after = [this](auto f) {
    return api::Json([this, f](const Request& req) {
      f(req);
      return StateWithCameras();
    });
  };
  auto camera_png = [s](const char* kind) {
    return [s, kind](const Request& req, Response& res) {
      const std::shared_ptr<CameraWork> w = s->Work(api::PathText(req));
      std::ifstream in(w->PlotPath(kind), std::ios::binary);
      if (w->solves() == 0 || !in)
        throw NotFoundError(std::string(kind), "no solve of " + w->name() + " yet");
      std::ostringstream bytes;
      bytes << in.rdbuf();
      res.set_header("Cache-Control", "no-store");
      res.set_content(bytes.str(), "image/png");
    };
  };
  return {
      {"GET", "/api/calibration", "GET /api/calibration",
       api::Json([this](const Request&) { return StateWithCameras(); })},
      {"POST", "/api/calibration/start",
       "POST /api/calibration/start {\"board\", \"cameras\", \"board_pose\", "
       "\"board_thickness_m\", \"min_views\", "
       "\"max_views\", \"min_coverage\", \"max_rms_px\", \"still_s\", \"floor_still_s\", "
       "\"use_current_intrinsics\"}",
       state_after([s](const Request& req) {
         s->Start(api::ObjectBody(req, api::kCalibrationStartFields));
         s->Retap();
       })},
      {"POST", "/api/calibration/cancel", "POST /api/calibration/cancel",
       state_after([s](const Request& req) {
         api::ObjectBody(req, {});
         s->RequireActive();
         s->Stop();
         std::lock_guard lock(s->mutex);
         s->error.clear();
       })},
      {"POST", "/api/calibration/drop",
       "POST /api/calibration/drop {\"camera\", \"which\": \"last\" | \"worst\"}",
       state_after([s](const Request& req) {
         const api::CalibrationDropRequest r =
             api::ParseCalibrationDrop(api::ObjectBody(req, api::kCalibrationDropFields));
         const std::string& which = r.which;
         for (const auto& w : s->Chosen(r.camera)) {
           w->Run([&](calib::CalibrationWizard& wiz) {
             try {
               which == "last" ? wiz.DropLast() : wiz.DropWorst();
             } catch (const InputError& e) {
               throw ConflictError(w->name(), e.what());
             }
             return 0;
           });
         }
       })},
      {"POST", "/api/calibration/solve",
       "POST /api/calibration/solve {\"camera\"} (202: runs in the background)",
       [this, s](const Request& req, Response& res) {
         const nlohmann::json body = api::ObjectBody(req, api::kCalibrationSolveFields);
         s->RequireActive();
         const std::optional<std::string> camera = api::ParseCameraName(body, false);
         const std::vector<std::shared_ptr<CameraWork>> chosen =
             s->ChosenInStep(camera, "intrinsics", "solve");
         for (const auto& w : chosen) w->StartSolve();
         api::Reply(res, 202, StateWithCameras());
       }},
      {"POST", "/api/calibration/ground",
       "POST /api/calibration/ground {\"camera\"} (the board lies on the floor now)",
       state_after([s](const Request& req) {
         const nlohmann::json body = api::ObjectBody(req, api::kCalibrationGroundFields);
         s->RequireActive();
         const std::optional<std::string> camera = api::ParseCameraName(body, false);
         const std::vector<std::shared_ptr<CameraWork>> chosen =
             s->ChosenInStep(camera, "ground", "ground");
         for (const auto& w : chosen) {
           w->Run([&](calib::CalibrationWizard& wiz) {
             try {
               wiz.BoardOnFloor(-1);
             } catch (const InputError& e) {
               throw ConflictError(w->name(), e.what());
             }
             return 0;
           });
         }
       })},
      {"POST", "/api/calibration/redo",
       "POST /api/calibration/redo {\"camera\", \"step\": \"intrinsics\" | \"ground\" | "
       "\"enclosure\"}",
       state_after([s](const Request& req) {
         const api::CalibrationRedoRequest r =
             api::ParseCalibrationRedo(api::ObjectBody(req, api::kCalibrationRedoFields));
         const WizardStep step = r.step;
         for (const auto& w : s->Chosen(r.camera)) {
           w->Run([&](calib::CalibrationWizard& wiz) {
             try {
               wiz.Redo(step);
             } catch (const InputError& e) {
               throw ConflictError(w->name(), e.what());
             }
             return 0;
           });
         }
         std::lock_guard lock(s->mutex);
         s->saved = nullptr;
         if (step == WizardStep::kIntrinsics && !s->joint.solving)
           s->joint = Impl::Joint{};  // of intrinsics that went
       })},
      {"POST", "/api/calibration/joint",
       "POST /api/calibration/joint (202: solves every camera with trusted intrinsics jointly, "
       "in the background)",
       [this, s](const Request& req, Response& res) {
         api::ObjectBody(req, {});
         s->StartJoint(true);
         api::Reply(res, 202, StateWithCameras());
       }},
      {"POST", "/api/calibration/floor",
       "POST /api/calibration/floor {\"camera\", \"detect\": true} | {\"camera\", \"pixels\": [[x, "
       "y], ...]}",
       state_after([s](const Request& req) {
         const nlohmann::json body = api::ObjectBody(req, api::kCalibrationFloorFields);
         const std::shared_ptr<CameraWork> w = s->Chosen(api::ParseCameraName(body, true)).front();
         const api::CalibrationFloorRequest r = api::ParseCalibrationFloor(body);
         if (!r.detect) {
           w->Run([&](calib::CalibrationWizard& wiz) {
             if (!wiz.posed_model())
               throw ConflictError(w->name(), "is not posed yet: finish the ground step first");
             wiz.SetFloorFromPixels(r.pixels);
             return 0;
           });
         } else {
           const LiveView live = w->Live();
           w->Run([&](calib::CalibrationWizard& wiz) {
             if (!wiz.posed_model())
               throw ConflictError(w->name(), "is not posed yet: finish the ground step first");
             if (live.bgr.empty())
               throw ConflictError(w->name(), "has no frame to find the floor in");
             try {
               wiz.DetectFloor(live.bgr);
             } catch (const InputError& e) {
               throw InputError("detect",
                                std::string("no green floor found: ") + e.what() +
                                    "; clear the floor, or click its corners on the image");
             }
             return 0;
           });
         }
         std::lock_guard lock(s->mutex);
         s->saved = nullptr;
       })},
      {"POST", "/api/calibration/save", "POST /api/calibration/save",
       api::Json([this, s](const Request& req) {
         api::ObjectBody(req, {});
         s->Save();
         return StateWithCameras();
       })},
      {"GET", R"(/api/calibration/cameras/([^/]+)/view\.json)",
       "GET /api/calibration/cameras/NAME/view.json?width=W",
       [s](const Request& req, Response& res) {
         const std::shared_ptr<CameraWork> w = s->Work(api::PathText(req));
         const int width = static_cast<int>(api::IntParam(req, "width", 640, 16, 4096));
         const LiveView live = w->Live();
         if (live.bgr.empty()) {
           api::ReplyError(res, 503,
                           "camera \"" + w->name() + "\" has delivered no frame to the wizard yet");
           return;
         }
         const double scale = std::min(1.0, static_cast<double>(width) / live.bgr.cols);
         cv::Mat image = live.bgr;
         if (scale < 1.0) cv::resize(live.bgr, image, cv::Size(), scale, scale, cv::INTER_AREA);
         nlohmann::json grid = nlohmann::json::array();
         for (const auto& line : live.grid) grid.push_back(Points(line));
         const nlohmann::json j = {{"frame", live.sequence},
                                   {"width", live.bgr.cols},
                                   {"height", live.bgr.rows},
                                   {"scale", scale},
                                   {"image", "data:image/jpeg;base64," + Base64(EncodeJpeg(image))},
                                   {"detected", live.detected},
                                   {"still", live.still},
                                   {"corners", Points(live.corners)},
                                   {"grid", grid},
                                   {"floor", Points(live.floor)}};
         res.set_header("Cache-Control", "no-store");
         res.set_content(api::Dump(j), "application/json");
       }},
      {"GET", R"(/api/calibration/cameras/([^/]+)/residuals\.png)",
       "GET /api/calibration/cameras/NAME/residuals.png", camera_png("residuals")},
      {"GET", R"(/api/calibration/cameras/([^/]+)/uncertainty\.png)",
       "GET /api/calibration/cameras/NAME/uncertainty.png", camera_png("uncertainty")},
  };
}

}  // namespace ss
