#!/usr/bin/env bash
# ctest mavlink_node_decode: plumb's MAVLink stream decoded by npm's node-mavlink.
# Exit 77 (ctest: skipped) where node or this folder's node_modules are absent. Install with:
#   npm ci --prefix tests/mavlink_node --no-audit --no-fund
# Usage: run_decode_test.sh SENDER_BINARY WORK_DIR
set -u
sender="$1"
workdir="$2"
here="$(cd "$(dirname "$0")" && pwd)"
if ! command -v node >/dev/null 2>&1; then
  echo "SKIP mavlink_node_decode: node is not installed (Debian: apt-get install nodejs npm)"
  exit 77
fi
if [ ! -f "$here/node_modules/node-mavlink/package.json" ]; then
  echo "SKIP mavlink_node_decode: node-mavlink is not installed;" \
       "run: npm ci --prefix tests/mavlink_node --no-audit --no-fund"
  exit 77
fi
mkdir -p "$workdir" || exit 1
exec node "$here/decode_check.js" --sender "$sender" --frames 250 \
  --expected "$workdir/expected_odometry.txt"
