#include "pipeline/transitions/transition_jumps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/option_checks.h"

namespace ss {
namespace {

struct Collected {
  JumpStats stats;
  std::vector<double> jumps;

  void Add(std::optional<double> jump) {
    ++stats.sampled;
    if (!jump) {
      ++stats.unmeasured;
      return;
    }
    ++stats.measured;
    jumps.push_back(*jump);
  }
  JumpStats Done() const {
    JumpStats out = stats;
    out.median = Quantile(jumps, 0.5);
    out.p95 = Quantile(jumps, 0.95);
    out.max = Quantile(jumps, 1.0);
    return out;
  }
};

nlohmann::json OrNull(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json StatsJson(const JumpStats& s) {
  return {{"sampled", s.sampled},       {"measured", s.measured}, {"unmeasured", s.unmeasured},
          {"median", OrNull(s.median)}, {"p95", OrNull(s.p95)},   {"max", OrNull(s.max)}};
}

std::string Figure(const std::optional<double>& v) {
  if (!v) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", *v);
  return text;
}

std::string StatsText(const char* kind, const JumpStats& s) {
  return std::string(kind) + " " + Figure(s.median) + " / " + Figure(s.p95) + " (" +
         std::to_string(s.measured) + ")";
}

}  // namespace

std::optional<double> Quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const double at = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto below = static_cast<size_t>(std::floor(at));
  const size_t above = std::min(values.size() - 1, below + 1);
  return values[below] + (at - static_cast<double>(below)) * (values[above] - values[below]);
}

bool TransitionJumpOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(max_transitions, AtLeast(0), "max_transitions", "at least 0");
  return check.ok();
}

nlohmann::json TransitionJumpSummary::ToJson() const {
  nlohmann::json j = StatsJson(all);
  j["transitions"] = transitions;
  j["median_step_px"] = median_step_px;
  j["by_kind"] = {{"within_clip", StatsJson(within_clip)},
                  {"joining_clips", StatsJson(joining_clips)},
                  {"original_mirror", StatsJson(original_mirror)}};
  return j;
}

std::string TransitionJumpSummary::ToText() const {
  char head[160];
  std::snprintf(head, sizeof head,
                "visible jump of %lld of %lld transitions (%lld unmeasured; 1 = an ordinary frame "
                "step of %.1f px): median %s, p95 %s",
                static_cast<long long>(all.measured), static_cast<long long>(transitions),
                static_cast<long long>(all.unmeasured), median_step_px, Figure(all.median).c_str(),
                Figure(all.p95).c_str());
  return std::string(head) +
         "; median / p95 (measured) by kind: " + StatsText("within a clip", within_clip) + ", " +
         StatsText("joining clips", joining_clips) + ", " +
         StatsText("original-mirror", original_mirror) + "\n";
}

TransitionJumpSummary MeasureTransitionJumps(
    VisibleJumpMeter& meter, const std::vector<std::pair<int64_t, int64_t>>& transitions,
    const TransitionJumpOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw InputError("transition jump options", why);
  TransitionJumpSummary out;
  out.transitions = static_cast<int64_t>(transitions.size());
  const size_t n = transitions.size();
  const size_t sampled = std::min(n, static_cast<size_t>(options.max_transitions));
  Collected all, within, joining, mirror;
  for (size_t k = 0; k < sampled; ++k) {
    // Evenly spread: transition k of `sampled` is the (k * n / sampled)-th of the table.
    const auto [from, to] = transitions[k * n / sampled];
    const std::optional<TransitionKind> kind = meter.KindOf(from, to);
    const std::optional<double> jump = kind ? meter.Jump(from, to) : std::nullopt;
    all.Add(jump);
    if (!kind) continue;
    switch (*kind) {
      case TransitionKind::kWithinClip:
        within.Add(jump);
        break;
      case TransitionKind::kJoiningClips:
        joining.Add(jump);
        break;
      case TransitionKind::kOriginalMirror:
        mirror.Add(jump);
        break;
    }
  }
  out.all = all.Done();
  out.within_clip = within.Done();
  out.joining_clips = joining.Done();
  out.original_mirror = mirror.Done();
  if (sampled > 0) out.median_step_px = meter.MedianStep_px();
  return out;
}

}  // namespace ss
