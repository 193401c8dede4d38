#!/usr/bin/env bash
# ctest mavlink_node_run: a REAL `plumb run --mavlink udp:...` of 250 frames decoded by npm's
# node-mavlink and compared with the run's own trajectory file (decode_run_check.js). Input: the
# TUM head250 clip when present, else synth:textured:1:250.
# Exit 77 (ctest: skipped) where node or node_modules are absent. Install with:
#   npm ci --prefix tests/mavlink_node --no-audit --no-fund
# Usage: run_decode_run_test.sh PLUMB_BINARY WORK_DIR DATASETS_DIR
set -u
plumb="$1"
workdir="$2"
datasets="$3"
here="$(cd "$(dirname "$0")" && pwd)"
if ! command -v node >/dev/null 2>&1; then
  echo "SKIP mavlink_node_run: node is not installed (Debian: apt-get install nodejs npm)"
  exit 77
fi
if [ ! -f "$here/node_modules/node-mavlink/package.json" ]; then
  echo "SKIP mavlink_node_run: node-mavlink is not installed;" \
       "run: npm ci --prefix tests/mavlink_node --no-audit --no-fund"
  exit 77
fi
dataset="synth:textured:1:250"
if [ -f "$datasets/tum_fr1_rpy_head250/rgb.txt" ]; then dataset="$datasets/tum_fr1_rpy_head250"; fi
rm -rf "$workdir" && mkdir -p "$workdir" || exit 1
exec node "$here/decode_run_check.js" --plumb "$plumb" --dataset "$dataset" --frames 250 --work "$workdir"
