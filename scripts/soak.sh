#!/usr/bin/env bash
# Soak test (issue 13): `plumb run --mode realtime` on a looped synthetic scene, paced at 30 Hz,
# for MINUTES minutes (default 60; CI runs 5), with a line per block of frames (5 minutes of them;
# 1 minute for runs shorter than 15 minutes): sensor-to-pose p50/p99/max, drops and resident memory. At the end it checks that RSS stayed flat
# (last block within 1 MiB of the first) and p99 of EVERY block within 20% of the first block, and exits 1 if not.
#   scripts/soak.sh [MINUTES] [PRESET]        (default 60, textured)
# RT_PRIORITY (default 20; 0 = normal scheduling) runs the capture, extract and track threads
# SCHED_FIFO, as on a robot whose CPU also serves other work (the map and loop stages stay normal
# priority, niced); plumb falls back with a warning where that is not permitted.
set -euo pipefail
cd "$(dirname "$0")/.."
MINUTES=${1:-60}
PRESET=${2:-textured}
PLUMB=${PLUMB:-build/bin/plumb}
RT_PRIORITY=${RT_PRIORITY:-20}
FPS=30
BLOCK_S=300
[ "$MINUTES" -lt 15 ] && BLOCK_S=60
BLOCK=$((BLOCK_S * FPS))             # tracked frames per block (frames dropped in real time do not count)
FRAMES=$((MINUTES * 60 * FPS))
[ -x "$PLUMB" ] || { echo "soak: $PLUMB not built (bash scripts/build.sh)"; exit 1; }
LOG=$(mktemp)
trap 'rm -f "$LOG"' EXIT
echo "soak: $MINUTES min of synth:$PRESET (looped path, Kinect-like noise), realtime at $FPS Hz, block $BLOCK frames, rt priority $RT_PRIORITY"
# The scene's camera path is periodic, so any frame count replays the same room over and over.
# --rss-every: poses are not kept in memory for an ATE at the end (an hour of them is ~16 MB, which
# an earlier soak showed as RSS growing ~1.6 MiB per block); the trajectory is discarded.
"$PLUMB" run --dataset "synth:$PRESET:1:$FRAMES" --synth-noise --mode realtime --discard-trajectory \
  --report-every "$BLOCK" --rss-every "$BLOCK" --output-delay 0 --rt-priority "$RT_PRIORITY" | tee "$LOG"
awk '/^block / {
       for (i = 1; i <= NF; ++i) { if ($i == "p99") p99 = $(i+1); if ($i == "rss") rss = $(i+1); if ($i == "dropped") d = $(i+1) }
       n++; if (n == 1) { p0 = p99; r0 = rss }
       if (p99 > 1.2 * p0) { over++; if (p99 > worst) worst = p99 }
       last_p = p99; last_r = rss; drops += d }
     END {
       if (n == 0) { print "soak: no block reported"; exit 1 }
       ok = (last_r - r0 <= 1024) && over == 0
       printf "soak: %d blocks; RSS first %d KiB, last %d KiB (%+d); p99 first %.2f ms, last %.2f ms, %d block(s) above 1.2x the first (worst %.2f ms); drops %d: %s\n",
              n, r0, last_r, last_r - r0, p0, last_p, over, worst, drops, ok ? "FLAT" : "NOT FLAT"
       exit ok ? 0 : 1 }' "$LOG"
