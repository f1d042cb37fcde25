#!/usr/bin/env bash
# shake from Python against the CLI's in-process time (docs/python.md): alternating runs of
# `build/vrelab shake CASE --json` (its solver_stats.wall_s) and vrelab.shake(case) timed from
# Python; prints the medians. Usage (from the repository's root): python/bench/shake_vs_cli.sh [CASE] [RUNS]
set -euo pipefail
case=${1:-cases/shake-sine-lab.toml}
runs=${2:-7}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for _ in $(seq "$runs"); do
  build/vrelab shake "$case" --json "$tmp/s.json" >/dev/null
  /usr/bin/python3 -c "import json, sys; print('cli', json.load(open(sys.argv[1]))['solver_stats']['wall_s'])" "$tmp/s.json"
  PYTHONPATH=build/python /usr/bin/python3 -c "
import sys, time, vrelab
c = vrelab.load_case(sys.argv[1])
t = time.perf_counter(); r = vrelab.shake(c); print('py', time.perf_counter() - t)" "$case"
done >"$tmp/times"
/usr/bin/python3 - "$tmp/times" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
cli = [float(v) for k, v in rows if k == "cli"]
py = [float(v) for k, v in rows if k == "py"]
print(f"CLI solver_stats.wall_s median {statistics.median(cli):.4f} s (min {min(cli):.4f}, max {max(cli):.4f})")
print(f"Python vrelab.shake     median {statistics.median(py):.4f} s (min {min(py):.4f}, max {max(py):.4f})")
print(f"ratio of the medians {statistics.median(py) / statistics.median(cli):.4f}")
PY
