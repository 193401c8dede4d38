#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer sweep: configure and build the `asan` preset
# (build-asan/, Debug, -fsanitize=address,undefined) and run every test binary under it.
#
#   bash scripts/sanitize.sh                  # all areas
#   bash scripts/sanitize.sh pipeline system  # only these areas
#   JOBS=1 nice -n 19 bash scripts/sanitize.sh
#   PRESET=asan-fast bash scripts/sanitize.sh # -O1 with asserts kept: the slow system tests in
#                                             # minutes instead of hours (Debug OpenCV/Eigen at -O0)
#
# Each area's binary runs once as a whole (not one process per test through ctest) because
# sanitizer start-up and Debug OpenCV/Eigen are slow; $JOBS binaries run side by side. Leaks are reported (detect_leaks=1), and
# the first UB report ends the binary (halt_on_error=1) so it cannot scroll by unnoticed.
# Exit status: 0 only if every binary passed. Full logs: build-<preset>/sanitize-logs/<area>.log.
set -uo pipefail
cd "$(dirname "$0")/.."

JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
PRESET=${PRESET:-asan}
BUILD_DIR=build-${PRESET}
ALL_AREAS=(platform runtime solver pipeline drivers api tools viewer system)
if [ "$#" -gt 0 ]; then AREAS=("$@"); else AREAS=("${ALL_AREAS[@]}"); fi

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# Known third-party leaks only (Debian's OpenNI2 drivers); the file says why each is there.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan_suppressions.txt:print_suppressions=0}

start=$(date +%s)
source scripts/generator.sh
plumb_generator_args "$BUILD_DIR"
cmake --preset "$PRESET" "${generator_args[@]}" >/dev/null || exit 1
targets=()
for area in "${AREAS[@]}"; do
  targets+=("plumb_test_${area}")
  # tools/system tests run the built `plumb` tool, so build it with them.
  case "$area" in tools | system) targets+=(plumb) ;; esac
done
cmake --build "$BUILD_DIR" -j "$JOBS" --target "${targets[@]}" || exit 1
built=$(date +%s)

logs=$BUILD_DIR/sanitize-logs
mkdir -p "$logs"
# The binaries run $JOBS at a time (each is mostly one thread; ctest already runs tests of different
# binaries side by side, so they share no files or ports), the longest first, so that the sweep
# takes about half the serial time on 2 cores. Summaries are printed in area order afterwards.
run_area() {
  local area=$1 t0 rc
  t0=$(date +%s)
  # The working directory is the build dir, as for ctest (tests find ../shared by absolute path).
  (cd "$BUILD_DIR" && "./bin/plumb_test_${area}") >"$logs/${area}.log" 2>&1
  rc=$?
  echo "$rc $(($(date +%s) - t0))" >"$logs/${area}.status"
}
longest_first=()
for area in system tools pipeline drivers api solver viewer runtime platform; do
  for wanted in "${AREAS[@]}"; do [ "$wanted" = "$area" ] && longest_first+=("$area"); done
done
for wanted in "${AREAS[@]}"; do
  case " ${longest_first[*]} " in *" $wanted "*) ;; *) longest_first+=("$wanted") ;; esac
done
rm -f "$logs"/*.status
for area in "${longest_first[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  run_area "$area" &
done
wait
failed=()
for area in "${AREAS[@]}"; do
  log="$logs/${area}.log"
  echo "== ASan+UBSan: plumb_test_${area} =="
  rc=1 secs=?
  [ -f "$logs/${area}.status" ] && read -r rc secs <"$logs/${area}.status"
  # The gtest summary lines plus any sanitizer report headline.
  grep -E '^\[  (PASSED|SKIPPED|FAILED) +\]|test suites? ran|ERROR: (Address|Leak)Sanitizer|runtime error:' \
    "$log" | head -30
  echo "   exit ${rc}, ${secs} s, log ${log}"
  [ "$rc" -eq 0 ] || failed+=("$area")
done
end=$(date +%s)
echo "== build $((built - start)) s, tests $((end - built)) s, total $((end - start)) s =="
if [ "${#failed[@]}" -gt 0 ]; then
  echo "FAILED: ${failed[*]}"
  exit 1
fi
echo "all ${#AREAS[@]} binaries passed under ASan+UBSan"
