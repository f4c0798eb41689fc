#!/bin/sh
# The console's browser tests (web/tests/*.test.mjs): CTest runs
#   web/tests/run.sh /abs/path/to/build/apps/spritestation
# They run in a private network namespace (as root `unshare -n`, else
# `unshare -rn`) with 127.0.0.2 on its loopback, so the emulated GigE cameras
# serve on port 3956 without meeting other tests' cameras. SS_WEB_TESTS=NAME[,NAME]
# runs only web/tests/NAME.test.mjs.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

if [ $# -ne 1 ]; then
  echo "usage: $0 /abs/path/to/spritestation" >&2
  exit 2
fi
bin=$1

if [ -z "${SS_WEB_INNER:-}" ]; then
  [ -x "$bin" ] || { echo "run.sh: $bin: not an executable" >&2; exit 2; }
  command -v node >/dev/null || { echo "run.sh: node not found (scripts/install-deps.sh installs nodejs)" >&2; exit 1; }
  [ -x "${CHROMIUM:-/usr/bin/chromium}" ] ||
    { echo "run.sh: ${CHROMIUM:-/usr/bin/chromium} not found (apt-get install chromium; scripts/install-deps.sh does)" >&2; exit 1; }
  [ -d "$here/node_modules/playwright-core" ] ||
    { echo "run.sh: web/tests/node_modules/playwright-core missing: run npm ci --prefix web/tests (scripts/install-deps.sh does)" >&2; exit 1; }
  command -v sqlite3 >/dev/null || { echo "run.sh: sqlite3 not found" >&2; exit 1; }
  if [ "$(id -u)" -eq 0 ]; then ns="unshare -n"; else ns="unshare -rn"; fi
  SS_WEB_INNER=1 exec $ns "$0" "$@"
fi

ip link set lo up
ip addr add 127.0.0.2/8 dev lo
ip addr add 127.0.0.3/8 dev lo

SS_WEB_WORK=$(mktemp -d "${TMPDIR:-/tmp}/ss-web-tests.XXXXXX")
export SS_WEB_WORK
export SPRITESTATION="$bin"
keep=${SS_WEB_KEEP:-}
cleanup() {
  if [ -n "$keep" ]; then echo "run.sh: kept $SS_WEB_WORK"; else rm -rf "$SS_WEB_WORK"; fi
}
trap cleanup EXIT INT TERM

cd "$repo"
# SS_WEB_TESTS=NAME runs web/tests/NAME.test.mjs alone; "calibrate,label" (or
# "calibrate label") runs those files (default: every *.test.mjs).
if [ -n "${SS_WEB_TESTS:-}" ]; then
  set --
  for t in $(echo "$SS_WEB_TESTS" | tr ',' ' '); do
    [ -f "$here/$t.test.mjs" ] || { echo "run.sh: no $here/$t.test.mjs" >&2; exit 2; }
    set -- "$@" "$here/$t.test.mjs"
  done
else
  set -- "$here"/*.test.mjs
fi
status=0
# A file's own waits each have their timeout; this one only ends a file that hangs. CI's
# machine has run the station file 3x slower than a quiet one (240+ s against 82 s).
node --test --test-concurrency=1 --test-timeout=600000 "$@" || status=$?
if [ "$status" -ne 0 ]; then
  for f in "$SS_WEB_WORK"/*.log "$SS_WEB_WORK"/*/*.log; do
    [ -f "$f" ] || continue
    echo "==== $f (last 40 lines)"
    tail -n 40 "$f"
  done
fi
exit "$status"
