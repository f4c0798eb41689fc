#include "animate/clone_cost.h"

#include <algorithm>

#include "animate/problem.h"
#include "core/error.h"
#include "core/options_binder.h"

namespace ss {

CloneTerm::CloneTerm(int sprite_a, int sprite_b, int lag_steps, double strength)
    : StepSumTerm("clone", {sprite_a, sprite_b}, strength), lag_steps_(lag_steps) {
  if (sprite_a == sprite_b) throw InputError("clones.sprites", "needs two different sprites");
  if (lag_steps < 0) throw InputError("clones.lag_steps", "must be >= 0");
}

std::pair<int, int> CloneTerm::Steps(Tracks tracks, const EvalRequest& /*request*/) const {
  return {0, std::min(tracks[sprites()[0]]->size(), tracks[sprites()[1]]->size())};
}

int CloneTerm::Coincidences(Tracks tracks, int t) const {
  const Track& a = *tracks[sprites()[0]];
  const Track& b = *tracks[sprites()[1]];
  if (t >= a.size() || t >= b.size()) return 0;
  const int first = std::max(0, t - lag_steps_);
  int n = 0;
  for (int u = first; u <= t; ++u) {
    if (b.frames[u] == a.frames[t]) {
      ++n;
      break;
    }
  }
  for (int u = first; u < t; ++u) {
    if (a.frames[u] == b.frames[t]) {
      ++n;
      break;
    }
  }
  return n;
}

double CloneTerm::StepCost(Tracks tracks, int t) const {
  return strength() * Coincidences(tracks, t);
}

int CloneTerm::CountViolations(Tracks tracks) const {
  const auto [begin, end] = Steps(tracks, EvalRequest{});
  int count = 0;
  for (int t = begin; t < end; ++t) count += Coincidences(tracks, t) > 0 ? 1 : 0;
  return count;
}

void CloneSpec::AddTerms(const TransitionGraph& /*graph*/, Problem& problem) const {
  if (strength <= 0) return;
  for (int a = 0; a < problem.num_sprites(); ++a) {
    for (int b = a + 1; b < problem.num_sprites(); ++b)
      problem.AddTerm(std::make_unique<CloneTerm>(a, b, lag_steps, strength));
  }
}

void RegisterClonesSpecTerm() {
  RegisterSpecTerm({"clones", "{strength, lag_steps}",
                    TermBlockReader<CloneSpec>(
                        [](OptionsBinder& keys, CloneSpec& c) {
                          keys.Add("strength", &c.strength, "a number >= 0",
                                   "per frame two sprites show together")
                              .Rule(AtLeast(0))
                              .Add("lag_steps", &c.lag_steps, "0..100 steps",
                                   "how far apart is together")
                              .Rule(Between(0, 100));
                        },
                        {"strength"})});
}

}  // namespace ss
