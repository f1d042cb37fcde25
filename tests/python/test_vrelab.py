"""The Python module against the CLI: the same case gives the same JSON (to_dict() == the
CLI's --json, number for number: the same C++ writers make both, so equality is exact but for
wall-clock times), series round trips into NumPy, the CLI's exit-2 messages as
vrelab.InputError, and shake on two threads at once.

The *_equals_cli tests are consistency checks of the binding (the Python call and the CLI
give the same numbers), not of the physics, which the C++ tests check against independent
values. The independent numbers here: eq. (3) at 5 Hz against the ODE
(test_shake_equals_cli), k2 A^2 / 2 by hand (test_sweep_columns), the series' own mean
difference against the run's measured error (test_shake_series_round_trip...), and the raw
records' measured errors, CSV against HDF5 (test_campaign_writes_raw_records...).

Run by ctest (python_tests, label python) with PYTHONPATH at build/python and VRELAB_CLI at
the program of the same build."""
import inspect
import json
import math
import os
import subprocess
import threading
import tomllib

import numpy as np
import pytest

import vrelab

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("VRELAB_CLI", os.path.join(SRC, "build", "vrelab"))
CASES = os.path.join(SRC, "cases")

# Keys that hold wall-clock times: they differ between any two runs.
TIMES = {"wall_s", "wall_time_s", "elapsed_s", "cpu_s"}


def strip_times(x):
    if isinstance(x, dict):
        return {k: strip_times(v) for k, v in x.items() if k not in TIMES}
    if isinstance(x, list):
        return [strip_times(v) for v in x]
    return x


def cli(*args, check=True):
    return subprocess.run([CLI, *args], capture_output=True, text=True, check=check)


def cli_json(tmp_path, *args):
    out = tmp_path / "cli.json"
    cli(*args, "--json", str(out))
    return json.loads(out.read_text())


def case(name):
    return os.path.join(CASES, name)


def test_version_is_the_programs():
    out = cli("--version").stdout
    assert vrelab.__version__ in out and vrelab.git_describe in out


# ---- the CLI's JSON, number for number

def test_predict_equals_cli(tmp_path):
    path = case("paper-predict.toml")
    assert vrelab.predict(path).to_dict() == cli_json(tmp_path, "predict", path)


def test_results_print_their_headline_not_an_address(lab_example):
    p = vrelab.predict(case("paper-predict.toml"))
    text = repr(p)
    assert text.startswith("<vrelab.PredictResult total_g=") and " at 0x" not in text
    assert ("total_g=%.6g" % p.total_g) in text
    d = lab_example
    text = repr(d)
    assert text.startswith("<vrelab.Diagnosis verdict=") and repr(d.verdict) in text and " at 0x" not in text


def test_signatures_are_what_the_calls_take():
    import inspect
    for fn, params in ((vrelab.predict, ["case", "frequency_dependent", "frequency_Hz", "amplitude_g"]),
                       (vrelab.identify, ["case", "monte_carlo", "seed"]),
                       (vrelab.shake, ["case", "series", "seed"]), (vrelab.frequency, ["case"])):
        sig = inspect.signature(fn)
        assert list(sig.parameters) == params, (fn.__name__, sig)
    sig = inspect.signature(vrelab.predict)
    assert sig.parameters["frequency_dependent"].default is False
    assert [sig.parameters[p].kind for p in ("frequency_Hz", "amplitude_g")] == [inspect.Parameter.KEYWORD_ONLY] * 2
    # The signature's names are the call's keywords: bound and called, the same result.
    bound = sig.bind(case("shake-sine.toml"), frequency_dependent=True)
    assert vrelab.predict(*bound.args, **bound.kwargs).frequency_dependent_g is not None


def test_frequency_dependent_predict_equals_cli(tmp_path):
    path = case("shake-sine.toml")
    r = vrelab.predict(path, frequency_dependent=True)
    assert r.to_dict() == cli_json(tmp_path, "predict", path, "--frequency-dependent")
    assert r.frequency_dependent_g is not None and r.printed_g is not None


def test_second_order_is_the_clis_and_in_the_total(tmp_path):
    # The pickoff beyond first order (docs/frequency.md): the CLI's numbers, in the total.
    path = case("shake-second-order-navmat.toml")
    r = vrelab.predict(path, frequency_dependent=True)
    j = cli_json(tmp_path, "predict", path, "--frequency-dependent")["frequency_dependent"]
    assert r.second_order_g == j["terms"]["pickoff_second_order"] and r.frequency_dependent_g == j["total_g"]
    assert r.second_order_error_g == j["second_order_error_g"] and not j["second_order_left_out"]
    assert -1e-3 < r.second_order_g < -7e-4 and 0 < r.second_order_error_g < 1e-5
    assert vrelab.predict(case("shake-sine.toml"), frequency_dependent=True).second_order_g == 0.0
    assert vrelab.predict(path).second_order_g is None


def test_identify_equals_cli(tmp_path):
    path = case("paper-static.toml")
    r = vrelab.identify(path)
    assert r.to_dict() == cli_json(tmp_path, "identify", path)
    assert r.methods == ["paper_printed", "paper_corrected", "least_squares"]
    assert set(r.estimate("least_squares")) == set(r.truth)
    with pytest.raises(KeyError):
        r.estimate("no_such_method")


def test_shake_equals_cli(tmp_path):
    path = case("shake-sine.toml")
    r = vrelab.shake(path)
    d = cli_json(tmp_path, "shake", path)
    assert strip_times(r.to_dict()) == strip_times(d)
    # eq. (3) holds at 5 Hz (1 % of the loop crossover): the measured error is the prediction.
    assert r.measured_g == pytest.approx(r.predicted_g, rel=1e-3)
    # Through the loop as the JSON has it, and closer still to the ODE at 5 Hz.
    assert r.predicted_frequency_dependent_g == d["predicted_frequency_dependent_g"]
    assert abs(r.measured_g - r.predicted_frequency_dependent_g) <= abs(r.measured_g - r.predicted_g)


def test_diagnose_equals_cli(tmp_path, lab_example):
    folder = case("lab-example")
    r = lab_example
    assert strip_times(r.to_dict()) == strip_times(cli_json(tmp_path, "diagnose", folder))
    assert r.verdict and r.runs > 0
    # The held-out floor: the runs' floors' rms, and the shrinkage above it in quadrature,
    # from the JSON's numbers by hand.
    d = r.to_dict()
    s = d["shrinkage"]
    before, after, floor = s["rms_before_g"], s["rms_after_g"], s["rms_floor_g"]
    assert r.rms_floor_g == floor > 0
    runs = d["runs"]
    assert floor == pytest.approx(math.sqrt(sum(x["heldout_floor_g"] ** 2 for x in runs) / len(runs)), rel=1e-12)
    above = 1 - math.sqrt(max(0.0, after**2 - floor**2)) / math.sqrt(before**2 - floor**2)
    assert r.shrinkage_above_floor == pytest.approx(above, rel=1e-12)
    assert s["fraction_above_floor_removed"] == pytest.approx(above, rel=1e-12)


def test_diagnose_on_one_thread_is_the_same_numbers(lab_example):
    # The fixture ran on every core (threads=0); one thread gives the same numbers.
    assert "threads" in inspect.signature(vrelab.diagnose).parameters
    one = vrelab.diagnose(case("lab-example"), threads=1).to_dict()
    every = lab_example.to_dict()
    assert one["threads"] == 1 and every["threads"] == (os.cpu_count() or 1)
    del one["threads"], every["threads"]
    assert strip_times(one) == strip_times(every)


def test_frequency_equals_cli_summary(tmp_path):
    with open(case("frequency.toml"), "rb") as f:
        d = tomllib.load(f)
    d["frequency_study"].update(points=6, ode_points=2)  # a small grid: two ODE runs
    path = tmp_path / "frequency-small.toml"
    path.write_text(vrelab.case_toml(d))
    r = vrelab.frequency(str(path))
    cli("frequency", str(path), "--out", str(tmp_path / "f"))
    with open(tmp_path / "f" / "summary.json") as f:
        summary = json.load(f)
    assert strip_times(r.to_dict()) == strip_times(summary)
    assert r.mechanisms


def test_dict_case_is_the_file_case():
    path = case("paper-predict.toml")
    with open(path, "rb") as f:
        d = tomllib.load(f)
    from_dict = vrelab.load_case(d)
    assert from_dict.path == "<dict>"
    assert vrelab.predict(from_dict).terms == vrelab.predict(path).terms
    assert from_dict.content == vrelab.load_case(path).content


# ---- NumPy series

def test_shake_series_round_trip_equals_the_cli_series_file(tmp_path):
    path = case("shake-sine-lab.toml")
    r = vrelab.shake(path, series=True)
    csv = tmp_path / "ts.csv"
    d = cli_json(tmp_path, "shake", path, "--series", str(csv))
    assert strip_times(r.to_dict()) == strip_times(d)
    data = np.loadtxt(csv, delimiter=",", comments="#", skiprows=3)
    s = r.series
    names = ["time_s", "input_IA_g", "input_PA_g", "input_OA_g", "output_mA"]
    assert list(s) == names
    for i, n in enumerate(names):
        assert isinstance(s[n], np.ndarray) and s[n].dtype == np.float64 and s[n].shape == (r.samples,)
        # the file holds 10 (inputs) and 13 (output) significant digits
        np.testing.assert_allclose(s[n], data[:, i], rtol=1e-9, atol=1e-12)
    # the series measures what the run measured: the mean output over the measuring window
    # minus the mean at rest (t < 0), over K1 = 1.25 mA/g. Both means are over whole periods of
    # the same samples (noise and quantisation included), so they agree to rounding (bound 1e-9
    # relative, ~3e-13 g). The window: whole 80 Hz periods at 20 kHz, 250 samples each.
    m = d["measurement"]
    t, u = s["time_s"], s["output_mA"]
    rest, on = t < 0, (t >= m["settle_s"]) & (t < m["settle_s"] + m["periods"] / 80.0)
    assert on.sum() == 250 * m["periods"] > 0 and rest.sum() > 0
    assert (u[on].mean() - u[rest].mean()) / 1.25 == pytest.approx(r.measured_g, rel=1e-9, abs=0)


def test_sweep_columns(tmp_path):
    d = {
        "coefficients": {"K1": 1.25, "k0": 0.0, "k1_asym": 0.0, "k2": 1.5e-5, "k3": 0.0, "k4": 0.0,
                         "delta_OA": 0.0, "delta_PA": 0.0, "k_IP": 0.0, "k_IO": 0.0, "k_PO": 0.0,
                         "k_PP": 0.0, "k_OO": 0.0},
        "orientation": {"a_g": [0.0, 0.0, 1.0]},
        "sweep": {"frequencies_Hz": [5.0, 10.0], "amplitudes_g": [1.0], "directions": [[1.0, 0.0, 0.0]]},
    }
    try:
        r = vrelab.sweep(d, threads=1)
    except vrelab.InputError as e:  # the [sweep] keys are the case reader's; show them
        pytest.fail(str(e))
    assert r.conditions == 2 and r.written == 2 and not r.failures
    cols = r.columns
    assert all(isinstance(v, np.ndarray) and len(v) == 2 for v in cols.values())
    # By hand: k2 alone, a 1 g peak along IA, IA horizontal: eq. (3) is k2 A^2 / 2 = 7.5 ug at
    # both frequencies; the ODE (k2 in the loop, |H|^2 = 1 - O((f / 500 Hz)^2) <= 4e-4 off) within 1 %.
    np.testing.assert_allclose(cols["predicted_eq3_g"], [7.5e-6, 7.5e-6], rtol=1e-12)
    np.testing.assert_allclose(cols["measured_g"], [7.5e-6, 7.5e-6], rtol=1e-2)
    # Integer columns stay integers (index, steps), the checksum text; so in the DataFrame.
    assert cols["index"].dtype == np.int64 and list(cols["index"]) == [0, 1]
    assert cols["steps"].dtype == np.int64 and cols["frequency_Hz"].dtype == np.float64
    assert cols["checksum"].dtype.kind == "U" and all(len(c) == 8 for c in cols["checksum"])
    pytest.importorskip("pandas")
    frame = r.frame()
    assert list(frame.columns) == list(cols)
    assert all(frame[k].dtype == (object if v.dtype.kind == "U" else v.dtype) for k, v in cols.items())


# ---- errors

def test_bad_case_file_raises_input_error_with_the_cli_message(tmp_path):
    bad = tmp_path / "typo.toml"
    bad.write_text(open(case("ideal-static.toml")).read().replace("angle_sigma_arcsec", "angle_sigma_arcsex"))
    p = cli("identify", str(bad), check=False)
    assert p.returncode == 2
    with pytest.raises(vrelab.InputError) as e:
        vrelab.identify(str(bad))
    assert isinstance(e.value, ValueError)
    assert p.stderr.strip() == "vrelab: error: " + str(e.value)


def test_missing_file_and_missing_table():
    with pytest.raises(vrelab.InputError, match="no such file"):
        vrelab.load_case("/no/such/case.toml")
    with pytest.raises(vrelab.InputError, match=r"paper-static.toml: shake needs a \[orientation\] table"):
        vrelab.shake(case("paper-static.toml"))


def test_bad_dict_names_the_dict_and_the_key():
    with open(case("paper-predict.toml"), "rb") as f:
        d = tomllib.load(f)
    d["coefficients"]["k2"] = math.nan
    with pytest.raises(vrelab.InputError, match=r"^lab-1:\d+: .*k2"):
        vrelab.load_case(d, name="lab-1")
    d["coefficients"]["k2"] = 1e-5
    d["vibraton"] = {}
    with pytest.raises(ValueError, match="did you mean 'vibration'"):
        vrelab.load_case(d)
    with pytest.raises(vrelab.InputError, match="cannot be written as TOML"):
        vrelab.load_case({"run": {"seed": object()}})


def test_solver_error_is_its_own_type_with_the_cli_message(tmp_path):
    assert issubclass(vrelab.SolverError, RuntimeError)
    assert not issubclass(vrelab.SolverError, ValueError)
    # a tolerance CVODE refuses at its first step: a real solver failure, raised by the library
    text = open(case("shake-sine.toml")).read()
    bad = tmp_path / "too-accurate.toml"
    bad.write_text(_with_shake_key(text, "relative_tolerance = 1e-18"))
    p = cli("shake", str(bad), check=False)
    assert p.returncode == 2
    with pytest.raises(vrelab.SolverError) as e:
        vrelab.shake(str(bad))
    assert p.stderr.strip() == "vrelab: error: " + str(e.value)
    assert e.value.call == "CVode" and e.value.flag < 0 and e.value.t_s == 0.0


def _with_shake_key(text, line):
    """The case text with `line` in its [shake] table (added when the case has none)."""
    lines = text.splitlines()
    if "[shake]" in lines:
        i = lines.index("[shake]")
        return "\n".join(lines[:i + 1] + [line] + lines[i + 1:]) + "\n"
    return text + "\n[shake]\n" + line + "\n"


def test_huge_int_in_a_dict_is_input_error():
    with pytest.raises(vrelab.InputError, match="run.seed: the integer does not fit in 64 bits"):
        vrelab.load_case({"run": {"seed": 2 ** 70}})


# ---- threads

def test_two_threads_shake_at_once():
    path = case("shake-sine.toml")
    alone = vrelab.shake(path).to_dict()
    results, errors = [None, None], []

    def run(i):
        try:
            results[i] = vrelab.shake(path).to_dict()
        except Exception as e:  # pragma: no cover
            errors.append(e)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert strip_times(results[0]) == strip_times(alone) == strip_times(results[1])


def test_shake_releases_the_gil():
    """While a shake runs on a thread, the main thread keeps running Python: no gap in its
    loop as long as the run (with the GIL held, the loop would stop for the whole run)."""
    import time
    # a random run of a minute's record (~0.3 s: one step per sample since issue 14; a sine
    # run reaches its steady state in ms)
    with open(case("shake-random-gevs.toml"), "rb") as f:
        d = tomllib.load(f)
    d["vibration"]["duration_s"] = 60.0
    c = vrelab.load_case(d)
    done, gaps = threading.Event(), []
    start = {}

    def run():
        start["t"] = time.perf_counter()
        vrelab.shake(c)
        start["wall"] = time.perf_counter() - start["t"]
        done.set()

    t = threading.Thread(target=run)
    t.start()
    last = time.perf_counter()
    while not done.is_set():
        time.sleep(0.001)
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
    t.join()
    assert start["wall"] > 0.05  # a run long enough to tell
    assert max(gaps) < 0.5 * start["wall"]


# ---- Ctrl-C

def _interrupt_after(seconds, call):
    """Sends Ctrl-C (SIGINT) to this process after `seconds`; `call` must raise
    KeyboardInterrupt, within a few seconds of the signal. Returns the seconds it took."""
    import signal
    import time
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        call()
    timer.join()
    return time.perf_counter() - start


def long_random_case():
    with open(case("shake-random-gevs.toml"), "rb") as f:
        d = tomllib.load(f)
    d["vibration"]["duration_s"] = 600.0  # ten minutes of random record: seconds uninterrupted
    return vrelab.load_case(d)


@pytest.mark.parametrize("series", [True, False])
def test_ctrl_c_interrupts_a_shake(series):
    # the ODE looks at the cancel flag at every output time; the binding at Python's signals every 50 ms
    assert _interrupt_after(0.5, lambda: vrelab.shake(long_random_case(), series=series)) < 5


def test_ctrl_c_interrupts_reproduce_and_writes_no_report(tmp_path):
    # the paper's experiment with 2400 shaker runs in its amplitude study (tens of seconds on
    # one thread; cases/paper.toml itself takes about a second since issue 14)
    with open(case("paper.toml"), "rb") as f:
        d = tomllib.load(f)
    d["reproduce"]["amplitudes_g"] = list(np.linspace(0.5, 4.0, 200))
    out = tmp_path / "paper"
    assert _interrupt_after(0.5, lambda: vrelab.reproduce(d, str(out), threads=1, plots=False)) < 10
    assert not (out / "report.html").exists() and not (out / "summary.json").exists()


def test_ctrl_c_interrupts_a_campaign_and_writes_nothing(tmp_path):
    # raw records of 20 s per run: a campaign of tens of seconds (summaries alone take < 1 s)
    text = open(case("campaign.toml")).read().replace("[campaign]", "[campaign]\nraw_series = true\nraw_record_s = 20.0", 1)
    long_campaign = tmp_path / "long-campaign.toml"
    long_campaign.write_text(text)
    out = tmp_path / "c1"
    assert _interrupt_after(0.5, lambda: vrelab.campaign(str(long_campaign), str(out))) < 10
    assert not (out / "runs.csv").exists()


# ---- a campaign in memory

def columns(path):
    import csv
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    out = {}
    for i, name in enumerate(rows[0]):
        values = [r[i] for r in rows[1:]]
        try:
            out[name] = np.array([float(v) for v in values])
        except ValueError:
            out[name] = values
    return out


def test_diagnose_data_in_memory_equals_the_folder(lab_example):
    folder = case("lab-example")
    static, runs = columns(os.path.join(folder, "static.csv")), columns(os.path.join(folder, "runs.csv"))
    with open(os.path.join(folder, "manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    a = strip_times(vrelab.diagnose_data(static, runs, manifest, name="lab-1").to_dict())
    b = strip_times(lab_example.to_dict())
    assert a.pop("data") == "lab-1" and b.pop("data") == folder  # the data as named
    assert a == b
    del runs["frequency_Hz"]
    with pytest.raises(vrelab.InputError, match="^lab-1/runs.csv: the header lacks column 'frequency_Hz'"):
        vrelab.diagnose_data(static, runs, manifest, name="lab-1")


def test_campaign_writes_raw_records_as_csv_or_hdf5(tmp_path):
    # vrelab.campaign(..., raw_format=) as `vrelab campaign --raw-format`: a small raw campaign
    # (2 runs of 0.2 s) written both ways; the same samples give the same diagnosis inputs
    # (each run's measured error as read back), the HDF5 files are HDF5 (the signature), and
    # a bad format or HDF5 for a case of summaries is refused.
    text = open(case("campaign.toml")).read()
    for key, value in [("frequencies_Hz", "[100.0]"), ("amplitudes_g", "[2.0]"), ("directions", "[[1.0, 0.0, 0.0]]")]:
        start = text.index(key + " = ")
        text = text[:start] + key + " = " + value + text[text.index("\n", start):]
    summaries = tmp_path / "small.toml"
    summaries.write_text(text)
    raw = tmp_path / "small-raw.toml"
    raw.write_text(text.replace("[campaign]", "[campaign]\nraw_series = true\nraw_record_s = 0.2", 1))
    written = {}
    for fmt, ext in [("csv", ".csv"), ("hdf5", ".h5")]:
        out = tmp_path / fmt
        w = vrelab.campaign(str(raw), str(out), raw_format=fmt)
        assert w.raw_records and w.runs == 2
        records = sorted(os.listdir(out / "records"))
        assert len(records) == 2 and all(r.endswith(ext) for r in records), records
        if fmt == "hdf5":
            assert (out / "records" / records[0]).read_bytes()[:8] == b"\x89HDF\r\n\x1a\n"
        written[fmt] = columns(out / "runs.csv")
    assert list(written["csv"]["id"]) == list(written["hdf5"]["id"])
    assert [s.replace(".csv", ".h5") for s in written["csv"]["series"]] == list(written["hdf5"]["series"])
    # The same samples read back from either format give each run the same measured error (the
    # diagnosis' input, ~230 ug here): the CSV holds the output to 13 significant digits (near
    # 1 mA), the HDF5 file whole doubles, so the windows' means differ by ~1e-13 g: bound 1e-12 g.
    measured = {fmt: [r["measured_g"] for r in vrelab.diagnose(str(tmp_path / fmt)).to_dict()["runs"]] for fmt in written}
    assert len(measured["csv"]) == 2 and all(abs(x) > 1e-5 for x in measured["csv"]), measured
    assert measured["hdf5"] == pytest.approx(measured["csv"], rel=0, abs=1e-12)
    with pytest.raises(ValueError, match="raw_format must be 'csv' or 'hdf5'"):
        vrelab.campaign(str(raw), str(tmp_path / "bad"), raw_format="h5")
    with pytest.raises(vrelab.InputError, match="--raw-format hdf5: the case writes summaries"):
        vrelab.campaign(str(summaries), str(tmp_path / "sum"), raw_format="hdf5")
    assert not (tmp_path / "sum" / "runs.csv").exists()
