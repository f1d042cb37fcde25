#!/usr/bin/env bash
# The four distributed commands under `mpirun -n 3` give the rows the threaded run gives
# (docs/mpi.md): a small sweep, a batch of campaigns with a bad folder among them, identify
# --monte-carlo, a small blind benchmark; then a sweep, a blind, a batch and a Monte Carlo resumed under
# mpirun from files cut short as a killed run leaves them equal the uninterrupted ones.
# Rows are compared as text, every column but wall time (and the header comments, which
# record the ranks and threads). Usage:
# mpi_same.sh <vrelab> <cases dir> <mpiexec> [fast|blind] (blind: the blind benchmark alone, a
# minute of CPU: a test of its own, not labelled fast).
set -u
bin=$1
cases=$2
mpiexec=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../cli/expect.sh"
. "$(dirname "$0")/same_json.sh"

# mpirun refuses to start as root unless told (CI may run as root); three ranks on any
# machine (--oversubscribe: more ranks than cores).
mpi=("$mpiexec" -n 3 --oversubscribe)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)

rows() {  # rows <csv>: data rows without the header comments and the last (wall time) column
  grep -v '^#' "$1" | sed 's/,[^,]*$//'
}
same_rows() { diff <(rows "$1") <(rows "$2") >"$tmp/diff" || { cat "$tmp/diff"; return 1; }; }
run_mpi() {  # run_mpi <want rc> <args...>: vrelab under mpirun
  local want=$1
  shift
  "${mpi[@]}" "$bin" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL: mpirun vrelab $* -> rc $rc (want $want): $(tail -c 800 "$tmp/err")"
    fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
}

fast_part() {
# ---- sweep: 24 conditions with readout noise (each condition's noise seeded by its index).
sed -e 's/^frequency_points = 40/frequency_points = 12/' -e 's/^frequency_to_Hz = 5000.0/frequency_to_Hz = 800.0/' \
  "$cases/sweep-frequency.toml" >"$tmp/sweep.toml"
cat >>"$tmp/sweep.toml" <<'TOML'

[readout]
sample_rate_Hz = 20000.0
noise_sigma_ug = 20.0
TOML
expect 0 'Done: 24 conditions' sweep "$tmp/sweep.toml" --out "$tmp/sweep-threads.csv" --no-progress
run_mpi 0 sweep "$tmp/sweep.toml" --out "$tmp/sweep-mpi.csv" --no-progress
check "sweep: rows under mpirun -n 3 = threaded rows" same_rows "$tmp/sweep-threads.csv" "$tmp/sweep-mpi.csv"
check "sweep: the header records 3 ranks" grep -q '^# run: 3 MPI rank' "$tmp/sweep-mpi.csv"
check "sweep: the threaded header records 1 rank" grep -q '^# run: 1 MPI rank' "$tmp/sweep-threads.csv"
# Killed mid-run: 9 rows and half of the 10th on disk; resumed under mpirun.
head -n $(( $(grep -c '^#' "$tmp/sweep-threads.csv") + 10 )) "$tmp/sweep-threads.csv" >"$tmp/sweep-cut.csv"
printf '%s' "$(sed -n '$p' "$tmp/sweep-threads.csv" | cut -c1-30)" >>"$tmp/sweep-cut.csv"
run_mpi 0 sweep "$tmp/sweep.toml" --out "$tmp/sweep-cut.csv" --no-progress
check "sweep: resumed under mpirun = uninterrupted" same_rows "$tmp/sweep-threads.csv" "$tmp/sweep-cut.csv"
check "sweep: the resume ran only the missing conditions" grep -q '9 already in' "$tmp/out"

# ---- identify --monte-carlo: blocks seeded by their index, merged in order.
expect 0 'Monte Carlo' identify "$cases/paper-static.toml" --monte-carlo 3000 --json "$tmp/mc-threads.json"
run_mpi 0 identify "$cases/paper-static.toml" --monte-carlo 3000 --json "$tmp/mc-mpi.json"
check "identify --monte-carlo: the same to the bit under mpirun -n 3" same_json "$tmp/mc-threads.json" "$tmp/mc-mpi.json"
check "identify --monte-carlo: the JSON records 3 ranks" grep -q '"monte_carlo_ranks": 3' "$tmp/mc-mpi.json"
# Killed mid-run with --checkpoint: 4 blocks and half of the 5th in the file; resumed under mpirun.
run_mpi 0 identify "$cases/paper-static.toml" --monte-carlo 3000 --checkpoint "$tmp/mc-ck"
head -n 5 "$tmp/mc-ck" >"$tmp/mc-cut"
sed -n '6p' "$tmp/mc-ck" | head -c 300 >>"$tmp/mc-cut"
run_mpi 0 identify "$cases/paper-static.toml" --monte-carlo 3000 --json "$tmp/mc-resumed.json" --checkpoint "$tmp/mc-cut"
check "identify --monte-carlo: resumed under mpirun from a cut checkpoint = uninterrupted" same_json "$tmp/mc-threads.json" "$tmp/mc-resumed.json"
check "identify --monte-carlo: the resume ran only the missing blocks" grep -q '4 of 12 blocks already in' "$tmp/err"

# ---- diagnose of many campaigns: a folder of three campaigns, and a bad folder.
# Each unit is cases/lab-example's first four runs (a gap explained by an effect, fitted: 0.7 s
# of CPU a diagnosis where all ten take 2.3 s).
mkdir -p "$tmp/units" "$tmp/bad"
unit() {  # unit <name>: lab-example with its first four runs
  cp -r "$cases/lab-example" "$tmp/units/$1"
  awk '/^#/ || /^id,/ || ++n <= 4' "$cases/lab-example/runs.csv" >"$tmp/units/$1/runs.csv"
}
unit unit-1
# three units, each its own numbers: another sigma, one run fewer
unit unit-2
sed -i 's/,0\.3$/,0.6/' "$tmp/units/unit-2/runs.csv"
unit unit-3
sed -i '$d' "$tmp/units/unit-3/runs.csv"
fast=(--resimulate-runs 0 --no-pairs --no-progress)
expect 2 'failed: .*bad: .*manifest' diagnose "$tmp/units" "$tmp/bad" --summary "$tmp/units-threads.csv" "${fast[@]}"
run_mpi 2 diagnose "$tmp/units" "$tmp/bad" --summary "$tmp/units-mpi.csv" "${fast[@]}"
check "diagnose --summary: the bad folder named under mpirun" grep -q 'failed: .*bad: .*manifest' "$tmp/out"
check "diagnose --summary: rows under mpirun -n 3 = threaded" same_rows "$tmp/units-threads.csv" "$tmp/units-mpi.csv"
check "diagnose --summary: a row per good campaign" test "$(rows "$tmp/units-mpi.csv" | grep -c unit-)" -eq 3
# Killed after one row: resumed under mpirun.
head -n $(( $(grep -c '^#' "$tmp/units-threads.csv") + 2 )) "$tmp/units-threads.csv" >"$tmp/units-cut.csv"
run_mpi 0 diagnose "$tmp/units" --summary "$tmp/units-cut.csv" "${fast[@]}"
check "diagnose --summary: resumed under mpirun = uninterrupted" same_rows "$tmp/units-threads.csv" "$tmp/units-cut.csv"
check "diagnose --summary: the resume kept one row" grep -q '1 already there' "$tmp/out"

# ---- the other commands run on rank 0 alone: one report, not three.
run_mpi 0 predict "$cases/paper-predict.toml"
check "predict under mpirun prints one report" test "$(grep -c '^vrelab ' "$tmp/out")" -eq 1

}

blind_part() {
# ---- blind: 2 campaigns (both clean: the cheapest).
# Over a campaigns.txt left by another seed (its line's checksum right): said on stderr, none
# of its lines read back (the rows below must still equal the MPI run's).
mkdir -p "$tmp/blind-threads"
printf '# vrelab blind: another seed\n0\tforged\t3ef6ef83\n' >"$tmp/blind-threads/campaigns.txt"
expect 0 'another seed, settings or program build; its campaigns are not read back' \
  blind --n 2 --seed 5 --out "$tmp/blind-threads" --no-progress
check "blind: the stale campaigns.txt replaced" grep -q 'seed 5 ' "$tmp/blind-threads/campaigns.txt"
run_mpi 0 blind --n 2 --seed 5 --out "$tmp/blind-mpi" --no-progress
check "blind: scores.json under mpirun -n 3 = threaded" same_json "$tmp/blind-threads/scores.json" "$tmp/blind-mpi/scores.json"
check "blind: confusion.csv the same" cmp -s "$tmp/blind-threads/confusion.csv" "$tmp/blind-mpi/confusion.csv"
check "blind: scores.json records 3 ranks" grep -q '"ranks": 3' "$tmp/blind-mpi/scores.json"
# Killed after the first campaign and half of the second: resumed under mpirun.
mkdir -p "$tmp/blind-cut"
head -n 2 "$tmp/blind-threads/campaigns.txt" >"$tmp/blind-cut/campaigns.txt"
sed -n '3p' "$tmp/blind-threads/campaigns.txt" | cut -c1-40 >>"$tmp/blind-cut/campaigns.txt"
run_mpi 0 blind --n 2 --seed 5 --out "$tmp/blind-cut" --no-progress
check "blind: resumed under mpirun = uninterrupted" same_json "$tmp/blind-threads/scores.json" "$tmp/blind-cut/scores.json"
check "blind: the resume read one campaign back" grep -q '1 campaign(s) read back' "$tmp/out"

}

if [ "${4:-fast}" = blind ]; then blind_part; else fast_part; fi
echo "mpi_same: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
