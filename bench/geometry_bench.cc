// spritestation bench geometry [google benchmark args]: the floor polygon's simplicity check.
//   geometry/is_simple/sweep/{comb,star}/N    GroundPolygon::IsSimple, the O(n log n) sweep
//   geometry/is_simple/brute_force/{comb,star}/N  the O(n^2) check it replaced (issue 20), kept
//                                             in tests/core/polygon_fixtures.h: the baseline
// Shapes (tests/core/polygon_fixtures.h): a comb, half of whose edges cross the sweep line at
// once, and a star of random radii; both simple, so that every check runs to the end.
// Figures: ms a check, and the brute force's time as a multiple of the sweep's, in this run.
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "core/geometry.h"
#include "tests/core/polygon_fixtures.h"

namespace ss::bench {
namespace {

std::vector<Eigen::Vector2d> Shape(const std::string& shape, size_t n) {
  if (shape == "comb") return testing::Comb(n / 4);
  std::mt19937 rng(1);
  return testing::Star(n, rng, 0.9);
}

void BM_Sweep(benchmark::State& state, std::string shape) {
  const GroundPolygon polygon(Shape(shape, static_cast<size_t>(state.range(0))));
  for (auto _ : state) {
    if (!polygon.IsSimple()) state.SkipWithError("not simple");
  }
}

void BM_BruteForce(benchmark::State& state, std::string shape) {
  const std::vector<Eigen::Vector2d> vertices = Shape(shape, static_cast<size_t>(state.range(0)));
  for (auto _ : state) {
    if (!testing::BruteForceIsSimple(vertices)) state.SkipWithError("not simple");
  }
}

BENCHMARK_CAPTURE(BM_Sweep, comb, std::string("comb"))
    ->Name("geometry/is_simple/sweep/comb")->RangeMultiplier(10)->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sweep, star, std::string("star"))
    ->Name("geometry/is_simple/sweep/star")->RangeMultiplier(10)->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BruteForce, comb, std::string("comb"))
    ->Name("geometry/is_simple/brute_force/comb")->RangeMultiplier(10)->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BruteForce, star, std::string("star"))
    ->Name("geometry/is_simple/brute_force/star")->RangeMultiplier(10)->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);

// Keeps each case's time so the suite can print the ratios after the table.
class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (!r.error_occurred && r.run_type == Run::RT_Iteration) ms[r.run_name.str()] = r.GetAdjustedRealTime();
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> ms;  // by "geometry/is_simple/sweep/comb/1000" (the unit is ms)
};

int Run(const std::vector<std::string>& args) {
  std::vector<std::string> storage = {"spritestation-bench", "--benchmark_filter=^geometry/"};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  if (benchmark::ReportUnrecognizedArguments(argc, argv.data())) return 2;
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();

  std::printf("\ngeometry figures (IsSimple, one thread; the brute force as a multiple of the sweep, this run):\n");
  for (const char* shape : {"comb", "star"}) {
    for (const int n : {1000, 10000, 100000, 1000000}) {
      const std::string sweep = std::string("geometry/is_simple/sweep/") + shape + "/" + std::to_string(n);
      const std::string brute = std::string("geometry/is_simple/brute_force/") + shape + "/" + std::to_string(n);
      if (!collector.ms.count(sweep)) continue;
      std::printf("  %-5s %8d vertices: sweep %9.3f ms", shape, n, collector.ms[sweep]);
      if (collector.ms.count(brute)) {
        std::printf(", brute force %9.1f ms = %6.0f x", collector.ms[brute], collector.ms[brute] / collector.ms[sweep]);
      }
      std::printf("\n");
    }
  }
  return 0;
}

const bool kRegistered = RegisterSuite({"geometry", "floor polygon simplicity check: the sweep vs the brute force", &Run});

}  // namespace
}  // namespace ss::bench
