#!/usr/bin/env bash
# Runs each reader's fuzz target for SECONDS (default 60) under ASan + UBSan, seeded with the
# kept findings (fuzz/regressions/<target>/) and the seeds (cases/, fuzz/corpus/<target>/).
# Prints each target's executions per second and total executions; exits 1 on a finding (its
# input is in BUILD/fuzz-findings/: keep it in fuzz/regressions/<target>/ with the fix).
# The targets run side by side, as many at a time as there are cores (FUZZ_JOBS to change it),
# each for SECONDS of wall time on a core of its own: the stage's wall time is about
# SECONDS x ceil(6 / FUZZ_JOBS) (CI: 13 s x 3 rounds on 2 cores, ~40 s).
# Usage: fuzz/run.sh BUILD_DIR [SECONDS]   (BUILD_DIR configured with -DVRELAB_FUZZ=ON)
set -u
build=$1
seconds=${2:-60}
jobs=${FUZZ_JOBS:-$(nproc)}
if ! [[ "$jobs" =~ ^[1-9][0-9]*$ ]]; then echo "fuzz/run.sh: FUZZ_JOBS must be a positive integer, not '$jobs'" >&2; exit 2; fi
src=$(cd "$(dirname "$0")/.." && pwd)
findings="$build/fuzz-findings"
mkdir -p "$findings"
targets=(case_file lab_data series psd_table raw_csv raw_hdf5)
fuzz_one() {  # target: runs it, its exit code into $build/fuzz-$t.rc
  local t=$1 work="$build/fuzz-corpus/$1"  # grows as the fuzzer finds new coverage; kept between runs
  mkdir -p "$work"
  local seeds=("$src/fuzz/regressions/$t")
  if [ "$t" = case_file ]; then seeds+=("$src/cases"); else seeds+=("$src/fuzz/corpus/$t"); fi
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$findings/$t-" "$work" "${seeds[@]}" >"$build/fuzz-$t.log" 2>&1
  echo $? >"$build/fuzz-$t.rc"
}
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
  rm -f "$build/fuzz-$t.rc"
  fuzz_one "$t" &
  running=$((running + 1))
done
wait
status=0
for t in "${targets[@]}"; do
  work="$build/fuzz-corpus/$t"
  log="$build/fuzz-$t.log"
  rc=$(cat "$build/fuzz-$t.rc" 2>/dev/null || echo 99)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -Eo 'cov: [0-9]+' "$log" | tail -1)
  echo "fuzz $t: ${execs:-?} executions in ${seconds} s, ${rate:-?} exec/s, ${cov:-cov: ?}, corpus $(ls "$work" | wc -l) inputs"
  if [ "$rc" -ne 0 ]; then
    echo "fuzz $t: FINDING (exit $rc); the input: $(ls "$findings"/"$t"-* 2>/dev/null | tr '\n' ' ')"
    grep -E 'ERROR|runtime error|terminate|what\(\)|SUMMARY' "$log" | head -20
    status=1
  fi
done
exit "$status"
