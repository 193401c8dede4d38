#!/usr/bin/env bash
# Accuracy under CPU load (issue 13): RUNS runs each of --mode fast and --mode realtime on a
# sequence while a competing CPU-bound process (one busy loop per core, normal priority) runs, and
# the single-threaded (deterministic) ATE for reference. Prints min/median/max ATE and drops, and
# how many fast runs wrote the single-threaded trajectory byte for byte (by design: all of them).
#   scripts/load_accuracy.sh [DATASET] [RUNS]     (default: ../shared/datasets/tum_fr1_rpy_head250, 10)
set -euo pipefail
cd "$(dirname "$0")/.."
DATASET=${1:-../shared/datasets/tum_fr1_rpy_head250}
RUNS=${2:-10}
PLUMB=${PLUMB:-build/bin/plumb}
GT="$DATASET/groundtruth.txt"
[ -x "$PLUMB" ] || { echo "load_accuracy: $PLUMB not built (bash scripts/build.sh)"; exit 1; }
[ -f "$GT" ] || { echo "load_accuracy: $GT not found"; exit 1; }
OUT=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$OUT"' EXIT

ate_of() { sed -n 's/^ATE RMSE \([0-9.]*\) m$/\1/p' "$1"; }
drops_of() { sed -n "s/.*dropped \([0-9]*\), late \([0-9]*\),.*/\1 \2/p" "$1" | head -1 | awk "{print \$1 + \$2}"; }
summary() {  # name file-with-one-number-per-line
  sort -g "$2" | awk -v name="$1" '{a[NR]=$1} END {
    if (NR == 0) { printf "%-22s no runs\n", name; exit }
    med = (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2
    printf "%-22s min %.4f  median %.4f  max %.4f  (%d runs)\n", name, a[1], med, a[NR], NR }'
}

"$PLUMB" run --dataset "$DATASET" --out "$OUT/single.txt" --gt "$GT" > "$OUT/single.log" 2>&1
single=$(ate_of "$OUT/single.log")
echo "single-threaded (deterministic, no load): ATE $single m"

# The competitor: one busy loop per core at the same priority as plumb.
for _ in $(seq "$(nproc)"); do (while :; do :; done) & done
for mode in fast realtime; do
  : > "$OUT/$mode.ate"; : > "$OUT/$mode.drops"; : > "$OUT/$mode.same"
  for i in $(seq "$RUNS"); do
    "$PLUMB" run --dataset "$DATASET" --out "$OUT/$mode.txt" --gt "$GT" --mode "$mode" > "$OUT/$mode.log" 2>&1 || true
    a=$(ate_of "$OUT/$mode.log"); d=$(drops_of "$OUT/$mode.log")
    same=no; cmp -s "$OUT/single.txt" "$OUT/$mode.txt" && same=yes && echo >> "$OUT/$mode.same"
    echo "  $mode run $i: ATE ${a:-none} m, dropped+late ${d:-?}, trajectory identical to single-threaded: $same"
    [ -z "$a" ] && sed -n 's/^plumb run: /    /p' "$OUT/$mode.log" | head -2
    [ -n "$a" ] && echo "$a" >> "$OUT/$mode.ate"
    echo "${d:-0}" >> "$OUT/$mode.drops"
  done
done
kill $(jobs -p) 2>/dev/null || true
echo
echo "under load ($(nproc) competing busy loops), $RUNS runs per mode:"
summary "fast ATE [m]" "$OUT/fast.ate"
summary "realtime ATE [m]" "$OUT/realtime.ate"
summary "realtime dropped+late" "$OUT/realtime.drops"
echo "fast runs byte-identical to single-threaded: $(wc -l < "$OUT/fast.same")/$RUNS"
awk -v s="$single" 'BEGIN { printf "reference single-threaded ATE %.4f m: fast median must be <= %.4f, max <= %.4f\n", s, s*1.15, s*1.5 }'
