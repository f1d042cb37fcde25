#!/usr/bin/env bash
# A valid PSD table of 10^6 rows is diagnosed right: cases/lab-random's
# GEVS table (four breakpoints) refined to 10^6 rows on its own straight lines in log-log axes
# is the same PSD, so `vrelab diagnose` must give the same verdict and the same chi^2 and gap
# rms (to 1e-6: the refined rows are the lines' values to 1e-12, and the PSD integral's grid
# is the same). Its time is printed, not judged (speed is a benchmark's: docs/performance.md);
# the 300 s limit only stops a hang (it took 18 s in Release).
# Usage: cli_big_psd.sh <vrelab binary> <cases dir>
set -u
bin=$1
cases=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp -r "$cases/lab-random" "$tmp/four"
cp -r "$cases/lab-random" "$tmp/million"
# gevs.csv: 20, 50, 800, 2000 Hz; 333 333 rows a segment, each level on its segment's power law.
awk 'BEGIN {
  f[0] = 20; f[1] = 50; f[2] = 800; f[3] = 2000; p[0] = 0.026; p[1] = 0.16; p[2] = 0.16; p[3] = 0.026
  n = 333333
  print "frequency_Hz,psd_IA_g2_per_Hz"
  for (k = 0; k < 3; ++k) {
    b = log(p[k + 1] / p[k]) / log(f[k + 1] / f[k])
    for (i = 0; i < n; ++i) {
      x = f[k] * exp(log(f[k + 1] / f[k]) * i / n)
      printf "%.17g,%.17g\n", x, p[k] * exp(b * log(x / f[k]))
    }
  }
  printf "%.17g,%.17g\n", f[3], p[3]
}' >"$tmp/million/gevs.csv"
rows=$(($(wc -l <"$tmp/million/gevs.csv") - 1))
[ "$rows" -ge 1000000 ] || { echo "FAIL: the refined table has $rows rows"; exit 1; }
since() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
start=$(date +%s.%N)
"$bin" diagnose "$tmp/four" --json "$tmp/four.json" >"$tmp/four.out" 2>&1 || { echo "FAIL: four rows: $(tail -5 "$tmp/four.out")"; exit 1; }
four_s=$(since "$start")
start=$(date +%s.%N)
timeout -k 5 300 "$bin" diagnose "$tmp/million" --json "$tmp/million.json" >"$tmp/million.out" 2>&1 ||
  { echo "FAIL: 10^6 rows: $(tail -5 "$tmp/million.out")"; exit 1; }
wall=$(since "$start")
echo "10^6-row PSD ($rows rows): diagnosed in $wall s, the four rows in $four_s s"
python3 - "$tmp/four.json" "$tmp/million.json" <<'EOF'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
bad = []
for key in ("verdict", "chosen"):
    if a[key] != b[key]:
        bad.append("%s: %r against %r" % (key, b[key], a[key]))
for name, x, y in (("chi2_nominal", a["chi2_nominal"], b["chi2_nominal"]),
                   ("rms_before_g", a["shrinkage"]["rms_before_g"], b["shrinkage"]["rms_before_g"]),
                   ("rms_after_g", a["shrinkage"]["rms_after_g"], b["shrinkage"]["rms_after_g"])):
    if abs(x - y) > 1e-6 * abs(x):
        bad.append("%s: %.10g against %.10g" % (name, y, x))
print("verdict %r, chi2 %.10g (four rows %.10g)" % (b["verdict"], b["chi2_nominal"], a["chi2_nominal"]))
for m in bad:
    print("FAIL: " + m)
sys.exit(1 if bad else 0)
EOF
