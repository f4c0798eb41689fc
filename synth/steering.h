#pragma once
// How the synthetic animals and flies steer clear of walls and of each other: terms added to a
// behaviour's turn rate (rad/s, positive to the left), and the step that keeps them apart and
// off the walls.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "synth/angles.h"
#include "synth/random.h"
#include "synth/scene.h"

namespace ss::synth {

// When the floor ahead of `position` along `heading_rad`, less `reach` (the body ahead of the
// root), is shorter than `look_ahead`: turns toward the side with more room (probed at
// +-`probe_rad`), up to `gain` as the room runs out. Returns that room ahead, metres.
inline double SteerFromWalls(const Studio& studio, const Eigen::Vector2d& position,
                             double heading_rad, double reach, double look_ahead, double probe_rad,
                             double gain, double* turn_rate) {
  const double room = RoomAhead(studio, position, heading_rad) - reach;
  if (room < look_ahead) {
    const double left = RoomAhead(studio, position, heading_rad + probe_rad);
    const double right = RoomAhead(studio, position, heading_rad - probe_rad);
    *turn_rate += (left >= right ? 1.0 : -1.0) * gain * (1.0 - std::max(0.0, room) / look_ahead);
  }
  return room;
}

// Turns away from each of `others` in front (within 90 degrees) and nearer than `radius`, up to
// `gain` at contact.
inline void SteerFromOthers(const Eigen::Vector2d& position, double heading_rad,
                            const std::vector<Eigen::Vector2d>& others, double radius, double gain,
                            double* turn_rate) {
  for (const auto& o : others) {
    const Eigen::Vector2d rel = o - position;
    const double d = rel.norm();
    if (d < radius && d > 1e-9) {
      const double bearing = Wrap(std::atan2(rel.y(), rel.x()) - heading_rad);
      if (std::abs(bearing) < M_PI / 2)
        *turn_rate += (bearing > 0 ? -1.0 : 1.0) * gain * (1.0 - d / radius);
    }
  }
}

// A heading 100-170 degrees (drawn from `rng`) away from `heading_rad`, turned toward the side
// with more room: where a subject with its head at the wall turns to.
inline double HeadingAwayFromWall(const Studio& studio, const Eigen::Vector2d& position,
                                  double heading_rad, Rng& rng) {
  const double left = RoomAhead(studio, position, heading_rad + M_PI / 2);
  const double right = RoomAhead(studio, position, heading_rad - M_PI / 2);
  return Wrap(heading_rad + (left >= right ? 1 : -1) * rng.Uniform(100, 170) * kDeg);
}

// Where a subject at `position` moving `*speed_mps` along `heading_rad` is after `dt`: held in
// place (and `*speed_mps` set to 0) where the step would take it within `block_m` of one of
// `others` and nearer to it.
inline Eigen::Vector2d StepAhead(const Eigen::Vector2d& position, double heading_rad,
                                 double* speed_mps, double dt,
                                 const std::vector<Eigen::Vector2d>& others, double block_m) {
  const Eigen::Vector2d dir(std::cos(heading_rad), std::sin(heading_rad));
  Eigen::Vector2d next = position + *speed_mps * dt * dir;
  for (const auto& o : others) {
    if ((next - o).norm() < block_m && (next - o).norm() < (position - o).norm()) {
      next = position;  // blocked by another subject
      *speed_mps = 0.0;
    }
  }
  return next;
}

// `root` moved as little as needed to keep the body 1 mm off the walls: a body reaching `front`
// ahead of the root and `back` behind it along `heading_rad`, and `half` to each side.
inline Eigen::Vector2d KeepBodyInside(const Studio& studio, const Eigen::Vector2d& root,
                                      double heading_rad, double front, double back, double half) {
  const double c = std::cos(heading_rad), sn = std::sin(heading_rad);
  const double ext_px = std::max(front * c, -back * c) + half * std::abs(sn);
  const double ext_nx = std::max(-front * c, back * c) + half * std::abs(sn);
  const double ext_py = std::max(front * sn, -back * sn) + half * std::abs(c);
  const double ext_ny = std::max(-front * sn, back * sn) + half * std::abs(c);
  const double hx = studio.half_x, hy = studio.half_y;
  return {std::clamp(root.x(), -hx + ext_nx + 0.001, hx - ext_px - 0.001),
          std::clamp(root.y(), -hy + ext_ny + 0.001, hy - ext_py - 0.001)};
}

}  // namespace ss::synth
