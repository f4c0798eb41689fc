// spritestation bench geometry [google benchmark args]: the floor polygon's simplicity check,
// and the floor mask (which pixels of a camera see the floor).
//   geometry/is_simple/sweep/{comb,star}/N    GroundPolygon::IsSimple, the O(n log n) sweep
//   geometry/is_simple/brute_force/{comb,star}/N  the O(n^2) check it replaced (issue 20), kept
//                                             in tests/core/polygon_fixtures.h: the baseline
//   geometry/floor_mask/index/{comb,star}/N   FloorPixels of a 640x480 camera through a
//                                             GroundPolygonIndex (the edges near each point)
//   geometry/floor_mask/every_edge/{comb,star}/N  the same mask through GroundPolygon::Contains
//                                             (every edge for every pixel: FloorMask before)
// Shapes (tests/core/polygon_fixtures.h): a comb, half of whose edges cross the sweep line at
// once, and a star of random radii; both simple, so that every check runs to the end. For the
// floor mask they are scaled to fill the camera's view of the floor.
// Figures: ms a check or a mask, and the old way's time as a multiple of the new, in this run.
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "core/camera_model.h"
#include "core/geometry.h"
#include "pipeline/filter/usability.h"
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
    ->Name("geometry/is_simple/sweep/comb")
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sweep, star, std::string("star"))
    ->Name("geometry/is_simple/sweep/star")
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BruteForce, comb, std::string("comb"))
    ->Name("geometry/is_simple/brute_force/comb")
    ->RangeMultiplier(10)
    ->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BruteForce, star, std::string("star"))
    ->Name("geometry/is_simple/brute_force/star")
    ->RangeMultiplier(10)
    ->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);

// A 640x480 pinhole camera 3 m above the floor looking straight down (3.84 x 2.88 m of floor), and
// the shape scaled into 3.6 x 2.6 m of it, centred: nearly every pixel's point is tested.
CameraModel MaskCamera() {
  Rigid3 cam_from_ground;
  cam_from_ground.rotation << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam_from_ground.translation = Eigen::Vector3d(0, 0, 3.0);
  return CameraModel("LENSMODEL_PINHOLE", {500, 500, 320, 240}, 640, 480, cam_from_ground);
}

GroundPolygon MaskFloor(const std::string& shape, size_t n) {
  std::vector<Eigen::Vector2d> v = Shape(shape, n);
  Eigen::Vector2d lo = v[0], hi = v[0];
  for (const auto& p : v) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d scale(3.6 / (hi - lo).x(), 2.6 / (hi - lo).y());
  for (auto& p : v) p = (p - 0.5 * (lo + hi)).cwiseProduct(scale);
  return GroundPolygon(std::move(v));
}

void BM_FloorMaskIndex(benchmark::State& state, std::string shape) {
  const CameraModel camera = MaskCamera();
  const GroundPolygon floor = MaskFloor(shape, static_cast<size_t>(state.range(0)));
  for (auto _ : state) {
    const GroundPolygonIndex index(floor);  // part of the cost: FloorMask builds one per camera
    const cv::Mat mask =
        FloorPixels(camera, 0.0, [&](const Eigen::Vector2d& p) { return index.Contains(p); });
    benchmark::DoNotOptimize(mask.data);
  }
}

void BM_FloorMaskEveryEdge(benchmark::State& state, std::string shape) {
  const CameraModel camera = MaskCamera();
  const GroundPolygon floor = MaskFloor(shape, static_cast<size_t>(state.range(0)));
  for (auto _ : state) {
    const cv::Mat mask =
        FloorPixels(camera, 0.0, [&](const Eigen::Vector2d& p) { return floor.Contains(p); });
    benchmark::DoNotOptimize(mask.data);
  }
}

BENCHMARK_CAPTURE(BM_FloorMaskIndex, comb, std::string("comb"))
    ->Name("geometry/floor_mask/index/comb")
    ->RangeMultiplier(10)
    ->Range(1000, 100000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FloorMaskIndex, star, std::string("star"))
    ->Name("geometry/floor_mask/index/star")
    ->RangeMultiplier(10)
    ->Range(1000, 100000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FloorMaskEveryEdge, comb, std::string("comb"))
    ->Name("geometry/floor_mask/every_edge/comb")
    ->RangeMultiplier(10)
    ->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FloorMaskEveryEdge, star, std::string("star"))
    ->Name("geometry/floor_mask/every_edge/star")
    ->RangeMultiplier(10)
    ->Range(1000, 10000)
    ->Unit(benchmark::kMillisecond);

int Run(const std::vector<std::string>& args) {
  RealTimes collector;  // by "geometry/is_simple/sweep/comb/1000", in ms
  if (const int status = RunGoogleBenchmarks("geometry/", args, &collector)) return status;

  std::printf(
      "\ngeometry figures (IsSimple, one thread; the brute force as a multiple of the sweep, this "
      "run):\n");
  for (const char* shape : {"comb", "star"}) {
    for (const int n : {1000, 10000, 100000, 1000000}) {
      const std::string sweep =
          std::string("geometry/is_simple/sweep/") + shape + "/" + std::to_string(n);
      const std::string brute =
          std::string("geometry/is_simple/brute_force/") + shape + "/" + std::to_string(n);
      if (!collector.time.count(sweep)) continue;
      std::printf("  %-5s %8d vertices: sweep %9.3f ms", shape, n, collector.time[sweep]);
      if (collector.time.count(brute)) {
        std::printf(", brute force %9.1f ms = %6.0f x", collector.time[brute],
                    collector.time[brute] / collector.time[sweep]);
      }
      std::printf("\n");
    }
  }
  std::printf(
      "\nfloor mask figures (640x480 camera, one thread; every edge as a multiple of the index, "
      "this run):\n");
  for (const char* shape : {"comb", "star"}) {
    for (const int n : {1000, 10000, 100000}) {
      const std::string index =
          std::string("geometry/floor_mask/index/") + shape + "/" + std::to_string(n);
      const std::string every =
          std::string("geometry/floor_mask/every_edge/") + shape + "/" + std::to_string(n);
      if (!collector.time.count(index)) continue;
      std::printf("  %-5s %8d vertices: index %9.2f ms", shape, n, collector.time[index]);
      if (collector.time.count(every)) {
        std::printf(", every edge %9.1f ms = %6.0f x", collector.time[every],
                    collector.time[every] / collector.time[index]);
      }
      std::printf("\n");
    }
  }
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"geometry",
     "floor polygon: simplicity check (sweep vs brute force), floor mask (index vs every edge)",
     &Run});

}  // namespace
}  // namespace ss::bench
