#!/usr/bin/env bash
# Quick start 2: install what is missing, build, run every test:
#   1. the Release build and its whole ctest suite;
#   2. platform/ and runtime/ tests again under ThreadSanitizer (lock-free code).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=$(nproc 2>/dev/null || echo 2)
bash scripts/install_deps.sh
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j "$JOBS" --timeout 900

echo "== ThreadSanitizer: platform/ and runtime/ =="
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPLUMB_TSAN_ONLY=ON \
  -DPLUMB_SANITIZE=thread >/dev/null
cmake --build build-tsan -j "$JOBS"
TSAN_OPTIONS="halt_on_error=1" ctest --test-dir build-tsan --output-on-failure -j "$JOBS" --timeout 600
