#pragma once
// The calibration wizard: intrinsics -> ground -> enclosure for one camera,
// fed one frame at a time (a live camera, a replayed session, later the
// browser). It captures a view only when the board is still and the view adds
// something (place, angle, size or image coverage), keeps a coverage grid,
// says what is missing ("cover the left edge", "tilt the board more", "lay
// the board flat on the floor"), and ends each step when its criteria are met.
// Every decision goes into a step log (JSON).
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/detect.h"
#include "calib/ground.h"
#include "calib/report.h"
#include "calib/solve.h"
#include "calib/wizard_step.h"
#include "core/camera_model.h"
#include "core/geometry.h"

namespace ss::calib {

// When a floor board's pose is doubtful (not taken): see GroundCheck. The values come from
// the synthetic calibration sessions (`synth --kind calibration`, 640x480, seeds 1 and 3-6, the
// chessboard held in 5 poses per session, then lying on the floor beside the ChArUco board) and
// from tests/calib/wizard_ground_test.cc.
struct GroundChecks {
  // (a) The ring around the board, between its checkered area grown by ring_from_squares and by
  // ring_to_squares squares (from 1.5: past the paper's white margin, 1 square on the synthetic
  // board), must be at least min_ring_green floor green (GreenFloorMask, the enclosure step's
  // test). Measured: lying on the floor 0.76-0.86 (the ChArUco board beside it covers part of
  // the ring), 0.90-1.00 alone; held up before the camera 0.00-0.49 (the room, the walls' darker
  // green and the floor's edge behind it), 0.00 in a room without green.
  double ring_from_squares = 1.5, ring_to_squares = 3.0;
  double min_ring_green = 0.6;
  // (b) The camera above the floor: the synthetic enclosure's cameras stand 0.77-1.5 m high
  // (1.08-1.24 m measured), the stage's 1.1-1.8 m; a board held at arm's length before the
  // camera poses it 0.24-0.64 m high (issue 41's hand-held recording: 0.31 m), which the ring
  // check (a) already refuses. The lower bound is for what no camera over a floor can be: a
  // tabletop rig for a hamster may stand 0.2-0.3 m high (a bound at 0.5 m would call every one
  // of them doubtful, for good); 6 m is above any room's ceiling. Its optical axis looks down at
  // the floor: 43-58 deg below the horizon in the enclosure, 2-10 deg on the stage; above the
  // horizon the board could not be the floor it watches.
  double min_height_m = 0.15, max_height_m = 6.0;
  double min_axis_down_deg = 0.0;
  // (c) The pose from each still frame (up to 5 of them) against the averaged one: a board lying
  // still differs by the corner noise only, 0.15-0.51 mm and 0.005-0.017 deg measured; 10 times
  // that means it moved (or the corners jump between two readings).
  double max_spread_mm = 5.0, max_spread_deg = 0.2;
  // False with "FIELD: reason" lines in `why` for values out of range.
  bool IsValid(std::string* why) const;
};

// What the ground step made of the last still floor board: its measurements and, when the
// pose is not taken, why.
struct GroundCheck {
  int frame = -1;
  std::string doubt;        // empty: taken
  double ring_green = NAN;  // fraction of the ring around the board that is floor green
  double height_m = NAN, axis_down_deg = NAN;
  double spread_mm = NAN, spread_deg = NAN;  // the still frames' poses against the averaged one
  int frames = 0;                            // still frames averaged
  double still_s = NAN;                      // their span by the timestamps
};

struct WizardOptions {
  BoardSpec board;
  DetectOptions detect;
  VerdictOptions
      verdict;  // min_views, min_coverage, min_tilt_deg, max_rms_px: when to stop, what to trust
  SolveOptions solve;
  double still_px = 0.5;  // largest corner motion between two frames of a still board
  int still_frames = 2;   // intrinsics: frames in a row the board must be still for a capture
  // Intrinsics: and still this long by the frames' timestamps, the last frame's interval
  // included (n frames at a steady rate cover n / rate s, as a count from the true rate did);
  // NaN: the count alone, as for frames fed without a timestamp. A count of frames from a rate
  // measured or guessed would depend on that rate.
  double still_s = NAN;
  double min_shift = 0.08;  // a new view differs from every captured one: its centre moved this
                            // fraction of the image diagonal, ...
  double min_tilt_change_deg = 10;  // ... or its tilt changed this much, ...
  double min_scale_change = 0.25;   // ... or its size in the image this fraction, ...
  int min_new_cells = 3;            // ... or it puts corners in this many empty coverage cells
  int max_views = 30;               // intrinsics: solve what there is at this many views
  // Ground: the board must lie still this long, by the frames' timestamps (a count of frames
  // would depend on how many the machine gets to process), and for at least this many frames
  // (the pose is averaged over them and checked for agreement). Frames fed without a timestamp
  // are counted only. Enclosure: frames in a row without a board before the floor is taken.
  double floor_still_s = 1.0;
  int floor_still_frames = 3;
  // Ground: a board lying still is taken only after the operator said it lies on the floor
  // (BoardOnFloor(): the console's button). False (the command line on a recording): at once,
  // trusted only by the checks below.
  bool floor_needs_word = false;
  // The word holds this long by the frames' timestamps (from the first frame after it): a board
  // not taken by then lapses it, and it must be given again. A word given as the board lay on
  // the floor must not take a board held up much later (one held level over the floor passes
  // the checks). 0: it never lapses.
  double floor_word_s = 10.0;
  GroundChecks ground_checks;
  Rigid3 ground_from_board = FloorBoardPose();
  std::vector<Eigen::Vector2d>
      floor_points;  // enclosure in ground metres; empty: the largest green floor region
  std::optional<CameraModel> intrinsics;  // known intrinsics: start at the ground step
  // false: the intrinsics are solved only when Solve() is called (the console's Solve button);
  // capturing stops at max_views.
  bool auto_solve = true;
  // Once done, go on finding the board (Feed's `detected`, `still` and last_view()): the
  // console's joint solve of a rig takes still views from every step, so a camera posed early
  // still adds the places the board is held before it and another camera. False: done is done.
  bool detect_when_done = false;
  // False with "FIELD: reason" lines in `why` for values out of range (detect., verdict. and
  // solve. name the nested blocks' fields).
  bool IsValid(std::string* why) const;
};

// How varied the captured views are, as ROS's camera_calibration shows it: each 0..1, the
// spread of the views' board centre (x, y), size and skew against the spread a good set has.
struct ViewDiversity {
  double x = 0, y = 0, size = 0, skew = 0;
};

// What one frame did.
struct WizardFrame {
  WizardStep step = WizardStep::kIntrinsics;
  bool detected = false, still = false, captured = false;
  std::vector<std::string> guidance;  // what to do now, most urgent first
};

// The intrinsics solve of a wizard's captured views, apart from the wizard: what
// CalibrationWizard::BeginSolve copies, Run solves on any thread, and EndSolve takes back. The
// console solves so on a thread of its own while the camera's wizard goes on capturing views (a
// solve on the camera's thread blinded it for the solve's seconds: issue 41).
struct IntrinsicsSolve {
  // What is solved (copied).
  BoardSpec board;
  std::string camera;
  int width = 0, height = 0;
  std::vector<BoardView> views;
  SolveOptions solve;
  VerdictOptions verdict;
  // What Run found: the solution (nullopt when the solver failed) and its report.
  std::optional<SolveSummary> solution;
  std::optional<CameraReport> report;
  void Run();
};

class CalibrationWizard {
 public:
  CalibrationWizard(std::string camera, int width, int height, WizardOptions options);

  // One frame (8-bit BGR or grey, the camera's size); `frame` is its index, `time_s` its
  // timestamp in seconds (NaN: none; the still spans are then counted in frames).
  WizardFrame Feed(const cv::Mat& image, int frame, double time_s = NAN);
  // The input ended: solves a step that has enough to solve, gives every
  // unfinished step its verdict with the reason.
  void Finish();

  WizardStep step() const { return step_; }
  bool done() const { return step_ == WizardStep::kDone; }
  bool intrinsics_good() const { return intrinsics_good_; }
  bool ground_good() const { return ground_.has_value(); }
  bool enclosure_good() const { return floor_.has_value(); }
  bool board_seen() const { return board_seen_; }

  const cv::Mat& coverage() const { return coverage_; }  // corners per cell of the captured views
  double coverage_fraction() const;
  double max_tilt_deg() const { return max_tilt_deg_; }
  int views() const { return static_cast<int>(views_.size()); }
  const std::vector<BoardView>& captured() const { return views_; }
  // What is missing for the intrinsics step, from the coverage grid and the tilts.
  std::vector<std::string> MissingForIntrinsics() const;
  ViewDiversity diversity() const;
  // The detection of the last frame fed (rejected with the reason when no board).
  const BoardView& last_view() const { return last_view_; }
  bool last_still() const { return run_.size() >= 2; }

  // The console's controls (the command line's wizard does these by itself).
  // Solves the intrinsics from the captured views now; a trusted result moves on to the
  // ground step. InputError with fewer than 3 views or past the intrinsics step.
  void Solve(int frame = -1);
  // Solve() in parts: BeginSolve copies the captured views (InputError as Solve, and while
  // another solve is out), the caller runs it where it likes, and EndSolve takes its result as
  // Solve would have; the views captured meanwhile stay, to be solved with the next. While a
  // solve is out the wizard captures views but solves none by itself.
  IntrinsicsSolve BeginSolve();
  void EndSolve(IntrinsicsSolve solved, int frame = -1);
  // Ends a solve begun whose run failed where it ran, `why` logged; nothing else changes.
  void AbandonSolve(const std::string& why);
  bool solve_out() const { return solve_out_; }
  // Drops the last captured view, or the worst (largest RMS in the last solve; before one, the
  // blurriest); the last solve goes with it. InputError when there is no view to drop or the
  // intrinsics step is over.
  void DropLast();
  void DropWorst();
  // The operator's word that the board lies on the floor now: the ground step takes the next
  // still span of it (floor_needs_word). InputError outside the ground step.
  void BoardOnFloor(int frame = -1);
  bool waiting_for_word() const {
    return step_ == WizardStep::kGround && o_.floor_needs_word && !word_;
  }
  // The last floor board checked (nullopt: none yet in this ground step).
  const std::optional<GroundCheck>& ground_check() const { return ground_check_; }
  // Back to the start of `step`: intrinsics (every view and result goes), ground (the pose and
  // the enclosure), enclosure (the enclosure). InputError when the step cannot be reached.
  void Redo(WizardStep step);
  // The enclosure from points clicked on the camera's image (carried onto the floor), or the
  // green floor of `image`. InputError (field "pixels" / "detect") when it cannot be made, when
  // the camera is not posed yet, or when the green floor found is smaller than the one seen with
  // the board lying on it (something hides the floor); else the enclosure step ends.
  void SetFloorFromPixels(const std::vector<Eigen::Vector2d>& pixels);
  void DetectFloor(const cv::Mat& image);
  const std::string& floor_from() const { return floor_from_; }

  const std::string& camera() const { return camera_; }
  const std::optional<SolveSummary>& solution() const { return solution_; }
  const std::optional<CameraReport>& report() const { return report_; }
  const std::optional<CameraModel>& intrinsics_model() const { return intrinsics_model_; }
  const std::optional<GroundResult>& ground() const { return ground_; }
  // The floor board's view ground() was solved from (its still frames averaged); empty before.
  const BoardView& floor_view() const { return floor_view_; }
  std::optional<CameraModel> posed_model() const;
  const std::optional<GroundPolygon>& floor() const { return floor_; }
  std::vector<std::string> verdicts() const { return verdicts_; }  // one line per step that failed
  const nlohmann::json& log() const { return log_; }

 private:
  struct Captured {
    Eigen::Vector2d centre;  // pixels
    double area = 0;         // corners' bounding box, px^2
    Eigen::Vector3d normal;  // board z in the camera (rough focal)
  };
  void Event(int frame, const std::string& kind, nlohmann::json detail = nlohmann::json::object());
  Captured Describe(const BoardView& view) const;
  bool Novel(const BoardView& view, const Captured& d, std::string* why) const;
  void Capture(const BoardView& view, const Captured& d, int frame, const std::string& why);
  void DropView(size_t index, const std::string& why);
  bool CriteriaMet() const;
  void CheckSolvable() const;  // InputError "solve" naming why Solve cannot now
  // InputError at `field` while a solve begun is out (the views it solves must stay).
  void RefuseWhileSolving(const char* field) const;
  void SolveIntrinsics(int frame);
  void TakeIntrinsics(IntrinsicsSolve solved, int frame);
  void EnterGround(int frame);
  void EnterEnclosure(int frame, const cv::Mat& image);
  // The largest green floor region of a frame through the posed model; throws when none.
  GroundPolygon GreenFloorIn(const cv::Mat& image) const;
  // A frame without the board: its green floor becomes the enclosure if nothing hides it.
  void TryEmptyFloor(const cv::Mat& image, int frame);
  double Focal() const;
  // Seconds the still run's frames cover up to `time_s`, its last frame's share included: its
  // first-to-last span x n / (n - 1), which is n / rate at a steady rate (the count from the true
  // rate it replaces). NaN for one frame or without timestamps. (The floor's still span is the
  // first-to-last span alone: floor_still_frames bound it too.)
  double StillRunCovers(double time_s) const;
  // The floor board's pose checked (GroundChecks) against the frame and the still run.
  GroundCheck CheckGround(const GroundResult& ground, const cv::Mat& image, int frame) const;

  std::string camera_;
  int width_, height_;
  WizardOptions o_;
  WizardStep step_ = WizardStep::kIntrinsics;
  std::vector<BoardView> run_;  // consecutive still detections ending at the last frame
  bool run_used_ = false;       // the current still run was captured already
  double run_start_s_ = NAN;    // the timestamp of the still run's first frame
  bool word_ = false;           // the operator said the board lies on the floor
  double word_since_s_ = NAN;   // the timestamp of the first frame after the word
  bool word_lapsed_ = false;    // the last word lapsed without a board taken
  std::optional<GroundCheck> ground_check_;
  int empty_frames_ = 0;          // enclosure: frames in a row without a board
  int fed_ = 0;                   // frames fed
  bool last_detected_ = false;    // the board was found in the last frame
  std::string last_rejection_;    // why the last searched frame had no board
  std::vector<BoardView> views_;  // captured intrinsics views
  std::vector<Captured> described_;
  cv::Mat coverage_;
  double max_tilt_deg_ = 0;
  int next_solve_at_ = 0;   // views needed before solving again after a failed verdict
  bool solve_out_ = false;  // BeginSolve was called, EndSolve not yet
  bool board_seen_ = false, intrinsics_good_ = false;
  std::optional<SolveSummary> solution_;
  std::optional<CameraReport> report_;
  std::optional<CameraModel> intrinsics_model_;
  std::optional<GroundResult> ground_;
  BoardView floor_view_;
  // The green floor of the frame with the board lying on it: the fallback enclosure, and
  // the least an empty floor shows (or why none was found).
  std::optional<GroundPolygon> floor_with_board_;
  std::string floor_with_board_error_;
  std::optional<GroundPolygon> floor_;
  std::string floor_from_;
  BoardView last_view_;
  std::vector<std::string> verdicts_;
  std::vector<std::string> last_guidance_;
  nlohmann::json log_ = nlohmann::json::array();
};

// Writes what the wizard reached into `out_dir`: CAMERA.cameramodel (posed
// after the ground step, else the intrinsics; none when the intrinsics were not
// trusted), the residual and coverage plots, enclosure.yaml, and wizard.json
// (verdicts, the intrinsics report, ground, enclosure, the step log), which is
// also returned.
nlohmann::json WriteWizardOutputs(const CalibrationWizard& wizard, const std::string& out_dir,
                                  const VerdictOptions& verdict = {});

}  // namespace ss::calib
