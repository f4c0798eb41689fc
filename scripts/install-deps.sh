#!/usr/bin/env bash
# Installs the Debian packages SpriteStation needs, in two sets:
#   scripts/install-deps.sh --run   what building and running need (scripts/demo.sh)
#   scripts/install-deps.sh         that and what the test suite adds (scripts/test.sh, CI)
# Idempotent: packages already present are left alone; safe to run on every build.
set -euo pipefail

set_name=all
case "${1:-}" in
  --run) set_name=run ;;
  "") ;;
  *) echo "install-deps: usage: install-deps.sh [--run]" >&2; exit 2 ;;
esac

# Building and running: the compiler, every library the executable links, and what its
# configure step asks for (GoogleTest and Google Benchmark are small, and `spritestation bench`
# is part of the executable).
RUN_PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkgconf ccache git
  # vision and geometry
  libopencv-dev libopencv-contrib-dev libeigen3-dev libmrcal-dev
  # cameras
  libaravis-dev libusb-1.0-0-dev libv4l-dev libcamera-dev
  # recordings (FFmpeg's libraries)
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libavfilter-dev
  # storage, config, CLI, logging, HTTP
  libsqlite3-dev libpq-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libspdlog-dev libfmt-dev libcpp-httplib-dev libsystemd-dev libpng-dev libzstd-dev
  # the configure step's test and benchmark libraries
  libgtest-dev libgmock-dev libbenchmark-dev
  # the demo's reference bank: scripts/reference-banks.sh tags its standing frames with SQL
  sqlite3
)
# What the tests add.
TEST_PACKAGES=(
  # the style check (scripts/check-style.sh): Debian 12's clang-format and clang-tidy (14)
  clang-format clang-tidy
  # clang and its runtimes for the sanitizer build and the libFuzzer targets (scripts/fuzz.sh)
  clang libclang-rt-14-dev
  # mrcal's tools (the calibration tests compare against mrcal-calibrate-cameras), aravis's
  # emulated camera tools, the ffmpeg CLI that checks what we write (sqlite3: in the run set)
  mrcal aravis-tools ffmpeg
  # real footage for the import tests (tests/e2e/import_*): OpenCV's sample videos,
  # vtest.avi (a fixed camera over people walking), Apache-2.0 / BSD-3-Clause
  opencv-doc
  # the PostgreSQL bank's tests start a private server each (initdb in /tmp, a free port of
  # 127.0.0.1; tests/support/postgres_server.h)
  postgresql
  # the daemon tests give each test a private loopback with a second address (ip), and
  # check /metrics with Prometheus's own promtool
  iproute2 prometheus
  # the console's browser tests (web/tests): Debian's Chromium driven by playwright-core
  # under node's test runner (npm installs playwright-core below; it downloads no browser)
  chromium nodejs
)
PACKAGES=("${RUN_PACKAGES[@]}")
if [ "$set_name" = all ]; then
  PACKAGES+=("${TEST_PACKAGES[@]}")
  # Optional: the `vivid` CTest test boots Debian's kernel under qemu to run the
  # V4L2 backend against the vivid driver (it skips without these). Set
  # SPRITESTATION_NO_VIVID=1 to leave them out (the kernel package takes minutes).
  if [ "${SPRITESTATION_NO_VIVID:-0}" != "1" ]; then
    PACKAGES+=(linux-image-amd64 qemu-system-x86 busybox-static)
  fi
fi

# One dpkg-query for all (one each took seconds): the packages installed, then what is missing.
mapfile -t present < <(dpkg-query -W -f='${Package} ${Status}\n' "${PACKAGES[@]}" 2>/dev/null |
  awk '$2 == "install" && $3 == "ok" && $4 == "installed" { print $1 }')
missing=()
for p in "${PACKAGES[@]}"; do
  printf '%s\n' "${present[@]}" | grep -qx "$p" || missing+=("$p")
done

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
start=$SECONDS
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present ($set_name set)"
else
  echo "install-deps: installing ${#missing[@]} packages ($set_name set): ${missing[*]}"
  echo "install-deps: apt-get update"
  $SUDO apt-get update -qq
  # One line a package as it is unpacked and set up: progress a person can follow.
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}" |
    grep --line-buffered -E '^(Get:[0-9]+|Setting up|Need to get|[0-9]+ upgraded)' |
    sed -u -E 's/^Get:([0-9]+) [^ ]+ [^ ]+ [^ ]+ ([^ ]+) .*/  downloading \1: \2/; s/^Setting up ([^ ]+).*/  set up \1/'
  status=("${PIPESTATUS[@]}")
  [ "${status[0]}" -eq 0 ] || { echo "install-deps: apt-get install failed (exit ${status[0]})" >&2; exit 1; }
  echo "install-deps: installed in $((SECONDS - start)) s"
fi
[ "$set_name" = run ] && { echo "install-deps: done"; exit 0; }

# Debian's nodejs comes without npm (NodeSource's includes it).
if ! command -v npm >/dev/null; then
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends npm
fi

# The browser tests' one npm package, pinned by web/tests/package-lock.json.
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tests="$top/web/tests"
if [ -f "$tests/package-lock.json" ] && { [ ! -d "$tests/node_modules/playwright-core" ] ||
   [ "$tests/package-lock.json" -nt "$tests/node_modules/.package-lock.json" ]; }; then
  (cd "$tests" && npm ci --no-audit --no-fund --loglevel=error) || {
    echo "install-deps: npm ci in web/tests failed" >&2; exit 1; }
fi
echo "install-deps: done"
