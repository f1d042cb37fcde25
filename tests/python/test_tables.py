"""Results as tables and predict over arrays (docs/python.md, "Tables" and "predict over arrays").

The tables are made from to_dict() (the CLI's JSON): checked here cell for cell against it, with
the naming of vector keys per axis (orientation_g -> orientation_IA_g) and the dtypes (integers
int64, not float). predict over arrays is checked element for element against a loop of scalar
calls, exactly (the same C++ path makes both), and the scalar call with frequency_Hz and
amplitude_g against a case file holding those values (the CLI's JSON, equal)."""
import inspect
import math
import os
import sys
import tomllib

import numpy as np
import pytest

import vrelab
from vrelab import tables

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CASES = os.path.join(SRC, "cases")
AXES = ("IA", "PA", "OA")


def case(name):
    return os.path.join(CASES, name)


def same(a, b):
    """A table's cell against the JSON's value: None (null) is NaN in a float column."""
    if b is None:
        return a is None or (isinstance(a, float) and math.isnan(a))
    return a == b and type(a) is type(b)


def cell(columns, name, i):
    """Row i of a column as a Python value (a NumPy scalar's .item())."""
    v = columns[name][i]
    return v.item() if isinstance(v, np.generic) else v


# ---- the flattening rules, on records made up to hold every kind of value

def test_columns_of_records_keep_ints_bools_and_units_last():
    records = [
        {"id": "a", "n": 3, "ok": True, "x_g": 1.5, "orientation_g": [0.5, 0.0, 1.0], "direction": [1, 0, 0],
         "motion": {"samples": 10, "welch": {"dof": 3.5}}, "range": [1.0, 2.0], "maybe": None},
        {"id": "b", "n": 4, "ok": False, "x_g": None, "orientation_g": [0.0, 1.0, 0.0], "direction": [0, 1, 0],
         "motion": {"samples": 12, "welch": {"dof": 4.5}}, "range": [3.0, 4.0], "maybe": 2.0},
        {"id": "c", "n": 5, "ok": True, "x_g": 2.5, "orientation_g": [0.0, 0.0, 1.0], "direction": [0, 0, 1],
         "range": [5.0, 6.0], "maybe": 1},
    ]
    cols = tables.columns(records, first=("ok",))
    assert list(cols) == ["ok", "id", "n", "x_g", "orientation_IA_g", "orientation_PA_g", "orientation_OA_g",
                          "direction_IA", "direction_PA", "direction_OA", "motion.samples", "motion.welch.dof",
                          "range", "maybe"]
    assert cols["n"].dtype == np.int64 and list(cols["n"]) == [3, 4, 5]
    assert cols["ok"].dtype == bool and list(cols["ok"]) == [True, False, True]
    assert cols["direction_PA"].dtype == np.int64 and list(cols["direction_PA"]) == [0, 1, 0]
    assert cols["orientation_OA_g"].dtype == np.float64 and list(cols["orientation_OA_g"]) == [1.0, 0.0, 1.0]
    assert cols["x_g"].dtype == np.float64 and math.isnan(cols["x_g"][1]) and cols["x_g"][2] == 2.5
    # an integer column a row lacks is a float column with NaN there; a mixed int/float column float
    assert cols["motion.samples"].dtype == np.float64 and list(cols["motion.samples"][:2]) == [10.0, 12.0]
    assert math.isnan(cols["motion.samples"][2])
    assert cols["maybe"].dtype == np.float64 and math.isnan(cols["maybe"][0]) and list(cols["maybe"][1:]) == [2.0, 1.0]
    assert cols["id"].dtype == object and list(cols["id"]) == ["a", "b", "c"]
    assert cols["range"].dtype == object and cols["range"][2] == [5.0, 6.0]  # not a vector of axes


# ---- Diagnosis

def test_runs_columns_are_the_json_runs(lab_example):
    runs = lab_example.to_dict()["runs"]
    cols = lab_example.runs_columns()
    assert len(runs) == lab_example.runs == len(cols["id"]) > 0
    assert list(cols)[:2] == ["id", "kind"]
    expected = {"id", "kind"}
    for i, r in enumerate(runs):
        for k, v in r.items():
            if k == "orientation_g":
                names = ["orientation_%s_g" % a for a in AXES]
            elif k == "direction":
                names = ["direction_%s" % a for a in AXES]
            else:
                assert same(cell(cols, k, i), v), (i, k, cell(cols, k, i), v)
                expected.add(k)
                continue
            assert [cell(cols, n, i) for n in names] == v, (i, k)
            expected.update(names)
    assert set(cols) == expected
    assert cols["measured_g"].dtype == np.float64 and cols["id"].dtype == object


def test_runs_frame_is_runs_columns(lab_example):
    pytest.importorskip("pandas")
    cols = lab_example.runs_columns()
    df = lab_example.runs_frame()
    assert list(df.columns) == list(cols) and len(df) == lab_example.runs
    for k, v in cols.items():
        assert df[k].dtype == v.dtype, k
        np.testing.assert_array_equal(df[k].to_numpy(), v)
    assert {"frequency_Hz", "amplitude_g", "measured_g", "sigma_measured_g", "predicted_g", "z"} <= set(df.columns)


def test_effects_columns_are_the_json_effects(lab_example):
    effects = lab_example.to_dict()["effects"]
    cols = lab_example.effects_columns()
    assert list(cols["name"]) == [e["name"] for e in effects]
    assert list(cols)[:3] == ["name", "evidence", "heldout_chi2"]
    assert cols["n_parameters"].dtype == np.int64 and cols["at_bound"].dtype == bool
    for i, e in enumerate(effects):
        assert cell(cols, "n_parameters", i) == len(e["parameters"])
        for k, v in e.items():
            if k != "parameters":
                assert same(cell(cols, k, i), v), (i, k)
    per = lab_example.effects_columns(parameters=True)
    flat = [(e, p) for e in effects for p in e["parameters"]]
    assert len(per["effect"]) == len(flat) > len(effects)  # some effects fit more than one parameter
    for i, (e, p) in enumerate(flat):
        assert cell(per, "effect", i) == e["name"] and cell(per, "evidence", i) == e["evidence"]
        assert [cell(per, "range_min", i), cell(per, "range_max", i)] == p["range"]
        for k in ("name", "value", "sigma", "unit", "status", "at_bound"):
            assert same(cell(per, k, i), p[k]), (i, k)
    pytest.importorskip("pandas")
    assert list(lab_example.effects_frame(parameters=True).columns) == list(per)


# ---- IdentifyResult

@pytest.fixture(scope="module")
def identified():
    return vrelab.identify(case("paper-static.toml"), monte_carlo=4)


def test_coefficients_columns_are_the_estimates_and_sigmas(identified):
    r, j = identified, identified.to_dict()
    cols = r.coefficients_columns()
    assert list(cols) == ["coefficient", "unit", "estimate", "sigma", "truth", "error", "given",
                          "monte_carlo_std", "monte_carlo_mean_error"]
    assert list(cols["coefficient"]) == list(r.truth)  # model (1)'s order
    estimate, sigma = r.estimate("least_squares"), r.sigma("least_squares")
    for i, n in enumerate(cols["coefficient"]):
        assert cols["estimate"][i] == estimate[n] and cols["sigma"][i] == sigma[n]
        assert cols["truth"][i] == j["truth"][n] and cols["error"][i] == j["errors"]["least_squares"][n]
        assert cols["unit"][i] == j["units"][n]
        assert cols["given"][i] == (n in j["given"]["least_squares"])
        assert cols["monte_carlo_std"][i] == j["monte_carlo"]["least_squares"]["std"][n]
    assert cols["given"].dtype == bool and cols["given"].any()
    every = r.coefficients_columns(method=None)
    assert list(every["method"]) == [m for m in r.methods for _ in r.truth]
    printed = every["method"] == "paper_printed"
    k = list(every["coefficient"][printed]).index("delta_OA")
    assert math.isnan(every["estimate"][printed][k]) and j["estimates"]["paper_printed"]["delta_OA"] is None
    with pytest.raises(KeyError, match="no method 'no_such_method'"):
        r.coefficients_columns("no_such_method")


def test_readings_columns_name_the_output_unit_and_keep_integers(identified):
    j = identified.to_dict()
    cols = identified.readings_columns()
    assert list(cols) == ["position", "series", "angle_deg", "a_nominal_IA_g", "a_nominal_PA_g", "a_nominal_OA_g", "output_mA"]
    assert cols["position"].dtype == np.int64 and cols["series"].dtype == np.int64
    assert len(cols["position"]) == identified.readings == len(j["readings"])
    for i, rd in enumerate(j["readings"]):
        assert cell(cols, "output_mA", i) == rd["output"] and cell(cols, "position", i) == rd["position"]
        assert [cell(cols, "a_nominal_%s_g" % a, i) for a in AXES] == rd["a_nominal_g"]
    pytest.importorskip("pandas")
    df = identified.coefficients_frame()
    assert df["given"].dtype == bool and df["estimate"].dtype == np.float64
    assert identified.readings_frame()["position"].dtype == np.int64


# ---- without pandas

def test_frames_without_pandas_say_how_to_install_it(monkeypatch, lab_example):
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now raises ImportError
    with pytest.raises(ImportError, match=r"Diagnosis.runs_frame\(\) needs pandas.*python3-pandas.*pip install pandas.*runs_columns\(\)"):
        lab_example.runs_frame()
    grid = vrelab.predict(case("shake-sine.toml"), amplitude_g=[1.0, 2.0])
    for call in (lab_example.effects_frame, grid.frame):
        with pytest.raises(ImportError, match="python3-pandas"):
            call()
    assert len(lab_example.runs_columns()["id"]) == lab_example.runs  # the NumPy columns need no pandas
    assert list(grid.columns()["amplitude_g"]) == [1.0, 2.0]


# ---- predict over arrays

def test_predict_over_arrays_is_a_loop_of_scalar_calls():
    c = vrelab.load_case(case("shake-sine.toml"))
    f_Hz = np.geomspace(1.0, 2000.0, 7)
    a_g = np.array([0.5, 1.0, 2.0, 4.0])
    grid = vrelab.predict(c, True, frequency_Hz=f_Hz[:, None], amplitude_g=a_g)
    assert isinstance(grid, vrelab.PredictArrays) and grid.shape == grid.total_g.shape == (7, 4)
    np.testing.assert_array_equal(grid.frequency_Hz, np.broadcast_to(f_Hz[:, None], (7, 4)))
    np.testing.assert_array_equal(grid.amplitude_g, np.broadcast_to(a_g, (7, 4)))
    for i in range(7):
        for j in range(4):
            one = vrelab.predict(c, True, frequency_Hz=f_Hz[i], amplitude_g=a_g[j])
            assert grid.total_g[i, j] == one.total_g and grid.printed_g[i, j] == one.printed_g
            assert grid.omitted_by_paper_g[i, j] == one.omitted_by_paper_g
            assert grid.frequency_dependent_g[i, j] == one.frequency_dependent_g
            assert {t: v[i, j] for t, v in grid.terms.items()} == one.terms
            assert {t: v[i, j] for t, v in grid.frequency_terms.items()} == one.frequency_terms
    # The frequency matters through the dynamics, the amplitude everywhere (A^2 terms).
    assert len(set(grid.frequency_dependent_g[:, 0])) == 7 and len(set(grid.total_g[0])) == 4
    cols = grid.columns()
    assert len(cols["total_g"]) == 28 and cols["k2_g"][5] == grid.terms["k2"].ravel()[5]
    assert cols["frequency_dependent_k2_g"][5] == grid.frequency_terms["k2"].ravel()[5]


def test_predict_over_one_array_keeps_the_case_s_other_value():
    c = vrelab.load_case(case("shake-sine.toml"))
    alone = vrelab.predict(c)
    over_f = vrelab.predict(c, frequency_Hz=[1.0, 10.0, 100.0])
    assert over_f.frequency_dependent_g is None and over_f.frequency_terms is None
    assert list(over_f.total_g) == [alone.total_g] * 3  # quasi-static: the case's amplitude, untouched
    assert list(over_f.amplitude_g) == [math.sqrt(10.0)] * 3  # |[3, 1, 0]| g
    over_a = vrelab.predict(c, amplitude_g=np.array([[1.0], [2.0]]))
    assert over_a.shape == (2, 1) and list(over_a.frequency_Hz.ravel()) == [5.0, 5.0]
    # A sine on random: its sine set, the random part kept; eq. (3) as printed has no value (NaN).
    sor = vrelab.load_case(case("shake-sine-on-random.toml"))
    over = vrelab.predict(sor, True, amplitude_g=[0.5, 1.0], frequency_Hz=[100.0, 200.0])
    for i in range(2):
        one = vrelab.predict(sor, True, amplitude_g=[0.5, 1.0][i], frequency_Hz=[100.0, 200.0][i])
        assert over.total_g[i] == one.total_g and over.frequency_dependent_g[i] == one.frequency_dependent_g
        assert one.printed_g is None and math.isnan(over.printed_g[i])


def test_predict_with_a_frequency_and_amplitude_is_the_case_file_holding_them():
    with open(case("shake-sine.toml"), "rb") as f:
        d = tomllib.load(f)
    d["vibration"]["amplitude_g"] = [1.0, 0.0, 0.0]
    set_here = vrelab.predict(d, True, frequency_Hz=40.0, amplitude_g=2.5)
    d["vibration"].update(amplitude_g=[2.5, 0.0, 0.0], frequency_Hz=40.0)
    in_file = vrelab.predict(d, True)
    assert set_here.to_dict() == in_file.to_dict()
    assert set_here.to_dict()["case"]["content"]["vibration"]["frequency_Hz"] == 40.0


def test_predict_refuses_what_a_case_file_refuses():
    c = vrelab.load_case(case("shake-sine.toml"))
    with pytest.raises(vrelab.InputError, match=r"frequency_Hz\[2\] must be a finite number >= 0 Hz, got -1"):
        vrelab.predict(c, frequency_Hz=[1.0, 2.0, -1.0])
    with pytest.raises(vrelab.InputError, match=r"frequency_Hz must be a finite number > 0 Hz, got 0"):
        vrelab.predict(case("shake-sine-on-random.toml"), frequency_Hz=0.0)  # as its case file: a sine on random needs one
    with pytest.raises(vrelab.InputError, match="amplitude_g must be between 0 and 1000 g"):
        vrelab.predict(c, amplitude_g=1e4)
    with pytest.raises(vrelab.InputError, match=r"amplitude_g\[0\] must be between"):
        vrelab.predict(c, amplitude_g=[math.nan])
    with pytest.raises(vrelab.InputError, match=r"random-predict.toml: .* not a \"random\""):
        vrelab.predict(case("random-predict.toml"), amplitude_g=[1.0, 2.0])
    with pytest.raises(ValueError, match="broadcast"):
        vrelab.predict(c, frequency_Hz=[1.0, 2.0], amplitude_g=[1.0, 2.0, 3.0])
    assert "frequency_Hz" in inspect.signature(vrelab.predict).parameters
