#!/usr/bin/env bash
# Configures and builds all of plumb (Release: the product, tests, benchmarks, the Python module)
# into ./build. Extra args go to cmake configure. Needs `scripts/install_deps.sh --tests`.
# (scripts/demo.sh builds the `plumb` target alone, with the product packages only.)
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=$(nproc 2>/dev/null || echo 2)
source scripts/generator.sh
plumb_generator_args build
cmake -S . -B build "${generator_args[@]}" -DCMAKE_BUILD_TYPE=Release -DPLUMB_BUILD_TESTS=ON -DPLUMB_BUILD_BENCH=ON \
  -DPLUMB_PYTHON=ON "$@" >/dev/null
cmake --build build -j "$JOBS"
