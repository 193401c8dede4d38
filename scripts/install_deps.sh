#!/usr/bin/env bash
# Installs the Debian (bookworm) packages plumb needs, only those that are missing.
#   bash scripts/install_deps.sh           what the `plumb` tool needs to build and run (the demo)
#   bash scripts/install_deps.sh --tests   that, plus what the tests and benchmarks need (test.sh)
# Run as root (or with sudo available). Safe to run again: does nothing when all are present.
set -euo pipefail
with_tests=0
for arg in "$@"; do
  case "$arg" in
    --tests) with_tests=1 ;;
    *) echo "install_deps: unknown argument '$arg' (usage: install_deps.sh [--tests])" >&2; exit 2 ;;
  esac
done

# The product: a compiler, Eigen, OpenCV core + imgproc only (cmake/plumb_find_opencv.cmake; all of
# libopencv-dev pulls VTK, GDAL, Qt, ... and was most of a 16-minute first run), image codecs and
# the sensor libraries.
PRODUCT_PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libopencv-core-dev libopencv-imgproc-dev libpng-dev libdeflate-dev
  libopenni2-dev libv4l-dev libusb-1.0-0-dev
  libjpeg62-turbo-dev  # MJPEG cameras and JPEG images in TUM folders (optional at build time)
)
# Tests, benchmarks and the Python module.
TEST_PACKAGES=(
  libopencv-dev libopencv-contrib-dev  # oracles in tests (imgcodecs, features2d), stock-OpenCV bench
  libgtest-dev libbenchmark-dev
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest
  valgrind  # ctest instruction_budget (bench/instructions/; skipped without it)
  clang libclang-rt-14-dev  # fuzz targets (scripts/fuzz.sh): libFuzzer is in libclang-rt-14-dev
  nodejs npm  # the independent MAVLink decoder of tests/mavlink_node (node-mavlink, pinned)
)

packages=("${PRODUCT_PACKAGES[@]}")
if [ "$with_tests" = 1 ]; then
  packages+=("${TEST_PACKAGES[@]}")
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm from a non-Debian source (nodesource, nvm) counts as present.
if command -v npm >/dev/null 2>&1; then
  kept=()
  for p in "${missing[@]}"; do
    case "$p" in nodejs|npm) ;; *) kept+=("$p") ;; esac
  done
  missing=("${kept[@]}")
fi
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

if [ "$with_tests" = 1 ]; then
  # node-mavlink for tests/mavlink_node, pinned by its package-lock.json.
  here="$(cd "$(dirname "$0")/.." && pwd)"
  if [ ! -f "$here/tests/mavlink_node/node_modules/node-mavlink/package.json" ]; then
    npm ci --prefix "$here/tests/mavlink_node" --no-audit --no-fund
  fi
fi
