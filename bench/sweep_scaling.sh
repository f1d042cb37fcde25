#!/usr/bin/env bash
# Sweep throughput on 1 and 2 threads (timed CLI runs), and the peak memory of a 10-minute
# random run with a 20 kHz record streamed to disk. Usage: bench/sweep_scaling.sh [build] [points]
# (points per sweep axis, default 100: 200 conditions, ~0.4 s on one core, too short to show
# the scaling past start-up and the longest conditions; 1000 gives a job of seconds).
set -euo pipefail
bin=${1:-build}/vrelab
points=${2:-100}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed "s/^frequency_points = .*/frequency_points = $points/" cases/sweep-frequency.toml >"$tmp/sweep.toml"
for n in 1 2; do
  start=$(date +%s.%N)
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -o "$tmp/t$n" -f "%U %S" "$bin" sweep "$tmp/sweep.toml" --out "$tmp/s$n.csv" --threads $n --no-progress >/dev/null
  else
    "$bin" sweep "$tmp/sweep.toml" --out "$tmp/s$n.csv" --threads $n --no-progress >/dev/null
    echo "? ?" >"$tmp/t$n"
  fi
  end=$(date +%s.%N)
  read -r user sys <"$tmp/t$n"
  echo "threads $n: $(echo "$end - $start" | bc) s wall, ${user} s user + ${sys} s sys CPU for $((2 * points)) conditions" \
    "(load average $(cut -d' ' -f1-3 /proc/loadavg))"
done
# 10 minutes of GEVS with the output sampled at 20 kHz (the record streamed through the
# measurement's sums, not kept): peak resident memory.
sed -e 's/^duration_s = .*/duration_s = 600.0/' cases/shake-random-gevs.toml >"$tmp/long.toml"
printf '[readout]\nsample_rate_Hz = 20000.0\n' >>"$tmp/long.toml"
if [ -x /usr/bin/time ]; then
  /usr/bin/time -f "10-minute random run: %e s wall, peak RSS %M kB" "$bin" shake "$tmp/long.toml" >/dev/null
else
  "$bin" shake "$tmp/long.toml" >/dev/null &
  pid=$!
  peak=0
  while kill -0 $pid 2>/dev/null; do
    rss=$(awk '/VmHWM/ {print $2}' /proc/$pid/status 2>/dev/null || echo 0)
    [ "${rss:-0}" -gt "$peak" ] && peak=$rss
    sleep 0.5
  done
  echo "10-minute random run: peak RSS ${peak} kB (sampled from /proc)"
fi
