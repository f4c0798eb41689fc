#!/usr/bin/env bash
# Configures and builds SpriteStation into build/ (or $SPRITESTATION_BUILD_DIR).
#   SPRITESTATION_SANITIZE=asan|tsan   build with sanitizers into build-asan/ or build-tsan/
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanitize="${SPRITESTATION_SANITIZE:-}"
extra=()
case "$sanitize" in
  "") build="${SPRITESTATION_BUILD_DIR:-$top/build}" ;;
  asan) build="${SPRITESTATION_BUILD_DIR:-$top/build-asan}"; extra+=(-DSPRITESTATION_ASAN=ON -DCMAKE_BUILD_TYPE=Debug) ;;
  tsan) build="${SPRITESTATION_BUILD_DIR:-$top/build-tsan}"; extra+=(-DSPRITESTATION_TSAN=ON -DCMAKE_BUILD_TYPE=Debug) ;;
  *) echo "build.sh: SPRITESTATION_SANITIZE must be asan or tsan, got '$sanitize'" >&2; exit 2 ;;
esac
# ccache: one cache for every build of this machine, CI's (.ci/run) and a
# developer's alike; paths under the tree hash as relative ones, so a clone in
# another folder (CI's) reuses what a build of this tree already compiled.
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.ccache}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$top}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-true}"
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$top" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${extra[@]}"
fi
cmake --build "$build" -j "$(nproc)"
echo "$build"
