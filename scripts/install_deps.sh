#!/usr/bin/env bash
# Installs the Debian (bookworm) packages plumb needs, only those that are missing.
# Run as root (or with sudo available). Safe to run again: does nothing when all are present.
set -euo pipefail
PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libopencv-dev libopencv-contrib-dev libpng-dev libdeflate-dev
  libopenni2-dev libv4l-dev libusb-1.0-0-dev
  libjpeg62-turbo-dev
  libgtest-dev libbenchmark-dev
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest
  valgrind
  clang libclang-rt-14-dev  # fuzz targets (scripts/fuzz.sh): libFuzzer is in libclang-rt-14-dev
  # test/bench: the virtual-machine camera bench (scripts/vm_camera_test.sh, ctest vm_camera).
  # The guest kernel (linux-image-amd64's linux-image-6.1.*), its linux-headers and the
  # v4l2loopback-dkms source are fetched by that script with `apt-get download` and unpacked into
  # the build folder, never installed: they always match each other, and installing the dkms
  # package would build a module for the host's kernels. gcc-12 and make (build-essential) build
  # v4l2loopback; udev provides the udevd that carries hot-plug events to libusb in the guest.
  qemu-system-x86 busybox-static kmod cpio udev
)
# libjpeg62-turbo-dev: MJPEG cameras and JPEG images in TUM folders (optional at build time).
# valgrind: ctest instruction_budget (bench/instructions/; skipped without it).
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
# The independent MAVLink decoder of tests/mavlink_node (npm's node-mavlink, pinned by its
# package-lock.json), where npm is installed; without it those tests skip.
here="$(cd "$(dirname "$0")/.." && pwd)"
if command -v npm >/dev/null 2>&1; then
  if [ ! -f "$here/tests/mavlink_node/node_modules/node-mavlink/package.json" ]; then
    npm ci --prefix "$here/tests/mavlink_node" --no-audit --no-fund
  fi
else
  echo "install_deps: npm not found: the MAVLink decoder tests will skip (Debian: apt-get install nodejs npm)"
fi
