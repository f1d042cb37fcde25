#!/usr/bin/env bash
# The classes of bad input of docs/data-format.md's "Bad input" table, each answered with exit 2
# and a message naming the file (line, column) and the reason, within a time limit (a hang
# fails the test), never "internal error": paths that are not regular files, numbers outside
# their physical ranges, a column named twice, reference channels that cannot give the VRC,
# results that are not finite. Reading only (`diagnose --check`, `measure` of short records):
# a few seconds under the sanitizers. Usage: cli_hardening.sh <vrelab binary> <source dir>
set -u
real_bin=$1
src=$2
cases=$src/cases
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
limit=30
all_output="$tmp/all-output"
bin=$real_bin
. "$(dirname "$0")/expect.sh"
expect() {  # as expect.sh's, under the time limit (timeout's 124 fails it), the messages kept for the last check
  local want=$1 pattern=$2
  shift 2
  timeout -k 5 "$limit" "$real_bin" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  cat "$tmp/out" "$tmp/err" >>"$all_output"
  if [ "$rc" -ne "$want" ] || ! grep -Eq -- "$pattern" "$tmp/err" "$tmp/out"; then
    echo "FAIL: vrelab $* -> rc $rc (want $want), stderr: $(tail -c 600 "$tmp/err")"
    fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
}
random_lab() {  # random_lab <name>: a fresh copy of the hand-written campaign with random runs
  rm -rf "${tmp:?}/$1"
  cp -r "$cases/lab-random" "$tmp/$1"
}
measure_args=(--on 1,2 --baseline 0,1 --frequency 10)
record=$src/fuzz/corpus/raw_csv/three-axes-sine  # 10 Hz along IA from t = 1 s, three reference axes
k1=(--K1 1.25)  # its output_mA states no scale factor: measure needs one

# ---- Paths that are not regular files: refused before they are opened.
random_lab fifo
rm "$tmp/fifo/gevs.csv" && mkfifo "$tmp/fifo/gevs.csv"
expect 2 "skipped: .*gevs\.csv: cannot open the PSD file: a FIFO \(named pipe\), not a regular file" diagnose --check "$tmp/fifo"
random_lab zero
sed -i 's/,gevs\.csv,/,\/dev\/zero,/' "$tmp/zero/runs.csv"
expect 2 "skipped: .*/dev/zero: cannot open the PSD file: a device, not a regular file" diagnose --check "$tmp/zero"
random_lab loop
rm "$tmp/loop/gevs.csv" && ln -s gevs.csv "$tmp/loop/gevs.csv"
expect 2 "skipped: .*gevs\.csv: cannot open the PSD file: a loop of symbolic links" diagnose --check "$tmp/loop"
random_lab folder
rm "$tmp/folder/gevs.csv" && mkdir "$tmp/folder/gevs.csv"
expect 2 "skipped: .*gevs\.csv: cannot open the PSD file: is a directory, not a file" diagnose --check "$tmp/folder"
mkfifo "$tmp/rec.fifo"
expect 2 "rec\.fifo: cannot open the series: a FIFO" measure "$tmp/rec.fifo" "${measure_args[@]}"
expect 2 "/dev/zero: cannot open the series: a device" measure /dev/zero "${measure_args[@]}"
ln -s rec-loop.h5 "$tmp/rec-loop.h5"
expect 2 "rec-loop\.h5: cannot open the series: a loop of symbolic links" measure "$tmp/rec-loop.h5" "${measure_args[@]}"
long="$tmp/$(printf 'a%.0s' {1..300})/case.toml"  # a name over the system's 255 bytes
expect 2 "cannot open the case file: the path is longer than the system allows" identify "$long"
deep="$(printf 'ab/%.0s' {1..1400})case.toml"  # a path over the system's 4096 bytes
expect 2 "\.\.\.\[4209 bytes\]\.\.\..*cannot open the case file: the path is longer than the system allows" identify "$deep"
mkdir -p "$tmp/o/sweep-folder"
expect 2 "--out: cannot write .*sweep-folder: is a directory, not a file" sweep "$cases/sweep-frequency.toml" --out "$tmp/o/sweep-folder"
expect 2 "--json: cannot write /dev/zero: a device" measure "$record" "${measure_args[@]}" --json /dev/zero

# ---- Physical ranges (docs/data-format.md, "Ranges and limits"): refused where they are read.
psd() {  # psd <name> <rows...>: lab-random with gevs.csv holding these rows
  local name=$1
  shift
  random_lab "$name"
  { echo "frequency_Hz,psd_IA_g2_per_Hz"; printf '%s\n' "$@"; } >"$tmp/$name/gevs.csv"
}
psd f-high 20,0.026 1e300,0.026
expect 2 "gevs\.csv:3: column frequency_Hz: 1e\+300 Hz is outside a frequency's range \[0\.01, 100000\] Hz" diagnose --check "$tmp/f-high"
psd f-low 1e-300,0.026 20,0.026
expect 2 "gevs\.csv:2: column frequency_Hz: 1e-300 Hz is outside a frequency's range" diagnose --check "$tmp/f-low"
psd level 20,1e300 2000,1e300
expect 2 "gevs\.csv:2: column psd_IA_g2_per_Hz: 1e\+300 g\^2/Hz is outside a PSD level's range \[1e-20, 10000\]" diagnose --check "$tmp/level"
psd band 1e299,0.026 1e300,0.026
expect 2 "gevs\.csv:2: column frequency_Hz: 1e\+299 Hz is outside" diagnose --check "$tmp/band"
psd rms 20,5000 2000,5000
expect 2 "gevs\.csv: column psd_IA_g2_per_Hz: the table's rms is 3146\.43 g, over the 1000 g" diagnose --check "$tmp/rms"
psd good 20,0.026 50,0.16 800,0.16 2000,0.026
expect 0 "15 shaker runs \(0 skipped\)" diagnose --check "$tmp/good"
awk -F, 'NR == 310 { $2 = "1e308" } 1' OFS=, "$record" >"$tmp/big-sample.csv"
expect 2 "big-sample\.csv:310:2: column output_mA: 1e\+308 output units is outside an output's range \|x\| <= 1e\+12" measure "$tmp/big-sample.csv" "${measure_args[@]}"
awk -F, 'NR == 311 { $3 = "-2e5" } 1' OFS=, "$record" >"$tmp/big-ref.csv"
expect 2 "big-ref\.csv:311:3: column ref_IA_g: -200000 g is outside a reference acceleration's range" measure "$tmp/big-ref.csv" "${measure_args[@]}"

# ---- A header naming a column twice; reference channels that do not give the VRC.
expect 2 "ref-column-twice:1:4: column 'ref_IA_g' appears twice in the header \(columns 3 and 4\)" measure "$src/fuzz/corpus/raw_csv/ref-column-twice" "${measure_args[@]}"
cut -d, -f1,2,4 "$record" >"$tmp/pa-only.csv"
expect 2 "pa-only\.csv: the reference channels cover PA only \(none for IA, OA\): without the input axis IA's channel .*give ref_IA_g \(or all three channels\) or --input-rms-g" measure "$tmp/pa-only.csv" "${measure_args[@]}" "${k1[@]}"
expect 0 "per axis \[-, [0-9.e+-]+, -\]; -: no channel" measure "$tmp/pa-only.csv" "${measure_args[@]}" "${k1[@]}" --input-rms-g 1.414
check "no nan or inf printed with one reference axis" bash -c "! grep -Eiq '(^|[^a-z])(nan|inf)([^a-z]|\$)' '$tmp/out'"
cut -d, -f1,2,3 "$record" >"$tmp/ia-only.csv"  # the drive axis alone: the VRC from its rms, the others' ratios "-"
expect 0 "per axis \[[0-9.e+-]+, -, -\]; -: no channel" measure "$tmp/ia-only.csv" "${measure_args[@]}" "${k1[@]}"
check "no nan or inf printed with the IA reference alone" bash -c "! grep -Eiq '(^|[^a-z])(nan|inf)([^a-z]|\$)' '$tmp/out'"
expect 0 "VRC \(input rms 1\.41[0-9]* g, reference channels\)" measure "$record" "${measure_args[@]}" "${k1[@]}"

# ---- An output in mA is not read as g: refused without a scale factor, the one the series
# states used (shake --series writes "# ...; K1 = 1.25 mA/g; ...").
expect 2 "three-axes-sine: the output column 'output_mA' is in mA, not g, and no scale factor is given: give --K1 \(mA per g\)" measure "$record" "${measure_args[@]}"
{ echo "# output in mA; K1 = 1.25 mA/g"; cat "$record"; } >"$tmp/stated.csv"
expect 0 "Output column 'output_mA', K1 = 1\.25 mA/g \(stated by the series, line 1\)" measure "$tmp/stated.csv" "${measure_args[@]}"
expect 0 "Note: the series states K1 = 1\.25 mA/g \(line 1\); --K1 2 used" measure "$tmp/stated.csv" "${measure_args[@]}" --K1 2
{ echo "# K1 = 1.25 V/g"; cat "$record"; } >"$tmp/stated-v.csv"
expect 2 "stated-v\.csv:1: the comment states K1 in V/g, the output column 'output_mA' is in mA" measure "$tmp/stated-v.csv" "${measure_args[@]}"
{ echo "# K1 = -3 mA/g"; cat "$record"; } >"$tmp/stated-neg.csv"
expect 2 "stated-neg\.csv:1: the comment states K1 = '-3': a scale factor is a positive number" measure "$tmp/stated-neg.csv" "${measure_args[@]}"

# ---- Results that are not finite: the command fails naming the quantity.
expect 2 "the result /[a-z_/0-9]+ is not a finite number \(inf\)" measure "$record" "${measure_args[@]}" --K1 1e-320

check "no message says internal error" bash -c "! grep -q 'internal error' '$all_output'"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
