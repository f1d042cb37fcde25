"""The diagnosis' settings through Python and the program, field by field from their one
description (vrelab.diagnose_settings(), DiagnoseSettings::Describe): each field, set to a value
other than its default, arrives as a keyword of vrelab.check_campaign and as a flag of
`vrelab diagnose --json` (all at once: one diagnosis of cases/lab-example, a few seconds), and
the JSON record of the settings used holds every field."""
import json
import os
import subprocess

import pytest

import vrelab

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("VRELAB_CLI", os.path.join(SRC, "build", "vrelab"))
LAB = os.path.join(SRC, "cases", "lab-example")

FIELDS = vrelab.diagnose_settings()


def admissible(f, x):
    if f["min"] is not None and not (x > f["min"] if f["min_open"] else x >= f["min"]):
        return False
    if f["max"] is not None and not (x < f["max"] if f["max_open"] else x <= f["max"]):
        return False
    return True


def other_value(f):
    """A value in f's range other than its default (the C++ test's rule, computed here)."""
    d = f["default"]
    if f["type"] == "bool":
        return not d
    if f["type"] == "int":
        return d + 1 if admissible(f, d + 1) else d - 1
    up = d * 1.25 + 0.25
    if admissible(f, up):
        return up
    return (d + (f["min"] if f["min"] is not None else d - 1)) / 2


def test_the_description_lists_eight_fields_with_help():
    # DiagnoseSettings' eight members (validation/diagnosis/settings.hpp).
    assert len(FIELDS) == 8
    assert len({f["name"] for f in FIELDS}) == 8
    for f in FIELDS:
        assert f["help"], f["name"]
        assert f["type"] in ("bool", "int", "float")
        assert other_value(f) != f["default"]
        if f["type"] != "bool":
            assert admissible(f, other_value(f))


@pytest.mark.parametrize("f", FIELDS, ids=[f["name"] for f in FIELDS])
def test_each_field_arrives_as_a_keyword(f):
    v = other_value(f)
    got = vrelab.check_campaign(LAB, **{f["name"]: v})["settings"]
    assert got[f["name"]] == v
    assert "set over by the caller" in got["from"]
    for g in FIELDS:  # the others at their defaults (lab-example has no [diagnose])
        if g is not f:
            assert got[g["name"]] == g["default"], g["name"]


def test_every_keyword_at_once_and_the_record_has_every_field():
    want = {f["name"]: other_value(f) for f in FIELDS}
    got = vrelab.check_campaign(LAB, **want)["settings"]
    assert {k: got[k] for k in want} == want
    assert set(got) == set(want) | {"from"}


def test_the_docstring_names_every_keyword_with_its_default():
    doc = vrelab.diagnose.__doc__
    for f in FIELDS:
        d = f["default"]
        text = ("true" if d else "false") if f["type"] == "bool" else repr(d).removesuffix(".0")
        assert "%s (%s, default %s" % (f["name"], f["type"], text) in doc, f["name"]


def test_an_unknown_keyword_or_a_wrong_type_raises_type_error():
    with pytest.raises(TypeError, match="significance"):
        vrelab.check_campaign(LAB, significance=4)
    with pytest.raises(TypeError, match="resimulate_runs takes a int"):
        vrelab.check_campaign(LAB, resimulate_runs=2.5)
    with pytest.raises(TypeError, match="try_pairs takes a bool"):
        vrelab.check_campaign(LAB, try_pairs=1)
    with pytest.raises(vrelab.InputError, match="significance_sigma = -1: must be a positive number of sigma"):
        vrelab.check_campaign(LAB, significance_sigma=-1)


def flag_args(f, v):
    flag = "--" + f["name"].replace("_", "-")
    if f["type"] == "bool":
        return [flag] if v else ["--no-" + f["name"].replace("_", "-")]
    return [flag, repr(v)]


def test_every_field_arrives_as_a_flag_of_the_program(tmp_path):
    want = {f["name"]: other_value(f) for f in FIELDS}
    args = [a for f in FIELDS for a in flag_args(f, want[f["name"]])]
    out = tmp_path / "s.json"
    r = subprocess.run([CLI, "diagnose", LAB, "--json", str(out), *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    got = json.loads(out.read_text())["settings"]
    assert {k: got[k] for k in want} == want
    assert set(got) == set(want) | {"from"}
