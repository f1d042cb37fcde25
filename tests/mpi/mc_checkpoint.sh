#!/usr/bin/env bash
# identify --monte-carlo --checkpoint on threads, without MPI (docs/mpi.md, Resuming): the
# checkpoint of a finished run, cut as a kill leaves it (whole lines and half a line), then
# the rerun equals the uninterrupted run's JSON to the bit; a finished checkpoint reruns
# nothing; another seed's checkpoint is refused (exit 2). Usage: mc_checkpoint.sh <vrelab> <cases dir>
set -u
bin=$1
cases=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../cli/expect.sh"
. "$(dirname "$0")/same_json.sh"


case=$cases/paper-static.toml
# 513 trials: 3 blocks of 256, the last one short (1 trial); each run ~9 s of CPU under the
# sanitizers (2.2 s of it the static test on the ODE, then ~13 ms a trial).
expect 0 'Monte Carlo' identify "$case" --monte-carlo 513 --json "$tmp/plain.json"
expect 0 'Monte Carlo' identify "$case" --monte-carlo 513 --json "$tmp/full.json" --checkpoint "$tmp/ck"
check "a checkpointed run = a plain run" same_json "$tmp/plain.json" "$tmp/full.json"
check "the checkpoint holds a header and 3 blocks" test "$(grep -c '^b ' "$tmp/ck")" -eq 3
# Killed after 2 blocks were in and half of the 3rd: the rerun runs 1 block...
head -n 3 "$tmp/ck" >"$tmp/cut"
sed -n '4p' "$tmp/ck" | head -c 300 >>"$tmp/cut"
# ... and one more: a block whose line was altered runs again too.
sed -i '3s/0x1/0x2/' "$tmp/cut"
expect 0 '1 of 3 blocks already in' identify "$case" --monte-carlo 513 --json "$tmp/resumed.json" --checkpoint "$tmp/cut"
check "resumed from a cut checkpoint = uninterrupted" same_json "$tmp/plain.json" "$tmp/resumed.json"
check "the resumed checkpoint holds the 3 blocks" test "$(grep -c '^b ' "$tmp/cut")" -eq 3
# A finished checkpoint: nothing to run, the same result.
expect 0 '3 of 3 blocks already in' identify "$case" --monte-carlo 513 --json "$tmp/again.json" --checkpoint "$tmp/ck"
check "rerun on a finished checkpoint = uninterrupted" same_json "$tmp/plain.json" "$tmp/again.json"
# Another run's file is not mixed in.
expect 2 'holds another run' identify "$case" --monte-carlo 513 --seed 9 --checkpoint "$tmp/ck"
expect 2 'holds another run' identify "$case" --monte-carlo 700 --checkpoint "$tmp/ck"
expect 2 'needs --monte-carlo' identify "$case" --checkpoint "$tmp/ck"
echo "mc_checkpoint: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
