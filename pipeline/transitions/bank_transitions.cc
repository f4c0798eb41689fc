#include "pipeline/transitions/bank_transitions.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <unordered_set>

#include <nlohmann/json.hpp>

#include "core/bank_verify.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "pipeline/transitions/bank_sprites.h"

namespace ss {

std::string WeightsFingerprint(const TransitionWeights& weights) {
  // The classifier part only: provenance text does not change what the weights decide.
  TransitionWeights w = weights;
  w.training_json = "{}";
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : WeightsToJson(w)) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char text[32];
  std::snprintf(text, sizeof(text), "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::vector<TransitionRecord> ToRecords(const std::vector<Transition>& transitions) {
  std::vector<TransitionRecord> out;
  out.reserve(transitions.size());
  for (const Transition& t : transitions) out.push_back({t.from, t.to, t.distance, t.cost});
  return out;
}

bool TransitionBars::Excludes(const Transition& t) const {
  const auto it = bars_.find(t.from);
  return it != bars_.end() && std::pair(t.cost, t.to) > it->second;
}

void TransitionBars::Set(const TransitionRecord& worst_kept) {
  bars_[worst_kept.from_sprite] = {worst_kept.cost, worst_kept.to_sprite};
}

RoundResult StoreTransitionRound(BankWriter& bank, std::vector<Transition> transitions,
                                 int max_per_sprite, TransitionBars* bars) {
  RoundResult r;
  if (max_per_sprite > 0) {
    const size_t before = transitions.size();
    std::erase_if(transitions, [&](const Transition& t) { return bars->Excludes(t); });
    std::sort(transitions.begin(), transitions.end(), [](const Transition& a, const Transition& b) {
      return std::pair(a.from, a.to) < std::pair(b.from, b.to);
    });
    KeepCheapestPerSprite(&transitions, max_per_sprite);
    r.skipped = static_cast<int64_t>(before - transitions.size());
  }
  // A few thousand rows a transaction: a round of a large bank holds tens of thousands, and one
  // transaction for all of them held the bank's write lock past the station writer's busy
  // timeout on a loaded machine (batches failed). Upserts are idempotent, so rows stored before
  // a failure are simply stored again by a rebuild or the unit's next attempt.
  const std::vector<TransitionRecord> records = ToRecords(transitions);
  for (size_t i = 0; i < records.size(); i += kTransitionRowsPerTransaction) {
    const auto end = records.begin() + static_cast<std::ptrdiff_t>(std::min(
                                           records.size(), i + kTransitionRowsPerTransaction));
    bank.UpsertTransitions(
        std::vector<TransitionRecord>(records.begin() + static_cast<std::ptrdiff_t>(i), end));
  }
  r.written = static_cast<int64_t>(records.size());
  if (max_per_sprite > 0 && !transitions.empty()) {
    // After the rows are committed, so that of two writers the later prune sees both.
    std::vector<int64_t> from;
    for (const Transition& t : transitions)
      if (from.empty() || from.back() != t.from) from.push_back(t.from);
    std::vector<TransitionRecord> worst;
    r.removed = bank.PruneTransitions(from, max_per_sprite, &worst);
    for (const TransitionRecord& w : worst) bars->Set(w);
  }
  return r;
}

StoreResult StoreTransitionTable(BankWriter& bank, const std::vector<Transition>& transitions,
                                 const std::string& fingerprint,
                                 const std::unordered_set<int64_t>& sprites) {
  StoreResult r;
  std::vector<TransitionRecord> existing = bank.LoadTransitions();  // sorted by (from, to)
  // Transitions of sprites outside the set (e.g. of clips still being written) stay as they are.
  std::erase_if(existing, [&](const TransitionRecord& t) {
    const bool outside = !sprites.count(t.from_sprite) || !sprites.count(t.to_sprite);
    r.outside += outside;
    return outside;
  });
  const auto stored_with = bank.GetMeta(kTransitionWeightsMetaKey);
  std::vector<TransitionRecord> write;
  // Merge the two sorted lists.
  size_t a = 0, b = 0;
  while (a < existing.size() || b < transitions.size()) {
    const bool take_old =
        b == transitions.size() ||
        (a < existing.size() && std::pair(existing[a].from_sprite, existing[a].to_sprite) <
                                    std::pair(transitions[b].from, transitions[b].to));
    const bool take_new =
        a == existing.size() ||
        (b < transitions.size() && std::pair(transitions[b].from, transitions[b].to) <
                                       std::pair(existing[a].from_sprite, existing[a].to_sprite));
    if (take_old) {
      ++r.removed;
      ++a;
    } else if (take_new) {
      ++r.added;
      write.push_back(
          {transitions[b].from, transitions[b].to, transitions[b].distance, transitions[b].cost});
      ++b;
    } else {
      const Transition& t = transitions[b];
      if (existing[a].d == t.distance && existing[a].cost == t.cost) {
        ++r.unchanged;
      } else {
        ++r.changed;
        write.push_back({t.from, t.to, t.distance, t.cost});
      }
      ++a;
      ++b;
    }
  }
  if (r.removed > 0 || (stored_with != fingerprint && !existing.empty())) {
    r.replaced_all = true;
    bank.ClearTransitions();  // (the ones outside the set go too: another weights' table is wrong)
    bank.UpsertTransitions(ToRecords(transitions));
  } else if (!write.empty()) {
    bank.UpsertTransitions(write);
  }
  bank.SetMeta(kTransitionWeightsMetaKey, fingerprint);
  return r;
}

bool BankUpdateOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(weights.IsValid(&part), "weights.", part);
  check.Within(threads, AtLeast(1), "threads", "at least 1 thread");
  check.Within(table.max_per_sprite, AtLeast(0), "max_per_sprite", "0 (every transition) or more");
  return check.ok();
}

BankUpdateSummary UpdateBankTransitions(const std::string& bank_path,
                                        const BankUpdateOptions& options) {
  auto log = Log("pipeline.transitions");
  BankUpdateSummary s;
  s.bank = bank_path;
  // Before any work.
  if (std::string why; !options.IsValid(&why)) throw InputError("transition update options", why);
  {
    // Read-only first: a missing file or a non-bank is an InputError, never a new bank.
    const Bank probe(bank_path);
    (void)probe;
  }
  RefuseDamagedBank(bank_path);
  BankWriter bank(bank_path);
  auto t = std::chrono::steady_clock::now();
  SegmentKeys keys;
  const BankSprites sprites = LoadBankSprites(
      bank, &keys,
      [&](size_t done, size_t total) {
        if (options.progress) options.progress("load", done, total);
      },
      options.table);
  s.seconds_load = SecondsSince(t);
  s.sprites = static_cast<int64_t>(sprites.inputs.size());
  s.clips = sprites.clips;
  s.left_out = static_cast<int64_t>(sprites.left_out.size());
  if (sprites.inputs.empty() && sprites.left_out.empty()) {
    throw InputError(
        bank_path,
        "the bank holds no sprites in complete clips: there is nothing to find transitions "
        "between (ingest a session first)");
  }
  t = std::chrono::steady_clock::now();
  std::vector<Transition> transitions;
  if (!sprites.inputs.empty()) {
    TransitionBuilder real(options.weights, sprites.px_per_m);
    BuildOptions build;
    build.threads = options.threads;
    build.progress = [&](size_t done, size_t total) {
      if (options.progress) options.progress("pairs", done, total);
    };
    real.BuildFromScratch(sprites.inputs, build);
    transitions = real.Transitions(options.table.max_per_sprite);
    s.build = real.stats();
  }
  s.seconds_build = SecondsSince(t);
  s.transitions = static_cast<int64_t>(transitions.size());
  if (s.clips == 1) {
    s.notes.push_back(
        "the bank has one clip: its transitions only jump within it (and its mirror)");
  }
  if (s.left_out > 0) {
    s.notes.push_back(std::to_string(s.left_out) +
                      " sprites tagged merged (two subjects in one blob) left out: "
                      "transitions.include_merged / --include-merged takes them");
  }
  if (s.transitions == 0) {
    s.notes.push_back(
        "no transitions found: the clips share no similar frames under these weights");
  }
  t = std::chrono::steady_clock::now();
  // The sprites left out belong to the table's universe: their old transitions (a table made
  // with include_merged) go.
  std::unordered_set<int64_t> universe(sprites.ids.begin(), sprites.ids.end());
  universe.insert(sprites.left_out.begin(), sprites.left_out.end());
  s.store = StoreTransitionTable(bank, transitions, WeightsFingerprint(options.weights), universe);
  bank.SetMeta(TableChoice::kMetaKey, options.table.MetaValue());
  bank.SetMeta(TableChoice::kCapMetaKey, options.table.CapMetaValue());
  s.seconds_store = SecondsSince(t);
  log->info("{}: {} sprites, {} transitions ({} added, {} changed, {} removed{})", bank_path,
            s.sprites, s.transitions, s.store.added, s.store.changed, s.store.removed,
            s.store.replaced_all ? ", table replaced" : "");
  return s;
}

std::string BankUpdateSummary::ToJson() const {
  nlohmann::json j{{"bank", bank},
                   {"sprites", sprites},
                   {"clips", clips},
                   {"left_out_merged", left_out},
                   {"stage1_candidates", build.stage1_candidates},
                   {"stage2_evaluations", build.stage2_evaluations},
                   {"kept_pairs", build.kept_pairs},
                   {"transitions", transitions},
                   {"added", store.added},
                   {"changed", store.changed},
                   {"unchanged", store.unchanged},
                   {"removed", store.removed},
                   {"replaced_all", store.replaced_all},
                   {"seconds_load", seconds_load},
                   {"seconds_build", seconds_build},
                   {"seconds_store", seconds_store},
                   {"notes", notes}};
  return j.dump(2);
}

std::string BankUpdateSummary::ToText() const {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%s: %lld sprites in %lld clips\n", bank.c_str(),
                static_cast<long long>(sprites), static_cast<long long>(clips));
  out += line;
  const double all_pairs = 0.5 * static_cast<double>(sprites) * (static_cast<double>(sprites) - 1);
  std::snprintf(
      line, sizeof(line),
      "  stage-1 candidates %lld, stage-2 evaluations %lld of %.0f pairs, kept pairs %lld\n",
      static_cast<long long>(build.stage1_candidates),
      static_cast<long long>(build.stage2_evaluations), all_pairs,
      static_cast<long long>(build.kept_pairs));
  out += line;
  std::snprintf(line, sizeof(line),
                "  transitions %lld: %lld added, %lld changed, %lld unchanged, %lld removed%s\n",
                static_cast<long long>(transitions), static_cast<long long>(store.added),
                static_cast<long long>(store.changed), static_cast<long long>(store.unchanged),
                static_cast<long long>(store.removed),
                store.replaced_all ? " (table replaced)" : "");
  out += line;
  std::snprintf(line, sizeof(line), "  time: load %.2f s, build %.2f s, store %.2f s\n",
                seconds_load, seconds_build, seconds_store);
  out += line;
  for (const std::string& n : notes) out += "  note: " + n + "\n";
  return out;
}

}  // namespace ss
