#!/usr/bin/env bash
# Builds every libFuzzer target (fuzz/, clang + ASan + UBSan) into build-fuzz and runs each for
# SECONDS (default 60) on a temporary copy of its seed corpus (fuzz/corpus/<target>/; the tree is
# not modified), with fuzz/dict/<target>.dict when there is one. Prints per target: executions,
# exec/s, coverage (cov: edges, ft: features), corpus size, and any crash (its input is kept in
# build-fuzz/artifacts/<target>/).
# Exit status 1 when any target crashed or broke an invariant, 2 when clang/libFuzzer is missing.
#   scripts/fuzz.sh [SECONDS] [TARGET...]     e.g. scripts/fuzz.sh 600 png_decoder
# FUZZ_SEED=N fixes libFuzzer's random seed (-seed=N): the same inputs in the same order, so a CI
# run that passed on a commit passes again (a faster machine only explores further). Unset: a
# fresh seed per run, for the long runs that look for new findings.
set -uo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-60}
shift || true
ALL_TARGETS=(png_decoder tum_lists camera_file trajectory_reader json_reader recording_reader map_file)
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=("${ALL_TARGETS[@]}")
JOBS=$(nproc 2>/dev/null || echo 2)
CXX_FUZZ=${CXX_FUZZ:-clang++}

# libFuzzer ships with clang (Debian: libclang-rt-NN-dev); check it links before configuring.
probe=$(mktemp -d)
trap 'rm -rf "$probe"' EXIT
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' >"$probe/p.cpp"
if ! "$CXX_FUZZ" -fsanitize=fuzzer,address,undefined "$probe/p.cpp" -o "$probe/p" 2>"$probe/err"; then
  echo "fuzz: $CXX_FUZZ cannot build a libFuzzer target (install clang and libclang-rt-14-dev):" >&2
  head -3 "$probe/err" >&2
  exit 2
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
source scripts/generator.sh
plumb_generator_args build-fuzz
cmake -S fuzz -B build-fuzz "${generator_args[@]}" -DCMAKE_CXX_COMPILER="$CXX_FUZZ" "${launcher[@]}" >/dev/null || exit 1
cmake --build build-fuzz -j "$JOBS" --target "${TARGETS[@]/#/fuzz_}" >/dev/null || exit 1

# The targets run $JOBS at a time (each fuzzer is one process on one core; with FUZZ_SEED a target
# sees the same inputs whichever runs beside it), and are reported in the order above.
run_target() {
  local t=$1 work="$probe/$1"
  mkdir -p "$work/corpus" "build-fuzz/artifacts/$t"
  cp fuzz/corpus/"$t"/* "$work/corpus/"
  local extra=()  # dictionary, seed
  [ -f "fuzz/dict/$t.dict" ] && extra=(-dict="fuzz/dict/$t.dict")
  [ -n "${FUZZ_SEED:-}" ] && extra+=(-seed="$FUZZ_SEED")
  ./build-fuzz/fuzz_"$t" -max_total_time="$SECONDS_PER_TARGET" -print_final_stats=1 -timeout=10 \
    "${extra[@]}" -artifact_prefix="build-fuzz/artifacts/$t/" "$work/corpus" >"$work/log" 2>&1
  echo $? >"$work/rc"
}
for t in "${TARGETS[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  run_target "$t" &
done
wait
failed=0
printf '%-18s %12s %8s %7s %7s %7s  %s\n' target executions exec/s cov ft corpus result
for t in "${TARGETS[@]}"; do
  work="$probe/$t"
  rc=1
  [ -f "$work/rc" ] && rc=$(cat "$work/rc")
  # The last status line ("#N DONE cov: C ft: F corp: K/B ...") holds the final coverage.
  status=$(grep -E '^#[0-9]+' "$work/log" | tail -1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")
  corp=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<<"$status")
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/log")
  [ -z "$execs" ] && execs=$(sed -n 's/^#\([0-9]*\).*/\1/p' <<<"$status")
  result=ok
  if [ "$rc" -ne 0 ]; then
    failed=1
    crash=$(ls -t "build-fuzz/artifacts/$t/" 2>/dev/null | head -1)
    result="CRASH (rc $rc) build-fuzz/artifacts/$t/$crash"
  fi
  printf '%-18s %12s %8s %7s %7s %7s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$result"
  if [ "$rc" -ne 0 ]; then
    grep -E 'INVARIANT|ERROR:|SUMMARY|runtime error|==[0-9]+==' "$work/log" | head -8 | sed 's/^/    /'
  fi
done
exit $failed
