#!/usr/bin/env bash
# The registration table (docs/SYNTHETIC.md "Unregistered depth", issue 21): for each preset and
# seed, the ATE of `plumb run` on three versions of one synthetic scene with Kinect-like noise:
#   registered   depth rendered from the colour camera (what every preset delivers);
#   with reg.    depth rendered from a depth camera 2.5 cm beside it (`plumb synth --depth-camera
#                offset`), whose camera.txt describes that camera: plumb registers each frame;
#   without      the same offset depth read under a camera file without the depth camera, i.e.
#                used as if it were registered (what happens when the calibration is missing).
# Colour images and ground truth are identical in all three. Also prints the register stage's
# mean wall milliseconds per frame (from --stats: a loaded machine inflates it; `plumb bench
# frontend --clock cpu` measures CPU time). POINTS_ONLY=1 adds the two offset runs with --no-lines
# (points-only against points+lines, with and without registration).
#   scripts/registration_table.sh [PRESETS] [SEEDS] [FRAMES]
#     (default: "textured low_texture fast_rotation" "1 2 3" 300; PLUMB=build/bin/plumb)
set -euo pipefail
cd "$(dirname "$0")/.."
PRESETS=${1:-textured low_texture fast_rotation}
SEEDS=${2:-1 2 3}
FRAMES=${3:-300}
PLUMB=${PLUMB:-build/bin/plumb}
[ -x "$PLUMB" ] || { echo "registration_table: $PLUMB not built (bash scripts/build.sh)"; exit 1; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
NOISE="--depth-noise --holes --pixel-noise 1"  # what `plumb run --synth-noise` adds

ate_of() { sed -n 's/^ATE RMSE \([0-9.]*\) m$/\1/p' "$1"; }
# Mean milliseconds of the register stage in a --stats file ("-" when the run did not register).
register_ms_of() { python3 -c 'import json,sys; t=json.load(open(sys.argv[1]))["ms_per_frame"]; print("%.2f" % t["register"]["mean"] if "register" in t else "-")' "$1"; }
run() {  # name dataset [plumb run options...]
  local name=$1 dataset=$2; shift 2
  "$PLUMB" run --dataset "$dataset" --gt "$dataset/groundtruth.txt" --out "$WORK/$name.txt" \
    --stats "$WORK/$name.json" "$@" > "$WORK/$name.log" 2>&1 || { echo "run $name failed:"; tail -3 "$WORK/$name.log"; }
}

POINTS_ONLY=${POINTS_ONLY:-0}
if [ "$POINTS_ONLY" = 1 ]; then
  printf '| preset | seed | registered ATE | with registration ATE | without registration ATE | with reg., points only | without reg., points only | register ms/frame (wall) |\n'
  printf '|---|---|---|---|---|---|---|---|\n'
else
  printf '| preset | seed | registered ATE | with registration ATE | without registration ATE | register ms/frame (wall) |\n'
  printf '|---|---|---|---|---|---|\n'
fi
for preset in $PRESETS; do
  for seed in $SEEDS; do
    reg="$WORK/reg_${preset}_$seed" off="$WORK/off_${preset}_$seed"
    # shellcheck disable=SC2086
    "$PLUMB" synth --preset "$preset" --seed "$seed" --frames "$FRAMES" $NOISE --out "$reg" > /dev/null
    # shellcheck disable=SC2086
    "$PLUMB" synth --preset "$preset" --seed "$seed" --frames "$FRAMES" $NOISE --depth-camera offset --out "$off" > /dev/null
    # The colour camera alone: the offset folder's camera.txt without the depth camera's keys.
    grep -v -E '^depth_(fx|fy|cx|cy|k1|k2|p1|p2|k3|width|height|to_colour_)' "$off/camera.txt" > "$WORK/colour_only.txt"
    run "r_$preset$seed" "$reg"
    run "w_$preset$seed" "$off"
    run "n_$preset$seed" "$off" --camera "$WORK/colour_only.txt"
    points_only=""
    if [ "$POINTS_ONLY" = 1 ]; then
      run "wp_$preset$seed" "$off" --no-lines
      run "np_$preset$seed" "$off" --camera "$WORK/colour_only.txt" --no-lines
      points_only="$(ate_of "$WORK/wp_$preset$seed.log") | $(ate_of "$WORK/np_$preset$seed.log") | "
    fi
    printf '| %s | %s | %s | %s | %s | %s%s |\n' "$preset" "$seed" \
      "$(ate_of "$WORK/r_$preset$seed.log")" "$(ate_of "$WORK/w_$preset$seed.log")" \
      "$(ate_of "$WORK/n_$preset$seed.log")" "$points_only" "$(register_ms_of "$WORK/w_$preset$seed.json")"
    rm -rf "$reg" "$off"
  done
done
