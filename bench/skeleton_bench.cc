// spritestation bench skeleton: the articulated-sprite matcher (seed 003 §2.2-2.3) on
// synthetic gesture skeletons (animate/skeleton/synthetic_poses.h): a target body playing
// Y/M/C/A/walk/idle routines against source clips of a differently proportioned body.
//   speed:   the linear-per-row DP on T x S (default 2,000 x 20,000), one thread, against
//            a plain quadratic DP (every predecessor for every source frame) measured in
//            the same run: fully on a small problem (checking both give the same optimum),
//            and on a few rows of the large one (its total extrapolated from them);
//   quality: gesture accuracy (share of target frames matched to a source frame with the
//            same label), freezes and stutters without penalties, with them and refined.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "animate/skeleton/cost_rows.h"
#include "animate/skeleton/descriptor.h"
#include "animate/skeleton/match_dp.h"
#include "animate/skeleton/skeleton_match.h"
#include "animate/skeleton/synthetic_poses.h"
#include "bench/bench_registry.h"
#include "core/error.h"
#include "core/log.h"

namespace ss::bench::skeleton_bench {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Args {
  int targets = 2000;
  int sources = 20000;
  int clip_frames = 2000;  // source frames per clip
  int naive_rows = 3;      // rows of the quadratic DP timed on the large problem
  int small_targets = 200, small_sources = 2000;
  bool quality = true;
  bool json = false;
  bool gbench = false;  // --gbench: the Google Benchmark cases on targets x sources instead
};

// Values as --name=value (the bench command hands numbers given apart to the suite out of
// order) or --name value.
Args Parse(const std::vector<std::string>& given) {
  std::vector<std::string> argv;
  for (const auto& s : given) {
    const size_t eq = s.find('=');
    if (s.rfind("--", 0) == 0 && eq != std::string::npos) {
      argv.push_back(s.substr(0, eq));
      argv.push_back(s.substr(eq + 1));
    } else {
      argv.push_back(s);
    }
  }
  Args a;
  for (size_t k = 0; k < argv.size(); ++k) {
    const std::string& s = argv[k];
    auto value = [&]() -> int {
      if (k + 1 >= argv.size()) throw InputError("bench skeleton", s + " needs a value");
      return std::stoi(argv[++k]);
    };
    if (s == "--targets")
      a.targets = value();
    else if (s == "--sources")
      a.sources = value();
    else if (s == "--clip-frames")
      a.clip_frames = value();
    else if (s == "--naive-rows")
      a.naive_rows = value();
    else if (s == "--small-targets")
      a.small_targets = value();
    else if (s == "--small-sources")
      a.small_sources = value();
    else if (s == "--skip-quality")
      a.quality = false;
    else if (s == "--json")
      a.json = true;
    else if (s == "--gbench")
      a.gbench = true;
    else
      throw InputError("bench skeleton",
                       "unknown argument '" + s + "' (see bench/skeleton_bench.cc)");
  }
  if (a.targets < 10 || a.sources < 100 || a.clip_frames < 50 || a.naive_rows < 1 ||
      a.small_targets < 2 || a.small_sources < 10) {
    throw InputError("bench skeleton", "sizes too small");
  }
  return a;
}

const std::vector<Gesture> kGestures = {Gesture::kIdle, Gesture::kY, Gesture::kM,
                                        Gesture::kC,    Gesture::kA, Gesture::kWalk};

// About `frames` frames of gestures in random order with random holds and speed.
LabelledSkeletons RandomPerformance(int frames, const BodyProportions& body, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::pair<Gesture, int>> script;
  GestureScriptOptions o;
  o.noise_px = 1.5f;
  o.seed = seed;
  o.speed = std::uniform_real_distribution<float>(0.75f, 1.3f)(rng);
  int total = 0;
  Gesture last = Gesture::kIdle;
  while (total < frames) {
    Gesture g = kGestures[rng() % kGestures.size()];
    if (g == last) continue;
    const int hold = 20 + static_cast<int>(rng() % 40);
    script.push_back({g, hold});
    total += static_cast<int>(hold / o.speed) + o.transition_frames;
    last = g;
  }
  LabelledSkeletons out = MakeGestureSequence(script, body, o);
  out.sequence.frames.resize(std::min<size_t>(out.sequence.frames.size(), frames));
  out.labels.resize(out.sequence.frames.size());
  return out;
}

// Source clips of `clip_frames` each, `total` frames in all.
std::vector<LabelledSkeletons> SourceClips(int total, int clip_frames) {
  std::vector<LabelledSkeletons> clips;
  for (int made = 0, k = 0; made < total; ++k) {
    const int n = std::min(clip_frames, total - made);
    clips.push_back(RandomPerformance(n, OtherBody(), 1000 + k));
    clips.back().sequence.clip = "clip" + std::to_string(k);
    made += clips.back().sequence.size();
  }
  return clips;
}

// The quadratic DP: every predecessor p for every s, state (s, repeats) as in match_dp.h
// (no listed transitions). Runs rows [0, rows) and returns the best value after them.
double QuadraticDp(const CostRows& costs, const std::vector<int>& clip_starts,
                   const MatchOptions& o, int rows) {
  const int S = costs.sources(), R = o.freeze_levels;
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<int> clip(S);
  for (size_t c = 0; c < clip_starts.size(); ++c) {
    const int end = c + 1 < clip_starts.size() ? clip_starts[c + 1] : S;
    std::fill(clip.begin() + clip_starts[c], clip.begin() + end, static_cast<int>(c));
  }
  std::vector<float> row(S), best(S), v(static_cast<size_t>(S) * (R + 1), inf), next(v.size());
  costs.Compute(0, 1, row.data());
  for (int s = 0; s < S; ++s) v[static_cast<size_t>(s) * (R + 1)] = row[s];
  for (int t = 1; t < rows; ++t) {
    costs.Compute(t, 1, row.data());
    for (int p = 0; p < S; ++p) {
      float m = inf;
      for (int r = 0; r <= R; ++r) m = std::min(m, v[static_cast<size_t>(p) * (R + 1) + r]);
      best[p] = m;
    }
    for (int s = 0; s < S; ++s) {
      float* n = &next[static_cast<size_t>(s) * (R + 1)];
      const float* cur = &v[static_cast<size_t>(s) * (R + 1)];
      float m = inf;
      for (int p = 0; p < S; ++p) {
        if (p == s) continue;
        const int d = s - p;
        float move = o.jump_cost;
        if (clip[p] == clip[s]) {
          if (d >= 1 && d <= o.max_forward_step)
            move = o.skip_cost * static_cast<float>(d - 1);
          else if (d < 0 && d >= -o.stutter_window)
            move = o.jump_cost + o.stutter_cost;
        }
        m = std::min(m, best[p] + move);
      }
      n[0] = m + row[s];
      for (int r = 1; r <= R; ++r) {
        const float from = r < R ? cur[r - 1] : std::min(cur[R - 1], cur[R]);
        n[r] = from + o.freeze_cost * static_cast<float>(r) + row[s];
      }
    }
    v.swap(next);
  }
  return *std::min_element(v.begin(), v.end());
}

struct Problem {
  LabelledSkeletons target;
  std::vector<LabelledSkeletons> clips;
  std::vector<const SkeletonSequence*> sequences;
  std::vector<int> clip_starts;
  std::vector<Gesture> source_labels;
};

Problem MakeProblem(int targets, int sources, int clip_frames) {
  Problem p;
  p.target = RandomPerformance(targets, BodyProportions{}, 7);
  p.clips = SourceClips(sources, clip_frames);
  int flat = 0;
  for (const auto& c : p.clips) {
    p.sequences.push_back(&c.sequence);
    p.clip_starts.push_back(flat);
    flat += c.sequence.size();
    p.source_labels.insert(p.source_labels.end(), c.labels.begin(), c.labels.end());
  }
  return p;
}

double Accuracy(const std::vector<int>& path, const Problem& p) {
  int same = 0;
  for (size_t t = 0; t < path.size(); ++t) same += p.target.labels[t] == p.source_labels[path[t]];
  return static_cast<double>(same) / static_cast<double>(path.size());
}

nlohmann::json StatsJson(const MatchStats& s, double accuracy) {
  return {
      {"gesture_accuracy", accuracy}, {"freezes", s.freezes}, {"longest_freeze", s.longest_freeze},
      {"stutters", s.stutters},       {"jumps", s.jumps},     {"skips", s.skips}};
}

// Google Benchmark cases on one T x S problem (built once, outside the timing), one thread:
//   BM_SkeletonMatchLinear:         descriptors + cost rows + the linear-per-row DP, whole problem;
//   BM_SkeletonMatchQuadraticRows:  the baseline, the plain quadratic DP on the first rows of
//                                   the same problem (costs included), extrapolated to all T rows.
int RunGbench(const Args& a) {
  static Problem* problem = nullptr;
  const auto t_make = Clock::now();
  problem = new Problem(MakeProblem(a.targets, a.sources, a.clip_frames));
  std::printf("problem %d x %d in %zu clips built in %.1f s (not timed)\n",
              problem->target.sequence.size(), static_cast<int>(problem->source_labels.size()),
              problem->clips.size(), Since(t_make));
  const std::string size = std::to_string(a.targets) + "x" + std::to_string(a.sources);
  benchmark::RegisterBenchmark(
      ("BM_SkeletonMatchLinear/" + size).c_str(),
      [](benchmark::State& state) {
        const Problem& p = *problem;
        MatchResult r;
        double describe_s = 0, solve_s = 0;
        for (auto _ : state) {
          auto t0 = Clock::now();
          const PoseDescriptors td = ComputeDescriptors(p.target.sequence, {});
          const PoseDescriptors sd = ComputeDescriptors(p.sequences, {});
          const DescriptorCostRows costs(td, sd);
          describe_s = Since(t0);
          t0 = Clock::now();
          r = SolveMatch(costs, p.clip_starts, MatchOptions{});
          solve_s = Since(t0);
          benchmark::DoNotOptimize(r.total_cost);
        }
        state.counters["describe_s"] = describe_s;
        state.counters["solve_s"] = solve_s;
        state.counters["cost_rows_s"] = r.cost_seconds;
        state.counters["forward_s"] = r.forward_seconds;
        state.counters["backward_s"] = r.backward_seconds;
        state.counters["memory_mib"] = static_cast<double>(r.memory_bytes) / (1 << 20);
        state.counters["gesture_accuracy"] = Accuracy(r.source_frames, p);
      })
      ->Unit(benchmark::kSecond)
      ->Iterations(1)
      ->UseRealTime();
  const int rows = a.naive_rows + 1;
  benchmark::RegisterBenchmark(
      ("BM_SkeletonMatchQuadraticRows/" + size).c_str(),
      [rows](benchmark::State& state) {
        const Problem& p = *problem;
        const PoseDescriptors td = ComputeDescriptors(p.target.sequence, {});
        const PoseDescriptors sd = ComputeDescriptors(p.sequences, {});
        const DescriptorCostRows costs(td, sd);
        double seconds = 0;
        for (auto _ : state) {
          const auto t0 = Clock::now();
          benchmark::DoNotOptimize(QuadraticDp(costs, p.clip_starts, MatchOptions{}, rows));
          seconds = Since(t0);
        }
        state.counters["rows"] = rows;
        state.counters["s_per_row"] = seconds / rows;
        state.counters["extrapolated_total_s"] = seconds / rows * costs.targets();
      })
      ->Unit(benchmark::kSecond)
      ->Iterations(1)
      ->UseRealTime();
  return RunGoogleBenchmarks("BM_SkeletonMatch", {});
}

int Run(const std::vector<std::string>& argv) {
  const Args a = Parse(argv);
  SetLogLevel("warn");
  if (a.gbench) return RunGbench(a);
  nlohmann::json result;
  MatchOptions options;

  // 1. Small problem: both DPs to completion, same optimum.
  {
    const Problem p = MakeProblem(a.small_targets, a.small_sources, a.clip_frames);
    const PoseDescriptors td = ComputeDescriptors(p.target.sequence, {});
    const PoseDescriptors sd = ComputeDescriptors(p.sequences, {});
    const DescriptorCostRows costs(td, sd);
    auto t0 = Clock::now();
    const MatchResult linear = SolveMatch(costs, p.clip_starts, options);
    const double linear_s = Since(t0);
    t0 = Clock::now();
    const double naive = QuadraticDp(costs, p.clip_starts, options, costs.targets());
    const double naive_s = Since(t0);
    const bool same = std::abs(naive - linear.total_cost) <= 1e-3 * std::max(1.0, std::abs(naive));
    result["small"] = {{"targets", costs.targets()},    {"sources", costs.sources()},
                       {"linear_dp_s", linear_s},       {"quadratic_dp_s", naive_s},
                       {"speedup", naive_s / linear_s}, {"linear_optimum", linear.total_cost},
                       {"quadratic_optimum", naive},    {"same_optimum", same}};
    std::printf(
        "small %d x %d: linear DP %.3f s, quadratic DP %.3f s (x%.0f); optimum %.4f vs %.4f%s\n",
        costs.targets(), costs.sources(), linear_s, naive_s, naive_s / linear_s, linear.total_cost,
        naive, same ? "" : "  MISMATCH");
    if (!same) return 1;
  }

  // 2. Large problem: the linear DP in full, the quadratic DP on a few rows.
  const auto t_make = Clock::now();
  const Problem p = MakeProblem(a.targets, a.sources, a.clip_frames);
  const double make_s = Since(t_make);
  auto t0 = Clock::now();
  const PoseDescriptors td = ComputeDescriptors(p.target.sequence, {});
  const PoseDescriptors sd = ComputeDescriptors(p.sequences, {});
  const double describe_s = Since(t0);
  const DescriptorCostRows costs(td, sd);
  t0 = Clock::now();
  const MatchResult linear = SolveMatch(costs, p.clip_starts, options);
  const double linear_s = Since(t0);
  t0 = Clock::now();
  QuadraticDp(costs, p.clip_starts, options, a.naive_rows + 1);
  const double naive_rows_s = Since(t0);
  // Row 0 only computes costs; rows 1..naive_rows relax. Per row (costs included):
  const double naive_row_s = naive_rows_s / (a.naive_rows + 1);
  const double naive_total_s = naive_row_s * costs.targets();
  const double linear_row_us = 1e6 * linear_s / costs.targets();
  result["large"] = {{"targets", costs.targets()},
                     {"sources", costs.sources()},
                     {"clips", p.clips.size()},
                     {"make_poses_s", make_s},
                     {"descriptors_s", describe_s},
                     {"linear_dp_s", linear_s},
                     {"linear_cost_rows_s", linear.cost_seconds},
                     {"linear_forward_s", linear.forward_seconds},
                     {"linear_backward_s", linear.backward_seconds},
                     {"linear_memory_mib", static_cast<double>(linear.memory_bytes) / (1 << 20)},
                     {"linear_us_per_row", linear_row_us},
                     {"quadratic_rows_timed", a.naive_rows + 1},
                     {"quadratic_s_per_row", naive_row_s},
                     {"quadratic_total_s_extrapolated", naive_total_s},
                     {"speedup_extrapolated", naive_total_s / linear_s}};
  std::printf(
      "large %d x %d (%zu clips): descriptors %.2f s; linear DP %.2f s (costs %.2f, forward %.2f, "
      "backward "
      "%.2f; %.1f MiB), %.0f us per target row\n",
      costs.targets(), costs.sources(), p.clips.size(), describe_s, linear_s, linear.cost_seconds,
      linear.forward_seconds, linear.backward_seconds,
      static_cast<double>(linear.memory_bytes) / (1 << 20), linear_row_us);
  std::printf(
      "quadratic DP: %.3f s per target row over %d rows -> %.0f s for all %d rows (extrapolated): "
      "x%.0f\n",
      naive_row_s, a.naive_rows + 1, naive_total_s, costs.targets(), naive_total_s / linear_s);

  // 3. Quality on the large problem: without penalties, with them, refined.
  if (a.quality) {
    SkeletonMatchOptions mo;
    mo.match = options;
    t0 = Clock::now();
    const SkeletonMatchResult r = MatchSkeletons(p.target.sequence, p.sequences, mo);
    const double match_s = Since(t0);
    const double acc_without = Accuracy(r.without_penalties->source_frames, p);
    const double acc_with = Accuracy(r.with_penalties.source_frames, p);
    const double acc_refined = Accuracy(r.refined->source_frames, p);
    result["quality"] = {{"seconds_all_three_passes", match_s},
                         {"without_penalties", StatsJson(r.without_penalties->stats, acc_without)},
                         {"with_penalties", StatsJson(r.with_penalties.stats, acc_with)},
                         {"refined", StatsJson(r.refined->stats, acc_refined)},
                         {"target_movements", r.refined->target_movements.size()},
                         {"source_movements", r.refined->source_movements.size()}};
    auto line = [](const char* name, const MatchStats& s, double acc) {
      std::printf("%-18s gesture accuracy %.1f%%, %d freezes (longest %d), %d stutters, %d jumps\n",
                  name, 100 * acc, s.freezes, s.longest_freeze, s.stutters, s.jumps);
    };
    line("without penalties:", r.without_penalties->stats, acc_without);
    line("with penalties:", r.with_penalties.stats, acc_with);
    line("refined:", r.refined->stats, acc_refined);
  }
  if (a.json) std::printf("%s\n", result.dump(2).c_str());
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"skeleton",
     "seed 003 skeleton matching: linear-per-row DP vs a quadratic DP, gesture accuracy", &Run});

}  // namespace
}  // namespace ss::bench::skeleton_bench
