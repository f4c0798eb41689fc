#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs the whole suite.
#   scripts/test.sh [ctest args...]     e.g. scripts/test.sh -L e2e
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$top/scripts/install-deps.sh"
build="$("$top/scripts/build.sh" | tail -n 1)"
cd "$build"
ctest --output-on-failure --timeout 300 -j "$(nproc)" "$@"
