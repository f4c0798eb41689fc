#pragma once
// What a session's content (animals, figures, boards) contributes to one frame:
// the scene to render and the camera-independent truth. Each kind of session
// has a Director that produces one snapshot per frame, in order.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/geometry.h"
#include "synth/board.h"
#include "synth/random.h"
#include "synth/renderer.h"
#include "synth/scene.h"

namespace ss::synth {

// Camera-independent truth of one subject at one frame.
struct SubjectTruth {
  std::string kind;                                    // "animal" | "figure"
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // root on the floor, ground x y
  double heading_rad = 0.0;
  double speed_mps = 0.0;
  double gait_phase = 0.0;              // [0, 1)
  std::string pose;                     // walk, trot, turn, idle, lean, stand, Y, M, C, A, ...
  bool touches_wall = false;            // some part within 3 mm of a green wall
  bool leaves_floor = false;            // some part's footprint reaches beyond the floor polygon
  double height_m = 0.0;                // top of the subject above the floor
  std::vector<Eigen::Vector3d> joints;  // figures: 3-D joints in JointNames() order
};

// A board in view and its pose.
struct BoardTruth {
  int board = 0;  // index into the director's board specs
  Rigid3 ground_from_board;
  std::string placement;  // "camera:<name>" (held before a camera) | "floor"
};

struct FrameSnapshot {
  FrameScene scene;
  std::vector<SubjectTruth> subjects;
  std::vector<BoardTruth> boards;
};

class Director {
 public:
  virtual ~Director() = default;
  virtual int subjects() const = 0;
  // Joint names of the figures (empty for other kinds).
  virtual std::vector<std::string> joint_names() const { return {}; }
  virtual const std::vector<BoardSpec>& board_specs() const {
    static const std::vector<BoardSpec> none;
    return none;
  }
  // Advances to time_s (non-decreasing) and fills the frame's snapshot.
  virtual void Frame(double time_s, FrameSnapshot* out) = 0;
  // A JSON description of the subjects (looks, proportions), for truth.json.
  virtual std::string SubjectsJson() const = 0;
};

// Clears `out` for a frame of `subjects` subjects and sets its motion-blur slices (4 with blur,
// else 1), which it returns. The directors render slice s at time_s - (0.5 / fps) * s / slices,
// last first: slice 0, which the shadows and the truth use, is the frame time.
int StartFrame(FrameSnapshot* out, int subjects, bool motion_blur);

// A starting place on the floor `margin_m` from the walls and more than `apart_m` from every one
// of `placed` (the last of 200 draws from `rng` when none is).
Eigen::Vector2d PlaceApart(const Studio& studio, Rng& rng,
                           const std::vector<Eigen::Vector2d>& placed, double margin_m,
                           double apart_m);

// Touch and floor tests shared by the directors.
// An animal's or fly's part within this of a wall touches it (truth's touches_wall, docs/synth.md).
inline constexpr double kWallTouchM = 0.003;
bool TouchesWall(const Studio& studio, const std::vector<Primitive>& prims, int subject,
                 double tolerance_m);
bool LeavesFloor(const Studio& studio, const std::vector<Primitive>& prims, int subject,
                 double tolerance_m);
double TopHeight(const std::vector<Primitive>& prims, int subject);

// The truth of subject `subject` from its behaviour's state (any with position, heading_rad,
// speed_mps, gait_phase and pose) and the frame's primitives; `touch_m` and `leave_m` are the
// tolerances of TouchesWall and LeavesFloor.
template <typename State>
SubjectTruth TruthOf(const char* kind, const State& state, const Studio& studio,
                     const std::vector<Primitive>& prims, int subject, double touch_m,
                     double leave_m) {
  SubjectTruth t;
  t.kind = kind;
  t.position = state.position;
  t.heading_rad = state.heading_rad;
  t.speed_mps = state.speed_mps;
  t.gait_phase = state.gait_phase;
  t.pose = state.pose;
  t.touches_wall = TouchesWall(studio, prims, subject, touch_m);
  t.leaves_floor = LeavesFloor(studio, prims, subject, leave_m);
  t.height_m = TopHeight(prims, subject);
  return t;
}

}  // namespace ss::synth
