#!/usr/bin/env bash
# Quick start 1: install what the product needs, build the `plumb` tool alone, run the demo on the
# built-in synthetic scenes (no download). Tests and benchmarks are not built here (scripts/test.sh
# installs their packages and builds them).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
JOBS=$(nproc 2>/dev/null || echo 2)
bash scripts/install_deps.sh
source scripts/generator.sh
plumb_generator_args build
cmake -S . -B build "${generator_args[@]}" -DCMAKE_BUILD_TYPE=Release -DPLUMB_BUILD_TESTS=OFF -DPLUMB_BUILD_BENCH=OFF \
  -DPLUMB_PYTHON=OFF >/dev/null
cmake --build build -j "$JOBS" --target plumb
built=$(date +%s)
./build/bin/plumb demo "$@"
end=$(date +%s)
echo "demo.sh: install + build $((built - start)) s, demo $((end - built)) s, total $((end - start)) s"
