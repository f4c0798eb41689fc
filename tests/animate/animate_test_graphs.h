#pragma once
// Small synthetic transition graphs for the animate tests.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "animate/transition_graph.h"

namespace ss::testing {

// A random graph: clips of 1..6 frames with random 2D velocities, plus `transitions`
// random edges with costs in [0, 2) (self-loops and duplicates included).
inline TransitionGraph RandomGraph(int num_frames, int transitions, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<FrameInfo> frames(num_frames);
  int clip = 0;
  for (int i = 0; i < num_frames; ++i) {
    if (i == 0 || rng() % 4 == 0) ++clip;
    frames[i].clip = clip;
    frames[i].velocity_m = Eigen::Vector2d(unit(rng), unit(rng)) * 0.1;
    if (rng() % 3 == 0) frames[i].tags.push_back("special");
  }
  std::vector<TransitionEdge> edges;
  for (int k = 0; k < transitions; ++k) {
    edges.push_back({static_cast<int>(rng() % num_frames), static_cast<int>(rng() % num_frames),
                     (unit(rng) + 1.0)});
  }
  return TransitionGraph(std::move(frames), edges);
}

// "Walking" frames: a ring clip whose heading turns once around (frames 0..47), eight
// straight walking clips of 16 frames heading 0°, 45°, ... (each looping back to its
// start), and a standing clip of 10 frames tagged "standing". Transitions join frames
// of similar heading; costs grow with the heading difference.
struct WalkingGraph {
  static constexpr int kRing = 48;
  static constexpr int kStraight = 16;
  static constexpr int kStand = 10;
  static constexpr double kSpeed = 0.05;  // metres per step
  static int Straight(int d, int m) { return kRing + d * kStraight + m; }
  static int Stand(int m) { return kRing + 8 * kStraight + m; }

  static TransitionGraph Make() {
    std::vector<FrameInfo> frames;
    auto heading = [](double a) -> Eigen::Vector2d {
      return Eigen::Vector2d(std::cos(a), std::sin(a)) * kSpeed;
    };
    const double two_pi = 2 * std::numbers::pi;
    for (int i = 0; i < kRing; ++i) frames.push_back({0, heading(two_pi * i / kRing), {}});
    for (int d = 0; d < 8; ++d) {
      for (int m = 0; m < kStraight; ++m) frames.push_back({1 + d, heading(two_pi * d / 8), {}});
    }
    for (int m = 0; m < kStand; ++m) frames.push_back({9, Eigen::Vector2d::Zero(), {"standing"}});
    std::vector<TransitionEdge> edges{{kRing - 1, 0, 0.0}};
    auto angle_diff = [&](double a, double b) { return std::abs(std::remainder(a - b, two_pi)); };
    for (int d = 0; d < 8; ++d) {
      const double phi = two_pi * d / 8;
      edges.push_back({Straight(d, kStraight - 1), Straight(d, 0), 0.05});
      for (int i = 0; i < kRing; ++i) {
        const double diff = angle_diff(two_pi * i / kRing, phi);
        if (diff < 0.3) {
          edges.push_back({i, Straight(d, 0), 0.1 + diff});
          edges.push_back({Straight(d, 8), i, 0.1 + diff});
        }
      }
      for (int m = 0; m < kStraight; m += 4) {
        edges.push_back({Straight(d, m), Straight((d + 1) % 8, m + 1), 0.3});
        edges.push_back({Straight(d, m), Straight((d + 7) % 8, m + 1), 0.3});
      }
      edges.push_back({Straight(d, 8), Stand(0), 0.4});
      edges.push_back({Stand(kStand - 1), Straight(d, 0), 0.4});
    }
    edges.push_back({Stand(kStand - 1), Stand(0), 0.05});
    return TransitionGraph(std::move(frames), edges);
  }
};

}  // namespace ss::testing
