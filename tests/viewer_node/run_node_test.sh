#!/usr/bin/env bash
# Runs one of the viewer's real-client tests (tests/viewer_node/*.js) for ctest.
# Exit 77 (ctest: skipped) where node, the npm packages (npm ci --prefix tests/viewer_node), or
# for the page tests Debian's chromium are absent, or when plumb was built without the viewer.
# Usage: run_node_test.sh SCRIPT.js NEEDS_BROWSER(0|1) PLUMB WORK_DIR
set -u
script="$1"; needs_browser="$2"; plumb="$3"; work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
name="$(basename "$script" .js)"
if ! command -v node >/dev/null 2>&1; then
  echo "SKIP $name: node is not installed (Debian: apt-get install nodejs npm)"; exit 77
fi
if [ ! -f "$here/node_modules/@foxglove/ws-protocol/package.json" ] || [ ! -f "$here/node_modules/playwright-core/package.json" ]; then
  echo "SKIP $name: npm packages missing; run: npm ci --prefix tests/viewer_node --no-audit --no-fund"; exit 77
fi
if [ "$needs_browser" = 1 ] && [ ! -x /usr/bin/chromium ]; then
  echo "SKIP $name: /usr/bin/chromium is not installed (Debian: apt-get install chromium)"; exit 77
fi
if "$plumb" view --out /dev/null --serve 0 2>&1 | grep -q "built without the viewer"; then
  echo "SKIP $name: this plumb was built without the viewer (PLUMB_VIEWER=OFF)"; exit 77
fi
exec node "$here/$script" "$plumb" "$work"
