// spritestation match TARGET.json --source SKEL.json... [--bank BANK] --out SEQ.json:
// choose a source frame for every target skeleton (seed 003 §2.2-2.3, docs/skeletons.md).
// With a bank the result is a sequences file `render` plays (the chosen sprites), else a
// skeleton-match file naming the chosen clip frames; --plot draws Figure 2 (without and
// with penalties) and, when refined, Figure 3.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animate/sequence_io.h"
#include "animate/skeleton/match_plot.h"
#include "animate/skeleton/skeleton_json.h"
#include "animate/skeleton/skeleton_match.h"
#include "apps/commands.h"
#include "core/bank.h"
#include "core/error.h"

namespace ss::apps {
namespace {

struct MatchArgs {
  std::string target, bank, out, plot, camera;
  std::vector<std::string> sources;
  SkeletonMatchOptions options;
  bool no_refine = false;
  double decision_mib = 3072;  // MatchOptions::max_decision_bytes, in MiB
  float transition_scale = 0.5f;
  bool json = false;
};

nlohmann::json StatsJson(const MatchStats& s) {
  return {{"freezes", s.freezes},
          {"freeze_runs", s.freeze_runs},
          {"longest_freeze", s.longest_freeze},
          {"stutters", s.stutters},
          {"skips", s.skips},
          {"jumps", s.jumps},
          {"listed", s.listed}};
}

// The bank's sprites for the source clips: per flat source frame its sprite id (0 when the
// bank has none for it) and ground position.
struct BankSprites {
  std::vector<int64_t> sprite;
  std::vector<std::pair<double, double>> ground_m;
  std::vector<SourceTransition> transitions;
};

BankSprites ResolveBank(const std::string& path, const std::vector<const SkeletonSequence*>& clips,
                        const std::vector<int>& clip_starts, int total, float transition_scale,
                        float jump_cost) {
  const Bank bank(path);
  std::map<int64_t, std::string> session_names;
  for (const auto& s : bank.ListSessions()) session_names[s.id] = s.name;
  const auto cameras = bank.ListCameras();
  std::map<int64_t, int64_t> clip_camera;
  for (const auto& c : bank.ListAllClips()) clip_camera[c.id] = c.camera_id;
  // (camera, frame) -> index into features, originals only.
  const auto features = bank.LoadFeatures();
  std::map<std::pair<int64_t, int64_t>, size_t> by_frame;
  for (size_t i = 0; i < features.size(); ++i) {
    if (!features[i].mirrored) by_frame[{clip_camera[features[i].clip_id], features[i].frame}] = i;
  }
  BankSprites out;
  out.sprite.assign(total, 0);
  out.ground_m.assign(total, {0.0, 0.0});
  std::map<int64_t, int> flat_of_sprite;
  for (size_t c = 0; c < clips.size(); ++c) {
    const std::string& name = clips[c]->clip;
    int64_t camera = -1;
    for (const auto& cam : cameras) {
      if (session_names[cam.session_id] + "/" + cam.name == name) camera = cam.id;
    }
    if (camera < 0 && cameras.size() == 1) camera = cameras[0].id;
    if (camera < 0) {
      throw InputError(path, "no camera of this bank is source clip '" + name +
                                 "' (skeleton clips are named SESSION/CAMERA by `skeleton track`)");
    }
    int found = 0;
    for (int i = 0; i < clips[c]->size(); ++i) {
      const auto it = by_frame.find({camera, clips[c]->frames[i].frame});
      if (it == by_frame.end()) continue;
      const int flat = clip_starts[c] + i;
      out.sprite[flat] = features[it->second].id;
      out.ground_m[flat] = {features[it->second].ground_x_m, features[it->second].ground_y_m};
      flat_of_sprite[features[it->second].id] = flat;
      ++found;
    }
    if (found == 0)
      throw InputError(path, "the bank holds no sprite of any frame of source clip '" + name + "'");
  }
  // Bank transitions between source frames, scaled so the median one costs transition_scale * J.
  const auto transitions = bank.LoadTransitions();
  std::vector<double> costs;
  for (const auto& t : transitions) {
    if (flat_of_sprite.count(t.from_sprite) && flat_of_sprite.count(t.to_sprite))
      costs.push_back(t.cost);
  }
  if (!costs.empty()) {
    std::nth_element(costs.begin(), costs.begin() + costs.size() / 2, costs.end());
    const double median = std::max(costs[costs.size() / 2], 1e-12);
    for (const auto& t : transitions) {
      const auto a = flat_of_sprite.find(t.from_sprite);
      const auto b = flat_of_sprite.find(t.to_sprite);
      if (a == flat_of_sprite.end() || b == flat_of_sprite.end()) continue;
      const float cost = static_cast<float>(transition_scale * jump_cost * t.cost / median);
      out.transitions.push_back({a->second, b->second, std::min(cost, jump_cost)});
    }
  }
  return out;
}

void Match(MatchArgs a) {
  const SkeletonSequence target = ReadSkeletonSequence(a.target);
  if (target.frames.empty()) throw InputError(a.target, "no target frames");
  std::vector<SkeletonSequence> loaded;
  for (const auto& s : a.sources) loaded.push_back(ReadSkeletonSequence(s));
  std::vector<const SkeletonSequence*> clips;
  std::vector<int> clip_starts;
  int total = 0;
  for (size_t c = 0; c < loaded.size(); ++c) {
    if (loaded[c].frames.empty()) throw InputError(a.sources[c], "no frames");
    if (loaded[c].clip.empty()) loaded[c].clip = a.sources[c];
    clips.push_back(&loaded[c]);
    clip_starts.push_back(total);
    total += loaded[c].size();
  }
  a.options.refine_enabled = !a.no_refine;
  if (!(a.decision_mib >= 0)) throw InputError("--decision-mib", "must be >= 0");
  a.options.match.max_decision_bytes = static_cast<size_t>(a.decision_mib * 1024 * 1024);
  a.options.compare_without_penalties = true;
  std::optional<BankSprites> bank;
  if (!a.bank.empty()) {
    bank = ResolveBank(a.bank, clips, clip_starts, total, a.transition_scale,
                       a.options.match.jump_cost);
    // Frames the bank has no sprite for can never be chosen: leave their joints out.
    for (size_t c = 0; c < loaded.size(); ++c) {
      for (int i = 0; i < loaded[c].size(); ++i) {
        if (bank->sprite[clip_starts[c] + i] == 0) {
          for (auto& j : loaded[c].frames[i].joints) j.present = false;
        }
      }
    }
    a.options.match.transitions = bank->transitions;
  }
  const SkeletonMatchResult r = MatchSkeletons(target, clips, a.options);

  auto frames_json = [&](const std::vector<int>& flat) {
    nlohmann::json list = nlohmann::json::array();
    for (size_t t = 0; t < flat.size(); ++t) {
      const int c =
          static_cast<int>(std::upper_bound(clip_starts.begin(), clip_starts.end(), flat[t]) -
                           clip_starts.begin()) -
          1;
      const int64_t frame = loaded[c].frames[flat[t] - clip_starts[c]].frame;
      nlohmann::json item = {
          {"target_frame", target.frames[t].frame}, {"clip", c}, {"frame", frame}};
      if (bank) item["sprite"] = bank->sprite[flat[t]];
      list.push_back(item);
    }
    return list;
  };
  nlohmann::json sources = nlohmann::json::array();
  for (size_t c = 0; c < loaded.size(); ++c) {
    sources.push_back(
        {{"path", a.sources[c]}, {"clip", loaded[c].clip}, {"frames", loaded[c].size()}});
  }
  nlohmann::json passes = {{"with_penalties",
                            {{"stats", StatsJson(r.with_penalties.stats)},
                             {"total_cost", r.with_penalties.total_cost},
                             {"matching_cost", r.with_penalties.matching_cost},
                             {"frames", frames_json(r.with_penalties.source_frames)}}}};
  if (r.without_penalties) {
    passes["without_penalties"] = {{"stats", StatsJson(r.without_penalties->stats)},
                                   {"total_cost", r.without_penalties->total_cost},
                                   {"matching_cost", r.without_penalties->matching_cost},
                                   {"frames", frames_json(r.without_penalties->source_frames)}};
  }
  nlohmann::json match = {{"target", a.target},
                          {"target_clip", target.clip},
                          {"sources", sources},
                          {"refined", r.refined.has_value()},
                          {"frames", frames_json(r.source_frames)},
                          {"passes", passes}};
  if (r.refined) {
    match["movements"] = {{"target", r.refined->target_movements},
                          {"source", r.refined->source_movements}};
    match["passes"]["refined"] = {{"stats", StatsJson(r.refined->stats)},
                                  {"total_cost", r.refined->total_cost}};
  }
  const double fps = target.fps > 0 ? target.fps : (loaded[0].fps > 0 ? loaded[0].fps : 30.0);
  if (bank) {
    SequenceFile file;
    file.frame_rate = fps;
    file.camera_path = a.camera;
    file.bank_paths = {a.bank};
    SpriteSequence sprite;
    sprite.name = target.clip.empty() ? "figure" : target.clip;
    // The figure performs in place: every step at the first chosen sprite's ground position.
    const auto at = bank->ground_m[r.source_frames.front()];
    for (int s : r.source_frames) {
      sprite.frames.push_back({0, bank->sprite[s]});
      sprite.positions_m.emplace_back(at.first, at.second);
    }
    file.sprites.push_back(std::move(sprite));
    file.num_steps = static_cast<int>(r.source_frames.size());
    file.summary = {{"skeleton_match", match}};
    WriteSequenceFile(a.out, file);
  } else {
    nlohmann::json doc = match;
    doc["format"] = "spritestation.skeleton_match";
    doc["version"] = 1;
    doc["frame_rate"] = fps;
    std::ofstream out(a.out);
    out << doc.dump(1) << "\n";
    if (!out) throw WorkError(a.out, "cannot write the match");
  }
  if (!a.plot.empty()) {
    std::vector<PlotPanel> panels;
    if (r.without_penalties)
      panels.push_back({"(a) without penalties", r.without_penalties->source_frames});
    panels.push_back({"(b) with penalties", r.with_penalties.source_frames});
    PlotOptions po;
    po.clip_starts = clip_starts;
    po.stutter_window = a.options.match.stutter_window;
    if (r.refined) {
      panels.push_back({"(c) refined", r.refined->source_frames});
      po.target_movements = r.refined->target_movements;
    }
    WriteMatchPlot(a.plot, panels, total, po);
  }
  if (a.json) {
    nlohmann::json report = {
        {"out", a.out},
        {"target_frames", target.size()},
        {"source_frames", total},
        {"with_penalties", StatsJson(r.with_penalties.stats)},
        {"seconds", r.with_penalties.cost_seconds + r.with_penalties.forward_seconds +
                        r.with_penalties.backward_seconds}};
    if (r.without_penalties) report["without_penalties"] = StatsJson(r.without_penalties->stats);
    if (r.refined) report["refined"] = StatsJson(r.refined->stats);
    if (!a.plot.empty()) report["plot"] = a.plot;
    std::printf("%s\n", report.dump(2).c_str());
    return;
  }
  std::printf("matched %d target frames to %d source frames in %zu clips -> %s\n", target.size(),
              total, loaded.size(), a.out.c_str());
  if (r.without_penalties)
    std::printf("without penalties: %s\n", r.without_penalties->Summary().c_str());
  std::printf("with penalties:    %s\n", r.with_penalties.Summary().c_str());
  if (r.refined) {
    const MatchStats& s = r.refined->stats;
    std::printf(
        "refined:           %zu target movements, %zu source movements; %d freezes (longest %d), "
        "%d stutters, "
        "%d jumps\n",
        r.refined->target_movements.size(), r.refined->source_movements.size(), s.freezes,
        s.longest_freeze, s.stutters, s.jumps);
  }
}

}  // namespace

void AddMatchCommand(CLI::App& app) {
  auto a = std::make_shared<MatchArgs>();
  CLI::App* cmd =
      app.add_subcommand("match", "Match target skeletons to source clips (articulated sprites)");
  cmd->add_option("target", a->target, "TARGET.json: the target skeleton sequence")->required();
  cmd->add_option("--source", a->sources, "SKEL.json of a source clip (repeat for several clips)")
      ->required();
  cmd->add_option("--bank", a->bank,
                  "The sprite bank holding the source clips: write renderable sequences");
  cmd->add_option("--out", a->out, "SEQ.json: sequences (with --bank) or the chosen clip frames")
      ->required();
  cmd->add_option("--plot", a->plot,
                  "PNG: source frame against target frame, without and with penalties");
  cmd->add_option("--camera", a->camera,
                  "With --bank: the virtual camera written into the sequences");
  cmd->add_option("--jump-cost", a->options.match.jump_cost, "J: any move that is not a short step")
      ->capture_default_str();
  cmd->add_option("--freeze-cost", a->options.match.freeze_cost,
                  "Per repeat of the same frame, growing with the run")
      ->capture_default_str();
  cmd->add_option("--stutter-cost", a->options.match.stutter_cost,
                  "Added to J for a short backward move")
      ->capture_default_str();
  cmd->add_option("--transition-scale", a->transition_scale,
                  "With --bank: the median bank transition costs this share of J")
      ->capture_default_str();
  cmd->add_option("--jump-per-frame", a->options.refine.jump_cost_per_frame,
                  "Refinement: extra cost per frame jumped inside a movement")
      ->capture_default_str();
  cmd->add_option("--window", a->options.refine.averaging_window,
                  "Refinement: averaging window, frames")
      ->capture_default_str();
  cmd->add_option(
         "--motion-weight", a->options.descriptor.motion_weight,
         "Per limb pair: weight of the motion term (how fast the pair moves); 0 = poses only")
      ->capture_default_str();
  cmd->add_option("--motion-window", a->options.descriptor.motion_window_s,
                  "Motion term: seconds before and after a frame the pose change is measured over")
      ->capture_default_str();
  cmd->add_option("--motion-scale", a->options.descriptor.motion_scale,
                  "Motion term: the pose change per second that counts as half moving")
      ->capture_default_str();
  cmd->add_option("--root-motion-weight", a->options.descriptor.root_motion_weight,
                  "Weight of the root limb's image speed (in root lengths per second); 0 = none")
      ->capture_default_str();
  cmd->add_option("--root-motion-scale", a->options.descriptor.root_motion_scale,
                  "Root motion: the speed (root lengths per second) that counts as half moving")
      ->capture_default_str();
  cmd->add_flag("--normalize-ratios", a->options.descriptor.normalize_ratios,
                "Subtract each sequence's median limb length ratios (different body proportions)");
  cmd->add_option(
         "--decision-mib", a->decision_mib,
         "Memory the DP may keep its per-cell decisions in (also at most half the available); "
         "past it the backtrack recomputes from checkpoints, slower; 0 = always")
      ->capture_default_str();
  cmd->add_flag("--no-refine", a->no_refine, "Skip the refinement by atomic movements");
  cmd->add_flag("--json", a->json, "Print the report as JSON");
  cmd->callback([a] { Match(*a); });
}

}  // namespace ss::apps
