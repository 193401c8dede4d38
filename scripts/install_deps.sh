#!/usr/bin/env bash
# Installs the Debian (bookworm) packages plumb needs, only those that are missing.
# Run as root (or with sudo available). Safe to run again: does nothing when all are present.
set -euo pipefail
PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libopencv-dev libopencv-contrib-dev libpng-dev libdeflate-dev
  libopenni2-dev libv4l-dev libusb-1.0-0-dev
  libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev  # fuzz targets (scripts/fuzz.sh): libFuzzer is in libclang-rt-14-dev
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
