#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs the whole suite.
#   scripts/test.sh [ctest args...]     e.g. scripts/test.sh -L e2e
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$top/scripts/install-deps.sh"
build="$("$top/scripts/build.sh" | tail -n 1)"
(cd "$build" && ctest --output-on-failure --timeout 300 -j "$(nproc)" "$@")
# Every parser of outside input under libFuzzer, ASan and UBSan for a bounded time
# (SPRITESTATION_FUZZ_SECONDS each, default 20; 0 skips), on the committed corpus.
if [ $# -eq 0 ] && [ "${SPRITESTATION_FUZZ_SECONDS:-20}" != "0" ]; then
  "$top/scripts/fuzz.sh" "${SPRITESTATION_FUZZ_SECONDS:-20}"
fi
