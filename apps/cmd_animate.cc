// spritestation animate SPEC --out SEQ.json: optimize sprite sequences for an animation spec
// (seed 000 §4–5) by repeated subsequence replacement or the beam search baseline.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animate/animate_run.h"
#include "animate/cost_plot.h"
#include "animate/scene.h"
#include "animate/sequence_io.h"
#include "animate/spec.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/log.h"
#include "judge/judge.h"

namespace ss::apps {
namespace {

struct AnimateArgs {
  std::string spec;
  std::string out;
  std::string plot;    // "" = next to --out
  std::string method;  // "": the spec's
  double time_budget_s = 0;
  int64_t seed = -1;
  int threads = 0;
  int max_turns = 0;  // 0: the time budget alone
  double snapshot_every_s = -1;
  bool json = false;
  bool no_judge = false;
};

void Run(const AnimateArgs& args) {
  AnimationSpec spec = LoadAnimationSpec(args.spec);
  // The spec's optimizer block with the command line's changes.
  AnimateRunOptions options{spec.optimizer};
  OptimizerSpec& o = options.optimizer;
  for (const auto& [value, text] : kOptimizerMethodTexts) {
    if (args.method == text) o.method = value;
  }
  if (args.time_budget_s > 0) o.replacement.time_budget_seconds = args.time_budget_s;
  if (args.seed >= 0) o.replacement.seed = static_cast<uint64_t>(args.seed);
  if (args.threads > 0) o.replacement.reach.num_threads = args.threads;
  if (args.snapshot_every_s >= 0) o.snapshot_every_s = args.snapshot_every_s;
  options.max_turns = args.max_turns;
  options.progress_every_s = 1.0;
  const std::string method = TextOf(o.method, kOptimizerMethodTexts);
  // Refused before the banks are read: the options with the command line's changes, and the
  // camera, which `render` reads (a YAML file named as the camera was accepted here).
  if (std::string why; !options.IsValid(&why)) throw InputError("animate options", why);
  ReadSpecCamera(spec);

  const auto scene = Scene::Load(std::move(spec));
  Log("animate")->info("{} sprites, {} frames, {} edges, {} cost terms; {} for {:.1f} s",
                       scene->problem().num_sprites(), scene->graph().num_frames(),
                       scene->graph().num_edges(), scene->problem().num_terms(), method,
                       o.replacement.time_budget_seconds);
  const AnimateResult result = RunAnimation(*scene, options);
  SequenceFile file = MakeSequenceFile(*scene, result);
  // What a viewer sees (judge/judge.h), kept in the file's summary beside the costs.
  std::optional<Judgement> judgement;
  if (!args.no_judge) {
    judgement = JudgeSequences(file, file.bank_paths, scene.get());
    nlohmann::json j = JudgementJson(*judgement);
    j["jumps"].erase("each");
    file.summary["judge"] = std::move(j);
  }
  WriteSequenceFile(args.out, file);

  std::string plot = args.plot;
  if (plot.empty()) plot = std::filesystem::path(args.out).replace_extension(".cost.png").string();
  WriteCostPlot(plot, {{method, result.summary.trace, cv::Scalar(200, 80, 0)}},
                std::filesystem::path(args.spec).filename().string());

  if (args.json) {
    nlohmann::json j = SummaryJson(result);
    j["sequences"] = args.out;
    j["plot"] = plot;
    j.erase("trace");
    if (judgement) j["judge"] = file.summary["judge"];
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  const ConstraintFigures& f = result.figures;
  std::printf("%s", result.summary.FullReport().c_str());
  std::printf("  lengths           ");
  for (const Track& t : result.tracks) std::printf(" %d", t.size());
  std::printf(" frames\n");
  std::printf("  path deviation     %.3f m max, %d unfinished\n", f.max_path_deviation_m,
              f.paths_unfinished);
  std::printf("  collisions         %d steps in %d pairs (closest %.3f m)\n", f.collision_steps,
              f.colliding_pairs, f.min_distance_m);
  std::printf("  frames off tag     %d of %d steps\n", f.frame_steps_off, f.frame_steps);
  std::printf("  sequences          %s\n  cost plot          %s\n", args.out.c_str(), plot.c_str());
  if (judgement) std::printf("%s", JudgementReport(*judgement).c_str());
}

}  // namespace

void AddAnimateCommand(CLI::App& app) {
  auto args = std::make_shared<AnimateArgs>();
  auto* cmd = app.add_subcommand("animate", "Optimize sprite sequences for an animation spec");
  cmd->add_option("spec", args->spec, "Animation spec (YAML, docs/animation.md)")->required();
  cmd->add_option("--out", args->out, "Sequences file to write (JSON)")->required();
  std::vector<std::string> methods;
  for (const auto& method : kOptimizerMethodTexts) methods.emplace_back(method.text);
  cmd->add_option("--method", args->method, "replace or beam (default: the spec's)")
      ->check(CLI::IsMember(methods));
  cmd->add_option("--time-budget", args->time_budget_s,
                  "Seconds for the whole run (default: the spec's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", args->seed, "Random seed (default: the spec's)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", args->threads, "Threads for the F/B sets (default: the spec's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-turns", args->max_turns,
                  "replace: stop after this many sprite turns, whichever comes first with the "
                  "budget (with a long budget: the same result on any machine)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--snapshot-every", args->snapshot_every_s,
                  "Keep the sequences every S seconds (for `render --stages`)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--plot", args->plot, "Cost-versus-time PNG (default: OUT with .cost.png)");
  cmd->add_flag("--json", args->json, "Print the summary as JSON");
  cmd->add_flag("--no-judge", args->no_judge,
                "Leave out the judge's figures (stutter, visible jumps: reads billboards)");
  cmd->callback([args] { Run(*args); });
}

}  // namespace ss::apps
