#!/usr/bin/env bash
# The NEES study of docs/UNCERTAINTY.md: mean NEES per dof of every published covariance.
#  - Monte Carlo: plumb_nees_study over SEEDS seeds of synth:textured (and a fifth of that of
#    synth:low_texture, synth:office_loop and synth:office_pass) with the renderer's Kinect-like noise, exact ground truth, two processes;
#  - real: TUM fr1/rpy head250 (whole, and its two halves: the first calibrated the
#    rolling-shutter terms, the second checks them) and fr1/desk first9, motion-capture truth,
#    through `plumb run --covariance --track-covariance --output-delay 0 --no-loops` and
#    `plumb eval --nees --json`. Skipped with a note when ../shared/datasets is absent.
# Prints a Markdown table. usage: scripts/nees_study.sh [build dir] [seeds (50)] [frames (150)]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
SEEDS=${2:-50}
FRAMES=${3:-150}
PLUMB="$BUILD/bin/plumb"
STUDY="$BUILD/bin/plumb_nees_study"
DATA=${PLUMB_DATASETS_DIR:-../shared/datasets}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for tool in "$PLUMB" "$STUDY"; do
  [ -x "$tool" ] || { echo "missing $tool: build it first (cmake --build $BUILD --target plumb plumb_nees_study)" >&2; exit 1; }
done

row() {  # name, then the three "NEES/dof (inside 95%)" cells
  echo "| $1 | $2 | $3 | $4 |"
}

# Monte Carlo: the pooled lines of plumb_nees_study ("keyframe_relative n N NEES/dof X ... inside 95% Y%").
monte_carlo() {  # preset seeds
  local preset=$1 seeds=$2 half=$(( $2 / 2 ))
  "$STUDY" --preset "$preset" --seeds "$half" --first-seed 1 --frames "$FRAMES" > "$OUT/$preset.a" &
  "$STUDY" --preset "$preset" --seeds $(( seeds - half )) --first-seed $(( half + 1 )) --frames "$FRAMES" > "$OUT/$preset.b"
  wait
  local cells=()
  for q in keyframe_relative tracked_world frame_motion; do
    cells+=("$(cat "$OUT/$preset.a" "$OUT/$preset.b" | awk -v q="$q" '$1 == q {n += $3; s += $3 * $5; i += $3 * $(NF)} END {gsub(/%/, "", i); printf "%.3f (%.0f%%, n %d)", s / n, i / n, n}')")
  done
  row "synth:$preset, $seeds seeds x $FRAMES frames" "${cells[@]}"
}

# Real data: one run, NEES from plumb eval --json.
real() {  # name dataset-folder
  local name=$1 dir=$2
  "$PLUMB" run --dataset "$dir" --camera tum1 --out "$OUT/t.txt" --output-delay 0 --no-loops \
    --covariance "$OUT/c.txt" --track-covariance "$OUT/tc.txt" > /dev/null 2>&1
  "$PLUMB" eval --gt "$dir/groundtruth.txt" --est "$OUT/t.txt" --covariance "$OUT/c.txt" \
    --track-covariance "$OUT/tc.txt" --nees --json > "$OUT/e.json"
  local cells=()
  for q in keyframe_relative tracked_world frame_motion; do
    cells+=("$(python3 -c "import json,sys; s=json.load(open(sys.argv[1]))['nees'][sys.argv[2]]; print('%.3f (%.0f%%, n %d)' % (s['mean_per_dof'], 100 * s['inside_95'], s['count']) if s['count'] else '-')" "$OUT/e.json" "$q")")
  done
  row "$name" "${cells[@]}"
}

# A half of a TUM folder: the same images (links), the first or last N associations.
half() {  # source which(head|tail) count dest
  mkdir -p "$4"
  ln -s "$(cd "$1" && pwd)/rgb" "$4/rgb"
  ln -s "$(cd "$1" && pwd)/depth" "$4/depth"
  ln -s "$(cd "$1" && pwd)/groundtruth.txt" "$4/groundtruth.txt"
  "$2" -n "$3" "$1/associations.txt" > "$4/associations.txt"
  awk '{print $1, $2}' "$4/associations.txt" > "$4/rgb.txt"
  awk '{print $3, $4}' "$4/associations.txt" > "$4/depth.txt"
}

echo "| sequence | keyframe-to-keyframe (BA joint marginal) | tracked pose (MAVLink) | frame-to-frame motion (MAVLink velocity) |"
echo "|---|---|---|---|"
monte_carlo textured "$SEEDS"
monte_carlo low_texture $(( SEEDS > 10 ? SEEDS / 5 : 2 ))
# The office scenes (long straight edges: the line-rich case of issue 20).
monte_carlo office_loop $(( SEEDS > 10 ? SEEDS / 5 : 2 ))
monte_carlo office_pass $(( SEEDS > 10 ? SEEDS / 5 : 2 ))
RPY="$DATA/tum_fr1_rpy_head250"
DESK="$DATA/tum_fr1_desk_first9"
if [ -d "$RPY" ]; then
  real "fr1/rpy head250" "$RPY"
  half "$RPY" head 125 "$OUT/rpy_a"
  half "$RPY" tail 125 "$OUT/rpy_b"
  real "fr1/rpy head250 frames 0-124 (calibration)" "$OUT/rpy_a"
  real "fr1/rpy head250 frames 125-249 (check)" "$OUT/rpy_b"
else
  echo "(fr1/rpy head250 not found under $DATA: real rows skipped)"
fi
if [ -d "$DESK" ]; then real "fr1/desk first9" "$DESK"; fi
echo "Cells: mean NEES per dof (share inside the 95% ellipsoid, samples). Target: synthetic 0.8-1.25, real 0.5-2."
