#!/usr/bin/env bash
# Fuzzes every parser of outside input (tests/fuzz/README.md): builds the libFuzzer targets
# with clang under ASan and UBSan into build-fuzz/, runs core's unit tests there (the same
# sanitizers), then fuzzes each target for SECONDS (default 20) on a working copy of its
# committed corpus. A finding (crash, sanitizer report, an exception
# other than the project's own errors, an input taking > 10 s or > 2 GB) stops the run with
# exit 1 and its input in build-fuzz/findings/<target>/: add it to tests/fuzz/corpus/<target>/
# once fixed, where the ordinary build's fuzz_corpus.<target> test replays it for good.
#   scripts/fuzz.sh [SECONDS] [target...]      e.g. scripts/fuzz.sh 600 config spec
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
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$top" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSPRITESTATION_FUZZ=ON >/dev/null
fi
cmake --build "$build" -j "$(nproc)"

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  # core's unit tests, built here under the same sanitizers (ASan + UBSan, clang)
  if ! (cd "$build" && tests/core_tests --gtest_brief=1 >"$build/core_tests.log" 2>&1); then
    echo "fuzz.sh: core_tests failed under ASan+UBSan (log $build/core_tests.log):" >&2
    grep -E 'ERROR|runtime error|FAILED' "$build/core_tests.log" | head -10 >&2
    exit 1
  fi
  echo "core_tests under ASan+UBSan: $(grep -o '[0-9]* tests\? from [0-9]* test suites\? ran' "$build/core_tests.log"), passed"

  for dir in "$top"/tests/fuzz/corpus/*/; do targets+=("$(basename "$dir")"); done
fi
status=0
for t in "${targets[@]}"; do
  exe="$build/tests/fuzz/${t}_fuzz"
  [ -x "$exe" ] || { echo "fuzz.sh: no target '$t' (tests/fuzz/corpus/ names them)" >&2; exit 2; }
  work="$build/corpus/$t" findings="$build/findings/$t"
  [ "${SPRITESTATION_FUZZ_FRESH:-0}" = "1" ] && rm -rf "$work"
  mkdir -p "$work" "$findings"
  cp -n "$top/tests/fuzz/corpus/$t/"* "$work/" 2>/dev/null || true
  log="$build/fuzz-$t.log"
  if "$exe" -max_total_time="$seconds" -seed="${SPRITESTATION_FUZZ_SEED:-0}" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -artifact_prefix="$findings/" -print_final_stats=1 "$work" >"$log" 2>&1; then
    runs="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')"
    echo "fuzz $t: ${seconds} s, $runs inputs, no finding"
  else
    status=1
    echo "fuzz $t: FINDING (input in $findings/, log $log):" >&2
    grep -E 'ERROR|SUMMARY|terminate called|what\(\)' "$log" | head -5 >&2 || tail -20 "$log" >&2
  fi
done
exit $status
