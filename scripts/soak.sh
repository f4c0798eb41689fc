#!/usr/bin/env bash
# The daemon soak (bench/soak/soak.mjs): builds, then runs a station on paced replay cameras
# with a capture session and a browser-like client for MINUTES (default 30), and checks RSS,
# API latency and drops. Not part of the test suite (it takes half an hour): a benchmark.
#   scripts/soak.sh [MINUTES]
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$("$top/scripts/build.sh")"
SPRITESTATION="$build/apps/spritestation" exec node "$top/bench/soak/soak.mjs" "${1:-30}"
