// spritestation judge SEQ.json [--spec SPEC] [--bank B]...: what a viewer of the sequences sees
// (docs/animation.md "Judging an animation"): each constraint's outcome, the stutter and the
// visible jump at each transition.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animate/scene.h"
#include "animate/sequence_io.h"
#include "animate/spec.h"
#include "apps/commands.h"
#include "core/error.h"
#include "judge/judge.h"

namespace ss::apps {
namespace {

struct JudgeArgs {
  std::string sequences;
  std::string spec;
  std::vector<std::string> banks;
  std::vector<std::string> still_tags;
  int stutter_window_steps = 15;
  int max_pairs = 0;
  bool no_jumps = false;
  bool json = false;
};

void Run(const JudgeArgs& args) {
  const SequenceFile file = ReadSequenceFile(args.sequences);
  std::vector<std::string> banks = file.bank_paths;
  if (!args.banks.empty()) {
    if (args.banks.size() != file.bank_paths.size()) {
      throw InputError("--bank", "the sequences name " + std::to_string(file.bank_paths.size()) +
                                     " banks, " + std::to_string(args.banks.size()) +
                                     " given (one --bank per bank, in the file's order)");
    }
    banks = args.banks;
  }
  std::unique_ptr<Scene> scene;
  if (!args.spec.empty()) {
    AnimationSpec spec = LoadAnimationSpec(args.spec);
    spec.bank_paths = banks;  // the sequences' bank indices are the file's
    scene = Scene::Load(std::move(spec));
  }
  JudgeOptions options;
  options.stutter_window_steps = args.stutter_window_steps;
  if (!args.still_tags.empty()) options.still_tags = args.still_tags;
  if (args.max_pairs > 0) options.jump.max_pairs = args.max_pairs;
  options.jumps = !args.no_jumps;
  const Judgement judgement = JudgeSequences(file, banks, scene.get(), options);
  if (args.json) {
    nlohmann::json j = JudgementJson(judgement);
    j["sequences"] = args.sequences;
    j["banks"] = banks;
    j["spec"] = args.spec.empty() ? nlohmann::json(nullptr) : nlohmann::json(args.spec);
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("%s", JudgementReport(judgement).c_str());
}

}  // namespace

void AddJudgeCommand(CLI::App& app) {
  auto args = std::make_shared<JudgeArgs>();
  auto* cmd = app.add_subcommand(
      "judge", "Judge sequences as a viewer sees them: constraints, stutter, visible jumps");
  cmd->add_option("sequences", args->sequences, "Sequences file from `animate` (JSON)")->required();
  cmd->add_option("--spec", args->spec,
                  "The animation spec the sequences were made for (constraint outcomes)");
  cmd->add_option("--bank", args->banks,
                  "The banks, in the file's order, where they are now (default: the file's)");
  cmd->add_option("--still-tag", args->still_tags,
                  "Bank tag of frames that hold still on purpose (default: still)");
  cmd->add_option("--stutter-window", args->stutter_window_steps,
                  "A step stutters when its frame was shown in this many steps before (15)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-pairs", args->max_pairs,
                  "Consecutive pairs behind a bank's median frame step (default 2000)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-jumps", args->no_jumps, "Skip the visible jumps (no billboards read)");
  cmd->add_flag("--json", args->json, "Print the judgement as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace ss::apps
