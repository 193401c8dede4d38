#!/usr/bin/env bash
# Installs the Debian (bookworm) packages plumb needs, only those that are missing.
# Run as root (or with sudo available). Safe to run again: does nothing when all are present.
set -euo pipefail
PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libopencv-dev libopencv-contrib-dev libpng-dev libdeflate-dev
  libopenni2-dev libv4l-dev libusb-1.0-0-dev
  libjpeg62-turbo-dev
  libwebsocketpp-dev libasio-dev  # product: the viewer's server (plumb run --serve, plumb view; header-only)
  chromium                        # test: the viewer page test (ctest viewer_page, headless)
  libgtest-dev libbenchmark-dev
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest
  valgrind
  clang libclang-rt-14-dev  # fuzz targets (scripts/fuzz.sh): libFuzzer is in libclang-rt-14-dev
)
# libjpeg62-turbo-dev: MJPEG cameras and JPEG images in TUM folders (optional at build time).
# valgrind: ctest instruction_budget (bench/instructions/; skipped without it).
# node and npm (product: build the viewer page; test: tests/*_node) from Debian only when the
# machine has none: a node installed otherwise (with its own npm) is used as it is.
if ! command -v npm >/dev/null 2>&1; then PACKAGES+=(nodejs npm); fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all packages present"
else
  echo "install_deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# npm packages, each folder pinned by its package-lock.json (npm ci), where npm is installed:
#   product: viewer/web (three.js and esbuild: the viewer page is bundled into `plumb` at build
#            time; without them `plumb` has no page, Foxglove still works);
#   test:    tests/mavlink_node (node-mavlink: the independent MAVLink decoder), tests/viewer_node
#            (@foxglove/ws-protocol, playwright-core, ws: the viewer's real-client tests).
# Without npm those tests skip.
here="$(cd "$(dirname "$0")/.." && pwd)"
npm_ci() {  # FOLDER MARKER_FILE
  if [ ! -f "$here/$1/node_modules/$2" ]; then
    npm ci --prefix "$here/$1" --no-audit --no-fund
  fi
}
if command -v npm >/dev/null 2>&1; then
  npm_ci viewer/web three/package.json
  npm_ci tests/mavlink_node node-mavlink/package.json
  npm_ci tests/viewer_node playwright-core/package.json
else
  echo "install_deps: npm not found: no viewer page, and the MAVLink decoder and viewer client tests will skip" \
       "(Debian: apt-get install nodejs npm)"
fi
