// spritestation bench floor-transitions --bank B: what aligning floor sprites' headings buys
// (issue 38). A floor sprite is stored turned so that its subject faces the image's top, and
// its velocity is compared in its own axes, so the transition search joins floor sprites
// whatever way they were filmed facing, and the animator turns the rest of a sequence at
// each such transition. Without that alignment the search would see the sprites as filmed:
// the image turned back to the floor's axes (by the sprite's heading) and the velocity in the
// floor's axes, and only sprites facing the same way could join.
//
// Both searches run here, on the same bank's floor sprites, with the same weights and
// threads, in the same run: transitions per sprite, and the visible jump of each set's kept
// transitions (pipeline/transitions/visible_jump.h), each measured as the viewer would see it:
// the aligned ones in the sprites' own axes (the animator turns them to agree), the
// as-filmed ones in the floor's axes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench_registry.h"
#include "core/bank.h"
#include "core/error.h"
#include "core/log.h"
#include "pipeline/transitions/bank_sprites.h"
#include "pipeline/transitions/builder.h"
#include "pipeline/transitions/transition_jumps.h"
#include "pipeline/transitions/weights.h"

namespace ss::bench::floor_transitions_bench {
namespace {

// The billboard turned from the sprite's axes (its subject facing the image's top) into the
// floor's (the image's top the floor's +y): by heading - 90 degrees about its anchor, onto a
// square canvas its diagonal wide, resampled premultiplied so transparent pixels lend no colour.
RgbaBillboard AsFilmed(const RgbaBillboard& b, double heading_rad) {
  const cv::Mat straight(b.height, b.width, CV_8UC4, const_cast<uint8_t*>(b.rgba.data()));
  cv::Mat pre;
  straight.convertTo(pre, CV_32FC4);
  std::vector<cv::Mat> ch;
  cv::split(pre, ch);
  for (int c = 0; c < 3; ++c) ch[c] = ch[c].mul(ch[3], 1.0 / 255.0);
  cv::merge(ch, pre);
  const int side = static_cast<int>(std::ceil(std::hypot(b.width, b.height))) | 1;
  const double centre = 0.5 * (side - 1);
  cv::Mat m = cv::getRotationMatrix2D(
      cv::Point2f(static_cast<float>(b.anchor_x_px), static_cast<float>(b.anchor_y_px)),
      heading_rad * 180.0 / M_PI - 90.0, 1.0);
  m.at<double>(0, 2) += centre - b.anchor_x_px;
  m.at<double>(1, 2) += centre - b.anchor_y_px;
  cv::Mat turned;
  cv::warpAffine(pre, turned, m, cv::Size(side, side), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                 cv::Scalar::all(0));
  cv::split(turned, ch);
  for (int c = 0; c < 3; ++c) {
    cv::Mat alpha = cv::max(ch[3], 1e-3f);
    cv::divide(ch[c], alpha, ch[c], 255.0);
  }
  cv::merge(ch, turned);
  cv::Mat out;
  turned.convertTo(out, CV_8UC4);  // saturating
  RgbaBillboard r;
  r.width = side;
  r.height = side;
  r.anchor_x_px = centre;
  r.anchor_y_px = centre;
  r.floor = true;
  r.rgba.assign(out.data, out.data + out.total() * 4);
  return r;
}

struct Side {
  int64_t transitions = 0;
  int64_t sprites_joined = 0;  // sprites with at least one transition out
  BuildStats stats;
  double seconds = 0;
  TransitionJumpSummary jumps;
  std::vector<double> distances;  // every transition's stage-2 distance D (Transition::distance)
  // The sample: (D, the jump as seen in px) of transitions spread evenly over the table.
  std::vector<std::pair<double, double>> sampled_d_px;
  // Transitions whose jump is at most `px`, estimated from the sample (its share of the table).
  double AtMost(double px) const {
    if (sampled_d_px.empty()) return 0;
    const auto k = std::count_if(sampled_d_px.begin(), sampled_d_px.end(),
                                 [&](const auto& d_px) { return d_px.second <= px; });
    return static_cast<double>(transitions) * static_cast<double>(k) /
           static_cast<double>(sampled_d_px.size());
  }
};

nlohmann::json SideJson(const Side& s, int64_t sprites) {
  return {{"transitions", s.transitions},
          {"per_sprite", sprites > 0 ? static_cast<double>(s.transitions) / sprites : 0.0},
          {"sprites_with_a_transition", s.sprites_joined},
          {"stage2_evaluations", s.stats.stage2_evaluations},
          {"seconds", s.seconds},
          {"jumps", s.jumps.ToJson()}};
}

// `seen_px(from, to)`: the jump a viewer sees at the transition, px (nullopt at a clip's end).
using SeenJump = std::function<std::optional<double>(int64_t from, int64_t to)>;

Side Search(const TransitionWeights& weights, double px_per_m, std::span<const SpriteInput> in,
            int threads, VisibleJumpMeter& meter, int max_jumps, const SeenJump& seen_px) {
  Side s;
  const auto t0 = std::chrono::steady_clock::now();
  TransitionBuilder builder(weights, px_per_m);
  BuildOptions build;
  build.threads = threads;
  builder.BuildFromScratch(in, build);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.stats = builder.stats();
  std::vector<std::pair<int64_t, int64_t>> pairs;
  std::unordered_set<int64_t> from;
  for (const Transition& t : builder.Transitions()) {
    pairs.emplace_back(t.from, t.to);
    s.distances.push_back(t.distance);
    from.insert(t.from);
  }
  s.transitions = static_cast<int64_t>(pairs.size());
  s.sprites_joined = static_cast<int64_t>(from.size());
  TransitionJumpOptions jump_options;
  jump_options.max_transitions = max_jumps;
  s.jumps = MeasureTransitionJumps(meter, pairs, jump_options);
  // The jumps as the viewer sees them, in the floor's axes, for counting both sets at one
  // visible jump.
  const size_t step = std::max<size_t>(1, pairs.size() / std::max(1, max_jumps));
  for (size_t k = 0; k < pairs.size(); k += step) {
    if (const auto px = seen_px(pairs[k].first, pairs[k].second))
      s.sampled_d_px.emplace_back(s.distances[k], *px);
  }
  return s;
}

int Run(const std::vector<std::string>& args) {
  std::string bank_path;
  int threads = 2, max_jumps = 4000;
  bool json = false;
  for (const std::string& a : args) {
    const auto [key, value] = OptionNameValue(a);
    if (key == "--bank")
      bank_path = value;
    else if (key == "--threads")
      threads = std::max(1, std::stoi(value));
    else if (key == "--jumps")
      max_jumps = std::max(0, std::stoi(value));
    else if (key == "--json")
      json = true;
    else
      throw InputError(a, "unknown option (--bank=B --threads=T --jumps=N --json)");
  }
  if (bank_path.empty()) throw InputError("--bank", "give the bank of an overhead session");
  SetLogLevel("warn");
  const Bank bank(bank_path);
  SegmentKeys keys;
  const BankSprites aligned = LoadBankSprites(bank, &keys);

  // The same sprites as filmed: floor axes for the image and the velocity.
  std::vector<RgbaBillboard> filmed_billboards;
  std::vector<SpriteInput> filmed = aligned.inputs;
  std::vector<JumpFrame> frames;
  std::unordered_map<int64_t, size_t> index;
  std::vector<std::optional<double>> headings;  // floor sprites'
  filmed_billboards.reserve(aligned.inputs.size());
  int64_t floor_sprites = 0;
  for (size_t k = 0; k < aligned.inputs.size(); ++k) {
    const SpriteRecord r = bank.LoadSprite(aligned.ids[k]);
    if (r.kind == SpriteKind::kFloor) ++floor_sprites;
    headings.push_back(r.kind == SpriteKind::kFloor ? std::optional<double>(r.heading_rad)
                                                    : std::nullopt);
    filmed_billboards.push_back(r.kind == SpriteKind::kFloor
                                    ? AsFilmed(aligned.billboards[k], r.heading_rad)
                                    : aligned.billboards[k]);
    filmed[k].cheap.velocity_x_mps = r.velocity_x_m_s;
    filmed[k].cheap.velocity_y_mps = r.velocity_y_m_s;
    index[r.id] = k;
    frames.push_back({r.id, r.clip_id, r.mirrored, std::nullopt});
  }
  if (floor_sprites == 0)
    throw InputError(bank_path, "holds no floor sprites: ingest a session filmed from above");
  for (size_t k = 0; k < filmed.size(); ++k) filmed[k].billboard = &filmed_billboards[k];
  VisibleJumpMeter bank_meter(bank);
  for (JumpFrame& f : frames) f.next = bank_meter.NaturalSuccessor(f.id);
  VisibleJumpMeter filmed_meter(
      frames, [&](int64_t id) { return filmed_billboards.at(index.at(id)); }, "");

  const TransitionWeights& weights = DefaultWeights();
  const int64_t n = static_cast<int64_t>(aligned.inputs.size());
  // Seen in the floor's axes, every image resampled once: an aligned transition shows `to`
  // turned to the heading its natural successor n had (as the animator turns it), an
  // as-filmed one shows `to` as filmed; each against n as filmed.
  const SeenJump aligned_seen = [&](int64_t from, int64_t to) -> std::optional<double> {
    const auto n = bank_meter.NaturalSuccessor(from);
    if (!n) return std::nullopt;
    const size_t kt = index.at(to), kn = index.at(*n);
    const RgbaBillboard turned = headings[kt] && headings[kn]
                                     ? AsFilmed(aligned.billboards[kt], *headings[kn])
                                     : aligned.billboards[kt];
    return ContactAlignedDifference_px(turned, filmed_billboards[kn]);
  };
  const SeenJump filmed_seen = [&](int64_t from, int64_t to) -> std::optional<double> {
    const auto n = filmed_meter.NaturalSuccessor(from);
    if (!n) return std::nullopt;
    return filmed_meter.Difference_px(to, *n);
  };
  const Side with = Search(weights, aligned.px_per_m, aligned.inputs, threads, bank_meter,
                           max_jumps, aligned_seen);
  const Side without =
      Search(weights, aligned.px_per_m, filmed, threads, filmed_meter, max_jumps, filmed_seen);
  const double ratio =
      without.transitions > 0 ? static_cast<double>(with.transitions) / without.transitions : 0.0;
  // At one visible jump: both sets counted up to the same jump as the viewer sees it, in the
  // floor's axes; the unit is the footage's ordinary frame step seen the same way.
  const double unit_px = filmed_meter.MedianStep_px();
  nlohmann::json at_jump = nlohmann::json::array();
  for (const double jump : {1.0, 1.5, 2.0, 2.5}) {
    const double a = with.AtMost(jump * unit_px), f = without.AtMost(jump * unit_px);
    at_jump.push_back(
        {{"jump", jump}, {"aligned", a}, {"as_filmed", f}, {"ratio", f > 0 ? a / f : 0.0}});
  }
  // By the classifier's distance D (stage 2's, kept when D <= its threshold): how many a
  // stricter bound (a quantile of the aligned table's D) would keep, and how visible they are.
  nlohmann::json by_distance = nlohmann::json::array();
  for (const double q : {0.01, 0.05, 0.1, 0.25, 0.5, 1.0}) {
    const double bound = Quantile(with.distances, q).value_or(0);
    nlohmann::json row = {{"quantile", q}, {"bound", bound}};
    for (const auto* side : {&with, &without}) {
      std::vector<double> jumps;
      for (const auto& [d, px] : side->sampled_d_px)
        if (d <= bound) jumps.push_back(px / unit_px);
      const auto kept = std::count_if(side->distances.begin(), side->distances.end(),
                                      [&](double d) { return d <= bound; });
      row[side == &with ? "aligned" : "as_filmed"] = {
          {"transitions", kept},
          {"per_sprite", static_cast<double>(kept) / static_cast<double>(n)},
          {"jump_median", Quantile(jumps, 0.5).value_or(NAN)},
          {"jump_p95", Quantile(jumps, 0.95).value_or(NAN)}};
    }
    by_distance.push_back(row);
  }
  if (json) {
    const nlohmann::json j = {{"bank", bank_path},
                              {"sprites", n},
                              {"floor_sprites", floor_sprites},
                              {"aligned", SideJson(with, n)},
                              {"as_filmed", SideJson(without, n)},
                              {"ratio", ratio},
                              {"step_px", unit_px},
                              {"at_jump", at_jump},
                              {"by_distance", by_distance}};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  auto line = [&](const char* name, const Side& s) {
    std::printf("%-10s %10lld %9.1f %9lld %7.1f s   %s\n", name,
                static_cast<long long>(s.transitions),
                n > 0 ? static_cast<double>(s.transitions) / n : 0.0,
                static_cast<long long>(s.sprites_joined), s.seconds, s.jumps.ToText().c_str());
  };
  std::printf("%s: %lld sprites (%lld floor)\n", bank_path.c_str(), static_cast<long long>(n),
              static_cast<long long>(floor_sprites));
  std::printf("%-10s %10s %9s %9s %9s   %s\n", "headings", "transitions", "a sprite", "joined",
              "search", "visible jump");
  line("aligned", with);
  line("as filmed", without);
  std::printf("aligned / as filmed: %.2fx the transitions\n", ratio);
  std::printf(
      "at one visible jump as seen (1 = a frame step as filmed, %.1f px), estimated from "
      "the samples:\n",
      unit_px);
  for (const auto& row : at_jump) {
    std::printf("  jump <= %.1f: %10.0f aligned, %9.0f as filmed: %.2fx\n",
                row["jump"].get<double>(), row["aligned"].get<double>(),
                row["as_filmed"].get<double>(), row["ratio"].get<double>());
  }
  std::printf("by stage 2's distance D (jumps in the unit above):\n");
  for (const auto& row : by_distance) {
    std::printf("  D <= %.3f (aligned's %2.0f %%):", row["bound"].get<double>(),
                100 * row["quantile"].get<double>());
    for (const char* side : {"aligned", "as_filmed"}) {
      const auto& r = row[side];
      std::printf("  %s %.1f a sprite, jump median %.2f p95 %.2f", side,
                  r["per_sprite"].get<double>(), r["jump_median"].get<double>(),
                  r["jump_p95"].get<double>());
    }
    std::printf("\n");
  }
  return 0;
}

const bool registered = RegisterSuite(
    {"floor-transitions",
     "floor sprites' transitions with their headings aligned against as filmed, same bank and "
     "run, with the visible jump of each [--bank=B --threads=T --jumps=N --json]",
     &Run});

}  // namespace
}  // namespace ss::bench::floor_transitions_bench
