#!/usr/bin/env bash
# clang-tidy over every product source file (platform runtime solver sensor pipeline drivers viewer
# api tools; not tests, benches or fuzz targets), with the checks and naming rules of .clang-tidy,
# warnings as errors. Needs a configured build folder for compile_commands.json (default build/).
# Exit 1 on any finding. ~6 s of CPU per file (the Eigen and OpenCV headers), so ~10 min on 2 cores.
#   scripts/tidy.sh [BUILD_DIR] [FOLDER_REGEX]      e.g. scripts/tidy.sh build 'solver|runtime'
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
FOLDERS=${2:-platform|runtime|solver|sensor|pipeline|drivers|viewer|api|tools}
JOBS=$(nproc 2>/dev/null || echo 2)
if ! command -v run-clang-tidy >/dev/null 2>&1; then
  echo "tidy: run-clang-tidy not found (scripts/install_deps.sh --tests installs clang-tidy)" >&2
  exit 2
fi
if [ ! -f "$BUILD/compile_commands.json" ]; then
  echo "tidy: $BUILD/compile_commands.json missing: configure with scripts/build.sh first" >&2
  exit 2
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
start=$(date +%s)
status=0
run-clang-tidy -p "$BUILD" -j "$JOBS" -quiet "$(pwd)/($FOLDERS)/.*\.cpp$" >"$log" 2>&1 || status=$?
# Findings, once each (a header's finding repeats for every file that includes it).
findings=$(sed 's/\x1b\[[0-9;]*m//g' "$log" | grep -E '^/.*: (warning|error): ' | sort -u || true)
files=$(grep -c '^.*clang-tidy.*-p=' "$log" || true)
if [ -n "$findings" ]; then
  echo "$findings"
  echo "tidy: $(echo "$findings" | wc -l) finding(s) in $(( $(date +%s) - start )) s"
  exit 1
fi
if [ "$status" -ne 0 ]; then
  tail -20 "$log"
  echo "tidy: run-clang-tidy failed (exit $status)"
  exit 1
fi
echo "tidy: no findings ($(( $(date +%s) - start )) s)"
