#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main
# job on the sample session (recordings/sample, rendered by `spritestation synth`
# the first time), printing what each stage did.
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$top/scripts/install-deps.sh"
build="$("$top/scripts/build.sh" | tail -n 1)"
ss="$build/apps/spritestation"
sample="$top/recordings/sample"
out="$top/recordings/demo-output"
mkdir -p "$out"

if [ ! -f "$sample/session.json" ]; then
  echo "== no recorded sample: rendering a synthetic one into $sample"
  rm -rf "$sample"
  "$ss" synth --out "$sample" --kind animal --seconds 10 --fps 30 --size 640x480 --cameras 2 --subjects 1 --seed 7
fi

echo "== replaying $sample"
"$ss" replay "$sample"

echo "== ingesting $sample into $out/sample.bank (the live pipeline, as fast as it runs)"
"$ss" ingest "$sample" --bank "$out/sample.bank"
"$ss" bank info "$out/sample.bank"

echo "== finding the bank's transitions (seed 000 §3)"
"$ss" transitions "$out/sample.bank"

echo "== the empty enclosure cam0 saw before the animal came in: the render's background"
"$ss" plate "$sample" --camera cam0 --out "$out/plate.png"

echo "== animating: one sprite walks a straight path across the floor (seed 000 §4-5)"
cat > "$out/walk.yaml" <<EOF
version: 1
frame_rate: 30
length: {frames: 90}
camera: $sample/cam0.cameramodel
background: $out/plate.png
banks: [$out/sample.bank]
optimizer: {method: replace, time_budget_s: 10}
sprites:
  - name: walker
    start: [-0.3, 0.0]
    constraints:
      - path:
          points: [[-0.3, 0.0], [0.3, 0.0]]
          distance_strength: 50
EOF
"$ss" animate "$out/walk.yaml" --out "$out/walk.json"

echo "== rendering the animation into the enclosure, with its contact shadow"
"$ss" render "$out/walk.json" --out "$out/walk.mkv"
echo "== done: the animation is $out/walk.mkv (cost plot: $out/walk.cost.png)"
