// The station's bank writer (station_impl.h): one thread takes the cameras' clip batches and
// appends them to the bank, keeps them in the spool while the bank is away and drains it when
// the bank answers again, and counts what was stored.
#include <chrono>
#include <exception>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/bank.h"
#include "core/error_kinds.h"
#include "station/station_impl.h"

namespace ss {

using station_detail::Clock;

void Station::Impl::Store(StationBatch sb) {
  {
    std::lock_guard lock(idle_mutex);
    ++batches_in;
  }
  if (!batches.Push(std::move(sb))) {
    std::lock_guard lock(idle_mutex);
    ++batches_done;
  }
}

void Station::Impl::WriterLoop() {
  DrainSpool();  // what an earlier run left
  while (true) {
    std::optional<StationBatch> sb;
    if (spool && !spool->empty()) {
      // Batches wait on disk: try the bank again every second even if no new batch comes. A
      // retry, as a camera's reopen is: nothing tells when a server that is away comes back.
      sb = batches.PopFor(std::chrono::seconds(1));
      if (!sb) {
        if (batches.closed()) break;
        DrainSpool();
        continue;
      }
    } else {
      sb = batches.Pop();
      if (!sb) break;
    }
    WriteBatch(*sb);
    std::lock_guard lock(idle_mutex);
    ++batches_done;
    idle_cv.notify_all();
  }
  DrainSpool();  // a last try; what is left waits for the next start
}

void Station::Impl::WriteBatch(StationBatch& sb) {
  const ClipRecord& clip = sb.batch.clip;
  if (disk.Check().state == StorageState::kSpritesStopped) {
    BreakClip(clip);  // so its later batches are not stored when the space comes back
    std::lock_guard lock(stats_mutex);
    ++batches_refused;
    return;
  }
  if (broken_clips.count(ClipKey(clip)) > 0) {
    BreakClip(clip);
    std::lock_guard lock(stats_mutex);
    ++batches_failed;
    return;
  }
  if (spool && !spool->empty()) {
    // Earlier batches wait in the spool: this one goes behind them, so that the bank takes
    // every clip's batches in order.
    Spool(sb.batch);
    DrainSpool();
    return;
  }
  AppendResult result;
  try {
    // Another writer of a SQLite bank (the transitions worker, a labelling page, another
    // process) may hold its write lock past the busy timeout (10 s) on a loaded machine: the
    // batch is still in hand, so it is tried again before it is spooled. A PostgreSQL bank
    // that is busy has lost its server: the spool takes the batch at once.
    const int attempts = bank->is_postgres() ? 1 : kBusyAttempts;
    for (int attempt = 1;; ++attempt) {
      try {
        std::lock_guard lock(bank_mutex);
        result = bank->AppendClipBatch(sb.batch.clip, sb.batch.sprites);
        break;
      } catch (const BusyError& e) {
        if (attempt == attempts) throw;
        log->warn("bank: {} (clip {}/{} from frame {}: try {} of {})", e.what(), clip.camera_id,
                  clip.track_id, clip.first_frame, attempt + 1, attempts);
        std::lock_guard lock(stats_mutex);
        ++batches_retried;
      }
    }
  } catch (const BusyError& e) {
    log->warn("bank: {} (clip {}/{} from frame {}: kept in the spool until the bank answers)",
              e.what(), clip.camera_id, clip.track_id, clip.first_frame);
    {
      std::lock_guard lock(stats_mutex);
      bank_error = e.what();
      last_append_failed = true;
    }
    Spool(sb.batch);
    return;
  } catch (const std::exception& e) {
    // A failed append is one rolled-back transaction: what was stored stays stored.
    log->error("bank: {} (the rest of clip {}/{} from frame {} is not stored)", e.what(),
               clip.camera_id, clip.track_id, clip.first_frame);
    BreakClip(clip);
    std::lock_guard lock(stats_mutex);
    ++batches_failed;
    bank_error = e.what();
    last_append_failed = true;
    return;
  }
  Stored(sb.batch, result, &sb.received);
}

void Station::Impl::BreakClip(const ClipRecord& clip) {
  if (clip.complete) {
    broken_clips.erase(ClipKey(clip));  // its last batch: the clip ends here
  } else {
    broken_clips.insert(ClipKey(clip));
  }
}

void Station::Impl::Spool(const ClipBatch& batch) {
  std::string why;
  try {
    if (spool && spool->Push(batch)) {
      std::lock_guard lock(stats_mutex);
      ++batches_spooled;
      spool_batches = spool->batches();
      spool_bytes = spool->bytes();
      return;
    }
    why = spool ? "the spool " + spool->dir() + " is full (storage.spool_max_mib)" : "no spool";
  } catch (const std::exception& e) {
    why = e.what();
  }
  const ClipRecord& clip = batch.clip;
  log->error("bank: clip {}/{} from frame {} not stored and not spooled: {}", clip.camera_id,
             clip.track_id, clip.first_frame, why);
  BreakClip(clip);
  std::lock_guard lock(stats_mutex);
  ++batches_failed;
  bank_error = why;
  last_append_failed = true;
}

void Station::Impl::DrainSpool() {
  size_t drained = 0;
  while (spool && !spool->empty()) {
    std::optional<ClipBatch> batch = spool->Front();
    if (!batch) break;
    AppendResult result;
    try {
      std::lock_guard lock(bank_mutex);
      result = bank->AppendClipBatch(batch->clip, batch->sprites);
    } catch (const BusyError&) {
      break;  // still away: the next batch or the next second tries again
    } catch (const std::exception& e) {
      log->error("bank: a spooled batch is refused: {}", e.what());
      spool->SetAsideFront(e.what());
      std::lock_guard lock(stats_mutex);
      ++batches_failed;
      bank_error = e.what();
      continue;
    }
    spool->PopFront();
    ++drained;
    Stored(*batch, result, nullptr);
  }
  std::lock_guard lock(stats_mutex);
  if (spool) {
    spool_batches = spool->batches();
    spool_bytes = spool->bytes();
  }
  if (drained > 0)
    log->info("bank: {} spooled batches stored, {} still waiting", drained, spool_batches);
}

void Station::Impl::Stored(const ClipBatch& batch, const AppendResult& result,
                           const std::vector<SteadyTime>* received) {
  const SteadyTime now = Clock::now();
  uint64_t originals = 0;
  {
    std::lock_guard lock(stats_mutex);
    for (size_t i = 0; i < batch.sprites.size(); ++i) {
      if (batch.sprites[i].mirrored) continue;
      ++originals;
      if (!received) continue;
      latencies_ms.push_back(Seconds(now - (*received)[i]) * 1e3);
      ++latency_count;
      latency_sum_ms += latencies_ms.back();
      if (latencies_ms.size() > 10000) latencies_ms.pop_front();
    }
    sprites_stored += originals;
    bank_sprites += result.inserted;
    ++batches_stored;
    last_append_failed = false;
    stored_log.emplace_back(now, sprites_stored);
    while (stored_log.size() > 2 && Seconds(now - stored_log.front().first) > 5.0)
      stored_log.pop_front();
  }
  {
    std::lock_guard lock(session_mutex);
    session.sprites_stored += originals;
  }
  if (transitions && result.inserted > 0) transitions->Submit(result.sprite_ids);
}

void Station::Impl::WaitWriterIdle() {
  std::unique_lock lock(idle_mutex);
  idle_cv.wait(lock, [&] { return batches_done >= batches_in; });
}

}  // namespace ss
