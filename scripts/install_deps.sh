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
  build-essential cmake pkg-config ninja-build  # ninja: scripts/generator.sh
  libeigen3-dev libopencv-core-dev libopencv-imgproc-dev libpng-dev libdeflate-dev
  libopenni2-dev libv4l-dev libusb-1.0-0-dev
  libjpeg62-turbo-dev  # MJPEG cameras and JPEG images in TUM folders (optional at build time)
  libwebsocketpp-dev libasio-dev  # the viewer's server (plumb run --serve, plumb view; header-only)
)
# Tests, benchmarks and the Python module.
TEST_PACKAGES=(
  libopencv-dev libopencv-contrib-dev  # oracles in tests (imgcodecs, features2d), stock-OpenCV bench
  libgtest-dev libbenchmark-dev
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest
  valgrind  # ctest instruction_budget (bench/instructions/; skipped without it)
  libceres-dev  # plumb_bench_solver's and plumb_test_solver_ceres's oracle (never linked by the product)
  clang libclang-rt-14-dev  # fuzz targets (scripts/fuzz.sh): libFuzzer is in libclang-rt-14-dev
  clang-tidy  # scripts/tidy.sh: bugprone and naming checks of .clang-tidy
  nodejs npm  # tests/mavlink_node, tests/viewer_node (pinned npm packages); builds the viewer page
  chromium    # the viewer page test (ctest viewer_page, headless, driven by playwright-core)
  # the virtual-machine camera bench (scripts/vm_camera_test.sh, ctest vm_camera).
  # The guest kernel (linux-image-amd64's linux-image-6.1.*), its linux-headers and the
  # v4l2loopback-dkms source are fetched by that script with `apt-get download` and unpacked into
  # the build folder, never installed: they always match each other, and installing the dkms
  # package would build a module for the host's kernels. gcc-12 and make (build-essential) build
  # v4l2loopback; udev provides the udevd that carries hot-plug events to libusb in the guest.
  qemu-system-x86 busybox-static kmod cpio udev
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

# npm packages, each folder pinned by its package-lock.json (npm ci), where npm is installed:
#   product: viewer/web (three.js and esbuild: the viewer page is bundled into `plumb` at build
#            time; without npm `plumb` has no page and Foxglove/Lichtblick still work);
#   tests:   tests/mavlink_node (node-mavlink: the independent MAVLink decoder), tests/viewer_node
#            (@foxglove/ws-protocol, playwright-core, ws: the viewer's real-client tests).
here="$(cd "$(dirname "$0")/.." && pwd)"
npm_ci() {  # FOLDER MARKER_FILE
  if [ ! -f "$here/$1/node_modules/$2" ]; then
    npm ci --prefix "$here/$1" --no-audit --no-fund
  fi
}
if command -v npm >/dev/null 2>&1; then
  npm_ci viewer/web three/package.json
  if [ "$with_tests" = 1 ]; then
    npm_ci tests/mavlink_node node-mavlink/package.json
    npm_ci tests/viewer_node playwright-core/package.json
  fi
else
  echo "install_deps: npm not found: plumb is built without its viewer page (Foxglove still works;" \
       "install_deps.sh --tests installs nodejs and npm)"
fi
