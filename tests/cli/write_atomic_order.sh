#!/usr/bin/env bash
# write_atomic's order on disk: the data reach the disk before the rename, the folder's entry
# after it (fsync, rename, fsync), seen with strace on `vrelab identify --json`.
# Usage: write_atomic_order.sh <vrelab binary> <cases dir>. Without strace the check cannot run:
# exit 77, which ctest reports as "Skipped" (SKIP_RETURN_CODE), never as passed.
set -u
bin=$1
cases=$2
if ! command -v strace >/dev/null; then
  echo "SKIPPED: strace is not installed; write_atomic's fsync/rename order is not checked"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/expect.sh"
mkdir -p "$tmp/o"
strace -f -e trace=fsync,rename,renameat,renameat2 -o "$tmp/trace" "$bin" identify "$cases/ideal-static.toml" \
  --json "$tmp/o/sync.json" >/dev/null 2>&1
check "identify wrote its JSON under strace" test -s "$tmp/o/sync.json"
check "fsync, rename, fsync in write_atomic" grep -Pzq 'fsync\(\d+\)\s+= 0\n[^\n]*rename[^\n]*sync\.json[^\n]*\n[^\n]*fsync\(\d+\)\s+= 0' "$tmp/trace"
echo "write_atomic_order: $pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -eq 2 ]
