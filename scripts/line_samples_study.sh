#!/usr/bin/env bash
# The paper's Fig. 8 study: ATE and cost against the number of line-guidance samples per line,
# N = 0 (points only), 2, 3, 5, 7, 10, on TUM fr1/rpy (first 250 frames) and on the synthetic
# low_texture scene with Kinect-like noise. Prints a Markdown table (docs/ODOMETRY.md has one).
#   usage: scripts/line_samples_study.sh [build dir] [low_texture frames]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
FRAMES=${2:-600}
PLUMB="$BUILD/bin/plumb"
RPY=${PLUMB_DATASETS_DIR:-../shared/datasets}/tum_fr1_rpy_head250
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

# Prints "ATE ms_mean" of one run (ATE "-" when it could not be computed).
measure() {
  local log="$OUT/log.txt"
  "$PLUMB" run "$@" --out "$OUT/traj.txt" > "$log" 2>&1
  local ate ms
  ate=$(sed -n 's/^ATE RMSE \([0-9.]*\) m$/\1/p' "$log")
  ms=$(sed -n 's/^ms per frame: mean \([0-9.]*\),.*/\1/p' "$log")
  echo "${ate:--} ${ms:--}"
}

echo "| N samples | fr1/rpy head250 ATE [m] | fr1/rpy ms/frame | low_texture ($FRAMES) ATE [m] | low_texture ms/frame |"
echo "|---|---|---|---|---|"
for n in 0 2 3 5 7 10; do
  if [ -d "$RPY" ]; then
    read -r rpy_ate rpy_ms < <(measure --dataset "$RPY" --camera tum1 --gt "$RPY/groundtruth.txt" --line-samples "$n")
  else
    rpy_ate="n/a"; rpy_ms="n/a"
  fi
  read -r lt_ate lt_ms < <(measure --dataset "synth:low_texture:1:$FRAMES" --synth-noise --line-samples "$n")
  echo "| $n | $rpy_ate | $rpy_ms | $lt_ate | $lt_ms |"
done
