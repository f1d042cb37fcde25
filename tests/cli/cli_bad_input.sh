#!/usr/bin/env bash
# The installed command line: exit code 2 and a message on stderr for bad input, exit 0
# and a JSON file for good input. Usage: cli_bad_input.sh <vrelab binary> <cases dir>
set -u
bin=$1
cases=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/expect.sh"

sed 's/^k2 = .*/k2 = nan/' "$cases/ideal-static.toml" >"$tmp/nan.toml"
expect 2 'k2: must be a finite number' identify "$tmp/nan.toml" --json "$tmp/o/nan.json"
[ -e "$tmp/o/nan.json" ] && { echo "FAIL: partial output written"; fail=$((fail + 1)); }
# Each kind of bad input: exit 2, the key named, no output file.
bad() {  # bad <name> <sed expression> <stderr regex> [case]
  local name=$1 expr=$2 pattern=$3 base=${4:-ideal-static.toml}
  sed -E "$expr" "$cases/$base" >"$tmp/$name.toml"
  expect 2 "$pattern" identify "$tmp/$name.toml" --json "$tmp/o/$name.json"
  [ -e "$tmp/o/$name.json" ] && { echo "FAIL: $name: partial output written"; fail=$((fail + 1)); }
  return 0
}
bad typo 's/^angle_sigma_arcsec/angle_sigma_arcsex/' "angle_sigma_arcsex: unknown key \(did you mean 'angle_sigma_arcsec'\?\)"
bad nocoef '/^k4 = /d' '\[coefficients\] k4: missing'
# Issue 13 item 10: a typo of a required key is an unknown key with its match, on its line.
bad typo_required 's/^k2 = /k_2 = /' "typo_required.toml:[0-9]+: \[coefficients\] k_2: unknown key \(did you mean 'k2'\?\); k2 is required"
# ... and a static orientation is gravity, |a| = 1 g, everywhere (0 g and 10 g refused).
sed 's/^a_g = .*/a_g = [0.0, 0.0, 0.0]/' "$cases/paper-predict.toml" >"$tmp/g0.toml"
expect 2 'g0.toml:[0-9]+: \[orientation\] a_g: a static orientation is gravity .*\|a\| = 1 g .*got \|a\| = 0 g' predict "$tmp/g0.toml"
sed 's/^a_g = .*/a_g = [10.0, 0.0, 0.0]/' "$cases/paper-predict.toml" >"$tmp/g10.toml"
expect 2 '\[orientation\] a_g: .*got \|a\| = 10 g' predict "$tmp/g10.toml"
sed 's/^orientations_g = .*/orientations_g = [[0.0, 0.0, 10.0]]/' "$cases/campaign.toml" >"$tmp/g10c.toml"
expect 2 '\[campaign\] orientations_g: .*got \|a\| = 10 g' campaign "$tmp/g10c.toml" --out "$tmp/o/g10c"
bad negative 's/^noise_sigma_ug = .*/noise_sigma_ug = -1.0/' 'noise_sigma_ug: must not be negative'
bad empty 's/^positions_per_series = .*/positions = []/' 'the position set is empty'
bad rank 's/^fixed = .*/fixed = { }/' 'rank 11 of 13'
bad bigint 's/^repeats = .*/repeats = 4294967297/' 'repeats: must be at most'
bad notarray 's/^positions_per_series = .*/positions = "abc"/' 'positions: expected an array of tables'
# Issue 13 item 1: a 4-position tumble entered as series/angle_deg at multiples of 90 deg sees no
# cross term: rank 6 of 9, refused, not k_IP from rounding.
bad tumble 's/^positions_per_series = .*/positions = [{series=1,angle_deg=0},{series=1,angle_deg=90},{series=1,angle_deg=180},{series=1,angle_deg=270},{series=2,angle_deg=0},{series=2,angle_deg=90},{series=2,angle_deg=180},{series=2,angle_deg=270},{series=3,angle_deg=0},{series=3,angle_deg=90},{series=3,angle_deg=180},{series=3,angle_deg=270}]/; s/^fixed = .*/fixed = { k1_asym = 2.0e-5, k3 = 1.0e-6, k4 = 2.0e-7, k_PP = 0.0 }/' 'rank 6 of 9'
mkdir -p "$tmp/o/isdir.json"
expect 2 'cannot write' identify "$cases/ideal-static.toml" --json "$tmp/o/isdir.json"
ls "$tmp/o" | grep -q 'tmp' && { echo "FAIL: a temporary file was left behind"; fail=$((fail + 1)); }
expect 2 'missing.toml: cannot open the case file' identify "$tmp/missing.toml"
expect 2 'required' identify
expect 2 'subcommand is required' bogus-command
expect 0 'least_squares' identify "$cases/ideal-static.toml" --json "$tmp/o/id.json"
[ -s "$tmp/o/id.json" ] || { echo "FAIL: no JSON written"; fail=$((fail + 1)); }
expect 0 'total' predict "$cases/paper-predict.toml" --json "$tmp/o/p.json"
expect 0 'vrelab 0' --version
# A solver failure is reported with the call and the simulated time, exit 2: rtol 1e-30 is
# accepted by the case reader and refused by CVODE itself at its first step.
sed 's/^\[run\]/[shake]\nrelative_tolerance = 1e-30\n\n[run]/' "$cases/shake-sine.toml" >"$tmp/solver.toml"
expect 2 'solver failure in CVode at simulated time t = [0-9.e+-]+ s \(CV_TOO_MUCH_ACC\)' shake "$tmp/solver.toml" --json "$tmp/o/solver.json"
sed 's/^\[plant\]/[plant]\nphase_margin_deg = 85.0/' "$cases/shake-sine.toml" >"$tmp/design.toml"
expect 2 'phase_margin_deg' shake "$tmp/design.toml"
expect 0 'measured vibration error' shake "$cases/shake-sine.toml" --json "$tmp/o/shake.json"
# Issue 13 item 8: an unstable loop names the file, the table and the keys that set the loop;
# integrator_zero_ratio out of its range is a validation error on that key; a directory given
# as the case file says so.
sed 's/^integrator_Hz = .*/integrator_Hz = 5000.0/' "$cases/shake-physical.toml" >"$tmp/unstable.toml"
expect 2 'unstable.toml:[0-9]+: \[plant\]: the closed loop is not stable .*the loop is set by .*integrator_Hz = 5000' shake "$tmp/unstable.toml"
sed 's/^\[plant\]/[plant]\nintegrator_zero_ratio = 1e-12/' "$cases/shake-sine.toml" >"$tmp/izr.toml"
expect 2 'izr.toml:[0-9]+: \[plant\] integrator_zero_ratio: must lie in \[1e-4, 0.5\]' shake "$tmp/izr.toml"
expect 2 'cannot open the case file: is a directory' shake "$cases"
# Issue 13 item 4: values that made results inf/NaN with exit 0 are range errors on their key;
# campaign writes nothing.
sed 's/^K1 = .*/K1 = 1e308/' "$cases/campaign.toml" >"$tmp/k1.toml"
expect 2 'k1.toml:[0-9]+: \[coefficients\] K1: must lie in \(0, 1e\+06\] output units per g, got 1e\+308' campaign "$tmp/k1.toml" --out "$tmp/o/k1"
[ -e "$tmp/o/k1/static.csv" ] && { echo "FAIL: campaign wrote static.csv for K1 = 1e308"; fail=$((fail + 1)); }
bad bigk2 's/^k2 = .*/k2 = 5.0/' '\[coefficients\] k2: must lie in \[-1, 1\] in its unit'
bad fixedk1 's/^fixed = .*/fixed = { k1_asym = 1e300, k_PP = 0.0, k_OO = 0.0 }/' '\[identification.fixed\] k1_asym: must lie in'
sed 's/^amplitude_g = .*/amplitude_g = [1e6, 0.0, 0.0]/' "$cases/shake-sine.toml" >"$tmp/amp.toml"
expect 2 '\[vibration\] amplitude_g: amplitudes must be at most 1000 g, got 1e\+06 g' shake "$tmp/amp.toml"
# Issue 13 item 5: absurd finite values are estimated before the run and refused with the
# estimate, the key and the flag (they ran with no end and no word).
sed 's/^frequency_Hz = .*/frequency_Hz = 1e9/' "$cases/shake-sine.toml" >"$tmp/f9.toml"
expect 2 'f9.toml: this would take ~1.08e\+09 ODE steps .*from \[vibration\] frequency_Hz.*--no-work-limit' shake "$tmp/f9.toml"
sed 's/^duration_s = .*/duration_s = 1e9/' "$cases/shake-random-gevs.toml" >"$tmp/dur.toml"
expect 2 'would take ~4e\+13 ODE steps.*set by \[vibration\] duration_s' shake "$tmp/dur.toml"
sed 's/^sample_rate_Hz = .*/sample_rate_Hz = 1e12/' "$cases/shake-sine-lab.toml" >"$tmp/rate.toml"
expect 2 'from \[readout\] sample_rate_Hz.*--no-work-limit' shake "$tmp/rate.toml"
sed 's/^type = "from_coefficients".*/type = "from_coefficients"\n[plant.effects.mechanical_mode]\nfrequency_Hz = 1e8\ndamping_ratio = 0.02/' "$cases/shake-sine.toml" >"$tmp/mode.toml"
expect 2 "highest frequency 1e\\+08 Hz, from the plant's fastest pole" shake "$tmp/mode.toml"
expect 2 'samples.*set by --monte-carlo' identify "$cases/ideal-static.toml" --monte-carlo 1000000000
sed 's/^frequencies_Hz = \[10.0, 40.0/frequencies_Hz = [10.0, 4.0e8/' "$cases/campaign.toml" >"$tmp/cf.toml"
expect 2 'highest frequency 4e\+08 Hz, from \[campaign\] frequencies_Hz.*--no-work-limit' campaign "$tmp/cf.toml" --out "$tmp/o/cf"
[ -e "$tmp/o/cf" ] && { echo "FAIL: campaign wrote a folder beyond the work limit"; fail=$((fail + 1)); }
# [[campaign.random_runs]]: the PSD file relative to the case file, its keys checked by name.
mkdir -p "$tmp/rr/psd" && cp "$cases/psd/gevs-ia.csv" "$tmp/rr/psd/"
rr() { cat "$cases/campaign.toml" - >"$tmp/rr/$1.toml"; }
printf '\n[[campaign.random_runs]]\npsd = "psd/nope.csv"\n' | rr nofile
expect 2 'nofile.toml:[0-9]+: \[campaign.random_runs\[1\]\] psd: no PSD file .*psd/nope.csv' campaign "$tmp/rr/nofile.toml" --out "$tmp/o/rr1"
printf '\n[[campaign.random_runs]]\npsd = "psd/gevs-ia.csv"\nrms_g = -1.0\n' | rr rms
expect 2 'rms.toml:[0-9]+: \[campaign.random_runs\[1\]\] rms_g: must be positive' campaign "$tmp/rr/rms.toml" --out "$tmp/o/rr2"
printf '\n[[campaign.random_runs]]\npsd = "psd/gevs-ia.csv"\nsine_amplitude_g = 2.0\n' | rr sine
expect 2 'needs sine_frequency_Hz, sine_amplitude_g and sine_direction' campaign "$tmp/rr/sine.toml" --out "$tmp/o/rr3"
sed 's/^run_sigma_ug = .*/random_record_s = 1e9/' "$cases/campaign.toml" >"$tmp/rr/rec.toml"
expect 2 'random_record_s: must lie in \(0, 3600\] s' campaign "$tmp/rr/rec.toml" --out "$tmp/o/rr4"
# Issue 13 item 6: min_measure_s = 1e9 is refused by its range, not overflowed in an int (which
# would drop it and measure 4 periods).
sed 's/^min_measure_s = .*/min_measure_s = 1e9/' "$cases/shake-sine-lab.toml" >"$tmp/measure.toml"
expect 2 'measure.toml:[0-9]+: \[shake\] min_measure_s = 1000000000: must be in \[0, 1000000\] s' shake "$tmp/measure.toml"
# A PSD table whose frequencies do not increase: the row is named.
sed 's/^psd_IA = .*/psd_IA = [[20.0, 0.026], [800.0, 0.16], [50.0, 0.16], [2000.0, 0.026]]/' "$cases/shake-random-gevs.toml" >"$tmp/psd.toml"
expect 2 'psd_IA: .*row 3' shake "$tmp/psd.toml" --json "$tmp/o/psd.json"
[ -e "$tmp/o/psd.json" ] && { echo "FAIL: psd: partial output written"; fail=$((fail + 1)); }
expect 0 'measured vibration error' shake "$cases/shake-physical.toml"
# reproduce: a case without the [reproduce] table, and a missing case, exit 2 with no report.
expect 2 'reproduce needs a \[reproduce\] table' reproduce "$cases/paper-static.toml" --out "$tmp/o/rep"
expect 2 'missing.toml: cannot open the case file' reproduce "$tmp/missing.toml" --out "$tmp/o/rep"
[ -e "$tmp/o/rep" ] && { echo "FAIL: reproduce: output written for bad input"; fail=$((fail + 1)); }
# diagnose: a folder without a manifest; a campaign folder that works (four of
# cases/lab-example's runs, diagnosed with the default settings: the natural-form fits, the
# held-out evidence and the ODE re-simulation under the sanitizers in about 22 s of CPU; all
# ten take 125 s, and LabDataCampaign.RoundTripAndTheHandWrittenExample diagnoses them in the
# Release build's suite).
expect 2 'nowhere/manifest.toml: cannot open the manifest' diagnose "$tmp/nowhere"
cp -r "$cases/lab-example" "$tmp/lab"
awk '/^#/ || /^id,/ || /^ia-40Hz-4g,/ || ++n <= 3' "$cases/lab-example/runs.csv" >"$tmp/lab/runs.csv"
expect 0 'Verdict: explained by pickoff_nonlinearity' diagnose "$tmp/lab"
check "the four runs diagnosed and re-simulated on the ODE" grep -q 'Re-simulated on the ODE plant (4 runs' "$tmp/out"
# ... and the same folder, cut to its first run and run ia-40Hz-4g, whose raw record has a NaN
# sample: that run is skipped with file and line, the other diagnosed (one run, no gap: the
# diagnosis stops at the gap, ~7 s of CPU under the sanitizers, where three runs take 21 s).
awk '/^#/ || /^id,/ || /^ia-40Hz-4g,/ || ++n <= 1' "$cases/lab-example/runs.csv" >"$tmp/lab/runs.csv"
awk 'BEGIN { print "time_s,output_mA"; for (k = 0; k <= 130; ++k) print -0.02 + 0.001 * k "," (k == 70 ? "nan" : "0.88") }' \
  >"$tmp/lab/rec.csv"  # 1 kHz, 4 periods of 40 Hz under vibration; the NaN on line 72
sed -i -e 's/^id,frequency_Hz,.*sigma_ug$/&,series,rest_from_s,rest_to_s,on_from_s,on_to_s/' \
  -e 's/^\(ia-40Hz-4g,.*\)$/\1,rec.csv,-0.0155,-0.0045,0.0045,0.1045/' "$tmp/lab/runs.csv"
expect 2 "skipped: .*rec.csv:72: a sample is not a finite number" diagnose --check "$tmp/lab"
# diagnose's settings, from the command line over the manifest's [diagnose]: a bad one exits 2
# naming the key and why, before any output.
expect 2 'significance_sigma = -1: must be a positive' diagnose "$cases/lab-example" --significance-sigma -1 --json "$tmp/o/s.json"
[ -e "$tmp/o/s.json" ] && { echo "FAIL: diagnose settings: output written for bad input"; fail=$((fail + 1)); }
printf '\n[diagnose]\nsignificance_sigm = 4.0\n' >>"$tmp/lab/manifest.toml"
expect 2 'manifest.toml:[0-9]+: \[diagnose\] significance_sigm: unknown key' diagnose "$tmp/lab"
sed -i 's/^significance_sigm = .*/explained_shrinkage = 1.5/' "$tmp/lab/manifest.toml"
expect 2 '\[diagnose\] explained_shrinkage = 1.5: .*in \(0, 1\]' diagnose "$tmp/lab"
sed -i 's/^explained_shrinkage = .*/explained_shrinkage = 0.8/' "$tmp/lab/manifest.toml"
# ... the settings good again: the NaN run skipped (exit 2), the other diagnosed.
expect 2 'Verdict: no significant gap' diagnose "$tmp/lab" --significance-sigma 4 --no-pairs --resimulate-runs 0
check "the NaN run skipped, the other diagnosed" grep -q '1 shaker runs (1 skipped)' "$tmp/out"
expect 2 'diagnose --check: reads and checks only' diagnose --check "$cases/lab-example" --json "$tmp/o/c.json"
[ -e "$tmp/o/c.json" ] && { echo "FAIL: diagnose --check wrote JSON"; fail=$((fail + 1)); }
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
