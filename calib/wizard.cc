#include "calib/wizard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/enclosure.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"

namespace ss::calib {
namespace {

bool SameIds(const BoardView& a, const BoardView& b) { return a.ids == b.ids; }

double MaxMotion(const BoardView& a, const BoardView& b) {
  double worst = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    worst = std::max(worst, (a.pixels[i] - b.pixels[i]).norm());
  return worst;
}

std::string Fmt(const char* format, double a, double b = 0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, format, a, b);
  return buf;
}

}  // namespace

const char* WizardStepName(WizardStep step) {
  switch (step) {
    case WizardStep::kIntrinsics:
      return "intrinsics";
    case WizardStep::kGround:
      return "ground";
    case WizardStep::kEnclosure:
      return "enclosure";
    case WizardStep::kDone:
      return "done";
  }
  return "?";
}

bool WizardOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(detect.IsValid(&part), "detect.", part);
  check.Nested(verdict.IsValid(&part), "verdict.", part);
  check.Nested(solve.IsValid(&part), "solve.", part);
  check(still_px > 0, "still_px",
        "expected a positive motion in pixels, got " + OptionProblems::Num(still_px));
  check(still_frames >= 1, "still_frames",
        "expected at least 1 frame, got " + std::to_string(still_frames));
  check(min_shift >= 0, "min_shift",
        "expected a fraction >= 0, got " + OptionProblems::Num(min_shift));
  check(min_tilt_change_deg >= 0, "min_tilt_change_deg",
        "expected degrees >= 0, got " + OptionProblems::Num(min_tilt_change_deg));
  check(min_scale_change >= 0, "min_scale_change",
        "expected a fraction >= 0, got " + OptionProblems::Num(min_scale_change));
  check(min_new_cells >= 0, "min_new_cells",
        "expected a number >= 0, got " + std::to_string(min_new_cells));
  check(max_views >= 1, "max_views", "expected at least 1 view, got " + std::to_string(max_views));
  check(floor_still_frames >= 1, "floor_still_frames",
        "expected at least 1 frame, got " + std::to_string(floor_still_frames));
  return check.ok();
}

CalibrationWizard::CalibrationWizard(std::string camera, int width, int height,
                                     WizardOptions options)
    : camera_(std::move(camera)), width_(width), height_(height), o_(std::move(options)) {
  if (std::string why; !o_.IsValid(&why)) throw InputError("calibration wizard options", why);
  coverage_ = cv::Mat(o_.verdict.grid_y, o_.verdict.grid_x, CV_32F, cv::Scalar(0));
  if (o_.intrinsics) {
    if (o_.intrinsics->width() != width_ || o_.intrinsics->height() != height_) {
      throw InputError("--intrinsics",
                       "the model's imager is " + std::to_string(o_.intrinsics->width()) + "x" +
                           std::to_string(o_.intrinsics->height()) + " but the camera delivers " +
                           std::to_string(width_) + "x" + std::to_string(height_));
    }
    intrinsics_model_ = o_.intrinsics;
    intrinsics_good_ = true;
    step_ = WizardStep::kGround;
  }
  next_solve_at_ = o_.verdict.min_views;
  Event(-1, "start",
        {{"camera", camera_},
         {"imager", {width_, height_}},
         {"board", o_.board.ToString()},
         {"step", WizardStepName(step_)}});
}

void CalibrationWizard::Event(int frame, const std::string& kind, nlohmann::json detail) {
  detail["frame"] = frame;
  detail["event"] = kind;
  detail["step"] = WizardStepName(step_);
  log_.push_back(std::move(detail));
}

double CalibrationWizard::coverage_fraction() const {
  return cv::countNonZero(coverage_) / static_cast<double>(coverage_.total());
}

double CalibrationWizard::Focal() const {
  // A pinhole guess for the tilt of each view: from the captured views once
  // there are a few, else a normal lens.
  if (views_.size() >= 3) {
    std::vector<std::vector<cv::Point3f>> object;
    std::vector<std::vector<cv::Point2f>> image;
    for (const auto& v : views_) {
      object.emplace_back();
      image.emplace_back();
      for (size_t i = 0; i < v.ids.size(); ++i) {
        const Eigen::Vector3d p = o_.board.Corner(v.ids[i]);
        object.back().emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
        image.back().emplace_back(static_cast<float>(v.pixels[i].x()),
                                  static_cast<float>(v.pixels[i].y()));
      }
    }
    try {
      const cv::Mat k = cv::initCameraMatrix2D(object, image, cv::Size(width_, height_), 1.0);
      const double f = 0.5 * (k.at<double>(0, 0) + k.at<double>(1, 1));
      if (std::isfinite(f) && f > 0.2 * width_ && f < 10.0 * width_) return f;
    } catch (const cv::Exception&) {
    }
  }
  return 0.8 * width_;
}

CalibrationWizard::Captured CalibrationWizard::Describe(const BoardView& view) const {
  Captured d;
  Eigen::Vector2d lo = view.pixels.front(), hi = lo, sum = Eigen::Vector2d::Zero();
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    lo = lo.cwiseMin(view.pixels[i]);
    hi = hi.cwiseMax(view.pixels[i]);
    sum += view.pixels[i];
    const Eigen::Vector3d p = o_.board.Corner(view.ids[i]);
    object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
    image.emplace_back(static_cast<float>(view.pixels[i].x()),
                       static_cast<float>(view.pixels[i].y()));
  }
  d.centre = sum / static_cast<double>(view.pixels.size());
  d.area = (hi - lo).prod();
  d.normal = Eigen::Vector3d::UnitZ();
  const double f = Focal();
  const cv::Matx33d k(f, 0, (width_ - 1) / 2.0, 0, f, (height_ - 1) / 2.0, 0, 0, 1);
  cv::Mat rvec, tvec;
  try {
    if (cv::solvePnP(object, image, k, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
      cv::Mat r;
      cv::Rodrigues(rvec, r);
      d.normal = {r.at<double>(0, 2), r.at<double>(1, 2), r.at<double>(2, 2)};
    }
  } catch (const cv::Exception&) {
  }
  return d;
}

bool CalibrationWizard::Novel(const BoardView& view, const Captured& d, std::string* why) const {
  int new_cells = 0;
  cv::Mat seen = coverage_.clone();
  for (const auto& p : view.pixels) {
    const int gx =
        std::clamp(static_cast<int>(p.x() / width_ * coverage_.cols), 0, coverage_.cols - 1);
    const int gy =
        std::clamp(static_cast<int>(p.y() / height_ * coverage_.rows), 0, coverage_.rows - 1);
    if (seen.at<float>(gy, gx) == 0) ++new_cells, seen.at<float>(gy, gx) = 1;
  }
  if (described_.empty()) {
    *why = "first view";
    return true;
  }
  if (new_cells >= o_.min_new_cells) {
    *why = std::to_string(new_cells) + " new coverage cells";
    return true;
  }
  const double diagonal = std::hypot(width_, height_);
  for (const auto& c : described_) {
    const bool moved = (d.centre - c.centre).norm() > o_.min_shift * diagonal;
    const double turn =
        std::acos(std::clamp(std::abs(d.normal.dot(c.normal)), 0.0, 1.0)) * 180 / M_PI;
    const bool turned = turn > o_.min_tilt_change_deg;
    const bool resized =
        std::abs(std::log(d.area / std::max(1.0, c.area))) > std::log1p(o_.min_scale_change);
    if (!moved && !turned && !resized) return false;
  }
  *why = "new place, angle or size";
  return true;
}

void CalibrationWizard::Capture(const BoardView& view, const Captured& d, int frame,
                                const std::string& why) {
  views_.push_back(view);
  described_.push_back(d);
  for (const auto& p : view.pixels) {
    const int gx =
        std::clamp(static_cast<int>(p.x() / width_ * coverage_.cols), 0, coverage_.cols - 1);
    const int gy =
        std::clamp(static_cast<int>(p.y() / height_ * coverage_.rows), 0, coverage_.rows - 1);
    coverage_.at<float>(gy, gx) += 1;
  }
  const double tilt = std::acos(std::clamp(std::abs(d.normal.z()), 0.0, 1.0)) * 180 / M_PI;
  max_tilt_deg_ = std::max(max_tilt_deg_, tilt);
  Event(frame, "capture",
        {{"view", static_cast<int>(views_.size())},
         {"why", why},
         {"corners", view.ids.size()},
         {"tilt_deg", tilt},
         {"coverage", coverage_fraction()}});
}

std::vector<std::string> CalibrationWizard::MissingForIntrinsics() const {
  std::vector<std::string> out;
  for (const auto& region : EmptyRegions(coverage_)) out.push_back("cover the " + region);
  if (coverage_fraction() < o_.verdict.min_coverage) {
    if (out.empty()) {
      out.push_back(Fmt("cover more of the image (%.0f%% of the cells, need %.0f%%)",
                        coverage_fraction() * 100, o_.verdict.min_coverage * 100));
    }
  }
  if (max_tilt_deg_ < o_.verdict.min_tilt_deg) {
    out.push_back(Fmt("tilt the board more (most tilted view %.0f deg, need %.0f)", max_tilt_deg_,
                      o_.verdict.min_tilt_deg));
  }
  if (views() < o_.verdict.min_views) {
    out.push_back("capture more views (" + std::to_string(views()) + " of " +
                  std::to_string(o_.verdict.min_views) + ")");
  }
  return out;
}

bool CalibrationWizard::CriteriaMet() const {
  return views() >= o_.verdict.min_views && coverage_fraction() >= o_.verdict.min_coverage &&
         EmptyRegions(coverage_).empty() && max_tilt_deg_ >= o_.verdict.min_tilt_deg;
}

void CalibrationWizard::SolveIntrinsics(int frame) {
  std::vector<BoardObservation> obs;
  for (size_t i = 0; i < views_.size(); ++i)
    obs.push_back({0, static_cast<int>(i), views_[i].source, views_[i].ids, views_[i].pixels});
  try {
    solution_ = SolveBoards(o_.board, {{camera_, width_, height_}}, obs, o_.solve);
    report_ = MakeCameraReport(o_.board, *solution_, 0, views_, o_.verdict);
    report_->camera = camera_;
  } catch (const std::runtime_error& e) {
    solution_.reset();
    report_ = FailedCameraReport(camera_, views_, e.what());
  }
  intrinsics_good_ = report_->good;
  Event(frame, "solve",
        {{"views", views()},
         {"verdict", intrinsics_good_ ? "good" : "rejected"},
         {"reasons", report_->reasons},
         {"rms_px", solution_ ? solution_->rms_px[0] : NAN}});
  if (intrinsics_good_) {
    intrinsics_model_ = solution_->models[0];
    intrinsics_model_->set_cam_from_ground(Rigid3{});
    EnterGround(frame);
  } else {
    next_solve_at_ = views() + 5;  // more views before trying again
  }
}

void CalibrationWizard::EnterGround(int frame) {
  step_ = WizardStep::kGround;
  run_.clear();
  run_used_ = false;
  Event(frame, "step");
}

void CalibrationWizard::EnterEnclosure(int frame, const cv::Mat& image) {
  step_ = WizardStep::kEnclosure;
  empty_frames_ = 0;
  Event(frame, "step");
  if (!o_.floor_points.empty()) {
    try {
      floor_ = FloorPolygonFromPoints(o_.floor_points, "--floor-points");
      floor_from_ = "given points";
      step_ = WizardStep::kDone;
      Event(frame, "enclosure", {{"from", "given points"}, {"area_m2", floor_->Area()}});
    } catch (const InputError& e) {
      verdicts_.push_back(std::string("enclosure: ") + e.what());
      step_ = WizardStep::kDone;
      Event(frame, "verdict", {{"reason", e.what()}});
    }
    return;
  }
  try {
    floor_with_board_ = GreenFloorIn(image);
  } catch (const std::runtime_error& e) {
    floor_with_board_error_ = e.what();
  }
}

GroundPolygon CalibrationWizard::GreenFloorIn(const cv::Mat& image) const {
  const std::optional<CameraModel> posed = posed_model();
  if (!posed) throw WorkError(camera_, "no ground pose to find the floor with");
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  return FindGreenFloor(*posed, bgr);
}

void CalibrationWizard::TryEmptyFloor(const cv::Mat& image, int frame) {
  const std::string from = "the empty floor";
  try {
    GroundPolygon found = GreenFloorIn(image);
    // No board in view is not yet an empty floor: a person or a board held up hides part of
    // it. Taking the board off the floor can only uncover green, so an empty floor shows at
    // least what the frame with the board lying on it showed.
    const double with_board_m2 = floor_with_board_ ? floor_with_board_->Area() : 0.0;
    if (found.Area() < 0.95 * with_board_m2) {
      Event(frame, "enclosure_rejected",
            {{"from", from}, {"area_m2", found.Area()}, {"with_board_m2", with_board_m2}});
      return;
    }
    floor_ = std::move(found);
    floor_from_ = "green floor";
    step_ = WizardStep::kDone;
    Event(frame, "enclosure",
          {{"from", from}, {"area_m2", floor_->Area()}, {"vertices", floor_->vertices().size()}});
  } catch (const std::runtime_error& e) {
    Event(frame, "enclosure_failed", {{"from", from}, {"reason", e.what()}});
  }
}

std::optional<CameraModel> CalibrationWizard::posed_model() const {
  if (!intrinsics_model_ || !ground_) return std::nullopt;
  CameraModel m = *intrinsics_model_;
  m.set_cam_from_ground(ground_->cam_from_ground);
  return m;
}

WizardFrame CalibrationWizard::Feed(const cv::Mat& image, int frame) {
  WizardFrame out;
  out.step = step_;
  if (step_ == WizardStep::kDone) return out;
  if (image.cols != width_ || image.rows != height_) {
    throw InputError(camera_ + " frame " + std::to_string(frame),
                     "the frame is " + std::to_string(image.cols) + "x" +
                         std::to_string(image.rows) + ", the camera " + std::to_string(width_) +
                         "x" + std::to_string(height_));
  }
  // Detection is slow on frames without a board (0.1-0.4 s): while none is
  // in view, every 4th frame is searched; once one is, every frame.
  BoardView view;
  view.source = camera_ + " frame " + std::to_string(frame);
  // A frame skipped between searches says why the last searched one had no board.
  view.rejection = last_rejection_.empty() ? "no board in the last frames" : last_rejection_;
  if (last_detected_ || fed_ % 4 == 0) {
    view = DetectBoard(o_.board, image, o_.detect, view.source);
    last_rejection_ = view.rejection;
  }
  ++fed_;
  last_detected_ = view.accepted;
  last_view_ = view;
  out.detected = view.accepted;
  board_seen_ = board_seen_ || view.accepted;
  if (!view.accepted) {
    run_.clear();
    run_used_ = false;
  } else if (!run_.empty() && SameIds(run_.back(), view) &&
             MaxMotion(run_.back(), view) < o_.still_px) {
    run_.push_back(view);
  } else {
    run_ = {view};
    run_used_ = false;
  }
  out.still = run_.size() >= 2;

  std::vector<std::string> now;
  if (step_ == WizardStep::kIntrinsics) {
    if (!view.accepted) {
      now.push_back("show the board to the camera (" + view.rejection + ")");
    } else if (static_cast<int>(run_.size()) < o_.still_frames) {
      now.push_back("hold the board still");
    } else if (!o_.auto_solve && views() >= o_.max_views) {
      now.push_back("enough views (" + std::to_string(views()) + "): solve, or drop the worst");
    } else if (!run_used_) {
      BoardView still;
      try {
        still = AverageStillViews(run_, 2 * o_.still_px);
      } catch (const InputError&) {
        still = run_.back();
      }
      const Captured d = Describe(still);
      std::string why;
      run_used_ = true;
      if (Novel(still, d, &why)) {
        Capture(still, d, frame, why);
        out.captured = true;
        if (!o_.auto_solve) {
          // The console solves when its operator asks.
        } else if (CriteriaMet() && views() >= next_solve_at_) {
          SolveIntrinsics(frame);
        } else if (views() >= o_.max_views) {
          SolveIntrinsics(frame);
          if (!intrinsics_good_) {
            verdicts_.push_back("intrinsics: " +
                                (report_->reasons.empty() ? "rejected" : report_->reasons.front()));
            step_ = WizardStep::kDone;
            Event(frame, "verdict", {{"reason", verdicts_.back()}});
          }
        }
      } else {
        now.push_back("move the board to a new place or angle");
      }
    } else {
      now.push_back("move the board to a new place or angle");
    }
    if (step_ == WizardStep::kIntrinsics) {
      std::vector<std::string> missing = MissingForIntrinsics();
      if (!o_.auto_solve && missing.empty())
        now.insert(now.begin(), "the views meet the criteria: solve");
      for (auto& m : missing) now.push_back(std::move(m));
    }
  }
  if (step_ == WizardStep::kGround) {
    if (!view.accepted) {
      now.push_back("lay the board flat on the floor, in view");
    } else if (static_cast<int>(run_.size()) < o_.floor_still_frames) {
      now.push_back("lay the board flat on the floor and leave it still");
    } else {
      try {
        floor_view_ = AverageStillViews(run_, 2 * o_.still_px);
        ground_ = SolveGroundPose(*intrinsics_model_, o_.board, floor_view_, o_.ground_from_board,
                                  camera_);
        Event(frame, "ground",
              {{"height_m", ground_->height_m},
               {"rms_px", ground_->rms_px},
               {"from", floor_view_.source}});
        EnterEnclosure(frame, image);
      } catch (const std::runtime_error& e) {
        Event(frame, "ground_failed", {{"reason", e.what()}});
        run_.clear();
        now.push_back(std::string("the floor board could not be used: ") + e.what());
      }
    }
  }
  if (step_ == WizardStep::kEnclosure) {
    empty_frames_ = view.accepted ? 0 : empty_frames_ + 1;
    if (empty_frames_ >= o_.floor_still_frames) {
      TryEmptyFloor(image, frame);
      if (!floor_) empty_frames_ = 0;
    }
    if (step_ == WizardStep::kEnclosure) {
      now.push_back(
          "take the board off the floor and clear the floor: the empty green floor gives the "
          "enclosure");
    }
  }
  out.step = step_;
  out.guidance = now;
  if (now != last_guidance_) {
    Event(frame, "guidance", {{"say", now}});
    last_guidance_ = now;
  }
  return out;
}

void CalibrationWizard::Solve(int frame) {
  if (step_ != WizardStep::kIntrinsics) {
    throw InputError(
        "solve", std::string("the intrinsics step is over (now: ") + WizardStepName(step_) + ")");
  }
  constexpr int kMinToSolve = 3;
  if (views() < kMinToSolve) {
    throw InputError("solve", std::to_string(views()) + " views captured; at least " +
                                  std::to_string(kMinToSolve) + " are needed to solve (" +
                                  std::to_string(o_.verdict.min_views) + " to trust it)");
  }
  SolveIntrinsics(frame);
}

void CalibrationWizard::DropView(size_t index, const std::string& why) {
  Event(-1, "drop",
        {{"view", static_cast<int>(index) + 1}, {"why", why}, {"source", views_[index].source}});
  views_.erase(views_.begin() + static_cast<std::ptrdiff_t>(index));
  described_.erase(described_.begin() + static_cast<std::ptrdiff_t>(index));
  // The coverage and the tilt are of the views that are left.
  coverage_.setTo(0);
  max_tilt_deg_ = 0;
  for (size_t i = 0; i < views_.size(); ++i) {
    for (const auto& p : views_[i].pixels) {
      const int gx =
          std::clamp(static_cast<int>(p.x() / width_ * coverage_.cols), 0, coverage_.cols - 1);
      const int gy =
          std::clamp(static_cast<int>(p.y() / height_ * coverage_.rows), 0, coverage_.rows - 1);
      coverage_.at<float>(gy, gx) += 1;
    }
    const double tilt =
        std::acos(std::clamp(std::abs(described_[i].normal.z()), 0.0, 1.0)) * 180 / M_PI;
    max_tilt_deg_ = std::max(max_tilt_deg_, tilt);
  }
  // The solve described views that changed.
  solution_.reset();
  report_.reset();
  next_solve_at_ = o_.verdict.min_views;
  run_used_ = true;  // the board still in view is not captured again at once
}

void CalibrationWizard::DropLast() {
  if (step_ != WizardStep::kIntrinsics) throw InputError("drop", "the intrinsics step is over");
  if (views_.empty()) throw InputError("drop", "no view captured yet");
  DropView(views_.size() - 1, "dropped by the operator (last)");
}

void CalibrationWizard::DropWorst() {
  if (step_ != WizardStep::kIntrinsics) throw InputError("drop", "the intrinsics step is over");
  if (views_.empty()) throw InputError("drop", "no view captured yet");
  size_t worst = 0;
  std::string why;
  if (solution_ && solution_->observation_frame.size() == views_.size()) {
    std::vector<double> sum2(views_.size(), 0.0);
    std::vector<int> n(views_.size(), 0);
    for (const auto& c : solution_->corners) {
      if (c.observation < 0 || static_cast<size_t>(c.observation) >= views_.size()) continue;
      sum2[static_cast<size_t>(c.observation)] += c.residual.squaredNorm();
      ++n[static_cast<size_t>(c.observation)];
    }
    double worst_rms = -1;
    for (size_t i = 0; i < views_.size(); ++i) {
      const double rms = n[i] ? std::sqrt(sum2[i] / n[i]) : 0.0;
      if (rms > worst_rms) worst_rms = rms, worst = i;
    }
    why = Fmt("dropped by the operator (worst: RMS %.3f px in the last solve)", worst_rms);
  } else {
    double blurriest = -1;
    for (size_t i = 0; i < views_.size(); ++i) {
      const double e = std::isfinite(views_[i].edge_width_px) ? views_[i].edge_width_px : 0.0;
      if (e > blurriest) blurriest = e, worst = i;
    }
    why = Fmt("dropped by the operator (worst: the blurriest, edges %.2f px wide)", blurriest);
  }
  DropView(worst, why);
}

void CalibrationWizard::Redo(WizardStep step) {
  switch (step) {
    case WizardStep::kIntrinsics:
      if (o_.intrinsics)
        throw InputError("step", "the intrinsics were given: redo the ground step instead");
      views_.clear();
      described_.clear();
      coverage_.setTo(0);
      max_tilt_deg_ = 0;
      solution_.reset();
      report_.reset();
      intrinsics_model_.reset();
      intrinsics_good_ = false;
      next_solve_at_ = o_.verdict.min_views;
      ground_.reset();
      floor_.reset();
      floor_with_board_.reset();
      step_ = WizardStep::kIntrinsics;
      break;
    case WizardStep::kGround:
      if (!intrinsics_model_ || !intrinsics_good_)
        throw InputError("step", "no trusted intrinsics yet: solve them first");
      ground_.reset();
      floor_.reset();
      floor_with_board_.reset();
      step_ = WizardStep::kGround;
      break;
    case WizardStep::kEnclosure:
      if (!ground_)
        throw InputError("step", "the camera is not posed yet: finish the ground step first");
      floor_.reset();
      step_ = WizardStep::kEnclosure;
      break;
    case WizardStep::kDone:
      throw InputError("step", "expected intrinsics, ground or enclosure");
  }
  verdicts_.clear();
  run_.clear();
  run_used_ = false;
  empty_frames_ = 0;
  floor_from_.clear();
  Event(-1, "redo");
}

void CalibrationWizard::SetFloorFromPixels(const std::vector<Eigen::Vector2d>& pixels) {
  const std::optional<CameraModel> posed = posed_model();
  if (!posed)
    throw InputError("pixels", "the camera is not posed yet: finish the ground step first");
  floor_ = FloorPolygonFromPixels(*posed, pixels, "pixels");
  floor_from_ = "clicked corners";
  step_ = WizardStep::kDone;
  Event(-1, "enclosure",
        {{"from", floor_from_},
         {"area_m2", floor_->Area()},
         {"vertices", floor_->vertices().size()}});
}

void CalibrationWizard::DetectFloor(const cv::Mat& image) {
  if (!posed_model())
    throw InputError("detect", "the camera is not posed yet: finish the ground step first");
  try {
    floor_ = GreenFloorIn(image);
  } catch (const WorkError& e) {
    throw InputError("detect", e.what());
  }
  floor_from_ = "green floor";
  step_ = WizardStep::kDone;
  Event(-1, "enclosure",
        {{"from", floor_from_},
         {"area_m2", floor_->Area()},
         {"vertices", floor_->vertices().size()}});
}

ViewDiversity CalibrationWizard::diversity() const {
  // As ROS camera_calibration: per view the board's mean corner position (x, y in 0..1), its
  // size (sqrt of the corners' bounding area over the image's) and skew (how far the angle
  // at the board's first corner is from 90 degrees); progress = spread / a good set's spread.
  ViewDiversity d;
  if (views_.empty()) return d;
  double lo[4] = {1e9, 1e9, 1e9, 1e9}, hi[4] = {-1e9, -1e9, -1e9, -1e9};
  const int cx = o_.board.corners_x();
  for (const auto& v : views_) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero(), a = v.pixels.front(), b = a;
    for (const auto& p : v.pixels) sum += p, a = a.cwiseMin(p), b = b.cwiseMax(p);
    const Eigen::Vector2d mean = sum / static_cast<double>(v.pixels.size());
    double skew = 0;
    // The angle at the first corner between its row and its column (ids id+1 and id+cx).
    for (size_t i = 0; i < v.ids.size() && skew == 0; ++i) {
      const auto right = std::find(v.ids.begin(), v.ids.end(), v.ids[i] + 1);
      const auto down = std::find(v.ids.begin(), v.ids.end(), v.ids[i] + cx);
      if (right == v.ids.end() || down == v.ids.end() || (v.ids[i] + 1) % cx == 0) continue;
      const Eigen::Vector2d u = v.pixels[static_cast<size_t>(right - v.ids.begin())] - v.pixels[i];
      const Eigen::Vector2d w = v.pixels[static_cast<size_t>(down - v.ids.begin())] - v.pixels[i];
      const double angle = std::acos(std::clamp(u.normalized().dot(w.normalized()), -1.0, 1.0));
      skew = std::min(1.0, 2.0 * std::abs(M_PI / 2 - angle));
    }
    const double value[4] = {mean.x() / width_, mean.y() / height_,
                             std::sqrt((b - a).prod() / (static_cast<double>(width_) * height_)),
                             skew};
    for (int k = 0; k < 4; ++k)
      lo[k] = std::min(lo[k], value[k]), hi[k] = std::max(hi[k], value[k]);
  }
  const double range[4] = {0.7, 0.7, 0.4, 0.5};  // ROS's param_ranges
  double* out[4] = {&d.x, &d.y, &d.size, &d.skew};
  for (int k = 0; k < 4; ++k) *out[k] = std::min(1.0, (hi[k] - lo[k]) / range[k]);
  return d;
}

void CalibrationWizard::Finish() {
  if (step_ == WizardStep::kIntrinsics) {
    constexpr int kMinToSolve = 3;
    if (views() >= kMinToSolve) SolveIntrinsics(-1);
    if (!intrinsics_good_) {
      std::string reason;
      if (!board_seen_) {
        reason = "no board (" + o_.board.ToString() + ") found in any frame; check the board spec";
      } else if (report_ && !report_->reasons.empty()) {
        reason = report_->reasons.front();
      } else {
        reason = "too few views: " + std::to_string(views()) + " captured (need " +
                 std::to_string(o_.verdict.min_views) + "); hold the board still in more places";
      }
      if (!report_) report_ = FailedCameraReport(camera_, views_, reason);
      verdicts_.push_back("intrinsics: " + reason);
      for (const auto& m : MissingForIntrinsics()) {
        const bool repeats = reason.find(m) != std::string::npos ||
                             (m.rfind("capture more views", 0) == 0 &&
                              reason.find("too few views") != std::string::npos);
        if (!repeats) {
          verdicts_.push_back("intrinsics: " + m);
        }
      }
      step_ = WizardStep::kDone;
      Event(-1, "verdict", {{"reasons", verdicts_}});
      return;
    }
  }
  if (step_ == WizardStep::kGround) {
    verdicts_.push_back(
        "ground: no board lying still on the floor was seen; lay the board flat on the floor");
    step_ = WizardStep::kDone;
    Event(-1, "verdict", {{"reason", verdicts_.back()}});
    return;
  }
  if (step_ == WizardStep::kEnclosure) {
    // No empty floor was seen: the frame with the board on the floor (the board is inside the
    // floor's outline).
    const std::string from = "the frame with the board on the floor";
    if (floor_with_board_) {
      floor_ = floor_with_board_;
      floor_from_ = "green floor";
      Event(-1, "enclosure",
            {{"from", from}, {"area_m2", floor_->Area()}, {"vertices", floor_->vertices().size()}});
    } else {
      Event(-1, "enclosure_failed", {{"from", from}, {"reason", floor_with_board_error_}});
      verdicts_.push_back(
          "enclosure: no green floor found; show the empty floor or give --floor-points");
      Event(-1, "verdict", {{"reason", verdicts_.back()}});
    }
    step_ = WizardStep::kDone;
  }
}

nlohmann::json WriteWizardOutputs(const CalibrationWizard& w, const std::string& out_dir,
                                  const VerdictOptions& verdict) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw WorkError(out_dir, "cannot create the output folder: " + ec.message());
  const std::string base = (fs::path(out_dir) / w.camera()).string();
  auto num = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  nlohmann::json j;
  j["camera"] = w.camera();
  j["verdict"] = w.verdicts().empty() ? "good" : "rejected";
  j["verdicts"] = w.verdicts();
  j["views_captured"] = w.views();
  j["coverage"] = w.coverage_fraction();
  j["max_tilt_deg"] = w.max_tilt_deg();
  std::string model_file;
  if (w.report()) {
    CameraReport r = *w.report();
    if (w.solution()) {
      r.residual_png = base + ".residuals.png";
      r.coverage_png = base + ".coverage.png";
      WriteResidualPlot(r.residual_png, *w.solution(), 0);
      WriteCoverageMap(r.coverage_png, *w.solution(), 0, verdict);
    }
    if (w.intrinsics_good()) r.model_file = model_file = base + ".cameramodel";
    j["intrinsics"] = ToJson(r);
  }
  if (const auto posed = w.posed_model()) {
    posed->Write(base + ".cameramodel");
    model_file = base + ".cameramodel";
    const GroundResult& g = *w.ground();
    j["ground"] = {{"height_m", g.height_m},
                   {"centre_in_ground_m",
                    {g.centre_in_ground.x(), g.centre_in_ground.y(), g.centre_in_ground.z()}},
                   {"optical_axis_down_deg", g.optical_axis_down_deg},
                   {"board_rms_px", num(g.rms_px)},
                   {"board_worst_px", num(g.worst_px)},
                   {"corners", g.corners}};
  } else if (w.intrinsics_good() && w.intrinsics_model()) {
    w.intrinsics_model()->Write(base + ".cameramodel");
  }
  if (w.floor()) {
    const std::string yaml = (fs::path(out_dir) / "enclosure.yaml").string();
    std::ofstream f(yaml);
    f << EnclosureYaml(*w.floor(), 0.0);
    if (!f) throw WorkError(yaml, "cannot write");
    j["enclosure"] = {
        {"file", yaml}, {"area_m2", w.floor()->Area()}, {"vertices", nlohmann::json::array()}};
    for (const auto& v : w.floor()->vertices())
      j["enclosure"]["vertices"].push_back({v.x(), v.y()});
  }
  j["model"] = model_file;
  j["log"] = w.log();
  const std::string path = (fs::path(out_dir) / "wizard.json").string();
  std::ofstream f(path);
  f << j.dump(2) << "\n";
  if (!f) throw WorkError(path, "cannot write the report");
  return j;
}

}  // namespace ss::calib
