#!/usr/bin/env bash
# The README's main command: installs what building and running need, builds the executable,
# and runs the main job, printing each stage and how long it took.
#   scripts/demo.sh             the offline job on the reference hamster's first 60 s
#                               (scripts/reference-banks.sh: render, ingest through the live
#                               pipeline, transitions, plate; cached), then animate and render
#   scripts/demo.sh --station   the live station instead: the daemon in test mode on the sample
#                               session (recordings/sample, rendered the first time;
#                               docs/station.replay.yaml), its console in the browser; Ctrl-C stops
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode=offline
case "${1:-}" in
  --station) mode=station ;;
  "") ;;
  *) echo "demo.sh: usage: scripts/demo.sh [--station]" >&2; exit 2 ;;
esac

t0=$SECONDS
stage_start=$SECONDS
stage_name=""
# Ends the stage in progress (its time) and starts the next: `stage NAME "what it does"`.
stage() {
  if [ -n "$stage_name" ]; then
    echo "   ($stage_name took $((SECONDS - stage_start)) s)"
  fi
  stage_name="$1"
  stage_start=$SECONDS
  echo "== [$((SECONDS - t0)) s] $2"
}

stage install "installing what building and running need (scripts/install-deps.sh --run)"
"$top/scripts/install-deps.sh" --run
# The executable without `spritestation bench` (the benchmark suites, a tenth of its compile
# time): the demo runs none. A later `scripts/test.sh` builds them in again.
stage build "building the executable (SPRITESTATION_BENCHMARKS=OFF scripts/build.sh spritestation)"
build="$(SPRITESTATION_BENCHMARKS=OFF "$top/scripts/build.sh" spritestation)"
ss="$build/apps/spritestation"
sample="$top/recordings/sample"
out="$top/recordings/demo-output"
mkdir -p "$out"

if [ "$mode" = station ]; then
  if [ ! -f "$sample/session.json" ]; then
    stage synth "rendering a synthetic sample session into $sample (scripts/sample.sh; no camera needed)"
    SPRITESTATION="$ss" "$top/scripts/sample.sh" "$sample"
  fi
  config="$top/docs/station.replay.yaml"
  stage station "starting the station on the sample session ($config)"
  log="$out/station.log"
  "$ss" daemon --config "$config" >"$log" 2>&1 &
  daemon=$!
  stop() {
    trap - INT TERM
    echo
    stage stop "stopping the station (any running session is stored)"
    kill -INT "$daemon" 2>/dev/null || true
    wait "$daemon" || true
    if [ -f "$out/station.bank" ]; then
      "$ss" bank verify "$out/station.bank" && "$ss" bank info "$out/station.bank"
    fi
    stage done "done (log: $log)"
    exit 0
  }
  trap stop INT TERM
  for _ in $(seq 1 300); do
    grep -q "daemon: control API on" "$log" 2>/dev/null && break
    kill -0 "$daemon" 2>/dev/null || { cat "$log" >&2; echo "demo.sh: the station did not start" >&2; exit 1; }
    sleep 0.1
  done
  url="$(grep -o 'http://[^ ]*' "$log" | head -1)/"
  cat <<EOF

   The station runs, its two sample cameras replayed as if live. Open the console:

       $url

   Try: Start a session (the station page), watch sprites arrive in the bank;
        the Bank page (${url}bank.html) to browse clips and tag frames;
        the Labelling page (${url}label.html) and Calibration (${url}calibrate.html).
   Scripts use the same port: curl -s ${url}api/status
   Ctrl-C stops the station: a running session is stored and the bank verified.

EOF
  wait "$daemon"
  exit $?
fi

# A bank that can make the walk: 10 s of a two-camera sample gave 6 clips of ~40 frames and no
# transition between them, and the walk stopped after 0.12 m; the reference hamster's first
# minute (one camera, 1,618 sprites in 7 clips, 13,713 transitions) finishes it.
ref_root="$top/recordings/reference"
stage reference "the reference hamster's first 60 s: rendered (no camera needed), ingested through the live pipeline, its transitions and clean plate (scripts/reference-banks.sh; cached: instant the second time)"
"$top/scripts/reference-banks.sh" "$ref_root" --sets hamster-60s --build "$build"

stage animate "animating: the hamster walks a straight path 0.6 m across the floor (docs/examples/walk.yaml; seed 000 §4-5)"
"$ss" animate "$top/docs/examples/walk.yaml" --out "$out/walk.json"

stage render "rendering the animation into the enclosure, with its contact shadow"
"$ss" render "$out/walk.json" --out "$out/walk.mkv"
stage done "done: the animation is $out/walk.mkv (cost plot: $out/walk.cost.png); $((SECONDS - t0)) s in all"
