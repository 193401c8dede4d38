#!/usr/bin/env bash
# Quick start 1: install what is missing, build, run the demo on the built-in synthetic scenes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
./build/bin/plumb demo "$@"
