#include "pipeline/transitions/unit_worker.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

#include "core/elapsed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"
#include "pipeline/transitions/bank_transitions.h"

namespace ss {
namespace {

std::string DefaultName() {
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  return std::string(host) + ":" + std::to_string(::getpid());
}

}  // namespace

bool UnitWorkerOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  std::string part;
  check.Nested(weights.IsValid(&part), "weights.", part);
  check.Within(lease_s, Positive(), "lease_s", "a positive number of seconds");
  check.Within(load_threads, AtLeast(1), "load_threads", "at least 1 thread");
  check.Within(table.max_per_sprite, AtLeast(0), "max_per_sprite", "0 (every transition) or more");
  return check.ok();
}

UnitWorker::UnitWorker(const std::string& bank, UnitWorkerOptions options)
    : options_(std::move(options)), queue_(bank), writer_(bank), reader_(bank) {
  if (std::string why; !options_.IsValid(&why)) throw InputError("unit worker options", why);
  if (options_.name.empty()) options_.name = DefaultName();
  // The bank's weights and sprite choice are decided by the first to set them, in one
  // statement each (KeepMeta: two workers starting at once are ordered by the key, and the
  // second reads the first's). A worker with other settings refuses whether or not a
  // transition is stored yet: the one that set them may be making transitions now, and the
  // table would be of neither (issue 39: on an empty table both used to proceed).
  const std::string fingerprint = WeightsFingerprint(options_.weights);
  const std::string table_weights = writer_.KeepMeta(kTransitionWeightsMetaKey, fingerprint);
  if (table_weights != fingerprint) {
    throw InputError(reader_.path(),
                     "its transitions are made with other weights (" + table_weights +
                         ", this worker's are " + fingerprint +
                         "); run every worker alike, or rebuild them with `spritestation "
                         "transitions BANK` with this worker's weights first");
  }
  for (const auto& [key, value] :
       {std::pair(TableChoice::kMetaKey, options_.table.MetaValue()),
        std::pair(TableChoice::kCapMetaKey, options_.table.CapMetaValue())}) {
    const std::string table_value = writer_.KeepMeta(key, value);
    if (table_value != value) {
      throw InputError(reader_.path(), std::string("its transitions are made with ") + key + " " +
                                           table_value + ", this worker has " + value +
                                           "; run every worker alike, or rebuild them with "
                                           "`spritestation transitions BANK` first");
    }
  }
}

void UnitWorker::CatchUp() {
  const auto t0 = std::chrono::steady_clock::now();
  // The clips' numbers first: every clip numbered up to `upto` is committed, so the features
  // read next hold all of them (and perhaps later ones, which are taken too and skipped later).
  int64_t upto = loaded_seq_;
  for (const ClipRecord& c : reader_.ListClips(loaded_seq_)) upto = std::max(upto, c.complete_seq);
  if (upto == loaded_seq_) return;
  std::vector<int64_t> ids;
  std::map<int64_t, int64_t> clip_of;  // sprite id -> clip id
  for (const SpriteFeatures& f : reader_.LoadFeatures(loaded_seq_)) {
    if (clip_range_.count(f.clip_id) || seen_clips_.count(f.clip_id)) continue;
    ids.push_back(f.id);
    clip_of[f.id] = f.clip_id;
  }
  loaded_seq_ = upto;
  if (ids.empty()) return;
  for (const auto& [id, clip] : clip_of) seen_clips_.insert(clip);
  const double scale = builder_ ? builder_->store().px_per_m() : 0.0;
  // The sprites the choice leaves out (merged ones) are never indexed: a clip of them only
  // has no range, and its unit finds nothing.
  const BankSprites sprites = LoadBankSpritesById(reader_, ids, &keys_, scale, &options_.table);
  if (sprites.inputs.empty()) return;
  if (!builder_) builder_ = std::make_unique<TransitionBuilder>(options_.weights, sprites.px_per_m);
  const int32_t first = builder_->AppendIndexOnly(sprites.inputs, options_.load_threads);
  for (size_t k = 0; k < sprites.ids.size(); ++k) {
    const int32_t index = first + static_cast<int32_t>(k);
    auto [it, fresh] = clip_range_.try_emplace(clip_of.at(sprites.ids[k]), index, index + 1);
    if (!fresh)
      it->second.second = index + 1;  // a clip's sprites are one run (LoadFeatures' order)
    if (fresh) ++stats_.clips_indexed;
  }
  stats_.sprites_indexed += static_cast<int64_t>(sprites.ids.size());
  stats_.seconds_index += SecondsSince(t0);
}

bool UnitWorker::RunOne() {
  queue_.Register();
  const std::optional<WorkUnit> unit = queue_.Claim(options_.name, options_.lease_s);
  if (!unit) return false;
  if (const auto pause = Environment("SPRITESTATION_WORKER_TEST_PAUSE_S")) {
    // Tests: hold the claimed unit a while, so that the worker can be killed in the middle of it.
    std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(pause->c_str())));
  }
  CatchUp();
  const auto range = clip_range_.find(unit->clip_id);
  if (range == clip_range_.end()) {
    // A clip whose sprites were all removed since: nothing to find.
    queue_.Done(unit->clip_id);
    ++stats_.units;
    return true;
  }
  auto t0 = std::chrono::steady_clock::now();
  const int64_t evaluations = builder_->stats().stage2_evaluations,
                kept = builder_->stats().kept_pairs;
  const TransitionDelta delta = builder_->AddPairsOf(range->second.first, range->second.second);
  stats_.seconds_pairs += SecondsSince(t0);
  stats_.stage2_evaluations += builder_->stats().stage2_evaluations - evaluations;
  stats_.kept_pairs += builder_->stats().kept_pairs - kept;

  t0 = std::chrono::steady_clock::now();
  const RoundResult stored =
      StoreTransitionRound(writer_, delta.transitions, options_.table.max_per_sprite, &bars_);
  queue_.Done(unit->clip_id);
  stats_.seconds_store += SecondsSince(t0);
  stats_.transitions += stored.written;
  ++stats_.units;
  Log("pipeline.transitions")
      ->debug("{}: unit clip {} (seq {}, try {}): {} transitions", options_.name, unit->clip_id,
              unit->complete_seq, unit->attempts, stored.written);
  return true;
}

}  // namespace ss
