#!/usr/bin/env bash
# The memory check of raw-record reading (issue 16): a ~1 GB HDF5 raw campaign diagnosed with
# its peak resident memory and CPU time measured, and a CSV copy of the same samples (shorter,
# so that its text stays a few hundred MB) diagnosed to the same JSON, number for number.
# Not a ctest (minutes, GBs of disk): run by hand from the source tree after a Release build:
#   bench/raw_hdf5_1gb.sh [build dir (build)] [work dir (/tmp/vrelab-1gb)] [record s (420)] [copy s (40)]
# 420 s per record: 3 records x 8.4 M samples x 5 channels (time, output, three reference
# channels) x 8 bytes = 1.01 GB. The work dir is removed at the end.
set -eu
build=${1:-build}
work=${2:-/tmp/vrelab-1gb}
seconds=${3:-420}
copy_seconds=${4:-40}
src=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$work"
mkdir -p "$work"
trap 'rm -rf "$work"' EXIT
peak() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
cpu() { awk -F': ' '/User time/ {u=$2} /System time/ {s=$2} END {printf "%.1f", u + s}' "$1"; }

echo "== generating the HDF5 campaign: 3 records of $seconds s at 20 kHz, 5 channels"
"$build/vrelab_raw_campaign" "$src/cases" "$work/big" "$seconds" hdf5
du -sb "$work/big/records" | awk '{printf "records: %.3f GB\n", $1 / 1e9}'
echo "== diagnose (HDF5)"
/usr/bin/time -v "$build/vrelab" diagnose "$work/big" --json "$work/big.json" >"$work/big.txt" 2>"$work/big.time"
grep -E "Verdict|skipped" "$work/big.txt" || true
echo "peak RSS $(peak "$work/big.time") kB, CPU $(cpu "$work/big.time") s (user + system)"
echo "== measure on one record (reads the reference channels too)"
/usr/bin/time -v "$build/vrelab" measure "$work/big/records/ia-100Hz-2g.h5" --baseline=-1,0 --on 0,"$seconds" --column output_mA \
  --frequency 100 --K1 1.25 >"$work/m.txt" 2>"$work/m.time"
grep -E "vibration error|Reference" "$work/m.txt"
echo "peak RSS $(peak "$work/m.time") kB, CPU $(cpu "$work/m.time") s"
rm -rf "$work/big"

echo "== the same samples as HDF5 and as CSV ($copy_seconds s records)"
"$build/vrelab_raw_campaign" "$src/cases" "$work/copy" "$copy_seconds" both
du -sb "$work/copy/h5/records" "$work/copy/csv/records" | awk '{printf "%s: %.3f GB\n", $2, $1 / 1e9}'
for f in h5 csv; do
  /usr/bin/time -v "$build/vrelab" diagnose "$work/copy/$f" --json "$work/$f.json" >"$work/$f.txt" 2>"$work/$f.time"
  echo "$f: peak RSS $(peak "$work/$f.time") kB, CPU $(cpu "$work/$f.time") s"
done
# Identical but for the folder's name (data) and the timings.
/usr/bin/python3 - "$work/h5.json" "$work/csv.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for j in (a, b):
    for k in ("data", "wall_s", "program"):
        j.pop(k, None)
print("HDF5 and CSV diagnoses identical:", a == b)
sys.exit(0 if a == b else 1)
PY
