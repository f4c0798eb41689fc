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
  check.Within(still_px, Positive(), "still_px", "a positive motion in pixels");
  check.Within(still_frames, AtLeast(1), "still_frames", "at least 1 frame");
  check.Within(min_shift, AtLeast(0), "min_shift", "a fraction >= 0");
  check.Within(min_tilt_change_deg, AtLeast(0), "min_tilt_change_deg", "degrees >= 0");
  check.Within(min_scale_change, AtLeast(0), "min_scale_change", "a fraction >= 0");
  check.Within(min_new_cells, AtLeast(0), "min_new_cells", "a number >= 0");
  check.Within(max_views, AtLeast(1), "max_views", "at least 1 view");
  check.Within(floor_still_frames, AtLeast(1), "floor_still_frames", "at least 1 frame");
  check.Within(floor_still_s, AtLeast(0), "floor_still_s", "seconds >= 0");
  check.Within(floor_word_s, AtLeast(0), "floor_word_s", "seconds >= 0");
  check(!floor_needs_word || floor_word_s == 0 || floor_word_s > floor_still_s, "floor_word_s",
        "expected 0 (never lapses) or longer than floor_still_s (" +
            OptionProblems::Num(floor_still_s) + " s), got " + OptionProblems::Num(floor_word_s));
  check(std::isnan(still_s) || (std::isfinite(still_s) && still_s >= 0), "still_s",
        "expected seconds >= 0 (or none), got " + OptionProblems::Num(still_s));
  check.Nested(ground_checks.IsValid(&part), "ground_checks.", part);
  return check.ok();
}

bool GroundChecks::IsValid(std::string* why) const {
  OptionProblems check(why);
  check(ring_from_squares >= 0 && ring_to_squares > ring_from_squares, "ring_to_squares",
        "expected 0 <= ring_from_squares < ring_to_squares, got " +
            OptionProblems::Num(ring_from_squares) + " and " +
            OptionProblems::Num(ring_to_squares));
  check.Within(min_ring_green, Between(0, 1), "min_ring_green", "a fraction 0..1");
  check(min_height_m >= 0 && max_height_m > min_height_m, "max_height_m",
        "expected 0 <= min_height_m < max_height_m, got " + OptionProblems::Num(min_height_m) +
            " and " + OptionProblems::Num(max_height_m));
  check.Within(min_axis_down_deg, Between(-90, 90), "min_axis_down_deg", "degrees -90..90");
  check.Within(max_spread_mm, Positive(), "max_spread_mm", "a positive distance");
  check.Within(max_spread_deg, Positive(), "max_spread_deg", "a positive angle");
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

void IntrinsicsSolve::Run() {
  std::vector<BoardObservation> obs;
  for (size_t i = 0; i < views.size(); ++i)
    obs.push_back({0, static_cast<int>(i), views[i].source, views[i].ids, views[i].pixels});
  try {
    solution = SolveBoards(board, {{camera, width, height}}, obs, solve);
    report = MakeCameraReport(board, *solution, 0, views, verdict);
    report->camera = camera;
  } catch (const std::runtime_error& e) {
    solution.reset();
    report = FailedCameraReport(camera, views, e.what());
  }
}

void CalibrationWizard::SolveIntrinsics(int frame) {
  IntrinsicsSolve s{o_.board, camera_, width_, height_, views_, o_.solve, o_.verdict};
  s.Run();
  TakeIntrinsics(std::move(s), frame);
}

void CalibrationWizard::TakeIntrinsics(IntrinsicsSolve solved, int frame) {
  const int views_solved = static_cast<int>(solved.views.size());
  solution_ = std::move(solved.solution);
  report_ = std::move(solved.report);
  intrinsics_good_ = report_->good;
  Event(frame, "solve",
        {{"views", views_solved},
         {"verdict", intrinsics_good_ ? "good" : "rejected"},
         {"reasons", report_->reasons},
         {"rms_px", solution_ ? solution_->rms_px[0] : NAN}});
  if (intrinsics_good_) {
    intrinsics_model_ = solution_->models[0];
    intrinsics_model_->set_cam_from_ground(Rigid3{});
    EnterGround(frame);
  } else {
    next_solve_at_ = views_solved + 5;  // more views before trying again
  }
}

void CalibrationWizard::EnterGround(int frame) {
  step_ = WizardStep::kGround;
  run_.clear();
  run_used_ = false;
  word_ = false;
  word_lapsed_ = false;
  ground_check_.reset();
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

// A green floor found later is whole when it shows at least this share of what the frame with the
// board lying on it showed (TryEmptyFloor, DetectFloor); less, something hides part of it.
constexpr double kUnhiddenShare = 0.95;

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
    if (found.Area() < kUnhiddenShare * with_board_m2) {
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

GroundCheck CalibrationWizard::CheckGround(const GroundResult& g, const cv::Mat& image,
                                           int frame) const {
  const GroundChecks& k = o_.ground_checks;
  GroundCheck c;
  c.frame = frame;
  c.frames = static_cast<int>(run_.size());
  c.height_m = g.height_m;
  c.axis_down_deg = g.optical_axis_down_deg;
  std::vector<std::string> doubts;
  // (a) A board lying on the floor is surrounded by it: the ring around the board (past the
  // paper's margin) is floor green; a board held up in front of the camera has a room behind it.
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  const cv::Mat green = GreenFloorMask(bgr);
  const Rigid3 cam_from_board = g.cam_from_ground * o_.ground_from_board;
  const double sq = o_.board.square_m, w = o_.board.squares_x * sq, h = o_.board.squares_y * sq;
  // The checkered area grown by `grow` squares, in pixels; empty when part of it is behind the
  // camera.
  auto outline = [&](double grow) {
    const double m = grow * sq;
    const Eigen::Vector3d rect[4] = {
        {-m, -m, 0}, {w + m, -m, 0}, {w + m, h + m, 0}, {-m, h + m, 0}};
    std::vector<cv::Point> px;
    constexpr int kPerSide = 16;
    for (int side = 0; side < 4; ++side) {
      for (int i = 0; i < kPerSide; ++i) {
        const Eigen::Vector3d p =
            rect[side] + (rect[(side + 1) % 4] - rect[side]) * (static_cast<double>(i) / kPerSide);
        const Eigen::Vector3d in_cam = cam_from_board * p;
        if (in_cam.z() < 1e-3) return std::vector<cv::Point>{};
        const Eigen::Vector2d q = intrinsics_model_->Project(in_cam);
        if (!q.allFinite()) return std::vector<cv::Point>{};
        // (far outside the image only the side it leaves by matters)
        px.emplace_back(
            static_cast<int>(std::lround(std::clamp(q.x(), -2.0 * width_, 3.0 * width_))),
            static_cast<int>(std::lround(std::clamp(q.y(), -2.0 * height_, 3.0 * height_))));
      }
    }
    return px;
  };
  const std::vector<cv::Point> outer = outline(k.ring_to_squares),
                               inner = outline(k.ring_from_squares);
  if (outer.empty() || inner.empty()) {
    doubts.push_back("the floor around the board would be behind the camera");
  } else {
    cv::Mat ring(bgr.size(), CV_8U, cv::Scalar(0));
    cv::fillPoly(ring, std::vector<std::vector<cv::Point>>{outer}, cv::Scalar(255));
    cv::fillPoly(ring, std::vector<std::vector<cv::Point>>{inner}, cv::Scalar(0));
    const double ring_area = cv::contourArea(outer) - cv::contourArea(inner);
    const int in_view = cv::countNonZero(ring);
    cv::Mat green_ring;
    cv::bitwise_and(ring, green, green_ring);
    // Less than a third of the ring in the image: too little to tell.
    if (in_view < 0.33 * ring_area || in_view == 0) {
      doubts.push_back(
          Fmt("too little of the floor around the board is in view (%.0f%% of it): "
              "lay the board further from the image's edges",
              100.0 * in_view / std::max(1.0, ring_area)));
    } else {
      c.ring_green = cv::countNonZero(green_ring) / static_cast<double>(in_view);
      if (c.ring_green < k.min_ring_green) {
        doubts.push_back(
            Fmt("the board is not surrounded by green floor (%.0f%% of the ring "
                "around it is floor green, need %.0f%%): is it lying on the floor?",
                100 * c.ring_green, 100 * k.min_ring_green));
      }
    }
  }
  // (b) A camera that watches a floor stands above it and looks down at it.
  if (!(g.height_m >= k.min_height_m && g.height_m <= k.max_height_m)) {
    doubts.push_back(Fmt("the camera would be %.2f m above the floor (expected %.2f", g.height_m,
                         k.min_height_m) +
                     Fmt(" to %.1f m)", k.max_height_m));
  }
  if (!(g.optical_axis_down_deg >= k.min_axis_down_deg)) {
    doubts.push_back(
        Fmt("the camera's optical axis would be %.1f deg below the horizon "
            "(expected at least %.0f: a camera watching a floor looks down at it)",
            g.optical_axis_down_deg, k.min_axis_down_deg));
  }
  // (c) Each still frame on its own gives the same pose as their mean.
  const size_t n = run_.size(), samples = std::min<size_t>(5, n);
  double spread_m = 0, spread_deg = 0;
  for (size_t s = 0; s < samples; ++s) {
    const size_t i = samples == 1 ? 0 : s * (n - 1) / (samples - 1);
    try {
      const GroundResult one =
          SolveGroundPose(*intrinsics_model_, o_.board, run_[i], o_.ground_from_board, camera_);
      spread_m = std::max(spread_m, (one.centre_in_ground - g.centre_in_ground).norm());
      const Eigen::Matrix3d d =
          one.cam_from_ground.rotation * g.cam_from_ground.rotation.transpose();
      spread_deg =
          std::max(spread_deg, std::acos(std::clamp((d.trace() - 1) / 2, -1.0, 1.0)) * 180 / M_PI);
    } catch (const std::runtime_error& e) {
      doubts.push_back(std::string("a still frame gives no pose: ") + e.what());
      break;
    }
  }
  c.spread_mm = spread_m * 1000;
  c.spread_deg = spread_deg;
  if (c.spread_mm > k.max_spread_mm || c.spread_deg > k.max_spread_deg) {
    doubts.push_back(Fmt("the still frames' poses disagree by %.1f mm", c.spread_mm) +
                     Fmt(" and %.2f deg: the board moved", c.spread_deg));
  }
  for (const auto& d : doubts) c.doubt += (c.doubt.empty() ? "" : "; ") + d;
  return c;
}

void CalibrationWizard::BoardOnFloor(int frame) {
  if (step_ != WizardStep::kGround) {
    throw InputError("board on floor", std::string("the camera is not in the ground step (now: ") +
                                           WizardStepName(step_) + ")");
  }
  word_ = true;
  word_since_s_ = NAN;
  word_lapsed_ = false;
  run_.clear();  // the still span starts now
  run_used_ = false;
  Event(frame, "board_on_floor");
}

std::optional<CameraModel> CalibrationWizard::posed_model() const {
  if (!intrinsics_model_ || !ground_) return std::nullopt;
  CameraModel m = *intrinsics_model_;
  m.set_cam_from_ground(ground_->cam_from_ground);
  return m;
}

double CalibrationWizard::StillRunCovers(double time_s) const {
  const double n = static_cast<double>(run_.size());
  return n < 2 ? NAN : (time_s - run_start_s_) * n / (n - 1);
}

WizardFrame CalibrationWizard::Feed(const cv::Mat& image, int frame, double time_s) {
  WizardFrame out;
  out.step = step_;
  if (step_ == WizardStep::kDone && !o_.detect_when_done) return out;
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
    run_start_s_ = time_s;
  }
  out.still = run_.size() >= 2;

  std::vector<std::string> now;
  if (step_ == WizardStep::kIntrinsics) {
    if (!view.accepted) {
      now.push_back("show the board to the camera (" + view.rejection + ")");
    } else if (static_cast<int>(run_.size()) < o_.still_frames ||
               StillRunCovers(time_s) < o_.still_s - 1e-6) {  // to a microsecond
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
        if (!o_.auto_solve || solve_out_) {
          // The console solves when its operator asks (or is solving).
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
    // The still span by the timestamps (frames without one: by the count alone).
    const double still_s = run_.empty() ? 0.0 : time_s - run_start_s_;
    const bool long_enough = static_cast<int>(run_.size()) >= o_.floor_still_frames &&
                             !(still_s < o_.floor_still_s);  // NaN: no timestamps
    if (word_ && std::isfinite(time_s)) {
      if (std::isnan(word_since_s_)) word_since_s_ = time_s;
      if (o_.floor_word_s > 0 && time_s - word_since_s_ > o_.floor_word_s) {
        word_ = false;
        word_lapsed_ = true;
        run_.clear();
        Event(frame, "board_on_floor_lapsed", {{"after_s", time_s - word_since_s_}});
      }
    }
    const bool may_take = !o_.floor_needs_word || word_;
    std::string failed;
    if (may_take && view.accepted && long_enough) {
      try {
        floor_view_ = AverageStillViews(run_, 2 * o_.still_px);
        GroundResult g = SolveGroundPose(*intrinsics_model_, o_.board, floor_view_,
                                         o_.ground_from_board, camera_);
        GroundCheck c = CheckGround(g, image, frame);
        c.still_s = still_s;
        auto num = [](double v) {
          return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
        };
        nlohmann::json detail = {{"height_m", g.height_m},
                                 {"axis_down_deg", g.optical_axis_down_deg},
                                 {"rms_px", g.rms_px},
                                 {"from", floor_view_.source},
                                 {"frames", c.frames},
                                 {"still_s", num(c.still_s)},
                                 {"ring_green", num(c.ring_green)},
                                 {"spread_mm", num(c.spread_mm)},
                                 {"spread_deg", num(c.spread_deg)}};
        word_ = false;  // one word, one board checked
        word_lapsed_ = false;
        ground_check_ = c;
        if (c.doubt.empty()) {
          ground_ = std::move(g);
          Event(frame, "ground", std::move(detail));
          EnterEnclosure(frame, image);
        } else {
          detail["doubt"] = c.doubt;
          Event(frame, "ground_doubtful", std::move(detail));
          run_.clear();
        }
      } catch (const std::runtime_error& e) {
        Event(frame, "ground_failed", {{"reason", e.what()}});
        run_.clear();
        word_ = false;
        failed = e.what();
      }
    }
    if (step_ == WizardStep::kGround) {
      if (ground_check_ && !ground_check_->doubt.empty())
        now.push_back("the floor board's pose is doubtful, not taken: " + ground_check_->doubt);
      if (!failed.empty()) {
        now.push_back("the floor board could not be used: " + failed);
      } else if (word_lapsed_) {
        char line[160];
        std::snprintf(line, sizeof line,
                      "no board lay still on the floor within %.0f s of the word: lay it flat on "
                      "the green floor, in view, then say so again (\"board on floor\")",
                      o_.floor_word_s);
        now.push_back(line);
      } else if (!may_take || (o_.floor_needs_word && !word_)) {
        now.push_back(
            "lay the board flat on the green floor, in view, then say so (\"board on floor\")");
      } else if (!view.accepted) {
        now.push_back("lay the board flat on the floor, in view");
      } else {
        now.push_back("lay the board flat on the floor and leave it still");
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

void CalibrationWizard::RefuseWhileSolving(const char* field) const {
  if (solve_out_) throw InputError(field, "a solve is running; wait for it to end");
}

void CalibrationWizard::CheckSolvable() const {
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
  RefuseWhileSolving("solve");
}

void CalibrationWizard::Solve(int frame) {
  CheckSolvable();
  SolveIntrinsics(frame);
}

IntrinsicsSolve CalibrationWizard::BeginSolve() {
  CheckSolvable();
  solve_out_ = true;
  return {o_.board, camera_, width_, height_, views_, o_.solve, o_.verdict};
}

void CalibrationWizard::EndSolve(IntrinsicsSolve solved, int frame) {
  if (!solve_out_) throw InputError("solve", "no solve was begun");
  solve_out_ = false;
  // Nothing but Feed changed the views since BeginSolve (the console takes no other command
  // while a solve is out): the solved ones are the first of views_, which it only appends to.
  if (step_ != WizardStep::kIntrinsics || solved.views.size() > views_.size()) return;
  TakeIntrinsics(std::move(solved), frame);
}

void CalibrationWizard::AbandonSolve(const std::string& why) {
  if (!solve_out_) throw InputError("solve", "no solve was begun");
  solve_out_ = false;
  Event(-1, "solve",
        {{"views", views()}, {"verdict", "failed"}, {"reasons", nlohmann::json::array({why})}});
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
  RefuseWhileSolving("drop");
  if (views_.empty()) throw InputError("drop", "no view captured yet");
  DropView(views_.size() - 1, "dropped by the operator (last)");
}

void CalibrationWizard::DropWorst() {
  if (step_ != WizardStep::kIntrinsics) throw InputError("drop", "the intrinsics step is over");
  RefuseWhileSolving("drop");
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
  RefuseWhileSolving("step");
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
  if (step != WizardStep::kEnclosure) {
    word_ = false;
    word_lapsed_ = false;
    ground_check_.reset();
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
  std::optional<GroundPolygon> found;
  try {
    found = GreenFloorIn(image);
  } catch (const WorkError& e) {
    throw InputError("detect", e.what());
  }
  // As the enclosure step's own detection (TryEmptyFloor): the floor found with the board lying
  // on it bounds what the camera sees of the floor from below. A board held up or a person
  // before the camera hides part of it; taken, that sliver would be the enclosure every sprite
  // is kept within (a console run saved 0.15 m² of a 0.81 m² floor so, and stored no sprite).
  const double with_board_m2 = floor_with_board_ ? floor_with_board_->Area() : 0.0;
  if (found->Area() < kUnhiddenShare * with_board_m2) {
    throw InputError("detect",
                     Fmt("the green floor found is %.2f m², less than the %.2f m² seen with the "
                         "board lying on it: something hides part of the floor (a board held up, a "
                         "person); detect it again when the floor is clear",
                         found->Area(), with_board_m2));
  }
  floor_ = std::move(*found);
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
    if (ground_check_ && !ground_check_->doubt.empty()) {
      verdicts_.push_back("ground: the floor board's pose was doubtful, not taken: " +
                          ground_check_->doubt);
    } else {
      verdicts_.push_back(
          "ground: no board lying still on the floor was seen; lay the board flat on the floor");
    }
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
