#!/usr/bin/env bash
# Renders the sample session the station demo replays (`scripts/demo.sh --station`,
# docs/station.replay.yaml) unless it is there: 10 s of one synthetic hamster seen by two
# cameras (no camera needed). The console's browser tests render theirs with this same command.
#   scripts/sample.sh [DIR]    DIR defaults to recordings/sample
# The executable: $SPRITESTATION, else build/apps/spritestation.
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="${1:-$top/recordings/sample}"
ss="${SPRITESTATION:-$top/build/apps/spritestation}"
[ -x "$ss" ] || { echo "sample.sh: no $ss (build first: scripts/build.sh spritestation)" >&2; exit 1; }
if [ -f "$dir/session.json" ]; then exit 0; fi
rm -rf "$dir"
"$ss" synth --out "$dir" --kind animal --seconds 10 --fps 30 --size 640x480 --cameras 2 --subjects 1 --seed 7
