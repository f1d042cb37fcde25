#!/usr/bin/env bash
# The three HTML reports as a reader gets them (issue 32): reproduce (a small case), diagnose
# (cases/lab-example) and blind (--n 4, its out-of-library campaign among them) each write one
# report.html that stands alone (every figure embedded as a data URI, no other file named) and
# renders in a real browser: headless Chromium's screenshot of each page is compared with one of
# the same page with its images taken out, and the figures must make a large, varied difference.
# The blind report must embed its confusion matrix, and confusion.csv hold every campaign.
# Exit 77 (ctest: Skipped) when Chromium is not installed.
# Usage: report_render.sh VRELAB SOURCE_DIR
set -uo pipefail
vrelab=$1
root=$2
browser=$(command -v chromium || command -v chromium-browser) || {
  echo "SKIP: chromium is not installed (apt-get install chromium): the reports cannot be rendered"
  exit 77
}
py=/usr/bin/python3
export VRELAB_PLOTS_DIR=$root/tools/plots
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
check() {  # check "what" command...
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; fail=1; return 1; fi
}

# The small case of tests/validation/test_reproduce.cpp: a few seconds.
cat >"$tmp/small.toml" <<'EOF'
g_m_per_s2 = 9.81
[instrument]
output_unit = "mA"
[coefficients]
K1 = 1.25
k0 = 1.5e-3
k1_asym = 2.0e-5
k2 = 1.5e-5
k3 = 1.0e-6
k4 = 2.0e-7
delta_OA = 1.0e-4
delta_PA = -5.0e-5
k_IP = 8.0e-6
k_IO = -5.0e-6
k_PO = 3.0e-6
k_PP = 0.0
k_OO = 0.0
[dividing_head]
positions_per_series = 8
initial_error_arcsec = [3.0, -2.0, 4.0]
angle_sigma_arcsec = 0.5
noise_sigma_ug = 0.5
repeats = 4
source = "ode"
[identification]
fixed = { k1_asym = 2.0e-5, k_PP = 0.0, k_OO = 0.0 }
[readout]
sample_rate_Hz = 5000.0
noise_sigma_ug = 20.0
[shake]
min_measure_s = 1.0
blocks = 10
[reproduce]
frequency_Hz = 20.0
amplitudes_g = [1.0, 3.0]
directions = [[1.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
direction_names = ["IA", "oblique"]
orientations_g = [[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]]
orientation_names = ["IA vertical", "IA horizontal"]
departure_frequencies_Hz = [20.0, 300.0]
invisible_shift_per_g = 4.0e-6
[reproduce.confirmation]
orientation = 1
direction = 1
amplitude_g = 2.0
record_s = 1.0
[run]
seed = 11
EOF

"$vrelab" reproduce "$tmp/small.toml" --out "$tmp/reproduce" >"$tmp/reproduce.log" 2>&1 || { cat "$tmp/reproduce.log"; exit 1; }
"$vrelab" diagnose "$root/cases/lab-example" --report "$tmp/diagnose" --no-progress >"$tmp/diagnose.log" 2>&1 ||
  { cat "$tmp/diagnose.log"; exit 1; }
"$vrelab" blind --n 4 --seed 7 --out "$tmp/blind" --no-progress >"$tmp/blind.log" 2>&1 || { cat "$tmp/blind.log"; exit 1; }

# Every campaign in confusion.csv (blind --n 4 once left its out-of-library one out).
check "blind: confusion.csv counts all 4 campaigns" test "$(grep -v '^#' "$tmp/blind/confusion.csv" | tail -n +2 |
  awk -F, '{for (i = 2; i <= NF; ++i) s += $i} END {print s}')" = 4
check "blind: confusion.csv has the out-of-library row" grep -q '(out of library),' "$tmp/blind/confusion.csv"

shot() {  # shot PAGE PNG: a 1280 px wide screenshot of the page's first 3000 px
  "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --user-data-dir="$tmp/profile" --screenshot="$2" --window-size=1280,3000 \
    "file://$1" >/dev/null 2>&1
}

# report KIND FIGURES: the checks of one report, FIGURES the figures it embeds.
report() {
  local kind=$1 figures=$2 page=$tmp/$1/report.html
  check "$kind: report.html written" test -s "$page" || return
  echo "$kind: report.html $(wc -c <"$page") bytes"
  check "$kind: the summary box comes first" $py -c "import sys; t = open(sys.argv[1]).read(); s = t.find('<section class=\"summary'); sys.exit(not (0 < s < t.find('<h2>')))" "$page"
  check "$kind: no src= or href= but data URIs" test -z "$(grep -oE '(src|href)="[^"]*' "$page" | grep -v '^src="data:image/')"
  check "$kind: no url( of another file" test -z "$(grep -oE 'url\([^)]*' "$page" | grep -v 'url(data:')"
  check "$kind: $figures figures embedded" test "$(grep -o '<img src="data:image/' "$page" | wc -l)" -eq "$figures"
  # The same page without its images: what the figures add to the screenshot.
  $py -c "import re, sys; t = open(sys.argv[1]).read(); open(sys.argv[2], 'w').write(re.sub(r'<img src=\"data:[^\"]*\"', '<img src=\"\"', t))" \
    "$page" "$tmp/$kind/bare.html"
  check "$kind: screenshot taken" shot "$page" "$tmp/$kind.png"
  check "$kind: screenshot without the figures taken" shot "$tmp/$kind/bare.html" "$tmp/$kind-bare.png"
  check "$kind: the figures render (screenshot)" $py - "$tmp/$kind.png" "$tmp/$kind-bare.png" <<'EOF'
import sys
import matplotlib.image as mpimg
import numpy as np
full, bare = (mpimg.imread(p)[..., :3] for p in sys.argv[1:3])
changed = np.abs(full - bare).max(axis=2) > 0.02
colours = len(np.unique((full[changed] * 255).astype(np.uint8), axis=0))
print(f"  {sys.argv[1]}: {full.shape[1]}x{full.shape[0]} px, {full.std():.3f} grey-level spread, "
      f"{100 * changed.mean():.1f} % of the pixels from the figures, {colours} colours among them")
sys.exit(not (full.std() > 0.05 and changed.mean() > 0.05 and colours > 20))
EOF
}

report reproduce 6
report diagnose 2
report blind 1
check "blind: the report embeds the confusion matrix" grep -q '<img src="data:image/[a-z+]*;base64,[^"]*" alt="The confusion matrix' \
  "$tmp/blind/report.html"
exit $fail
