#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs the whole suite.
#   scripts/test.sh [ctest args...]     e.g. scripts/test.sh -L e2e
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$top/scripts/install-deps.sh"
build="$("$top/scripts/build.sh" | tail -n 1)"
(cd "$build" && ctest --output-on-failure --timeout 300 -j "$(nproc)" "$@")
# The sanitizer build (scripts/fuzz.sh): every unit suite again under ASan and UBSan, then every
# parser of outside input under libFuzzer for a bounded time (SPRITESTATION_FUZZ_SECONDS each,
# default 20; 0 skips the whole step), from the committed corpus with a fixed seed: the inputs
# CI tries are the ones tried before the commit (longer runs with new seeds are
# scripts/fuzz.sh's job, and their findings join the corpus).
if [ $# -eq 0 ] && [ "${SPRITESTATION_FUZZ_SECONDS:-20}" != "0" ]; then
  SPRITESTATION_FUZZ_SEED="${SPRITESTATION_FUZZ_SEED:-1}" SPRITESTATION_FUZZ_FRESH=1 \
    "$top/scripts/fuzz.sh" "${SPRITESTATION_FUZZ_SECONDS:-20}"
fi
