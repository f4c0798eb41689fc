#include "synth/motion_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/csv_table.h"
#include "core/error.h"

namespace ss::synth {
namespace {

// The q-quantile (0..1) of `v` by the nearest rank; 0 for none.
double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

std::vector<MotionSample> ReadSubjectsCsv(const std::string& path) {
  CsvTable csv(path, "cannot open (expected a session's truth/subjects.csv)");
  const size_t c_frame = csv.Column("frame"), c_subject = csv.Column("subject"),
               c_x = csv.Column("x"), c_y = csv.Column("y"), c_heading = csv.Column("heading_rad"),
               c_speed = csv.Column("speed_mps"), c_pose = csv.Column("pose"),
               c_wall = csv.Column("touches_wall");
  std::vector<MotionSample> out;
  while (csv.Next()) {
    try {
      MotionSample s;
      s.frame = std::stoi(csv[c_frame]);
      s.subject = std::stoi(csv[c_subject]);
      s.position = {std::stod(csv[c_x]), std::stod(csv[c_y])};
      s.heading_rad = std::stod(csv[c_heading]);
      s.speed_mps = std::stod(csv[c_speed]);
      s.pose = csv[c_pose];
      s.touches_wall = csv[c_wall] == "1";
      out.push_back(std::move(s));
    } catch (const std::logic_error&) {
      throw InputError(csv.Where(), "a number does not parse: '" + csv.line() + "'");
    }
  }
  return out;
}

MotionStats MeasureMotion(const std::vector<MotionSample>& samples, double fps, double half_x,
                          double half_y) {
  MotionStats s;
  std::vector<const MotionSample*> rows;
  for (const MotionSample& m : samples) {
    if (m.pose != "absent") rows.push_back(&m);
  }
  std::sort(rows.begin(), rows.end(), [](const MotionSample* a, const MotionSample* b) {
    return std::pair(a->subject, a->frame) < std::pair(b->subject, b->frame);
  });
  s.frames = static_cast<int>(rows.size());
  if (rows.empty()) return s;
  std::vector<double> speeds, turns;
  int moving = 0, running = 0, left = 0, right = 0, touching = 0, near_wall = 0, centre = 0;
  std::set<std::pair<int, int>> cells;
  for (size_t i = 0; i < rows.size(); ++i) {
    const MotionSample& m = *rows[i];
    speeds.push_back(m.speed_mps);
    moving += m.speed_mps > 0.05;
    running += m.speed_mps > 0.3;
    s.pose_share[m.pose] += 1.0;
    touching += m.touches_wall;
    const double to_wall =
        std::min(half_x - std::abs(m.position.x()), half_y - std::abs(m.position.y()));
    near_wall += to_wall < s.near_wall_m;
    centre += std::abs(m.position.x()) < half_x / 2 && std::abs(m.position.y()) < half_y / 2;
    cells.insert({static_cast<int>(std::floor((m.position.x() + half_x) / 0.1)),
                  static_cast<int>(std::floor((m.position.y() + half_y) / 0.1))});
    if (i > 0 && rows[i - 1]->subject == m.subject && rows[i - 1]->frame + 1 == m.frame) {
      const double rate = std::remainder(m.heading_rad - rows[i - 1]->heading_rad, 2 * M_PI) * fps;
      turns.push_back(std::abs(rate));
      left += rate > 0.3;
      right += rate < -0.3;
    }
  }
  const double n = static_cast<double>(rows.size());
  s.speed_median_mps = Quantile(speeds, 0.5);
  s.speed_p90_mps = Quantile(speeds, 0.9);
  s.speed_p99_mps = Quantile(speeds, 0.99);
  s.speed_max_mps = *std::max_element(speeds.begin(), speeds.end());
  s.moving_share = moving / n;
  s.running_share = running / n;
  s.turn_abs_median_rad_s = Quantile(turns, 0.5);
  s.turn_abs_p90_rad_s = Quantile(turns, 0.9);
  const double pairs = std::max<double>(1.0, static_cast<double>(turns.size()));
  s.turning_left_share = left / pairs;
  s.turning_right_share = right / pairs;
  for (auto& [pose, share] : s.pose_share) share /= n;
  s.wall_touch_share = touching / n;
  s.near_wall_share = near_wall / n;
  s.centre_share = centre / n;
  const int cells_x = static_cast<int>(std::ceil(2 * half_x / 0.1 - 1e-9));
  const int cells_y = static_cast<int>(std::ceil(2 * half_y / 0.1 - 1e-9));
  s.cells_visited_share = static_cast<double>(cells.size()) / (cells_x * cells_y);
  return s;
}

std::string MotionStatsText(const MotionStats& s) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "subject-frames %d\n"
                "speed m/s: median %.3f, p90 %.3f, p99 %.3f, max %.3f; moving (> 0.05) %.1f %%, "
                "running (> 0.3) %.1f %%\n"
                "turn rate rad/s: |median| %.2f, |p90| %.2f; turning left %.1f %%, right %.1f %% "
                "(> 0.3 rad/s)\n"
                "floor: touching a wall %.1f %%, root within %.2f m of a wall %.1f %%, in the "
                "inner half %.1f %%, 0.1 m cells visited %.1f %%\n",
                s.frames, s.speed_median_mps, s.speed_p90_mps, s.speed_p99_mps, s.speed_max_mps,
                100 * s.moving_share, 100 * s.running_share, s.turn_abs_median_rad_s,
                s.turn_abs_p90_rad_s, 100 * s.turning_left_share, 100 * s.turning_right_share,
                100 * s.wall_touch_share, s.near_wall_m, 100 * s.near_wall_share,
                100 * s.centre_share, 100 * s.cells_visited_share);
  std::string out = buf;
  out += "poses:";
  for (const auto& [pose, share] : s.pose_share) {
    std::snprintf(buf, sizeof buf, " %s %.1f %%", pose.c_str(), 100 * share);
    out += buf;
  }
  return out + "\n";
}

std::string MotionStatsJson(const MotionStats& s) {
  nlohmann::json j = {{"subject_frames", s.frames},
                      {"speed_median_mps", s.speed_median_mps},
                      {"speed_p90_mps", s.speed_p90_mps},
                      {"speed_p99_mps", s.speed_p99_mps},
                      {"speed_max_mps", s.speed_max_mps},
                      {"moving_share", s.moving_share},
                      {"running_share", s.running_share},
                      {"turn_abs_median_rad_s", s.turn_abs_median_rad_s},
                      {"turn_abs_p90_rad_s", s.turn_abs_p90_rad_s},
                      {"turning_left_share", s.turning_left_share},
                      {"turning_right_share", s.turning_right_share},
                      {"pose_share", s.pose_share},
                      {"wall_touch_share", s.wall_touch_share},
                      {"near_wall_m", s.near_wall_m},
                      {"near_wall_share", s.near_wall_share},
                      {"centre_share", s.centre_share},
                      {"cells_visited_share", s.cells_visited_share}};
  return j.dump(2);
}

}  // namespace ss::synth
