#!/usr/bin/env bash
# Configures and builds SpriteStation into build/ (or $SPRITESTATION_BUILD_DIR); prints the build
# folder on stdout, last, and everything else (ninja's [n/N] progress) on stderr.
#   scripts/build.sh [TARGET...]       only those targets (the demo: spritestation), else all
#   SPRITESTATION_SANITIZE=asan|tsan   build with sanitizers into build-asan/ or build-tsan/
#   SPRITESTATION_UNIT_SUITES=ON|OFF    build and register the unit suites here or not (kept as set;
#                                      scripts/test.sh turns them off: they run in its sanitizer build)
#   SPRITESTATION_BENCHMARKS=ON|OFF     build `spritestation bench` into the executable or not (kept as
#                                      set; default ON; scripts/demo.sh turns it off, test.sh on)
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
# The options kept as set: given in the environment, they are passed to cmake (and configure again
# when the build folder has them otherwise); not given, the build folder keeps what it has.
kept=()
for option in SPRITESTATION_UNIT_SUITES SPRITESTATION_BENCHMARKS; do
  [ -n "${!option:-}" ] && kept+=("-D$option=${!option}")
done
extra+=("${kept[@]}")
# ccache: one cache for every build of this machine, CI's (.ci/run) and a
# developer's alike; paths under the tree hash as relative ones, so a clone in
# another folder (CI's) reuses what a build of this tree already compiled.
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.ccache}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$top}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-true}"
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# The ordinary build: -O2 with -g1 (line tables and function names: backtraces, perf and
# sanitizer reports name file:line) rather than full -g, which costs ~25 % more compile time
# per file (measured: tests/fuzz/README.md, "Cost"). SPRITESTATION_DEBUG_INFO=full gives -g.
debug="-g1"
[ "${SPRITESTATION_DEBUG_INFO:-}" = full ] && debug="-g"
# A configure that failed (a package missing) leaves a cache but no build files: configure again,
# else the next build only said "loading 'build.ninja': No such file".
if [ ! -f "$build/CMakeCache.txt" ] || { [ ! -f "$build/build.ninja" ] && [ ! -f "$build/Makefile" ]; }; then
  cmake -S "$top" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 $debug -DNDEBUG" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 $debug -DNDEBUG" \
    "${extra[@]}" >&2
fi
for define in "${kept[@]}"; do
  setting="${define#-D}"
  if ! grep -qx "${setting%%=*}:BOOL=${setting#*=}" "$build/CMakeCache.txt"; then
    cmake -S "$top" -B "$build" "${kept[@]}" >&2
    break
  fi
done
targets=()
for t in "$@"; do targets+=(--target "$t"); done
start=$SECONDS
cmake --build "$build" -j "$(nproc)" "${targets[@]}" >&2
echo "build.sh: built ${*:-everything} in $((SECONDS - start)) s" >&2
echo "$build"
