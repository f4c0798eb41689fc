#pragma once
// A sprite's sequence S = s_0..s_{n-1} and its states (p, v, f)_t (seed 000 §5).
// Positions integrate the source frames' ground velocities:
//   p_t = p_{t-1} + v(s_t)   for t >= 1,
// turned, for floor sprites (filmed from above), by the sequence's turn at t: each transition
// between floor sprites turns the rest of the sequence so that the sprite goes on facing the way
// its source frame's successor faced (TransitionGraph::Turn), and the renderer turns it alike.
// anchored at the start (p_0 given, or optimized for a free start) or at the end
// (p_{n-1} given; seed 000 §6.2 fixes the flies' end locations). After its last step a
// sprite holds its last position and frame with zero velocity.
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "animate/transition_graph.h"

namespace ss {

// Which position of a sprite is given.
enum class Anchor {
  kStart,  // p_0 fixed
  kEnd,    // p_{n-1} fixed
  kFree,   // p_0 optimized along with the frames
};

struct Track {
  static constexpr int kChunkSteps = 16;

  std::vector<int> frames;                    // s_t
  std::vector<Eigen::Vector2d> positions_m;   // p_t, ground metres
  std::vector<Eigen::Vector2d> velocities_m;  // v_t = v(s_t), metres per step (turned)
  // theta_t: how far step t is turned from its source frame, radians (floor sprites; empty when
  // the graph has none).
  std::vector<double> turns_rad;
  // Bounding box of the positions of steps [16c, 16c + 16) per chunk c (kept by
  // IntegrateTrack and ShiftTrack; lets pairwise terms skip chunks far apart).
  std::vector<Eigen::AlignedBox2d> chunk_boxes_m;

  int size() const { return static_cast<int>(frames.size()); }
  bool empty() const { return frames.empty(); }
  // State at step t >= 0; held after the last step (zero velocity).
  const Eigen::Vector2d& PositionAt(int t) const {
    return positions_m[t < size() ? t : size() - 1];
  }
  Eigen::Vector2d VelocityAt(int t) const {
    return t < size() ? velocities_m[t] : Eigen::Vector2d::Zero();
  }
  int FrameAt(int t) const { return frames[t < size() ? t : size() - 1]; }
  // Box around the positions of chunk c (c past the end: the held last position); nullptr
  // when the boxes are not up to date.
  const Eigen::AlignedBox2d* ChunkBox(int c, Eigen::AlignedBox2d* held) const;
  // p_0 for start anchors, p_{n-1} for end anchors.
  Eigen::Vector2d AnchorPosition(Anchor anchor) const {
    return anchor == Anchor::kEnd ? positions_m.back() : positions_m.front();
  }
};

// The tracks of all sprites of a problem, indexed by sprite id.
using Tracks = std::span<const Track* const>;

// Recomputes velocities, positions and chunk boxes for `track->frames` from `anchor_m` (p_0
// for kStart and kFree, p_{n-1} for kEnd). With a start anchor, the states and the chunk
// boxes before `from_step` are kept as they are (the caller guarantees they are current).
// `anchor_facing_rad` (floor sprites): the ground direction the anchored step (p_0's, or
// p_{n-1}'s for kEnd) faces, whatever frame it shows: its turn is that less the frame's heading.
// None: that step is shown as filmed (turn 0).
void IntegrateTrack(const TransitionGraph& graph, Anchor anchor, const Eigen::Vector2d& anchor_m,
                    std::optional<double> anchor_facing_rad, Track* track, int from_step = 0);

// A track built from scratch.
Track MakeTrack(const TransitionGraph& graph, std::vector<int> frames, Anchor anchor,
                const Eigen::Vector2d& anchor_m,
                std::optional<double> anchor_facing_rad = std::nullopt);

// Moves every position by `offset_m` (a new start for a free sprite).
void ShiftTrack(const Eigen::Vector2d& offset_m, Track* track);

// Recomputes chunk_boxes_m from the positions (from the chunk holding `from_step` on).
void UpdateChunkBoxes(Track* track, int from_step = 0);

}  // namespace ss
