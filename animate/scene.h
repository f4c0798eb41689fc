#pragma once
// An animation spec made concrete: the banks' transition graph and the Problem (sprites
// and cost terms) the spec asks for, plus the optimizer options it sets.
#include <atomic>
#include <memory>
#include <vector>

#include "animate/bank_graph.h"
#include "animate/beam_search.h"
#include "animate/problem.h"
#include "animate/replacement.h"
#include "animate/spec.h"

namespace ss {

class Scene {
 public:
  // Builds the terms of `spec` over `bank`. InputError naming the spec's line and field
  // for a constraint the banks cannot meet (an unknown tag, sprite id).
  Scene(AnimationSpec spec, BankGraph bank);
  // Opens the spec's banks and builds the scene; `cancel` stops the banks' load between its
  // reads (LoadBankGraph).
  static std::unique_ptr<Scene> Load(AnimationSpec spec, const std::atomic<bool>* cancel = nullptr);
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  const AnimationSpec& spec() const { return spec_; }
  const BankGraph& bank() const { return bank_; }
  const TransitionGraph& graph() const { return bank_.graph; }
  const Problem& problem() const { return *problem_; }

  // `options` (by default the spec's optimizer block) with what the scene derives from the
  // spec: Ĉ's fast-frame terms.
  ReplacementOptions MakeReplacementOptions(ReplacementOptions options) const;
  ReplacementOptions MakeReplacementOptions() const {
    return MakeReplacementOptions(spec_.optimizer.replacement);
  }

 private:
  void AddTerms();
  double IntervalS() const {
    return bank_.frame_interval_s.empty() ? 1.0 / 30 : bank_.frame_interval_s[0];
  }

  AnimationSpec spec_;
  BankGraph bank_;
  std::unique_ptr<Problem> problem_;
};

}  // namespace ss
