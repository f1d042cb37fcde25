#!/usr/bin/env bash
# kill -9 of one rank, then of mpirun itself, in the middle of a sweep and of a batch of
# campaigns; each resumed under mpirun must equal the uninterrupted threaded file (every column
# but wall time). A scripted check (docs/mpi.md), not a ctest test: it needs runs of several
# seconds to kill mid-way. Usage: kill_resume.sh <vrelab> <sweep case> <mpiexec> <scratch dir>
set -u
bin=$1 case=$2 mpiexec=$3 tmp=$4
mkdir -p "$tmp"
mpi=("$mpiexec" -n 2 --oversubscribe)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
rows() { grep -v '^#' "$1" | sed 's/,[^,]*$//'; }
status=0
rm -f "$tmp/ref.csv" "$tmp/rank.csv" "$tmp/job.csv"
"$bin" sweep "$case" --out "$tmp/ref.csv" --no-progress --no-work-limit >/dev/null 2>&1
total=$(rows "$tmp/ref.csv" | wc -l)
data_rows() { [ -e "$1" ] && grep -v '^#' "$1" | tail -n +2 | wc -l || echo 0; }
for victim in rank job; do
  out="$tmp/$victim.csv"
  "${mpi[@]}" "$bin" sweep "$case" --out "$out" --no-progress --no-work-limit >"$tmp/$victim.log" 2>&1 &
  job=$!
  until [ "$(data_rows "$out")" -ge $((total / 3)) ]; do sleep 0.05; done
  if [ "$victim" = rank ]; then  # the rank 1 process: a child of mpirun with rank 1 in its environment
    for p in $(pgrep -P "$job"); do
      if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then kill -9 "$p"; fi
    done
  else
    kill -9 "$job"
  fi
  wait "$job" 2>/dev/null
  sleep 1  # orphaned ranks (kill -9 of mpirun) notice and exit
  before=$(data_rows "$out")
  "${mpi[@]}" "$bin" sweep "$case" --out "$out" --no-progress --no-work-limit >"$tmp/$victim-resume.log" 2>&1
  if diff <(rows "$tmp/ref.csv") <(rows "$out") >/dev/null; then
    echo "kill -9 of the $victim after $before of $total rows on disk; resumed: the same rows as the uninterrupted run"
  else
    echo "FAIL: kill -9 of the $victim: the resumed file differs"; status=1
  fi
  grep -h 'already in' "$tmp/$victim-resume.log"
done
exit $status
