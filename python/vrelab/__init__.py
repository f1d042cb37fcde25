"""vrelab: a virtual shaker laboratory for the vibration rectification error (VRE) of
pendulous accelerometers -- the C++ library, from Python.

Every function is one library call, the same as the CLI command of its name; results are
objects with typed attributes (units in their names and docstrings: g, Hz, s) and a
to_dict() equal to the CLI's JSON for the same case.

    import vrelab
    case = vrelab.load_case("cases/shake-sine.toml")     # or a dict of tables
    r = vrelab.shake(case, series=True)
    r.measured_g, r.sigma_g, r.predicted_g                # g
    r.series["time_s"], r.series["output_mA"]              # NumPy arrays
    vrelab.predict(case, True, frequency_Hz=[5.0, 50.0, 500.0]).frequency_dependent_g  # NumPy, one call
    vrelab.diagnose("cases/lab-example").runs_frame()     # pandas (runs_columns(): NumPy)

Errors: vrelab.InputError (a ValueError; the CLI's exit code 2, same message) and
vrelab.SolverError (the ODE solver failed; .call, .t_s). Units: README "Units".
"""
import functools
import os
import tempfile

import numpy as np

from ._core import (  # noqa: F401
    Case,
    CampaignWritten,
    Diagnosis,
    FrequencyResult,
    IdentifyResult,
    InputError,
    PredictResult,
    ReproduceResult,
    ShakeResult,
    SolverError,
    SweepRun,
    __version__,
    case_toml,
    frequency,
    git_describe,
    identify,
    limits,
    predict_total_g,
    reproduce,
    shake,
)
from . import _core
from . import tables
from .tables import PredictArrays

tables.attach(_core)  # runs_frame(), effects_frame(), coefficients_frame(), ... on the result classes


def _find_plot_scripts():
    """The library finds its plot scripts beside the running program, which here is Python:
    point it (VRELAB_PLOTS_DIR, unless set) at the package's own vrelab/plots (pip install),
    the build tree's share/vrelab/plots (build/python/vrelab -> build/share/vrelab/plots) or
    the installed prefix's (<prefix>/lib/python3.X/dist-packages/vrelab -> <prefix>/share/vrelab/plots)."""
    if os.environ.get("VRELAB_PLOTS_DIR"):
        return
    here = os.path.dirname(os.path.realpath(__file__))
    for up in ("plots", "../../share/vrelab/plots", "../../../../share/vrelab/plots"):
        d = os.path.normpath(os.path.join(here, up))
        if os.path.isfile(os.path.join(d, "reproduce.py")):
            os.environ["VRELAB_PLOTS_DIR"] = d
            return


_find_plot_scripts()

# What a result's repr shows: its headline attributes, units in their names (g, s), so that a
# notebook or the REPL prints "<vrelab.PredictResult total_g=0.00012 ...>" rather than an address.
_REPR_FIELDS = {
    "PredictResult": ("total_g", "frequency_dependent_g"),
    "ShakeResult": ("measured_g", "sigma_g", "predicted_g", "predicted_frequency_dependent_g"),
    "IdentifyResult": ("methods", "rank", "condition_number"),
    "Diagnosis": ("verdict", "chosen", "rms_before_g", "rms_after_g", "rms_floor_g"),
    "FrequencyResult": ("mechanisms",),
    "ReproduceResult": ("out_dir", "report_html", "figures_missing"),
    "CampaignWritten": ("out_dir", "statics", "runs", "seed"),
    "SweepRun": ("conditions", "ran", "written", "failures", "path"),
}


def _repr_value(v):
    if isinstance(v, float):
        return "%.6g" % v
    if isinstance(v, (list, tuple)) and len(v) > 4:
        return "[%s, ... %d in all]" % (", ".join(_repr_value(x) for x in v[:3]), len(v))
    if isinstance(v, (list, tuple)):
        return "[%s]" % ", ".join(_repr_value(x) for x in v)
    return repr(v)


def _make_repr(name, fields):
    def __repr__(self):
        shown = []
        for f in fields:
            v = getattr(self, f)
            if v is not None:
                shown.append("%s=%s" % (f, _repr_value(v)))
        return "<vrelab.%s %s>" % (name, " ".join(shown))
    return __repr__


for _name, _fields in _REPR_FIELDS.items():
    setattr(getattr(_core, _name), "__repr__", _make_repr(_name, _fields))

__all__ = [
    "Case", "InputError", "SolverError", "load_case", "case_toml", "identify", "predict", "PredictArrays", "shake",
    "sweep", "frequency", "campaign", "diagnose", "diagnose_data", "check_campaign", "diagnose_settings",
    "reproduce", "limits", "__version__",
]


def load_case(case, name=None):
    """A Case from a path (str or os.PathLike), a dict of tables, or a Case (returned as is).

    A dict is written as TOML (vrelab.case_toml) and read by the same reader as a file, so bad
    input raises vrelab.InputError with the file reader's message (naming `name`, default
    "<dict>", and the TOML line).
    """
    if isinstance(case, Case):
        return case
    if isinstance(case, dict):
        return Case.from_dict(case, name or "<dict>")
    if isinstance(case, (str, os.PathLike)):
        return Case.from_file(os.fspath(case))
    raise TypeError("a case is a path, a dict of tables or a vrelab.Case, not %s" % type(case).__name__)


def _signature(fn):
    """inspect.Signature of a pybind11 function from its docstring's first line,
    'name(a: T, b: T = default) -> R' (pybind11 gives builtins no __signature__), with `case`
    annotated as every form _wrap takes; None where the line does not parse."""
    import ast
    import inspect
    first = (fn.__doc__ or "").split("\n", 1)[0]
    head, sep, ret = first.partition(") -> ")
    if not sep or "(" not in head:
        return None
    params, depth, cur = [], 0, ""
    for ch in head.split("(", 1)[1]:
        depth += 1 if ch in "[(" else -1 if ch in "])" else 0
        if ch == "," and depth == 0:
            params.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        params.append(cur.strip())
    out = []
    for text in params:
        decl, has_default, default_text = text.partition(" = ")
        name, _, annotation = decl.partition(": ")
        if not name.isidentifier():
            return None
        default = inspect.Parameter.empty
        if has_default:
            try:
                default = ast.literal_eval(default_text)
            except (ValueError, SyntaxError):
                default = default_text
        if name == "case":
            annotation = "vrelab.Case | str | os.PathLike | dict"
        out.append(inspect.Parameter(name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=default,
                                     annotation=annotation or inspect.Parameter.empty))
    return inspect.Signature(out, return_annotation=ret.strip())


def _wrap(fn):
    """Lets fn take a path or a dict where it takes a Case (help() shows fn's signature and units)."""
    @functools.wraps(fn)
    def call(case, *args, **kwargs):
        return fn(load_case(case), *args, **kwargs)
    sig = _signature(fn)
    if sig is not None:
        call.__signature__ = sig  # what inspect, IDEs and notebooks show
    call.__doc__ = (fn.__doc__ or "") + (
        "\n\ncase: a vrelab.Case, a case file path (str or os.PathLike) or a dict of tables "
        "(vrelab.load_case). Bad input raises vrelab.InputError (a ValueError) with the CLI's "
        "message; a failure of the ODE solver raises vrelab.SolverError (.call, .flag, .t_s in s).")
    return call


identify = _wrap(_core.identify)


def predict(case: "vrelab.Case | str | os.PathLike | dict", frequency_dependent: bool = False, *,
            frequency_Hz=None, amplitude_g=None) -> "PredictResult | PredictArrays":
    c = load_case(case)
    if frequency_Hz is None and amplitude_g is None:  # the case as it is (no np.ndim: a microsecond a call)
        return _core.predict(c, frequency_dependent)
    if np.ndim(frequency_Hz) == 0 and np.ndim(amplitude_g) == 0:
        return _core.predict(c, frequency_dependent, frequency_Hz=frequency_Hz, amplitude_g=amplitude_g)
    given = {k: np.asarray(v, dtype=float) for k, v in (("frequency_Hz", frequency_Hz), ("amplitude_g", amplitude_g))
             if v is not None}
    shape = np.broadcast_shapes(*(v.shape for v in given.values()))
    flat = {k: np.broadcast_to(v, shape).ravel().tolist() for k, v in given.items()}
    return PredictArrays(_core._predict_arrays(c, frequency_dependent, flat.get("frequency_Hz"), flat.get("amplitude_g")), shape)


predict.__doc__ = _core.predict.__doc__ + """

Arrays: frequency_Hz and amplitude_g may be arrays (any shape; a scalar or None beside an array
is broadcast, None keeping the case's value); the result is then a vrelab.PredictArrays whose
attributes (total_g, terms, printed_g, frequency_dependent_g, ...) are NumPy arrays of the
broadcast shape, each element the number of the scalar call with that element's values, in one
call (the loop runs in C++ with the GIL released; Ctrl-C stops it). A bad element raises
vrelab.InputError naming its index in the flattened broadcast (frequency_Hz[3]).

case: a vrelab.Case, a case file path (str or os.PathLike) or a dict of tables
(vrelab.load_case). Bad input raises vrelab.InputError (a ValueError) with the CLI's message."""
predict_total_g = _wrap(_core.predict_total_g)
shake = _wrap(_core.shake)
frequency = _wrap(_core.frequency)


def reproduce(case="cases/paper.toml", out_dir="out/paper", threads=-1, plots=True):
    return _core.reproduce(load_case(case), os.fspath(out_dir), threads, plots)


reproduce.__doc__ = _core.reproduce.__doc__


class SweepResult:
    """A sweep: the counts of the run (conditions, ran, written, failures, wall_s in s), the
    CSV file (path) and its rows as a dict of NumPy columns (columns; .frame() gives a pandas
    DataFrame when pandas is installed)."""

    def __init__(self, run, columns):
        self.run = run
        self.path = run.path
        self.conditions, self.ran, self.written = run.conditions, run.ran, run.written
        self.failures, self.wall_s = list(run.failures), run.wall_s
        self.columns = columns

    def frame(self):
        """.columns as a pandas DataFrame (integer columns stay int64)."""
        return tables.frame(self.columns, "SweepResult.frame()", "SweepResult.columns")

    def report(self):
        return self.run.report()

    def to_dict(self):
        return {"conditions": self.conditions, "ran": self.ran, "written": self.written,
                "failures": self.failures, "wall_s": self.wall_s, "path": self.path,
                "columns": {k: v.tolist() for k, v in self.columns.items()}}


def _read_csv_columns(path, ints=(), text=()):
    """The columns of a CSV file ('#' lines are comments) as NumPy arrays: those named in
    `ints` int64 and in `text` str (a sweep's index and steps; its checksum, 8 hex digits,
    some of them all decimal), every other float64 where every value is a number, else str.
    By name, not by the values: a frequency written 5 stays a float."""
    import csv
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    if not rows:
        return {}
    head, body = rows[0], rows[1:]
    cols = {}
    for i, name in enumerate(head):
        values = [r[i] if i < len(r) else "" for r in body]
        if name in ints:
            cols[name] = np.array([int(v) for v in values], dtype=np.int64)
        elif name in text:
            cols[name] = np.array(values, dtype=str)
        else:
            try:
                cols[name] = np.array([float(v) for v in values], dtype=np.float64)
            except ValueError:
                cols[name] = np.array(values, dtype=str)
    return cols


# The sweep CSV's columns that are not floats (docs/json-output.md, "vrelab sweep").
_SWEEP_COLUMNS = {"ints": ("index", "steps"), "text": ("checksum",)}


def sweep(case, out=None, restart=False, threads=-1, progress=False):
    """sweep(case, out=None, restart=False, threads=-1, progress=False) -> SweepResult

    A grid of shaker runs (the case's [sweep]: frequency Hz x amplitude g x direction x
    orientation) on `threads` threads (-1: the case's; 0: all cores), written to the CSV file
    `out` (resumed when it exists unless restart=True; None: a temporary file) and returned as
    a dict of NumPy columns (measured and predicted errors in g). Same as `vrelab sweep CASE
    --out FILE`. Releases the GIL.
    """
    c = load_case(case)
    if out is None:
        with tempfile.TemporaryDirectory(prefix="vrelab-sweep-") as d:
            path = os.path.join(d, "sweep.csv")
            run = _core._sweep(c, path, True, threads, progress)
            return SweepResult(run, _read_csv_columns(path, **_SWEEP_COLUMNS))
    run = _core._sweep(c, os.fspath(out), restart, threads, progress)
    return SweepResult(run, _read_csv_columns(os.fspath(out), **_SWEEP_COLUMNS))


def campaign(case, out_dir, key=None, seed=None, raw_format="csv"):
    """campaign(case_path, out_dir, key=None, seed=None, raw_format='csv') -> CampaignWritten

    The virtual lab: a whole campaign (static test, shaker runs) simulated from the case's
    truth with its hidden effects ([campaign]) and written to out_dir in the lab data format;
    the answer key apart (key, default <out_dir>.key.json). Same as `vrelab campaign CASE
    --out DIR [--key FILE] [--raw-format csv|hdf5]`. raw_format: the raw records (a case with
    [campaign] raw_series = true) as records/<id>.csv or records/<id>.h5 (docs/data-format.md,
    "Raw records in HDF5"); 'hdf5' for a case that writes summaries raises InputError, as the
    CLI exits 2. Takes a case file path (the folder records it). Releases the GIL.
    """
    if not isinstance(case, (str, os.PathLike)):
        raise TypeError("campaign takes a case file path (the campaign's manifest records it)")
    if raw_format not in ("csv", "hdf5"):
        raise ValueError("campaign: raw_format must be 'csv' or 'hdf5', got %r" % (raw_format,))
    return _core._campaign(os.fspath(case), os.fspath(out_dir), os.fspath(key) if key else "", seed, raw_format)


def diagnose(dir, threads=0, **settings):
    return _core.diagnose(os.fspath(dir), threads, **settings)


diagnose.__doc__ = _core.diagnose.__doc__


def check_campaign(dir, **settings):
    return _core.check_campaign(os.fspath(dir), **settings)


check_campaign.__doc__ = _core.check_campaign.__doc__
diagnose_settings = _core.diagnose_settings


def _write_columns(path, columns):
    """A CSV file of the lab data format from a dict of columns (or a pandas DataFrame)."""
    names = [str(n) for n in columns.keys()]
    cols = [list(columns[n]) for n in columns.keys()]
    if len({len(c) for c in cols}) > 1:
        raise InputError("%s: the columns differ in length" % os.path.basename(path))

    def text(v):
        if isinstance(v, (bool, int, str)):
            return str(v)
        try:
            return format(float(v), ".17g")  # exact: the file's reader gets the same double
        except (TypeError, ValueError):
            return str(v)

    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*cols):
            f.write(",".join(text(v) for v in row) + "\n")


def _rows(argument, columns, limit, what):
    """The rows of a dict of columns (or a pandas DataFrame) given as `argument`; TypeError for
    anything else, InputError for columns of different lengths or more rows than `limit` (the
    reader's size limit, checked before anything is written: docs/data-format.md, "Ranges and
    limits")."""
    if not isinstance(columns, dict) and not (hasattr(columns, "columns") and hasattr(columns, "keys")):
        raise TypeError("diagnose_data(): %s must be a dict of columns (lists or NumPy arrays) or a pandas "
                        "DataFrame, not %s" % (argument, type(columns).__name__))
    lengths = {}
    for k in columns.keys():
        try:
            lengths[k] = len(columns[k])
        except TypeError:
            raise TypeError("diagnose_data(): %s[%r] must be a column (a list or a NumPy array), not %s"
                            % (argument, k, type(columns[k]).__name__)) from None
    if len(set(lengths.values())) > 1:
        raise InputError("diagnose_data(): %s: the columns differ in length (%s)"
                         % (argument, ", ".join("%s %d" % (k, n) for k, n in lengths.items())))
    rows = next(iter(lengths.values()), 0)
    if rows > limit:
        raise InputError("diagnose_data(): %s has %d rows, more than the %d %s the diagnosis takes "
                         "(docs/data-format.md, Ranges and limits)" % (argument, rows, limit, what))
    return rows


def diagnose_data(static, runs, manifest=None, name="<memory>", **settings):
    """diagnose_data(static, runs, manifest=None, name="<memory>", **settings) -> Diagnosis

    diagnose() on a campaign in memory: `static` and `runs` are dicts of columns (lists or
    NumPy arrays) or pandas DataFrames with the columns of static.csv and runs.csv
    (docs/data-format.md: series, angle_deg, output_<unit>, sigma_<unit>, count; id,
    frequency_Hz, amplitude_g, d_IA, d_PA, d_OA, a_IA_g, a_PA_g, a_OA_g, measured_ug,
    sigma_ug), `manifest` the manifest's tables as a dict (default: output unit mA, default
    dynamics). They are written in the lab data format to a private temporary folder and read
    by the same reader as a folder, so the checks and messages are the folder's (naming
    `name` for the folder). Settings as for diagnose().

    Raises TypeError when static or runs is not a dict of columns or a DataFrame (or manifest
    not a dict), vrelab.InputError when their columns differ in length, hold more rows than
    vrelab.limits allows (checked before anything is written), or the folder's reader refuses them.
    """
    _rows("static", static, _core.limits["static_readings"], "static readings")
    _rows("runs", runs, _core.limits["runs"], "shaker runs")
    if manifest is not None and not isinstance(manifest, dict):
        raise TypeError("diagnose_data(): manifest must be a dict of tables or None, not %s" % type(manifest).__name__)
    if not isinstance(name, str):
        raise TypeError("diagnose_data(): name must be a str, not %s" % type(name).__name__)
    man = manifest if manifest is not None else {"campaign": {"name": name, "format_version": 1},
                                                 "instrument": {"output_unit": "mA"}}
    with tempfile.TemporaryDirectory(prefix="vrelab-campaign-") as d:
        with open(os.path.join(d, "manifest.toml"), "w") as f:
            f.write(case_toml(man))
        _write_columns(os.path.join(d, "static.csv"), static)
        _write_columns(os.path.join(d, "runs.csv"), runs)
        try:
            result = _core.diagnose(d, **settings)
        except InputError as e:
            raise InputError(str(e).replace(d, name)) from None
    result.dir = name  # the folder is gone; the result names the data as given
    return result
