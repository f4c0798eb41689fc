#include "animate/skeleton/refine.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {

bool MovementOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(lag_s, Positive(), "lag_s", "a positive number of seconds");
  check.Within(smoothing_s, AtLeast(0), "smoothing_s", "seconds >= 0");
  check.Within(min_length_s, AtLeast(0), "min_length_s", "seconds >= 0");
  check.Within(min_prominence, AtLeast(0), "min_prominence", "at least 0");
  check.Within(noise_factor, AtLeast(0), "noise_factor", "at least 0");
  return check.ok();
}

bool RefineOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(movements.IsValid(&part), "movements.", part);
  check.Within(jump_cost_per_frame, AtLeast(0), "jump_cost_per_frame", "at least 0");
  check.Within(averaging_window, AtLeast(1), "averaging_window", "at least 1");
  return check.ok();
}

MovementFrames MovementWindows(const MovementOptions& options, double fps) {
  if (!(fps > 0)) throw InputError("refine", "the frame rate must be > 0");
  auto frames = [&](double seconds) {
    return std::max(1, static_cast<int>(std::lround(seconds * fps)));
  };
  return {frames(options.lag_s), frames(options.smoothing_s), frames(options.min_length_s)};
}

std::vector<int> FindMovements(const std::vector<float>& sequential_cost,
                               const MovementOptions& options, double fps) {
  const MovementFrames windows = MovementWindows(options, fps);
  const int n = static_cast<int>(sequential_cost.size());  // frames - 1
  std::vector<int> starts = {0};
  if (n < 3) return starts;
  // Smooth.
  const int half = std::max(0, windows.smoothing_window / 2);
  std::vector<double> q(n);
  for (int t = 0; t < n; ++t) {
    double sum = 0;
    int used = 0;
    for (int u = std::max(0, t - half); u <= std::min(n - 1, t + half); ++u) {
      sum += sequential_cost[u];
      ++used;
    }
    q[t] = sum / used;
  }
  std::vector<float> sorted = sequential_cost;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double threshold =
      std::max<double>(options.min_prominence, options.noise_factor * sorted[n / 2]);
  // Local maxima (the first frame of a plateau) and their prominence.
  struct Peak {
    int t;
    double height;
  };
  std::vector<Peak> peaks;
  for (int t = 1; t + 1 < n; ++t) {
    if (!(q[t] > q[t - 1] && q[t] >= q[t + 1])) continue;
    double left = q[t], right = q[t];
    for (int u = t - 1; u >= 0 && q[u] <= q[t]; --u) left = std::min(left, q[u]);
    for (int u = t + 1; u < n && q[u] <= q[t]; ++u) right = std::min(right, q[u]);
    if (q[t] - std::max(left, right) >= threshold) peaks.push_back({t, q[t]});
  }
  // Highest first; a boundary (frame t + 1 starts the next movement) too close to a kept
  // one or to either end is dropped.
  std::sort(peaks.begin(), peaks.end(),
            [](const Peak& a, const Peak& b) { return a.height > b.height; });
  const int frames = n + 1;
  std::vector<int> kept;
  for (const auto& p : peaks) {
    const int boundary = p.t + 1;
    if (boundary < windows.min_length || frames - boundary < windows.min_length) continue;
    bool clear = true;
    for (int k : kept) clear = clear && std::abs(k - boundary) >= windows.min_length;
    if (clear) kept.push_back(boundary);
  }
  starts.insert(starts.end(), kept.begin(), kept.end());
  std::sort(starts.begin(), starts.end());
  return starts;
}

std::vector<float> MovementCost(const PoseDescriptors& frames, int begin, int end, int lag) {
  const int l = std::max(1, lag);
  std::vector<float> q;
  for (int t = begin; t + 1 < end; ++t) {
    q.push_back(
        PoseCost(frames, std::max(begin, t + 1 - l), frames, std::min(end - 1, t + l), false));
  }
  return q;
}

std::vector<int> FindMovements(const PoseDescriptors& frames, const std::vector<int>& clip_starts,
                               const MovementOptions& options) {
  std::vector<int> starts;
  for (size_t c = 0; c < clip_starts.size(); ++c) {
    const int begin = clip_starts[c];
    const int end = c + 1 < clip_starts.size() ? clip_starts[c + 1] : frames.count;
    const double fps = FrameRateAt(frames, begin);
    const int lag = MovementWindows(options, fps).lag;
    for (int s : FindMovements(MovementCost(frames, begin, end, lag), options, fps))
      starts.push_back(begin + s);
  }
  return starts;
}

std::vector<int> AverageWithinSegments(const std::vector<int>& frames,
                                       const std::vector<int>& starts, int window) {
  std::vector<int> out = frames;
  const int half = std::max(0, window / 2);
  if (half == 0) return out;
  const int n = static_cast<int>(frames.size());
  for (size_t g = 0; g < starts.size(); ++g) {
    const int begin = starts[g];
    const int end = g + 1 < starts.size() ? starts[g + 1] : n;
    for (int t = begin; t < end; ++t) {
      double sum = 0;
      int used = 0;
      for (int u = std::max(begin, t - half); u <= std::min(end - 1, t + half); ++u) {
        sum += frames[u];
        ++used;
      }
      out[t] = static_cast<int>(std::lround(sum / used));
    }
  }
  return out;
}

std::vector<int> SplitByFirstPass(const std::vector<int>& target_starts,
                                  const std::vector<int>& source_starts,
                                  const std::vector<int>& first_pass, int min_length) {
  const int n = static_cast<int>(first_pass.size());
  std::vector<long> movement(n);  // the source movement of each first-pass frame
  for (int t = 0; t < n; ++t) {
    movement[t] = std::upper_bound(source_starts.begin(), source_starts.end(), first_pass[t]) -
                  source_starts.begin();
  }
  std::vector<int> out = target_starts;
  for (size_t g = 0; g < target_starts.size(); ++g) {
    const int begin = target_starts[g];
    const int end = g + 1 < target_starts.size() ? std::min(n, target_starts[g + 1]) : n;
    long anchor = -1;  // the source movement of the last run long enough
    for (int t = begin; t < end;) {
      const long id = movement[t];
      int u = t;
      while (u < end && movement[u] == id) ++u;
      if (u - t >= std::max(1, min_length)) {
        if (anchor >= 0 && id != anchor) out.push_back(t);
        anchor = id;
      }
      t = u;
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

RefineResult RefineMatch(const CostRows& costs, const PoseDescriptors& targets,
                         const PoseDescriptors& sources, const std::vector<int>& clip_starts,
                         const MatchOptions& options, const RefineOptions& refine,
                         const std::vector<int>* first_pass) {
  if (targets.count != costs.targets() || sources.count != costs.sources()) {
    throw InputError("refine", "the descriptors do not match the cost rows");
  }
  if (std::string why; !refine.IsValid(&why)) throw InputError("refine options", why);
  RefineResult result;
  result.target_movements = FindMovements(targets, {0}, refine.movements);
  result.source_movements = FindMovements(sources, clip_starts, refine.movements);
  if (first_pass != nullptr && static_cast<int>(first_pass->size()) != targets.count) {
    throw InputError("refine", "the first pass has " + std::to_string(first_pass->size()) +
                                   " frames for " + std::to_string(targets.count) +
                                   " target frames");
  }
  if (first_pass != nullptr && targets.count > 0) {
    const int min_length = MovementWindows(refine.movements, FrameRateAt(targets, 0)).min_length;
    result.target_movements =
        SplitByFirstPass(result.target_movements, result.source_movements, *first_pass, min_length);
  }
  MovementConstraint constraint;
  constraint.target_starts = result.target_movements;
  constraint.source_starts = result.source_movements;
  constraint.jump_cost_per_frame = refine.jump_cost_per_frame;
  if (targets.count == 0) return result;
  result.second_pass = SolveMatch(costs, clip_starts, options, &constraint);
  result.source_frames = AverageWithinSegments(result.second_pass.source_frames,
                                               result.target_movements, refine.averaging_window);
  result.stats = AnalyzePath(result.source_frames, clip_starts, options);
  result.total_cost = PathCost(costs, clip_starts, options, &constraint, result.source_frames);
  return result;
}

}  // namespace ss
