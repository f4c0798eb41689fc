#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, checks the style, runs the whole
# suite.
#   scripts/test.sh [ctest args...]     e.g. scripts/test.sh -L e2e (then: those tests alone)
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$top/scripts/install-deps.sh"
fuzz_seconds="${SPRITESTATION_FUZZ_SECONDS:-20}"
# The unit suites run in the sanitizer build (below), so this build leaves them out: a third of
# its compile time (bench/RESULTS.md, "build"). They are built here when they run here: with
# ctest arguments, SPRITESTATION_FUZZ_SECONDS=0 or a whole-tree sanitizer build.
unit=OFF
if [ $# -gt 0 ] || [ "$fuzz_seconds" = 0 ] || [ -n "${SPRITESTATION_SANITIZE:-}" ]; then unit=ON; fi
# (with `spritestation bench` in it, which the demo's build leaves out)
build="$(SPRITESTATION_UNIT_SUITES=$unit SPRITESTATION_BENCHMARKS=ON "$top/scripts/build.sh")"
if [ $# -gt 0 ]; then
  (cd "$build" && ctest --output-on-failure --timeout 300 -j "$(nproc)" "$@")
  exit
fi
# clang-format on every file, clang-tidy on what changed since it last read all (the script says).
"$top/scripts/check-style.sh" "$build"
# The sanitizer build (scripts/fuzz.sh) runs every unit suite under ASan and UBSan, then fuzzes
# every parser of outside input under libFuzzer for a bounded time (SPRITESTATION_FUZZ_SECONDS
# each, default 20), from the committed corpus with a fixed seed: the inputs CI tries are the
# ones tried before the commit (longer runs with new seeds are scripts/fuzz.sh's job, and their
# findings join the corpus). The unit suites run there, not twice: this build runs the rest
# (end-to-end, browser, vivid, ...). SPRITESTATION_FUZZ_SECONDS=0 skips the sanitizer build and
# runs the unit suites here instead, as does a whole-tree sanitizer build (SPRITESTATION_SANITIZE,
# scripts/build.sh).
if [ "$fuzz_seconds" = 0 ] || [ -n "${SPRITESTATION_SANITIZE:-}" ]; then
  (cd "$build" && ctest --output-on-failure --timeout 300 -j "$(nproc)")
  exit
fi
(cd "$build" && ctest --output-on-failure --timeout 300 -j "$(nproc)" -LE '^unit$')
SPRITESTATION_FUZZ_SEED="${SPRITESTATION_FUZZ_SEED:-1}" SPRITESTATION_FUZZ_FRESH=1 \
  "$top/scripts/fuzz.sh" "$fuzz_seconds"
