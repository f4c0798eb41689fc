#pragma once
// How synthetic subjects move, measured over their truth (truth/subjects.csv, docs/synth.md):
// speed, turning, poses and where on the floor they spend their time. `spritestation bench
// synth-motion` prints these for a session or a simulated run; tests/synth asserts on them.
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ss::synth {

// One row of truth/subjects.csv (the columns the measures read).
struct MotionSample {
  int frame = 0;
  int subject = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // root, ground metres
  double heading_rad = 0.0;
  double speed_mps = 0.0;
  std::string pose;
  bool touches_wall = false;
};

struct MotionStats {
  int frames = 0;  // subject-frames measured ("absent" ones left out)
  // Forward speed (the truth's speed_mps), m/s.
  double speed_median_mps = 0.0, speed_p90_mps = 0.0, speed_p99_mps = 0.0, speed_max_mps = 0.0;
  double moving_share = 0.0;   // frames over 0.05 m/s (the pipeline's stillness speed)
  double running_share = 0.0;  // frames over 0.3 m/s
  // Heading rate between consecutive frames, rad/s; left is counter-clockwise (+).
  double turn_abs_median_rad_s = 0.0, turn_abs_p90_rad_s = 0.0;
  double turning_left_share = 0.0, turning_right_share = 0.0;  // |rate| over 0.3 rad/s
  std::map<std::string, double> pose_share;                    // by pose label
  double wall_touch_share = 0.0;     // frames with some part within touching distance of a wall
  double near_wall_share = 0.0;      // root within `near_wall_m` of a wall
  double centre_share = 0.0;         // root in the inner half (|x| < hx/2 and |y| < hy/2)
  double cells_visited_share = 0.0;  // 0.1 m cells of the floor the root entered
  double near_wall_m = 0.15;
};

// Reads truth/subjects.csv; throws InputError naming the file and line.
std::vector<MotionSample> ReadSubjectsCsv(const std::string& path);

// The measures over the samples (sorted or not) of a floor [-half_x, half_x] x [-half_y, half_y]
// filmed at `fps`.
MotionStats MeasureMotion(const std::vector<MotionSample>& samples, double fps, double half_x,
                          double half_y);

// A few lines of text (numbers with units) and the same as a JSON object.
std::string MotionStatsText(const MotionStats& s);
std::string MotionStatsJson(const MotionStats& s);

}  // namespace ss::synth
