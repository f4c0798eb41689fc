// spritestation bench animate: the scenes of seed 000 §6 on a synthetic critter graph
// (default 30,000 frames), each optimized by repeated subsequence replacement and by beam
// search at the same time budget in the same run.
//   1 circle path   2 loiter, then out of the way at t = 4 s   3 two crossing, anti-collision
//   4 curved path ending in a 2 s stand-up   5 + a follower in formation copying it
//   6 64 sprites arriving on a grid: end anchors, free starts, >= 100 frames, pairwise collisions
//   7 (not run by default) scene 6 with each fly's start pulled to a ring 1.5 m out, so paths cross
// Figures: final cost (and beam/replace ratio), path deviation, collisions, frames on tag, time.
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "animate/animate_run.h"
#include "animate/basic_costs.h"
#include "animate/beam_search.h"
#include "animate/collision_cost.h"
#include "animate/location_cost.h"
#include "animate/path_cost.h"
#include "animate/replacement.h"
#include "bench/bench_registry.h"
#include "core/error.h"

namespace ss::bench::animate_bench {
namespace {

struct Args {
  int frames = 30000;
  double budget_s = 60;
  double budget6_s = 600;
  int threads = 2;
  std::vector<int> scenes{1, 2, 3, 4, 5, 6};
  bool beam = true;
  bool json = false;
  bool detail = false;  // per-sprite figures in the JSON
  std::string start;    // replacement's start: random, sequential, beam; "": per scene
  double fly_collision_strength = 100;  // scenes 6 and 7: each pair's anti-collision strength
  // replacement's picks aimed at a collision; < 0: its default
  double collision_pick_fraction = -1;
};

Args Parse(const std::vector<std::string>& argv) {
  Args a;
  // `spritestation bench` hands positional words before the options it did not parse, so
  // the suite's options come as --name=value (the --name value form works when alone).
  for (size_t k = 0; k < argv.size(); ++k) {
    std::string s = argv[k];
    std::string inline_value;
    bool has_inline = false;
    if (const size_t eq = s.find('='); s.rfind("--", 0) == 0 && eq != std::string::npos) {
      inline_value = s.substr(eq + 1);
      s = s.substr(0, eq);
      has_inline = true;
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (k + 1 >= argv.size()) throw InputError("bench animate", s + " needs a value");
      return argv[++k];
    };
    if (s == "--frames")
      a.frames = std::stoi(value());
    else if (s == "--budget")
      a.budget_s = std::stod(value());
    else if (s == "--budget6")
      a.budget6_s = std::stod(value());
    else if (s == "--threads")
      a.threads = std::stoi(value());
    else if (s == "--no-beam")
      a.beam = false;
    else if (s == "--json")
      a.json = true;
    else if (s == "--detail")
      a.detail = true;
    else if (s == "--start")
      a.start = value();
    else if (s == "--fly-collision-strength")
      a.fly_collision_strength = std::stod(value());
    else if (s == "--collision-pick-fraction")
      a.collision_pick_fraction = std::stod(value());
    else if (s == "--scenes") {
      a.scenes.clear();
      std::string list = value();
      for (size_t p = 0; p < list.size();) {
        const size_t q = list.find(',', p);
        a.scenes.push_back(std::stoi(list.substr(p, q - p)));
        p = q == std::string::npos ? list.size() : q + 1;
      }
    } else {
      throw InputError(
          "bench animate",
          "unknown argument " + s +
              " (--frames=N --budget=S --budget6=S --threads=N "
              "--scenes=1,2,.. --start=random|sequential|beam --fly-collision-strength=X "
              "--collision-pick-fraction=F --no-beam --json --detail)");
    }
  }
  return a;
}

// A critter like the paper's hamster: clips of 20..60 frames whose heading drifts, walking
// at 0.5..3 cm per frame, a few standing clips (tagged, rare), transitions between frames of
// similar heading and speed (cost grows with the difference).
TransitionGraph CritterGraph(int num_frames, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double two_pi = 2 * std::numbers::pi;
  std::vector<FrameInfo> frames;
  std::vector<double> heading, speed;
  int clip = 0;
  while (static_cast<int>(frames.size()) < num_frames) {
    ++clip;
    const bool standing = unit(rng) < 0.03;
    const int n =
        std::min(num_frames - static_cast<int>(frames.size()), 20 + static_cast<int>(rng() % 41));
    double a = two_pi * unit(rng);
    const double turn = (unit(rng) - 0.5) * 0.08;
    const double v = standing ? 0.0 : 0.005 + 0.025 * unit(rng);
    for (int m = 0; m < n; ++m) {
      a += turn;
      FrameInfo f;
      f.clip = clip;
      f.velocity_m = Eigen::Vector2d(std::cos(a), std::sin(a)) * v;
      if (standing) f.tags.push_back("standing");
      frames.push_back(std::move(f));
      heading.push_back(std::remainder(a, two_pi));
      speed.push_back(v);
    }
  }
  // Buckets of heading (24) x speed (4); each frame gets transitions into its bucket.
  auto bucket = [&](int i) {
    const int h = static_cast<int>((heading[i] + std::numbers::pi) / two_pi * 24) % 24;
    const int s =
        speed[i] == 0 ? 0 : 1 + std::min(2, static_cast<int>((speed[i] - 0.005) / 0.0084));
    return h * 4 + s;
  };
  std::vector<std::vector<int>> buckets(24 * 4);
  for (int i = 0; i < num_frames; ++i) buckets[bucket(i)].push_back(i);
  std::vector<TransitionEdge> edges;
  for (int i = 0; i < num_frames; ++i) {
    const std::vector<int>& b = buckets[bucket(i)];
    const bool rare = frames[i].tags.size() == 1;
    for (int k = 0; k < (rare ? 2 : 3); ++k) {
      const int j = b[rng() % b.size()];
      if (j == i || j == i + 1) continue;
      const double dh = std::abs(std::remainder(heading[i] - heading[j], two_pi));
      edges.push_back({i, j, 0.05 + dh + 20 * std::abs(speed[i] - speed[j]) + 0.1 * unit(rng)});
    }
  }
  // Standing up happens from slow walking only, and back.
  std::vector<int> standing, slow;
  for (int i = 0; i < num_frames; ++i) {
    if (speed[i] == 0)
      standing.push_back(i);
    else if (speed[i] < 0.012)
      slow.push_back(i);
  }
  for (size_t k = 0; k < standing.size() / 4 && !slow.empty(); ++k) {
    edges.push_back({slow[rng() % slow.size()], standing[rng() % standing.size()], 0.5});
    edges.push_back({standing[rng() % standing.size()], slow[rng() % slow.size()], 0.5});
  }
  return TransitionGraph(std::move(frames), edges);
}

std::vector<Eigen::Vector2d> Arc(const Eigen::Vector2d& c, double r, double a0, double a1, int n) {
  std::vector<Eigen::Vector2d> p;
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    p.push_back(c + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return p;
}

std::unique_ptr<Problem> MakeScene(int scene, const TransitionGraph& g,
                                   double fly_collision_strength) {
  auto p = std::make_unique<Problem>(g);
  const double pi = std::numbers::pi;
  auto standing = std::make_shared<std::vector<bool>>(g.FramesWithTag("standing"));
  auto sprite = [&](const char* name, Anchor anchor, Eigen::Vector2d at, int initial, int max) {
    SpriteSpec s;
    s.name = name;
    s.anchor = anchor;
    s.anchor_m = std::move(at);
    s.initial_frames = initial;
    s.max_frames = max;
    return p->AddSprite(std::move(s));
  };
  const Polyline curve(Arc({0, 0.5}, 0.5, -pi / 2, 0.2, 6));
  switch (scene) {
    case 1: {
      const int s = sprite("hamster", Anchor::kStart, {0.5, 0}, 150, 600);
      p->AddTerm(std::make_unique<PathTerm>(s, Polyline(Arc({0, 0}, 0.5, 0, 2 * pi, 16)),
                                            PathStrengths{0.5, 50, 100}));
      break;
    }
    case 2: {
      const int s = sprite("hamster", Anchor::kStart, {0, 0}, 180, 180);
      p->AddTerm(std::make_unique<LocationTerm>(s, StepWindow::Range(0, 117),
                                                LocationTarget::Fixed({0, 0}), 0.5));
      p->AddTerm(std::make_unique<LocationTerm>(s, StepWindow{120, false, 0, true},
                                                LocationTarget::Fixed({0.8, 0.6}), 50));
      p->AddTerm(std::make_unique<LengthTerm>(s, 180, 100));
      break;
    }
    case 3: {
      const int a = sprite("right_goer", Anchor::kStart, {-0.8, 0}, 150, 150);
      const int b = sprite("left_goer", Anchor::kStart, {0.8, 0.05}, 150, 150);
      p->AddTerm(std::make_unique<LocationTerm>(a, StepWindow::LastStep(),
                                                LocationTarget::Fixed({0.8, 0}), 20));
      p->AddTerm(std::make_unique<LocationTerm>(b, StepWindow::LastStep(),
                                                LocationTarget::Fixed({-0.8, 0.05}), 20));
      p->AddTerm(std::make_unique<LengthTerm>(a, 150, 100));
      p->AddTerm(std::make_unique<LengthTerm>(b, 150, 100));
      p->AddTerm(std::make_unique<CollisionTerm>(a, b, 0.15, 200));
      break;
    }
    case 4:
    case 5: {
      const int s = sprite("leader", Anchor::kStart, curve.points().front(), 150, 600);
      p->AddTerm(std::make_unique<PathTerm>(s, curve, PathStrengths{0.5, 50, 100}));
      p->AddTerm(std::make_unique<FrameTerm>(s, standing, StepWindow::All(), 5,
                                             PathTrigger{s, curve, 60}));
      if (scene == 5) {
        const int f = sprite("follower", Anchor::kStart,
                             curve.points().front() + Eigen::Vector2d(-0.15, 0), 150, 600);
        p->AddTerm(std::make_unique<LocationTerm>(f, StepWindow::All(),
                                                  LocationTarget::Follow(s, {-0.15, 0.12}), 20));
        p->AddTerm(std::make_unique<FrameTerm>(f, standing, StepWindow::All(), 5,
                                               PathTrigger{s, curve, 60}));
        p->AddTerm(std::make_unique<CollisionTerm>(s, f, 0.08, 100));
      }
      break;
    }
    case 6:
    case 7: {
      for (int k = 0; k < 64; ++k) {
        const int column = k % 8, row = k / 8;  // an 8 x 8 grid of ends
        const Eigen::Vector2d end(-0.7 + 0.2 * column, -0.7 + 0.2 * row);
        const int s = sprite("fly", Anchor::kEnd, end, 110, 200);
        p->AddTerm(std::make_unique<LengthTerm>(s, 100, 5));
        p->AddTerm(std::make_unique<FastFrameTerm>(s, 0.02, 20));
        if (scene == 7) {  // arriving from a ring 1.5 m out, in shuffled order: the paths cross
          const double a = 2 * pi * ((k * 27) % 64) / 64.0;
          p->AddTerm(std::make_unique<LocationTerm>(
              s, StepWindow::At(0),
              LocationTarget::Fixed(1.5 * Eigen::Vector2d(std::cos(a), std::sin(a))), 20));
        }
      }
      for (int a = 0; a < 64; ++a) {
        for (int b = a + 1; b < 64; ++b)
          p->AddTerm(std::make_unique<CollisionTerm>(a, b, 0.08, fly_collision_strength));
      }
      break;
    }
    default:
      throw InputError("bench animate", "no scene " + std::to_string(scene));
  }
  return p;
}

nlohmann::json Figures(const std::string& method, const Summary& summary,
                       const ConstraintFigures& f) {
  return {{"method", method},
          {"cost", summary.final_cost.total},
          {"by_kind", summary.final_cost.by_kind},
          {"seconds", summary.total_seconds},
          {"moves_kept", summary.moves_kept},
          {"moves_tried", summary.moves_tried},
          {"start_seconds", summary.start_seconds},
          {"restarts", summary.restarts},
          {"message", summary.message},
          {"min_distance_m", f.min_distance_m},
          {"max_path_deviation_m", f.max_path_deviation_m},
          {"paths_unfinished", f.paths_unfinished},
          {"colliding_pairs", f.colliding_pairs},
          {"collision_steps", f.collision_steps},
          {"frame_steps_off", f.frame_steps_off},
          {"frame_steps", f.frame_steps},
          {"sprites_short", f.sprites_short}};
}

// The 1-minute load average (the machine is shared; figures are read against it).
double LoadAverage() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  double load = -1;
  if (f != nullptr) {
    if (std::fscanf(f, "%lf", &load) != 1) load = -1;
    std::fclose(f);
  }
  return load;
}

// Per sprite: length, start and end, frame windows and steps off them (--detail).
nlohmann::json SpriteDetail(const Problem& problem, const std::vector<Track>& tracks) {
  const std::vector<const Track*> view = TrackPointers(tracks);
  nlohmann::json out = nlohmann::json::array();
  for (int s = 0; s < problem.num_sprites(); ++s) {
    const Track& t = tracks[s];
    nlohmann::json j = {{"sprite", s},
                        {"frames", t.size()},
                        {"start_m", {t.positions_m.front().x(), t.positions_m.front().y()}},
                        {"end_m", {t.positions_m.back().x(), t.positions_m.back().y()}}};
    double speed = 0;
    for (int k = 0; k < t.size(); ++k) speed += t.velocities_m[k].norm();
    j["mean_speed_m"] = speed / std::max(1, t.size());
    for (int k : problem.TermsOf(s)) {
      const CostTerm& term = problem.term(k);
      if (term.sprites()[0] != s) continue;
      j["cost_" + term.kind()] = j.value("cost_" + term.kind(), 0.0) + term.Evaluate(view);
      if (const auto* frame = dynamic_cast<const FrameTerm*>(&term)) {
        const auto [begin, end] = frame->Window(view);
        j["frame_window"] = {begin, end};
        j["frame_off"] = frame->CountViolations(view);
      }
    }
    out.push_back(j);
  }
  return out;
}

int Run(const std::vector<std::string>& argv) {
  const Args args = Parse(argv);
  const double t0 = MonotonicSeconds();
  const TransitionGraph graph = CritterGraph(args.frames, 42);
  std::fprintf(stderr, "critter graph: %d frames, %lld edges (%.1f s)\n", graph.num_frames(),
               static_cast<long long>(graph.num_edges()), MonotonicSeconds() - t0);
  nlohmann::json out = nlohmann::json::array();
  if (!args.json) {
    std::printf("%-6s %-8s %12s %8s %9s %8s %9s %9s %8s\n", "scene", "method", "cost", "seconds",
                "path_dev", "unfin", "collide", "tag_off", "short");
  }
  for (int scene : args.scenes) {
    const auto problem = MakeScene(scene, graph, args.fly_collision_strength);
    const double budget = scene >= 6 ? args.budget6_s : args.budget_s;
    nlohmann::json row = {{"scene", scene}, {"budget_s", budget}, {"load_at_start", LoadAverage()}};
    ReplacementOptions replace;
    replace.time_budget_seconds = budget;
    replace.reach.num_threads = args.threads;
    if (args.collision_pick_fraction >= 0)
      replace.collision_pick_fraction = args.collision_pick_fraction;
    row["collision_pick_fraction"] = replace.collision_pick_fraction;
    if (scene >= 6) {
      replace.reference_speed_m = 0.02;
      replace.slow_frame_cost = 20;
    }
    // Replacement starts one sprite after the other (the default); 64 flies start from
    // beam search (a quarter of the budget), as the paper allows (§4.2).
    const std::string start = !args.start.empty() ? args.start : scene >= 6 ? "beam" : "sequential";
    if (start == "random")
      replace.start = StartMethod::kRandom;
    else if (start == "beam")
      replace.start = StartMethod::kBeam;
    else if (start == "sequential")
      replace.start = StartMethod::kSequential;
    else
      throw InputError("--start", "expected random, sequential or beam, got " + start);
    row["start"] = start;
    // The F/B sets are per bank (and frame constraint), built before the run as the paper
    // did; the budget is the optimization's, the same for both methods.
    const ReplacementSets sets = ReplacementSets::Build(*problem, replace);
    row["sets_seconds"] = sets.build_seconds();
    std::fprintf(stderr, "scene %d: F/B sets %.1f s\n", scene, sets.build_seconds());
    Summary rs;
    const std::vector<Track> rt = OptimizeSequences(*problem, replace, &rs, &sets);
    const ConstraintFigures rf = MeasureConstraints(*problem, rt);
    row["replace"] = Figures("replace", rs, rf);
    if (args.detail) row["replace"]["sprites"] = SpriteDetail(*problem, rt);
    std::vector<std::pair<std::string, std::pair<Summary, ConstraintFigures>>> results{
        {"replace", {rs, rf}}};
    if (args.beam) {
      BeamOptions beam;
      beam.time_budget_seconds = budget;
      Summary bs;
      const std::vector<Track> bt = BeamSearch(*problem, beam, &bs);
      const ConstraintFigures bf = MeasureConstraints(*problem, bt);
      row["beam"] = Figures("beam", bs, bf);
      if (args.detail) row["beam"]["sprites"] = SpriteDetail(*problem, bt);
      row["beam_over_replace"] = bs.final_cost.total / std::max(1e-12, rs.final_cost.total);
      results.push_back({"beam", {bs, bf}});
    }
    row["load_at_end"] = LoadAverage();
    out.push_back(row);
    if (!args.json) {
      for (const auto& [name, r] : results) {
        const auto& [s, f] = r;
        std::printf("%-6d %-8s %12.5g %8.1f %9.3f %8d %9d %9d %8d\n", scene, name.c_str(),
                    s.final_cost.total, s.total_seconds, f.max_path_deviation_m, f.paths_unfinished,
                    f.colliding_pairs, f.frame_steps_off, f.sprites_short);
      }
      if (args.beam)
        std::printf("       beam/replace cost ratio: %.2f\n",
                    row["beam_over_replace"].get<double>());
      std::fflush(stdout);
    }
  }
  if (args.json) std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

const bool kRegistered = RegisterSuite(
    {"animate", "seed 000 §6 scenes: replacement vs beam search at the same budget", &Run});

}  // namespace
}  // namespace ss::bench::animate_bench
