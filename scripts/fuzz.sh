#!/usr/bin/env bash
# The sanitizer build (tests/fuzz/README.md): builds unit suites and the libFuzzer targets with
# clang under ASan and UBSan into build-fuzz/ (-O1, line tables only: no app, web or
# benchmarks), runs those suites there (SPRITESTATION_SANITIZE_SUITES, below), then
# fuzzes each parser of outside input for SECONDS (default 20) on a working copy of its committed
# corpus. A sanitizer report or a failed test stops the run with exit 1 (logs in build-fuzz/). A
# fuzz finding (crash, sanitizer report, an exception
# other than the project's own errors, an input taking > 10 s or > 2 GB) stops the run with
# exit 1 and its input in build-fuzz/findings/<target>/: add it to tests/fuzz/corpus/<target>/
# once fixed, where the ordinary build's fuzz_corpus.<target> test replays it for good.
#   scripts/fuzz.sh [SECONDS] [target...]      e.g. scripts/fuzz.sh 600 config spec
# Naming targets fuzzes only them (no unit suites). No unit suite runs `spritestation` (those
# tests are in tests/e2e/), so this build has no app.
# SPRITESTATION_FUZZ_SEED=N fixes libFuzzer's seed (default: a new one each run), and
# SPRITESTATION_FUZZ_FRESH=1 starts from the committed corpus alone: together they make a run
# repeat the inputs of an earlier one (scripts/test.sh uses both, so CI replays what ran here).
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-20}"
shift || true
build="${SPRITESTATION_FUZZ_BUILD_DIR:-$top/build-fuzz}"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.ccache}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$top}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-true}"
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# -O1 (AddressSanitizer's advice: reports stay exact) and line tables only (file:line in every
# report, without full debug info to write and link). Always configured: an older build-fuzz/
# takes these flags too.
flags="-O1 -gline-tables-only"
# The unit suites built and run here (SPRITESTATION_SANITIZE_SUITES, CMake's names, or `all`,
# the default: CI runs every unit suite here and not in the ordinary build; tests/fuzz/README.md,
# Cost).
all="core_tests capture_tests synth_tests calib_tests pipeline_tests config_tests station_tests animate_tests import_tests libcamera_tests judge_tests"
suites="${SPRITESTATION_SANITIZE_SUITES:-all}"
[ "$suites" = all ] && suites="$all"
CC=clang CXX=clang++ cmake -S "$top" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$flags" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$flags" -DSPRITESTATION_FUZZ=ON \
  "-DSPRITESTATION_SANITIZE_SUITES=${suites// /;}" >/dev/null
cmake --build "$build" -j "$(nproc)"

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  # The unit suites, built here under ASan + UBSan (clang).
  # Leaks inside Debian's libraries, each explained in the file, are not reported.
  export LSAN_OPTIONS="suppressions=$top/tests/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
  log="$build/unit-tests.log"
  start=$SECONDS
  if ! (cd "$build" && ctest -L unit --timeout 900 -j "$(nproc)" --output-on-failure >"$log" 2>&1); then
    echo "fuzz.sh: unit suites failed under ASan+UBSan (log $log):" >&2
    grep -E 'ERROR: |runtime error|SUMMARY|\*\*\*Failed|\*\*\*Exception|Timeout|tests failed' "$log" | head -20 >&2
    exit 1
  fi
  echo "unit suites under ASan+UBSan ($suites): $(grep -o '[0-9]* tests failed out of [0-9]*' "$log"), $((SECONDS - start)) s"

  for dir in "$top"/tests/fuzz/corpus/*/; do targets+=("$(basename "$dir")"); done
fi
for t in "${targets[@]}"; do
  [ -x "$build/tests/fuzz/${t}_fuzz" ] || { echo "fuzz.sh: no target '$t' (tests/fuzz/corpus/ names them)" >&2; exit 2; }
done
# Fuzzes target $1 for $seconds; its verdict on stdout (a finding: exit 1 and its lines on stdout).
fuzz_one() {
  local t="$1"
  local exe="$build/tests/fuzz/${t}_fuzz"
  local work="$build/corpus/$t" findings="$build/findings/$t"
  [ "${SPRITESTATION_FUZZ_FRESH:-0}" = "1" ] && rm -rf "$work"
  mkdir -p "$work" "$findings"
  cp -n "$top/tests/fuzz/corpus/$t/"* "$work/" 2>/dev/null || true
  local log="$build/fuzz-$t.log"
  # The spec's numbers size the problem it builds: issue 39 bounds that within 1 GiB (the
  # process under ASan starts at ~500 MB of it). The other parsers get 2 GiB.
  local mb=2048
  [ "$t" = spec ] && mb=1024
  if "$exe" -max_total_time="$seconds" -seed="${SPRITESTATION_FUZZ_SEED:-0}" -timeout=10 -rss_limit_mb=$mb -malloc_limit_mb=$mb \
      -artifact_prefix="$findings/" -print_final_stats=1 "$work" >"$log" 2>&1; then
    local runs
    runs="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')"
    echo "fuzz $t: ${seconds} s, $runs inputs, no finding"
  else
    echo "fuzz $t: FINDING (input in $findings/, log $log):"
    grep -E 'ERROR|SUMMARY|terminate called|what\(\)' "$log" | head -5 || tail -20 "$log"
    return 1
  fi
}
# One target a core at a time (libFuzzer runs one process on one core): each still gets its
# SECONDS, and the run takes SECONDS x targets / cores. Verdicts are printed in the targets'
# order once all have run.
verdicts="$(mktemp -d)"
trap 'rm -rf "$verdicts"' EXIT
jobs_max="$(nproc)"
for i in "${!targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do wait -n || true; done
  (if fuzz_one "${targets[$i]}" >"$verdicts/$i"; then :; else touch "$verdicts/$i.finding"; fi) &
done
wait
status=0
for i in "${!targets[@]}"; do
  if [ -e "$verdicts/$i.finding" ]; then
    status=1
    cat "$verdicts/$i" >&2
  else
    cat "$verdicts/$i"
  fi
done
exit $status
