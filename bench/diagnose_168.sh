#!/bin/bash
# The 168-run diagnosis' CPU time on one core (issue 15: <= 10 s), by hand (not a ctest):
#   bench/diagnose_168.sh [build dir] [work dir]
# Makes three campaigns of the default design (cases/campaign.toml: 7 frequencies x 3
# amplitudes x 4 directions x 2 orientations): an out-of-library clipping (unexplained: the
# pairs are tried), a clean one, and the clean one with every stated sigma divided by 2.2 (the
# sigma-understated path: the diagnosis runs twice). Prints each one's verdict and CPU time.
set -euo pipefail
build=${1:-build}
work=${2:-$(mktemp -d)}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
sed -e 's/^hidden = .*$/hidden = [ { name = "readout_clipping", parameter = 4.4 } ]/' "$here/cases/campaign.toml" >"$work/unexplained.toml"
sed -e 's/^hidden = .*$/hidden = []/' "$here/cases/campaign.toml" >"$work/clean.toml"
for c in unexplained clean; do
  [ -d "$work/$c" ] || "$build/vrelab" campaign "$work/$c.toml" --out "$work/$c" --no-progress >/dev/null
done
if [ ! -d "$work/understated" ]; then
  cp -r "$work/clean" "$work/understated"
  awk -F, 'BEGIN { OFS = "," } /^#/ || /^id,/ { print; next } { $11 = $11 / 2.2; print }' "$work/clean/runs.csv" \
    >"$work/understated/runs.csv"
fi
for c in unexplained clean understated; do
  /usr/bin/time -f "$c: %U s user, %S s system, %e s wall, %M kB" \
    "$build/vrelab" diagnose "$work/$c" --threads 1 --json "$work/$c.json" 2>&1 | grep -E "^Verdict|s user"
done
echo "campaigns and JSON in $work"
