// spritestation bench transitions --workers: transition workers sharing one PostgreSQL bank
// (issue 21, docs/scaling.md) against the single-process build of the same bank, same run.
//   transitions/workers/single_process  `transitions BANK` (UpdateBankTransitions, 1 thread)
//                                       on a SQLite copy of the bank: the baseline
//   transitions/workers/1, /2           1 or 2 UnitWorkers (threads, each its own connections,
//                                       as separate processes would be) doing every unit of
//                                       the bank copied into PostgreSQL
// Needs SPRITESTATION_BENCH_POSTGRES (a database) and SPRITESTATION_BENCH_BANK (a SQLite bank
// of complete clips); scripts/bench-postgres.sh BUILD transitions makes both.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_registry.h"
#include "core/bank.h"
#include "core/bank_copy.h"
#include "core/bank_work.h"
#include "core/posix.h"
#include "core/sql.h"
#include "core/sql_postgres.h"
#include "pipeline/transitions/bank_transitions.h"
#include "pipeline/transitions/unit_worker.h"

namespace ss::bench {
namespace {

namespace fs = std::filesystem;

// The variable's value; empty when it is not set.
std::string Env(const char* name) { return Environment(name).value_or(""); }

bool Inputs(benchmark::State& state) {
  if (Env("SPRITESTATION_BENCH_POSTGRES").empty() || Env("SPRITESTATION_BENCH_BANK").empty()) {
    state.SkipWithError(
        "SPRITESTATION_BENCH_POSTGRES and SPRITESTATION_BENCH_BANK are needed "
        "(scripts/bench-postgres.sh BUILD transitions sets both)");
    return false;
  }
  return true;
}

void BM_SingleProcess(benchmark::State& state) {
  if (!Inputs(state)) return;
  const fs::path copy = fs::temp_directory_path() /
                        ("spritestation-workers-bench-" + std::to_string(getpid()) + ".db");
  BankUpdateSummary last;
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove(copy);
    fs::copy_file(Env("SPRITESTATION_BENCH_BANK"), copy);
    state.ResumeTiming();
    BankUpdateOptions options;
    options.threads = 1;
    last = UpdateBankTransitions(copy.string(), options);
  }
  fs::remove(copy);
  state.counters["sprites"] = static_cast<double>(last.sprites);
  state.counters["transitions"] = static_cast<double>(last.transitions);
  state.counters["load_ms_per_sprite"] =
      1e3 * last.seconds_load / static_cast<double>(std::max<int64_t>(1, last.sprites));
  state.counters["pairs_s"] = last.seconds_build;
  state.counters["store_s"] = last.seconds_store;
}

// The PostgreSQL bank, made once from the SQLite one; each iteration starts with no
// transitions and no work done.
const std::string& PostgresBank() {
  static const std::string address = [] {
    std::string pg = Env("SPRITESTATION_BENCH_POSTGRES");
    if (BankWriter(pg).Counts().sessions == 0) CopyBank(Env("SPRITESTATION_BENCH_BANK"), pg);
    return pg;
  }();
  return address;
}

void Reset(const std::string& pg) {
  BankWriter w(pg);
  w.ClearTransitions();
  BankWorkQueue queue(pg);  // makes the table when missing
  sql::Db db = sql::OpenPostgres(pg, /*read_only=*/false);
  db.Exec("DELETE FROM transition_work");
}

void BM_Workers(benchmark::State& state) {
  if (!Inputs(state)) return;
  const int n = static_cast<int>(state.range(0));
  std::vector<UnitWorkerStats> stats(static_cast<size_t>(n));
  for (auto _ : state) {
    state.PauseTiming();
    const std::string& pg = PostgresBank();
    Reset(pg);
    state.ResumeTiming();
    std::vector<std::thread> threads;
    threads.reserve(n);
    for (int k = 0; k < n; ++k) {
      threads.emplace_back([&, k] {
        UnitWorker worker(pg, UnitWorkerOptions{.name = "bench-" + std::to_string(k)});
        while (true) {
          if (worker.RunOne()) continue;
          const WorkCounts c = worker.Counts();
          if (c.pending == 0 && c.leased == 0) break;
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        stats[static_cast<size_t>(k)] = worker.stats();
      });
    }
    for (std::thread& t : threads) t.join();
  }
  UnitWorkerStats sum;
  double index_s = 0, pairs_s = 0, store_s = 0;
  for (const UnitWorkerStats& s : stats) {
    sum.units += s.units;
    sum.transitions += s.transitions;
    sum.sprites_indexed += s.sprites_indexed;
    index_s += s.seconds_index;
    pairs_s += s.seconds_pairs;
    store_s += s.seconds_store;
  }
  state.counters["units"] = static_cast<double>(sum.units);
  state.counters["transitions"] = static_cast<double>(sum.transitions);
  // Every worker indexes the whole bank: per sprite indexed, per transition stored.
  state.counters["index_ms_per_sprite"] =
      1e3 * index_s / static_cast<double>(std::max<int64_t>(1, sum.sprites_indexed));
  state.counters["pairs_s"] = pairs_s;
  state.counters["upsert_ms_per_row"] =
      1e3 * store_s / static_cast<double>(std::max<int64_t>(1, sum.transitions));
}

BENCHMARK(BM_SingleProcess)
    ->Name("transitions/workers/single_process")
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_Workers)
    ->Name("transitions/workers")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

// Called by `bench transitions --workers [benchmark flags]`.
int RunTransitionWorkers(const std::vector<std::string>& args) {
  RealTimes seconds;
  if (const int status = RunGoogleBenchmarks("transitions/workers", args, &seconds)) return status;
  const auto base = seconds.time.find("transitions/workers/single_process");
  if (base == seconds.time.end()) return 1;
  for (const auto& [name, s] : seconds.time) {
    if (name != base->first)
      std::printf("%s: %.2f s = %.2f x the single-process build (%.2f s)\n", name.c_str(), s,
                  s / base->second, base->second);
  }
  return 0;
}

}  // namespace ss::bench
