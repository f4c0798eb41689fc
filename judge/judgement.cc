#include "judge/judgement.h"

#include <algorithm>
#include <cstddef>
#include <cstdio>

namespace ss {
namespace {

using nlohmann::json;

json Optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string Figure(const std::optional<double>& v, const char* format = "%.2f") {
  if (!v) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, *v);
  return text;
}

}  // namespace

json JudgementJson(const Judgement& j) {
  json lengths = json::array();
  for (const LengthOutcome& l : j.lengths) {
    lengths.push_back({{"sprite", l.sprite}, {"frames", l.frames}, {"min_frames", l.min_frames}});
  }
  json out = {{"lengths", std::move(lengths)}, {"constraints_judged", j.constraints_judged}};
  json paths = json::array();
  for (const PathOutcome& p : j.paths) {
    paths.push_back({{"sprite", p.sprite},
                     {"field", p.field},
                     {"length_m", p.length_m},
                     {"swept_share", p.swept_share},
                     {"finished_step", p.finished_step},
                     {"max_deviation_m", p.max_deviation_m},
                     {"median_deviation_m", p.median_deviation_m}});
  }
  out["paths"] = std::move(paths);
  json locations = json::array();
  for (const LocationOutcome& l : j.locations) {
    locations.push_back({{"sprite", l.sprite},
                         {"field", l.field},
                         {"target", l.target},
                         {"first_step", l.first_step},
                         {"end_step", l.end_step},
                         {"distance_m",
                          {{"first", l.first_m},
                           {"last", l.last_m},
                           {"min", l.min_m},
                           {"median", l.median_m},
                           {"max", l.max_m}}}});
  }
  out["locations"] = std::move(locations);
  json collisions = json::array();
  for (const CollisionOutcome& c : j.collisions) {
    collisions.push_back({{"sprites", {c.a, c.b}},
                          {"min_distance_m", c.min_distance_m},
                          {"closest_m", c.closest_m},
                          {"closest_step", c.closest_step},
                          {"steps_closer", c.steps_closer}});
  }
  out["collisions"] = std::move(collisions);
  json frames = json::array();
  for (const FrameOutcome& f : j.frames) {
    frames.push_back({{"sprite", f.sprite},
                      {"field", f.field},
                      {"set", f.set},
                      {"first_step", f.first_step},
                      {"end_step", f.end_step},
                      {"steps_on", f.steps_on},
                      {"on_share", f.on_share}});
  }
  out["frames"] = std::move(frames);
  const StutterFigures& s = j.stutter;
  out["stutter"] = {{"window_steps", s.window_steps},
                    {"steps", s.steps},
                    {"still_steps", s.still_steps},
                    {"repeats", s.repeats},
                    {"share", s.share},
                    {"replayed", s.replayed},
                    {"replayed_share", s.replayed_share}};
  const CloneFigures& c = j.clones;
  out["clones"] = {{"lag_steps", c.lag_steps},
                   {"steps", c.steps},
                   {"cloned_steps", c.cloned_steps},
                   {"share", c.share},
                   {"sprites_cloned", c.sprites_cloned}};
  const FacingFigures& f = j.facing;
  out["facing"] = {{"measured", f.measured},
                   {"min_speed_m_s", f.min_speed_m_s},
                   {"half_window_steps", f.half_window_steps},
                   {"moving_steps", f.moving_steps},
                   {"median_deg", Optional(f.median_deg)},
                   {"p90_deg", Optional(f.p90_deg)}};
  const JumpFigures& v = j.jumps;
  json each = json::array();
  for (const TransitionJump& t : v.each) {
    each.push_back({{"sprite", t.sprite},
                    {"step", t.step},
                    {"from", {t.from.bank, t.from.sprite_id}},
                    {"to", {t.to.bank, t.to.sprite_id}},
                    {"natural", t.natural ? json(*t.natural) : json(nullptr)},
                    {"jump", Optional(t.jump)}});
  }
  out["jumps"] = {{"measured", v.measured},
                  {"transitions", v.transitions},
                  {"unmeasured", v.unmeasured},
                  {"median", Optional(v.median)},
                  {"p95", Optional(v.p95)},
                  {"max", Optional(v.max)},
                  {"median_step_px", v.median_step_px},
                  {"each", std::move(each)}};
  return out;
}

std::string JudgementReport(const Judgement& j) {
  std::string out;
  char line[320];
  auto add = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof line, format, args...);
    out += line;
  };
  add("What a viewer sees\n");
  for (const LengthOutcome& l : j.lengths) {
    add("  length      %-10s %d frames", l.sprite.c_str(), l.frames);
    if (l.min_frames > 0)
      add(" (min %d%s)", l.min_frames, l.frames < l.min_frames ? ": SHORT" : "");
    add("\n");
  }
  if (!j.constraints_judged) add("  constraints (no spec given: --spec)\n");
  for (const PathOutcome& p : j.paths) {
    add("  path        %-10s swept %.1f %% of %.3f m, %s; deviation max %.3f m, median %.3f m\n",
        p.sprite.c_str(), 100 * p.swept_share, p.length_m,
        p.finished_step >= 0 ? ("finished at step " + std::to_string(p.finished_step)).c_str()
                             : "unfinished",
        p.max_deviation_m, p.median_deviation_m);
  }
  for (const LocationOutcome& l : j.locations) {
    add("  location    %-10s %s, steps %d-%d: distance first %.3f, last %.3f, median %.3f, max "
        "%.3f m\n",
        l.sprite.c_str(), l.target.c_str(), l.first_step, l.end_step - 1, l.first_m, l.last_m,
        l.median_m, l.max_m);
  }
  for (const CollisionOutcome& c : j.collisions) {
    add("  collision   %s-%s closest %.3f m at step %d (min %.3f m), %d steps closer\n",
        c.a.c_str(), c.b.c_str(), c.closest_m, c.closest_step, c.min_distance_m, c.steps_closer);
  }
  for (const FrameOutcome& f : j.frames) {
    add("  frames      %-10s %s, steps %d-%d: %.1f %% on (%d)\n", f.sprite.c_str(), f.set.c_str(),
        f.first_step, f.end_step - 1, 100 * f.on_share, f.steps_on);
  }
  const StutterFigures& s = j.stutter;
  add("  stutter     %.1f %% (%d of %d steps show a frame of the %d before; %d still steps not "
      "counted)\n",
      100 * s.share, s.repeats, s.steps - s.still_steps, s.window_steps, s.still_steps);
  if (s.replayed > 0) {
    add("  replayed    %.1f %% (%d steps show a frame shown earlier, past the stutter's window "
        "too: loops)\n",
        100 * s.replayed_share, s.replayed);
  }
  if (j.clones.steps > 0 && j.clones.cloned_steps > 0) {
    add("  clones      %.1f %% (%d of %d steps show a frame another sprite shows within %d "
        "steps; %d sprites mostly copies)\n",
        100 * j.clones.share, j.clones.cloned_steps, j.clones.steps, j.clones.lag_steps,
        j.clones.sprites_cloned);
  }
  if (j.facing.measured) {
    add("  facing      drawn heading vs motion over %d moving steps (> %.2f m/s): median %s, p90 "
        "%s degrees\n",
        j.facing.moving_steps, j.facing.min_speed_m_s, Figure(j.facing.median_deg).c_str(),
        Figure(j.facing.p90_deg).c_str());
  }
  const JumpFigures& v = j.jumps;
  if (!v.measured) {
    add("  jumps       not measured\n");
  } else {
    add("  jumps       %d transitions (%d from a clip's end, unmeasured): median %s, p95 %s, "
        "max %s x an ordinary frame step\n",
        v.transitions, v.unmeasured, Figure(v.median).c_str(), Figure(v.p95).c_str(),
        Figure(v.max).c_str());
    // The most visible ones, to look at first.
    std::vector<const TransitionJump*> worst;
    for (const TransitionJump& t : v.each) {
      if (t.jump) worst.push_back(&t);
    }
    const size_t shown = std::min<size_t>(3, worst.size());
    std::partial_sort(
        worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(shown), worst.end(),
        [](const TransitionJump* a, const TransitionJump* b) { return *a->jump > *b->jump; });
    for (size_t k = 0; k < shown; ++k) {
      const TransitionJump& t = *worst[k];
      add("              %.2f: %s step %d shows sprite %lld for %lld (after %lld)\n", *t.jump,
          t.sprite.c_str(), t.step, static_cast<long long>(t.to.sprite_id),
          static_cast<long long>(*t.natural), static_cast<long long>(t.from.sprite_id));
    }
  }
  return out;
}

}  // namespace ss
