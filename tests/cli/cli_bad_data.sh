#!/usr/bin/env bash
# Lab data as labs and spreadsheets write it: encodings, separators, loose numbers, a hand-
# edited sweep, figures and reports written whole. Exit 2 and a message naming the file, the
# line and the column for bad data; exit 0 and a result for good data in odd clothes (a BOM, a
# path that is not UTF-8). Usage: cli_bad_data.sh <vrelab binary> <cases dir>
set -u
bin=$1
cases=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/expect.sh"
# (where only the reading matters, `diagnose --check` reads and checks without diagnosing: a
# diagnosis of the ten runs takes ~2 minutes of CPU under the sanitizers; the three report runs
# diagnose one run, no gap: ~7 s each, where three runs took 21 s)
lab() {  # lab <name>: a fresh copy of the hand-written campaign
  rm -rf "${tmp:?}/$1"
  cp -r "$cases/lab-example" "$tmp/$1"
}
valid_json() { python3 -c 'import json,sys; json.load(open(sys.argv[1], encoding="utf-8"))' "$1"; }
latin1=$(printf '\xb0')

# ---- (2) text that is not UTF-8: refused at read time in data; a path is not data.
lab enc
sed -i "4s/^ia-10Hz-2g,/ia-10Hz-2g${latin1},/" "$tmp/enc/runs.csv"
expect 2 'enc/runs\.csv:4:11: not UTF-8 at byte 11 \(0xB0.*save the file as UTF-8' diagnose "$tmp/enc" --json "$tmp/o/enc.json"
check "no JSON written for non-UTF-8 data" test ! -e "$tmp/o/enc.json"
lab "dir$latin1"  # diagnosed with a report in (3) below: its JSON must stay valid
expect 0 '10 shaker runs \(0 skipped\)' diagnose --check "$tmp/dir$latin1"
cp "$cases/ideal-static.toml" "$tmp/case$latin1.toml"
expect 0 'least_squares' identify "$tmp/case$latin1.toml" --json "$tmp/o/case.json"
check "a Latin-1 case path still gives valid JSON" valid_json "$tmp/o/case.json"
lab encm
sed -i "s/^name = .*/name = \"lab ${latin1}\"/" "$tmp/encm/manifest.toml"
expect 2 'encm/manifest\.toml:[0-9]+: .*utf-8' diagnose "$tmp/encm"

# ---- (7) Excel's CSV UTF-8 (a byte-order mark), ';' separators, a column's case.
lab bom
# (without the comment lines, so the BOM stands before the header on line 1)
for f in static runs; do grep -v '^#' "$cases/lab-example/$f.csv" | { printf '\xef\xbb\xbf'; cat; } >"$tmp/bom/$f.csv"; done
expect 0 'Read and checked .*10 sine' diagnose --check "$tmp/bom"
# A spreadsheet's ';' export reads as its comma twin (tests/io/test_lab_data.cpp: the same
# campaign to the byte); with its decimal commas, refused naming the cell.
lab semi
sed -i '/^#/!s/,/;/g' "$tmp/semi/runs.csv" "$tmp/semi/static.csv"
expect 0 'Read and checked .*10 sine' diagnose --check "$tmp/semi"
lab semidec
sed -i -e '/^#/!s/,/;/g' -e '/^#/!s/\./,/g' "$tmp/semidec/runs.csv" "$tmp/semidec/static.csv"
expect 2 "semidec/static\.csv:5:3: column output_mA: '-1,248095066' is not a number \(a decimal comma; write a decimal point\)" diagnose "$tmp/semidec"
lab case
sed -i 's/^id,frequency_Hz,/id,frequency_hz,/' "$tmp/case/runs.csv"
expect 2 "lacks column 'frequency_Hz' \(the header has: id, frequency_hz, .*did you mean 'frequency_Hz' for 'frequency_hz'\? \(column names are case-sensitive" diagnose "$tmp/case"
lab typo
sed -i 's/^series,angle_deg,/series,angel_deg,/' "$tmp/typo/static.csv"
expect 2 "lacks column 'angle_deg'.*did you mean 'angle_deg' for 'angel_deg'\?" diagnose "$tmp/typo"

# ---- (9) loose CSV: more cells than the header, a fractional count, hex, inf; an empty manifest.
lab cells
sed -i '5s/$/,7/' "$tmp/cells/runs.csv"
expect 2 'cells/runs\.csv:5:12: 12 cells, the header has 11' diagnose "$tmp/cells"
lab count
sed -i '6s/,2$/,2.5/' "$tmp/count/static.csv"
expect 2 'count/static\.csv:6:5: column count: 2\.5 is not a whole number' diagnose "$tmp/count"
lab hex
sed -i '6s/^1,30,/1,0x1E,/' "$tmp/hex/static.csv"
expect 2 "hex/static\.csv:6:2: column angle_deg: '0x1E' is not a number \(hexadecimal" diagnose "$tmp/hex"
lab hexrun
sed -i '5s/^ia-100Hz-2g,100,/ia-100Hz-2g,0x1E,/' "$tmp/hexrun/runs.csv"
expect 2 "skipped: run 'ia-100Hz-2g': .*hexrun/runs\.csv:5:2: column frequency_Hz: '0x1E' is not a number \(hexadecimal" diagnose --check "$tmp/hexrun"
lab inf
sed -i '6s/^1,30,/1,inf,/' "$tmp/inf/static.csv"
expect 2 'inf/static\.csv:6:2: column angle_deg: inf is not a finite number' diagnose "$tmp/inf"
lab empty
: >"$tmp/empty/manifest.toml"
expect 2 'empty/manifest\.toml: missing \[campaign\] format_version = 1; \[instrument\] output_unit .*; \[identification\] fixed' diagnose "$tmp/empty"
# measure's series: hexadecimal time, a BOM, ';' with a decimal comma.
printf 'time_s,output\n0.0,1.0\n0x1,1.0\n' >"$tmp/hex.csv"
expect 2 "hex\.csv:3: not a number in '0x1,1\.0' \(column 1, '0x1': hexadecimal" measure "$tmp/hex.csv" --on 1,2 --baseline 0,1
printf 'time_s;output\n0;1,5\n' >"$tmp/semi.csv"
expect 2 "semi\.csv:2: not a number in '0;1,5' \(column 2, '1,5': a decimal comma" measure "$tmp/semi.csv" --on 1,2 --baseline 0,1

# ---- (3) figures whole or not at all; a report folder never mixes runs.
# The report runs diagnose the first shaker run of dir<latin1> (no gap): what they check is the
# report folder, not the diagnosis (cli_bad_input.sh diagnoses four runs, pairs and ODE included).
awk '/^#/ || /^id,/ || ++n <= 1' "$cases/lab-example/runs.csv" >"$tmp/dir$latin1/runs.csv"
plots=$(dirname "$bin")/share/vrelab/plots
# A figure whose writing dies half-way (a partial PNG, then an interruption): no file of that
# name, no temporary file left.
mkdir -p "$tmp/fig"
check "the plot scripts write through atomic_figure.py" grep -q 'savefig_atomic(fig' "$plots/diagnose.py"
python3 - "$plots" "$tmp/fig" <<'PY' >"$tmp/fig.log" 2>&1
import os, sys
sys.path.insert(0, sys.argv[1])
from atomic_figure import savefig_atomic
class Dying:
    def savefig(self, path, format=None, **kw):
        with open(path, "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\n half a figure")
        raise KeyboardInterrupt
try:
    savefig_atomic(Dying(), os.path.join(sys.argv[2], "fig.png"), dpi=150)
except KeyboardInterrupt:
    pass
PY
check "an interrupted figure leaves no file ($(ls "$tmp/fig"))" test -z "$(ls -A "$tmp/fig")"
# An old report with a figure this run does not draw, and the user's own file: the old figure
# goes, the user's file stays.
mkdir -p "$tmp/rep"
printf 'old' >"$tmp/rep/fig9_old.png"
printf 'mine' >"$tmp/rep/notes.txt"
printf '# vrelab report files\nfig9_old.png\nreport.html\n# complete\n' >"$tmp/rep/report-files.txt"
expect 0 'Gap:' diagnose --resimulate-runs 0 --no-pairs "$tmp/dir$latin1" --report "$tmp/rep"
check "the old report's figure is removed" test ! -e "$tmp/rep/fig9_old.png"
check "the user's file is kept" test -e "$tmp/rep/notes.txt"
check "the new report lists its files" grep -qx 'diagnosis.json' "$tmp/rep/report-files.txt"
check "the new report is complete" test -s "$tmp/rep/report.html"
check "a Latin-1 folder name still gives valid JSON" valid_json "$tmp/rep/diagnosis.json"
# A run killed while drawing (the plot script kills the program): the old report is gone, no
# new one stands beside the new data, and the next run clears what the killed one wrote.
mkdir -p "$tmp/killer"
cat >"$tmp/killer/diagnose.py" <<'PY'
import os, signal
pid = os.getppid()  # the shell of std::system, then the program
while pid > 1:
    if open(f"/proc/{pid}/comm").read().strip() == "vrelab":
        os.kill(pid, signal.SIGKILL)
        break
    pid = int(open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[1])
PY
(VRELAB_PLOTS_DIR="$tmp/killer" "$bin" diagnose --resimulate-runs 0 --no-pairs "$tmp/dir$latin1" --report "$tmp/rep"; true) >/dev/null 2>&1
check "a killed run leaves no report beside its data" test ! -e "$tmp/rep/report.html" -a -e "$tmp/rep/diagnosis.json"
check "a killed run leaves the old figures removed" test ! -e "$tmp/rep/gap_map.png"
expect 0 'Gap:' diagnose --resimulate-runs 0 --no-pairs "$tmp/dir$latin1" --report "$tmp/rep"
check "the next run writes a whole report" test -s "$tmp/rep/report.html" -a -s "$tmp/rep/gap_map.png"

# ---- (11) a resumed sweep finds a row edited by hand (its checksum) and runs it again.
sed 's/frequency_points = 40/frequency_points = 4/; s/^directions = .*/directions = [[1.0, 0.0, 0.0]]/; s/frequency_to_Hz = 5000.0/frequency_to_Hz = 200.0/' \
  "$cases/sweep-frequency.toml" >"$tmp/sw.toml"
expect 0 '4 written, 0 failed' sweep "$tmp/sw.toml" --out "$tmp/sw.csv" --threads 2 --no-progress
rows() { grep -v '^#' "$1" | cut -d, -f1-14; }  # the results (checksum and wall time aside)
rows "$tmp/sw.csv" >"$tmp/sw.rows"
line=$(grep -n '^2,' "$tmp/sw.csv" | cut -d: -f1)
sed -i '/^2,/s/,2\.8/,3.8/' "$tmp/sw.csv"  # measured_g 2.8e-4 -> 3.8e-4 by hand
check "the edit took" bash -c "! rows '$tmp/sw.csv' | cmp -s - '$tmp/sw.rows'" 2>/dev/null
expect 0 "sw\.csv:$line: condition 2: the row does not match its checksum \(edited by hand\?\); run again" \
  sweep "$tmp/sw.toml" --out "$tmp/sw.csv" --threads 2 --no-progress
check "the edited row is computed again, as before" cmp -s <(rows "$tmp/sw.csv") "$tmp/sw.rows"
# write_atomic's fsync/rename order: tests/cli/write_atomic_order.sh (its own ctest test, shown
# as skipped where strace is missing).

echo "cli_bad_data: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
