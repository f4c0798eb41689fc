// spritestation bench geometry [google benchmark args]: the floor polygon's simplicity check,
// and the floor mask (which pixels of a camera see the floor).
//   geometry/is_simple/sweep/{comb,star}/N    GroundPolygon::IsSimple, the O(n log n) sweep
//   geometry/is_simple/brute_force/{comb,star}/N  the O(n^2) check it replaced (issue 20), kept
//                                             in tests/core/polygon_fixtures.h: the baseline
//   geometry/floor_mask/index/{comb,star}/N   FloorPixels of a 640x480 camera through a
//                                             GroundPolygonIndex (the edges near each point)
//   geometry/floor_mask/every_edge/{comb,star}/N  the same mask through GroundPolygon::Contains
//                                             (every edge for every pixel: FloorMask before)
//   geometry/contact_point                    ContactPoint of a person-sized matte (48x120), its
//                                             options checked on each call as they are now
//   geometry/contact_point/eager_check        the same after a check that writes every reason
//                                             whether or not it fails (OptionProblems before)
// Shapes (tests/core/polygon_fixtures.h): a comb, half of whose edges cross the sweep line at
// once, and a star of random radii; both simple, so that every check runs to the end. For the
// floor mask they are scaled to fill the camera's view of the floor.
// Figures: ms a check or a mask, and the old way's time as a multiple of the new, in this run.
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_registry.h"
#include "core/camera_model.h"
#include "core/contact_point.h"
#include "core/geometry.h"
#include "core/option_checks.h"
#include "pipeline/filter/usability.h"
#include "tests/core/polygon_fixtures.h"

namespace ss::bench::geometry_bench {
namespace {

std::vector<Eigen::Vector2d> Shape(const std::string& shape, size_t n) {
  if (shape == "comb") return testing::Comb(n / 4);
  std::mt19937 rng(1);
  return testing::Star(n, rng, 0.9);
}

void BM_Sweep(benchmark::State& state, const std::string& shape) {
  const GroundPolygon polygon(Shape(shape, static_cast<size_t>(state.range(0))));
  for (auto _ : state) {
    if (!polygon.IsSimple()) state.SkipWithError("not simple");
  }
}

void BM_BruteForce(benchmark::State& state, const std::string& shape) {
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

void BM_FloorMaskIndex(benchmark::State& state, const std::string& shape) {
  const CameraModel camera = MaskCamera();
  const GroundPolygon floor = MaskFloor(shape, static_cast<size_t>(state.range(0)));
  for (auto _ : state) {
    const GroundPolygonIndex index(floor);  // part of the cost: FloorMask builds one per camera
    const cv::Mat mask =
        FloorPixels(camera, 0.0, [&](const Eigen::Vector2d& p) { return index.Contains(p); });
    benchmark::DoNotOptimize(mask.data);
  }
}

void BM_FloorMaskEveryEdge(benchmark::State& state, const std::string& shape) {
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

// A person's matte: a body 30 px wide and 100 tall, two legs apart below it.
cv::Mat PersonMatte() {
  cv::Mat alpha(120, 48, CV_8U, cv::Scalar(0));
  alpha(cv::Rect(9, 4, 30, 100)).setTo(255);
  alpha(cv::Rect(9, 100, 10, 18)).setTo(255);
  alpha(cv::Rect(29, 100, 10, 18)).setTo(255);
  return alpha;
}

void BM_ContactPoint(benchmark::State& state) {
  const cv::Mat alpha = PersonMatte();
  const ContactPointOptions options;
  cv::Point2d point;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ContactPoint(alpha, &point, options));
    benchmark::DoNotOptimize(point);
  }
}
BENCHMARK(BM_ContactPoint)->Name("geometry/contact_point")->Unit(benchmark::kMicrosecond);

// The options check as ContactPointOptions::IsValid wrote it before: every reason built.
bool EagerCheck(const ContactPointOptions& o, std::string* why) {
  OptionProblems check(why);
  check(std::isfinite(o.band_fraction) && o.band_fraction >= 0 && o.band_fraction <= 1,
        "band_fraction",
        "expected a fraction from 0 to 1, got " + OptionProblems::Num(o.band_fraction));
  check(std::isfinite(o.min_band_px) && o.min_band_px > 0, "min_band_px",
        "expected a positive number of pixels, got " + OptionProblems::Num(o.min_band_px));
  return check.ok();
}

void BM_ContactPointEagerCheck(benchmark::State& state) {
  const cv::Mat alpha = PersonMatte();
  const ContactPointOptions options;
  cv::Point2d point;
  for (auto _ : state) {
    std::string why;
    benchmark::DoNotOptimize(EagerCheck(options, &why));
    benchmark::DoNotOptimize(ContactPoint(alpha, &point, options));
    benchmark::DoNotOptimize(point);
  }
}
BENCHMARK(BM_ContactPointEagerCheck)
    ->Name("geometry/contact_point/eager_check")
    ->Unit(benchmark::kMicrosecond);

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
  const std::string lazy = "geometry/contact_point", eager = "geometry/contact_point/eager_check";
  if (collector.time.count(lazy) && collector.time.count(eager)) {
    std::printf(
        "\ncontact point (48x120 matte, one thread): %.3f us a call; with the eager check %.3f us "
        "= %.2f x\n",
        collector.time[lazy], collector.time[eager], collector.time[eager] / collector.time[lazy]);
  }
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"geometry",
     "floor polygon: simplicity check (sweep vs brute force), floor mask (index vs every edge); "
     "the contact point",
     &Run});

}  // namespace
}  // namespace ss::bench::geometry_bench
