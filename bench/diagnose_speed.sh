#!/bin/bash
# diagnose's CPU time on the two campaigns issue 31 names, by hand (not a ctest):
#   bench/diagnose_speed.sh [build dir] [work dir] [an earlier vrelab to compare with]
# Writes the 50-run mixed campaign of cases/campaign-mixed.toml (37 sine, 11 random, 2
# sine-on-random runs) and the 168-run sine campaign of cases/campaign.toml, then prints for
# each: the best of three `diagnose --threads 1` user CPU times (s) and the wall time of
# `--threads 2`. With an earlier binary, its times too, and bench/json_compare.py of the two
# diagnoses' JSON (tolerance 0: every number that differs, the largest relative difference).
set -euo pipefail
build=${1:-build}
work=${2:-$(mktemp -d)}
before=${3:-}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
[ -d "$work/mixed" ] || "$build/vrelab" campaign "$here/cases/campaign-mixed.toml" --out "$work/mixed" --no-progress >/dev/null
[ -d "$work/sine168" ] || "$build/vrelab" campaign "$here/cases/campaign.toml" --out "$work/sine168" --no-progress >/dev/null
best_user() {  # best of 3 user CPU seconds of one thread
  local best=""
  for _ in 1 2 3; do
    /usr/bin/time -o "$work/.time" -f "%U" "$1" diagnose "$2" --threads 1 --no-progress --json "$3" >/dev/null 2>&1
    t=$(cat "$work/.time")
    if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$t; fi
  done
  echo "$best"
}
wall2() {
  /usr/bin/time -o "$work/.time" -f "%e" "$1" diagnose "$2" --threads 2 --no-progress >/dev/null 2>&1
  cat "$work/.time"
}
for c in mixed sine168; do
  echo "$c: $("$build/vrelab" --version 2>/dev/null | head -1)"
  echo "  1 thread, user CPU (best of 3): $(best_user "$build/vrelab" "$work/$c" "$work/$c.json") s; 2 threads, wall: $(wall2 "$build/vrelab" "$work/$c") s"
  if [ -n "$before" ]; then
    echo "  before ($("$before" --version 2>/dev/null | head -1)): 1 thread $(best_user "$before" "$work/$c" "$work/$c.before.json") s; 2 threads $(wall2 "$before" "$work/$c") s"
    "$here/bench/json_compare.py" "$work/$c.before.json" "$work/$c.json" | tail -1 || true
  fi
done
echo "campaigns and JSON in $work"
