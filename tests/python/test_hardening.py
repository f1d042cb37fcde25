"""The Python boundary under bad arguments (docs/python.md, "Errors"): each answered with a
Python exception of a documented type naming the argument, never a crash of the interpreter,
a hang or "internal error" -- a dict that contains itself or nests 100 000 deep, arguments of
the wrong type, a path holding a NUL byte, data over the readers' size limits, a path that is
not a regular file.

Run by ctest (python_tests, label python) with PYTHONPATH at build/python."""
import os

import numpy as np
import pytest

import vrelab

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CASES = os.path.join(SRC, "cases")


def test_a_dict_that_contains_itself_is_refused_naming_where():
    d = {"coefficients": {"K1": 1.25}}
    d["coefficients"]["again"] = d
    with pytest.raises(vrelab.InputError, match=r"Case\.from_dict\(d\): coefficients\.again holds a dict or list that contains itself"):
        vrelab.load_case(d)
    lst = [1.0]
    lst.append(lst)
    with pytest.raises(vrelab.InputError, match="contains itself"):
        vrelab.case_toml({"vibration": {"amplitude_g": lst}})


def test_a_dict_nested_100000_deep_is_refused_not_a_crash():
    d = {}
    inner = d
    for _ in range(100000):
        inner["a"] = {}
        inner = inner["a"]
    with pytest.raises(vrelab.InputError, match=r"Case\.from_dict\(d\): a(\.a)+ nests deeper than 32 levels"):
        vrelab.load_case(d)


def test_diagnose_data_of_none_is_a_type_error_naming_the_argument():
    with pytest.raises(TypeError, match=r"diagnose_data\(\): static must be a dict of columns .* not NoneType"):
        vrelab.diagnose_data(None, None)
    with pytest.raises(TypeError, match=r"diagnose_data\(\): runs must be a dict of columns"):
        vrelab.diagnose_data({"a_IA_g": [1.0]}, None)
    with pytest.raises(TypeError, match=r"diagnose_data\(\): static\['a_IA_g'\] must be a column"):
        vrelab.diagnose_data({"a_IA_g": 1.0}, {})
    with pytest.raises(TypeError, match=r"diagnose_data\(\): manifest must be a dict of tables or None, not str"):
        vrelab.diagnose_data({}, {}, manifest="manifest.toml")


def test_diagnose_data_over_the_size_limit_is_refused_before_writing_anything():
    # 3e7 rows as views of one number: no memory, and the refusal comes from the lengths alone.
    n = 30_000_000
    static = {name: np.broadcast_to(0.0, (n,)) for name in ("series", "angle_deg", "output_mA", "sigma_mA")}
    with pytest.raises(vrelab.InputError, match=r"diagnose_data\(\): static has 30000000 rows, more than the 1000000 static readings"):
        vrelab.diagnose_data(static, {"id": []})
    assert vrelab.limits == {"static_readings": 1000000, "runs": 2000, "psd_rows": 10000000}


def test_a_path_with_a_nul_byte_is_named_with_the_nul_shown():
    with pytest.raises(vrelab.InputError, match=r"^cases\\0evil\.toml: cannot open the case file: the path holds a NUL byte \(at byte 6\)"):
        vrelab.load_case("cases\0evil.toml")
    with pytest.raises(vrelab.InputError, match=r"lab\\0x/manifest\.toml: cannot open the manifest: the path holds a NUL byte"):
        vrelab.diagnose("lab\0x")


def test_a_path_that_is_not_a_regular_file_is_refused(tmp_path):
    with pytest.raises(vrelab.InputError, match=r"cannot open the case file: is a directory, not a file"):
        vrelab.load_case(str(tmp_path))
    fifo = tmp_path / "case.toml"
    os.mkfifo(fifo)
    with pytest.raises(vrelab.InputError, match=r"case\.toml: cannot open the case file: a FIFO"):
        vrelab.load_case(str(fifo))
    with pytest.raises(vrelab.InputError, match=r"cannot open the case file: the path is longer than the system allows"):
        vrelab.load_case(str(tmp_path / ("a" * 300)))
