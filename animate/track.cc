#include "animate/track.h"

#include <algorithm>
#include <cmath>

namespace ss {

void IntegrateTrack(const TransitionGraph& graph, Anchor anchor, const Eigen::Vector2d& anchor_m,
                    std::optional<double> anchor_facing_rad, Track* track, int from_step) {
  const int n = track->size();
  track->velocities_m.resize(n);
  track->positions_m.resize(n);
  if (n == 0) return;
  if (anchor == Anchor::kEnd) from_step = 0;
  from_step = std::clamp(from_step, 0, n);
  if (graph.has_floor_frames()) {
    // Floor sprites turn at transitions: on from the start (kept before from_step), or back from
    // the end; the anchored step itself faces anchor_facing_rad, or stays as filmed.
    std::vector<double>& turn = track->turns_rad;
    turn.resize(n);
    // The anchored step's turn: toward anchor_facing_rad, or none.
    const auto anchored_turn = [&](int t) {
      const std::optional<double>& heading = graph.frame(track->frames[t]).heading_rad;
      if (!anchor_facing_rad || !heading) return 0.0;
      return std::remainder(*anchor_facing_rad - *heading, 2 * M_PI);
    };
    if (anchor == Anchor::kEnd) {
      turn[n - 1] = anchored_turn(n - 1);
      for (int t = n - 1; t > 0; --t) {
        turn[t - 1] = turn[t] - graph.Turn(track->frames[t - 1], track->frames[t]);
      }
    } else {
      if (from_step == 0) turn[0] = anchored_turn(0);
      for (int t = std::max(from_step, 1); t < n; ++t) {
        turn[t] = turn[t - 1] + graph.Turn(track->frames[t - 1], track->frames[t]);
      }
    }
    for (int t = from_step; t < n; ++t) {
      const Eigen::Vector2d& v = graph.velocity_m(track->frames[t]);
      const double c = std::cos(turn[t]), s = std::sin(turn[t]);
      track->velocities_m[t] = Eigen::Vector2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
    }
  } else {
    track->turns_rad.clear();
    for (int t = from_step; t < n; ++t) track->velocities_m[t] = graph.velocity_m(track->frames[t]);
  }
  if (anchor == Anchor::kEnd) {
    track->positions_m[n - 1] = anchor_m;
    for (int t = n - 1; t > 0; --t) {
      track->positions_m[t - 1] = track->positions_m[t] - track->velocities_m[t];
    }
    UpdateChunkBoxes(track);
    return;
  }
  const int first_box_step = from_step;
  if (from_step == 0) {
    track->positions_m[0] = anchor_m;
    from_step = 1;
  }
  for (int t = from_step; t < n; ++t) {
    track->positions_m[t] = track->positions_m[t - 1] + track->velocities_m[t];
  }
  UpdateChunkBoxes(track, first_box_step);
}

void UpdateChunkBoxes(Track* track, int from_step) {
  const int n = track->size();
  const int chunks = (n + Track::kChunkSteps - 1) / Track::kChunkSteps;
  const int first =
      std::clamp(from_step / Track::kChunkSteps, 0, static_cast<int>(track->chunk_boxes_m.size()));
  track->chunk_boxes_m.resize(chunks);
  for (int c = first; c < chunks; ++c) {
    Eigen::AlignedBox2d box;  // empty
    const int end = std::min(n, (c + 1) * Track::kChunkSteps);
    for (int t = c * Track::kChunkSteps; t < end; ++t) box.extend(track->positions_m[t]);
    track->chunk_boxes_m[c] = box;
  }
}

const Eigen::AlignedBox2d* Track::ChunkBox(int c, Eigen::AlignedBox2d* held) const {
  const int chunks = (size() + kChunkSteps - 1) / kChunkSteps;
  if (static_cast<int>(chunk_boxes_m.size()) != chunks || chunks == 0) return nullptr;
  if (c < chunks) return &chunk_boxes_m[c];
  *held = Eigen::AlignedBox2d(positions_m.back(), positions_m.back());
  return held;
}

Track MakeTrack(const TransitionGraph& graph, std::vector<int> frames, Anchor anchor,
                const Eigen::Vector2d& anchor_m, std::optional<double> anchor_facing_rad) {
  Track track;
  track.frames = std::move(frames);
  IntegrateTrack(graph, anchor, anchor_m, anchor_facing_rad, &track);
  return track;
}

void ShiftTrack(const Eigen::Vector2d& offset_m, Track* track) {
  for (Eigen::Vector2d& p : track->positions_m) p += offset_m;
  UpdateChunkBoxes(track);
}

}  // namespace ss
