#!/usr/bin/env bash
# The reference data sets (seed 000 §6), made by our own pipeline: for each set, `synth` renders a
# studio session, `ingest` runs it through the live pipeline into a sprite bank, `transitions`
# finds the bank's transitions and `plate` makes the clean plate of the enclosure; the session's
# camera becomes the virtual camera. docs/synth.md, "Reference data sets", lists what each holds.
#
#   scripts/reference-banks.sh [OUT] [--sets LIST] [--keep-sessions] [--build DIR]
#
# OUT defaults to recordings/reference. LIST (comma-separated, default hamster-60s,flies):
#   hamster-60s, hamster-5min, hamster-30min  one animal, seed 53: the same animal's first 60 s,
#                                             5 min and 30 min (the paper's 30 minutes)
#   flies                                     4 flies at once, seed 62, 5 min (§6.2)
# OUT/NAME/ holds BANK.ssbank (hamster.ssbank or fly.ssbank), floor.png (the clean plate),
# virtual.cameramodel, subjects.csv and truth.json (the session's truth), bank-info.txt,
# timings.txt (each stage's wall time) and inputs.txt (what the stages were made from);
# OUT/hamster links to the longest hamster set OUT holds (what docs/examples name).
#
# Cached by its inputs: each stage keeps a hash of what it was made from (the content of the
# sources it runs, its arguments and config, the recipe's version and the stage before's) and
# is skipped when that has not changed, so a second run is instant. The rendered session is
# deleted once the bank and the plate are made unless --keep-sessions (a 30 min session is
# ~21 GB); a later stage that needs it again renders it again (synth is deterministic).
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$top/recordings/reference"
sets="hamster-60s,flies"
keep_sessions=0
build="${SPRITESTATION_BUILD_DIR:-$top/build}"
positional=0
while [ $# -gt 0 ]; do
  case "$1" in
    --sets) sets="$2"; shift 2 ;;
    --sets=*) sets="${1#--sets=}"; shift ;;
    --keep-sessions) keep_sessions=1; shift ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    -*) echo "reference-banks.sh: unknown option $1" >&2; exit 2 ;;
    *)
      if [ "$positional" -ne 0 ]; then echo "reference-banks.sh: one OUT folder only" >&2; exit 2; fi
      out="$1"; positional=1; shift ;;
  esac
done
ss="$build/apps/spritestation"
if [ ! -x "$ss" ]; then
  echo "reference-banks.sh: no $ss (build first: scripts/build.sh)" >&2
  exit 1
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"

# The sources each stage runs (the code that decides its output).
synth_sources=(synth core capture apps/cmd_synth.cc)
pipeline_sources=(pipeline core capture config apps/cmd_ingest.cc apps/cmd_transitions.cc apps/cmd_plate.cc apps/cmd_bank.cc)
# The content of those files (tracked or new, committed or not): a commit that changes nothing
# they hold keeps the cache.
sources_hash() {
  if git -C "$top" rev-parse --git-dir >/dev/null 2>&1; then
    (cd "$top" && files="$(git ls-files -co --exclude-standard -- "$@" | sort)" &&
      paste -d' ' <(echo "$files") <(echo "$files" | git hash-object --stdin-paths)) |
      sha256sum | cut -c1-16
  else  # not a checkout: the binary stands for its sources
    sha256sum "$ss" | cut -c1-16
  fi
}
synth_src="$(sources_hash "${synth_sources[@]}")"
pipeline_src="$(sources_hash "${pipeline_sources[@]}")"
# Bump when a stage's recipe below changes in a way its arguments do not show.
recipe=1

stage_order="synth ingest transitions plate tag"
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
# CPU seconds (user + system) of the finished child processes so far: the wall clock of this
# shared machine measures the other jobs too.
# Sets cpu_now. (`times` must run in this shell: in a pipe or $(...) it counts a subshell's.)
children_cpu() {
  times > "$out/.times"
  cpu_now="$(tail -n 1 "$out/.times" | awk '{ t = 0; for (i = 1; i <= 2; ++i) { split($i, p, "m"); t += p[1] * 60 + p[2] } printf "%.1f", t }')"
}

# stage NAME KEY COMMAND...: runs COMMAND unless DIR/.NAME.key holds KEY; records its time.
stage() {
  local name="$1" key="$2"
  shift 2
  if [ -f "$dir/.$name.key" ] && [ "$(cat "$dir/.$name.key")" = "$key" ]; then
    echo "   $name: cached ($(grep "^$name " "$dir/timings.txt" 2>/dev/null | cut -d' ' -f2- || echo '?'))"
    return 0
  fi
  # This stage runs: every later one runs again too (they read what it makes).
  local later=0
  for s in $stage_order; do
    [ "$later" -eq 1 ] && rm -f "$dir/.$s.key"
    [ "$s" = "$name" ] && later=1
  done
  rm -f "$dir/.$name.key"
  echo "   $name: $*"
  local t0 c0
  t0="$(now)"
  children_cpu
  c0="$cpu_now"
  "$@"
  local took cpu
  took="$(elapsed "$t0")"
  children_cpu
  cpu="$(awk -v a="$c0" -v b="$cpu_now" 'BEGIN { printf "%.1f", b - a }')"
  touch "$dir/timings.txt"
  grep -v "^$name " "$dir/timings.txt" > "$dir/timings.tmp" || true
  echo "$name ${took} s wall, ${cpu} s CPU ($(date -u +%FT%TZ), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))" >> "$dir/timings.tmp"
  mv "$dir/timings.tmp" "$dir/timings.txt"
  echo "$key" > "$dir/.$name.key"
  echo "   $name: done in ${took} s (${cpu} s CPU)"
}

run_synth() { rm -rf "$dir/session"; nice -n 10 "$ss" synth --out "$dir/session" "${synth_args[@]}"; }
run_ingest() {
  rm -f "$dir/$bank" "$dir/$bank-wal" "$dir/$bank-shm"
  nice -n 10 "$ss" ingest "$dir/session" --bank "$dir/$bank" --no-transitions "${ingest_args[@]}"
}
run_transitions() { nice -n 10 "$ss" transitions "$dir/$bank" --threads 2 --quiet; }
run_plate() {
  nice -n 10 "$ss" plate "$dir/session" --camera cam0 --out "$dir/floor.png"
  cp "$dir/session/cam0.cameramodel" "$dir/virtual.cameramodel"
  cp "$dir/session/truth/subjects.csv" "$dir/subjects.csv"
  cp "$dir/session/truth/truth.json" "$dir/truth.json"
}
# Tags `standing` the sprites (and their mirrors) whose truth pose is `stand`: the animal reared
# up facing the camera (one camera: it always faces cam0), what standup.yaml asks for.
run_tag() {
  local frames ids
  frames="$(awk -F, 'NR > 1 && $10 == "stand" { print $1 }' "$dir/subjects.csv" | paste -sd, -)"
  if [ -z "$frames" ]; then echo "   (no standing frames in the truth)"; return 0; fi
  ids="$(sqlite3 "$dir/$bank" "SELECT id FROM sprites WHERE frame IN ($frames);" | paste -sd, -)"
  if [ -z "$ids" ]; then echo "   (no standing frame kept in the bank)"; return 0; fi
  "$ss" bank tag "$dir/$bank" --sprites "$ids" --tag standing
}

# The sessions are rendered in ffvhuff, not the recorder's ffv1: both lossless, and these sessions
# are read once and deleted, so speed counts, not size. A 20 s hamster (640x480, 30 fps) rendered
# in 4.0 s against 10.9 s and ingested in 1.4 s against 6.5 s (the decoding), 12 % larger
# (bench/RESULTS.md, "The demo on a fresh machine, twice").
codec=(--codec ffvhuff)
IFS=',' read -r -a names <<< "$sets"
for name in "${names[@]}"; do
  ingest_args=()
  case "$name" in
    hamster-60s|hamster-5min|hamster-30min)
      case "$name" in
        hamster-60s) seconds=60 ;;
        hamster-5min) seconds=300 ;;
        hamster-30min) seconds=1800 ;;
      esac
      bank=hamster.ssbank
      synth_args=(--kind animal --seconds "$seconds" --fps 30 --size 640x480 --cameras 1 --subjects 1 --seed 53 --no-mattes "${codec[@]}")
      ;;
    flies)
      bank=fly.ssbank
      synth_args=(--kind fly --seconds 300 --fps 30 --size 640x480 --cameras 1 --subjects 4 --seed 62 --no-mattes "${codec[@]}")
      ;;
    *) echo "reference-banks.sh: unknown set '$name' (hamster-60s, hamster-5min, hamster-30min, flies)" >&2; exit 2 ;;
  esac
  dir="$out/$name"
  mkdir -p "$dir"
  if [ "$name" = flies ]; then
    # The fly is ~25-30 px long in these cameras: the station's default 400 px floor for a
    # matte blob (sized for hamsters) would drop every one.
    printf 'version: 1\npipeline:\n  min_area_px: 80\n' > "$dir/ingest.yaml"
    ingest_args=(--config "$dir/ingest.yaml")
  fi
  synth_key="$(echo "$synth_src ${synth_args[*]}" | sha256sum | cut -c1-16)"
  config=""
  [ ${#ingest_args[@]} -gt 0 ] && config="$(cat "$dir/ingest.yaml")"
  ingest_key="$(echo "$synth_key $pipeline_src ${ingest_args[*]} $config $recipe" | sha256sum | cut -c1-16)"
  printf 'synth: %s (sources %s: %s)\ningest: %s (sources %s: %s)\nkeys: synth %s, later stages %s\n' \
    "${synth_args[*]}" "$synth_src" "${synth_sources[*]}" "--no-transitions ${ingest_args[*]}" \
    "$pipeline_src" "${pipeline_sources[*]}" "$synth_key" "$ingest_key" > "$dir/inputs.txt"
  echo "== $name -> $dir"
  t_set="$(now)"
  # The session is deleted after use: render it again only when a stage that reads it must run.
  if [ ! -f "$dir/session/session.json" ]; then
    for s in ingest plate; do
      [ "$(cat "$dir/.$s.key" 2>/dev/null)" = "$ingest_key" ] || rm -f "$dir/.synth.key"
    done
  fi
  stage synth "$synth_key" run_synth
  stage ingest "$ingest_key" run_ingest
  stage transitions "$ingest_key" run_transitions
  stage plate "$ingest_key" run_plate
  stage tag "$ingest_key" run_tag
  "$ss" bank info "$dir/$bank" > "$dir/bank-info.txt"
  if [ "$keep_sessions" -eq 0 ] && [ -d "$dir/session" ]; then
    du -sh "$dir/session" | awk '{ print "   deleting the rendered session (" $1 "; --keep-sessions keeps it)" }'
    rm -rf "$dir/session"
  fi
  echo "   $(head -n 3 "$dir/bank-info.txt" | paste -sd' ' -)"
  echo "== $name: $(elapsed "$t_set") s"
done
# The longest hamster set OUT holds (made in this run or before): the demo's 60 s set made
# after a 5 min one must not take the examples' bank from them.
for longest_hamster in hamster-30min hamster-5min hamster-60s; do
  if [ -f "$out/$longest_hamster/hamster.ssbank" ]; then
    ln -sfn "$longest_hamster" "$out/hamster"
    echo "== $out/hamster -> $longest_hamster"
    break
  fi
done
if [[ ",$sets," == *",flies,"* ]]; then ln -sfn flies "$out/fly"; fi
