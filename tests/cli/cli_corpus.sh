#!/usr/bin/env bash
# Each reader's fuzz inputs (fuzz/corpus/<target>/, the seeds, and fuzz/regressions/<target>/,
# the findings) through the command line as a user would give them: a campaign folder or a
# PSD table to `vrelab diagnose --check`, a record (CSV or HDF5) to `vrelab measure`. Each
# must answer within a time limit with exit 0 or 2 (bad input, named), never a crash, a hang
# or "internal error". The files are made by the fuzz targets' own functions
# (vrelab_fuzz_replay --write). Usage: cli_corpus.sh <vrelab> <vrelab_fuzz_replay> <source dir>
set -u
bin=$1
replay=$2
src=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
limit=30
fail=0
runs=0
inputs() {  # inputs <target>: its seeds and kept findings
  find "$src/fuzz/corpus/$1" "$src/fuzz/regressions/$1" -type f ! -name README.md 2>/dev/null | sort
}
answer() {  # answer <input> <args...>: vrelab under the time limit; exit 0 or 2 and no internal error
  local input=$1
  shift
  timeout -k 5 "$limit" "$bin" "$@" >"$tmp/out" 2>&1
  local rc=$?
  runs=$((runs + 1))
  if { [ "$rc" -ne 0 ] && [ "$rc" -ne 2 ]; } || grep -q 'internal error' "$tmp/out"; then
    echo "FAIL: $input: vrelab $* -> rc $rc: $(tail -c 400 "$tmp/out")"
    fail=$((fail + 1))
  fi
}
measure=(--on 1,2 --baseline 0,1 --frequency 10)

for f in $(inputs lab_data); do
  rm -rf "$tmp/lab" && "$replay" --write lab_data "$f" "$tmp/lab"
  answer "$f" diagnose --check "$tmp/lab"
done
for f in $(inputs psd_table); do
  rm -rf "$tmp/psd" && cp -r "$src/cases/lab-random" "$tmp/psd" && cp "$f" "$tmp/psd/gevs.csv"
  answer "$f" diagnose --check "$tmp/psd"
done
for t in series raw_csv; do
  for f in $(inputs $t); do answer "$f" measure "$f" "${measure[@]}"; done
done
for f in $(inputs raw_hdf5); do
  rm -f "$tmp/rec.h5" && "$replay" --write raw_hdf5 "$f" "$tmp/rec.h5"
  answer "$f" measure "$tmp/rec.h5" "${measure[@]}"
done
echo "$runs inputs answered, $fail failed"
[ "$runs" -gt 0 ] && [ "$fail" -eq 0 ]
