#!/usr/bin/env bash
# Runs `spritestation bench bank` with a private PostgreSQL server (Debian's, installed by
# scripts/install-deps.sh) for its PostgreSQL case: initdb in a folder under /tmp, a free port
# of 127.0.0.1, run as `nobody` when we are root; stopped and removed on exit.
#   scripts/bench-postgres.sh [BUILD_DIR] [bench arguments...]
# With `transitions` after BUILD_DIR: `bench transitions --workers` instead, on a bank made
# first from a synthetic session (SPRITESTATION_BENCH_SYNTH: synth's arguments).
#   scripts/bench-postgres.sh BUILD_DIR transitions [bench arguments...]
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$top/build}"
shift || true
suite=bank
if [ "${1:-}" = "transitions" ]; then suite=transitions; shift; fi
bin="$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -n 1)"
dir="$(mktemp -d /tmp/spritestation-pg-bench-XXXXXX)"
as=()
if [ "$(id -u)" -eq 0 ]; then
  chown nobody:nogroup "$dir"
  as=(setpriv --reuid=nobody --regid=nogroup --clear-groups)
fi
port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
"${as[@]}" "$bin/initdb" -D "$dir/data" -U spritestation --auth=trust --no-sync >"$dir/log" 2>&1
"${as[@]}" "$bin/postgres" -D "$dir/data" -p "$port" -k "$dir" -c listen_addresses=127.0.0.1 >>"$dir/log" 2>&1 &
server=$!
trap 'kill -INT $server 2>/dev/null; wait $server 2>/dev/null; rm -rf "$dir"' EXIT
for _ in $(seq 100); do
  "$bin/pg_isready" -q -h 127.0.0.1 -p "$port" && break
  sleep 0.1
done
"$bin/createdb" -h 127.0.0.1 -p "$port" -U spritestation bench
export SPRITESTATION_BENCH_POSTGRES="postgresql://spritestation@127.0.0.1:$port/bench"
if [ "$suite" = "transitions" ]; then
  synth="${SPRITESTATION_BENCH_SYNTH:---kind animal --seconds 30 --fps 30 --size 640x480 --cameras 2 --subjects 3 --seed 3}"
  # shellcheck disable=SC2086
  "$build/apps/spritestation" synth --out "$dir/session" $synth >/dev/null
  "$build/apps/spritestation" --log-level warn ingest "$dir/session" --bank "$dir/source.db" --no-transitions
  SPRITESTATION_BENCH_BANK="$dir/source.db" "$build/apps/spritestation" bench transitions --workers "$@"
else
  "$build/apps/spritestation" bench bank "$@"
fi
