#!/usr/bin/env bash
# Installs every Debian package SpriteStation needs to build, test and run.
# Idempotent: packages already present are left alone; safe to run on every build.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkgconf ccache git
  # the style check (scripts/check-style.sh): Debian 12's clang-format and clang-tidy (14)
  clang-format clang-tidy
  # vision and geometry
  libopencv-dev libopencv-contrib-dev libeigen3-dev
  libmrcal-dev mrcal
  # cameras
  libaravis-dev aravis-tools libusb-1.0-0-dev libv4l-dev libcamera-dev
  # recordings (FFmpeg's libraries; the ffmpeg CLI makes test videos and runs benchmarks)
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libavfilter-dev ffmpeg
  # real footage for the import tests (tests/e2e/import_*): OpenCV's sample videos,
  # vtest.avi (a fixed camera over people walking), Apache-2.0 / BSD-3-Clause
  opencv-doc
  # storage, config, CLI, logging, HTTP
  libsqlite3-dev sqlite3 libpq-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libspdlog-dev libfmt-dev libcpp-httplib-dev libsystemd-dev libpng-dev libzstd-dev
  # tests and benchmarks; clang and its runtimes for the libFuzzer targets (scripts/fuzz.sh)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # the PostgreSQL bank (libpq) and, for its tests, the server: each test starts a private
  # one (initdb in /tmp, a free port of 127.0.0.1; tests/support/postgres_server.h)
  postgresql
  # the daemon tests give each test a private loopback with a second address (ip), and
  # check /metrics with Prometheus's own promtool
  iproute2 prometheus
  # the console's browser tests (web/tests): Debian's Chromium driven by playwright-core
  # under node's test runner (npm installs playwright-core below; it downloads no browser)
  chromium nodejs
)
# Optional: the `vivid` CTest test boots Debian's kernel under qemu to run the
# V4L2 backend against the vivid driver (it skips without these). Set
# SPRITESTATION_NO_VIVID=1 to leave them out (the kernel package takes minutes).
if [ "${SPRITESTATION_NO_VIVID:-0}" != "1" ]; then
  PACKAGES+=(linux-image-amd64 qemu-system-x86 busybox-static)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
else
  echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
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
