"""Results as tables: dicts of NumPy columns (always) and pandas DataFrames (where pandas is
installed), made from the result's to_dict() -- the CLI's JSON -- so a table's numbers are the
JSON's, one row a record and one column a key.

Column names are the JSON keys, units last (measured_g, frequency_Hz); a key holding a vector
[IA, PA, OA] becomes three columns with the axis before the unit (orientation_g ->
orientation_IA_g, orientation_PA_g, orientation_OA_g; direction -> direction_IA, ...), and a
key holding a table its keys after a dot (motion.rms_ratio). A column's dtype: bool when every
value is a bool, int64 when every value is an integer, float64 when every value is a number
or missing (JSON null, a non-finite number, or a key a row lacks: NaN), else object (strings,
None where missing)."""
import numpy as np

AXES = ("IA", "PA", "OA")
# The unit a key ends in, kept last when an axis is added (orientation_g -> orientation_IA_g).
_UNITS = {"g", "Hz", "s", "deg", "rad", "ug", "m", "g2"}


def pandas_module(what, instead):
    """pandas, or an ImportError saying how to install it and, `instead`, where the same table
    is without it."""
    try:
        import pandas
    except ImportError:
        raise ImportError("%s needs pandas, which is not installed: apt-get install python3-pandas (Debian) or "
                          "pip install pandas. Without pandas the same table is a dict of NumPy arrays: %s"
                          % (what, instead)) from None
    return pandas


def frame(columns, what, instead):
    """A pandas DataFrame of a dict of NumPy columns (dtypes kept: int64 stays int64)."""
    return pandas_module(what, instead).DataFrame(columns, copy=False)


def _axis_name(key, axis):
    head, _, unit = key.rpartition("_")
    return "%s_%s_%s" % (head, axis, unit) if head and unit in _UNITS else "%s_%s" % (key, axis)


def flatten(record, prefix=""):
    """One JSON record as flat {column: value}: vectors of three numbers per axis, tables' keys after a dot."""
    out = {}
    for key, value in record.items():
        name = prefix + key
        if isinstance(value, dict):
            out.update(flatten(value, name + "."))
        elif (isinstance(value, list) and len(value) == 3
              and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)):
            for axis, x in zip(AXES, value):
                out[_axis_name(name, axis)] = x
        else:
            out[name] = value
    return out


def column(values):
    """A NumPy column of JSON values (the dtype rules of the module's docstring)."""
    if values and all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if values and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=np.int64)
    if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values):
        return np.array([np.nan if v is None else v for v in values], dtype=np.float64)
    out = np.empty(len(values), dtype=object)
    out[:] = values
    return out


def columns(records, first=()):
    """The columns of a list of JSON records (flattened): `first` in front, then the keys in
    the order the records give them; a key a record lacks is missing there."""
    rows = [flatten(r) for r in records]
    names = [n for n in first if any(n in r for r in rows)]
    for r in rows:
        names.extend(n for n in r if n not in names)
    return {n: column([r.get(n) for r in rows]) for n in names}


# ---- Diagnosis

def runs_columns(self):
    """The runs as the diagnosis used them, one row a run (to_dict()['runs']): id, kind,
    frequency_Hz, amplitude_g, the direction and orientation per axis, measured_g,
    sigma_measured_g, predicted_g, gap_g, z, the held-out gaps (g), ... as a dict of NumPy
    columns (vrelab.tables: names and dtypes)."""
    return columns(self.to_dict()["runs"], first=("id", "kind"))


def runs_frame(self):
    """runs_columns() as a pandas DataFrame (one row a run)."""
    return frame(self.runs_columns(), "Diagnosis.runs_frame()", "runs_columns()")


def effects_columns(self, parameters=False):
    """The effects ranked by held-out evidence (to_dict()['effects']), one row an effect: name,
    evidence, heldout_chi2, insample_chi2 and insample_dof (the fit on every run), its headline parameter (parameter_name, parameter, sigma, unit,
    at_bound) and the number of its fitted parameters (n_parameters). parameters=True: one row
    a fitted parameter of an effect (effect, evidence, heldout_chi2, then the parameter's name,
    value, sigma, unit, status, at_bound, range_min, range_max). A dict of NumPy columns."""
    effects = self.to_dict()["effects"]
    if not parameters:
        rows = [dict({k: v for k, v in e.items() if k != "parameters"}, n_parameters=len(e["parameters"])) for e in effects]
        return columns(rows, first=("name", "evidence", "heldout_chi2"))
    rows = []
    for e in effects:
        for p in e["parameters"]:
            low, high = p.get("range") or (None, None)
            rows.append(dict({"effect": e["name"], "evidence": e["evidence"], "heldout_chi2": e["heldout_chi2"]},
                             **{k: v for k, v in p.items() if k != "range"}, range_min=low, range_max=high))
    return columns(rows, first=("effect", "evidence", "heldout_chi2", "name", "value", "sigma", "unit"))


def effects_frame(self, parameters=False):
    """effects_columns(parameters) as a pandas DataFrame."""
    return frame(self.effects_columns(parameters), "Diagnosis.effects_frame()", "effects_columns()")


# ---- IdentifyResult

def coefficients_columns(self, method="least_squares"):
    """Model (1)'s coefficients as identified by `method` (None: every method that ran, one
    block each, with a `method` column), one row a coefficient: coefficient, unit (of estimate,
    sigma, truth and error: K1 output units/g, k0 g, k2 1/g, ...), estimate, sigma (first
    order), truth, error (estimate - truth), given (held at a known or assumed value, sigma 0),
    and with monte_carlo=N the trials' monte_carlo_std and monte_carlo_mean_error. A coefficient
    the method does not give (the printed formulas: delta_OA, delta_PA) is NaN. A dict of NumPy
    columns."""
    j = self.to_dict()
    ran = [m for m in j["estimates"] if j["estimates"][m] is not None]
    if method is not None and method not in ran:
        raise KeyError("no method %r (the methods that ran: %s)" % (method, ", ".join(ran)))
    names = list(self.truth)  # model (1)'s order: K1, k0, k1_asym, k2, ...
    rows = []
    for m in self.methods if method is None else [method]:
        mc = (j.get("monte_carlo") or {}).get(m)
        for n in names:
            row = {"method": m} if method is None else {}
            row.update(coefficient=n, unit=j["units"][n], estimate=j["estimates"][m][n], sigma=j["sigma"][m][n],
                       truth=j["truth"][n], error=j["errors"][m][n], given=n in j["given"][m])
            if mc:
                row.update(monte_carlo_std=mc["std"][n], monte_carlo_mean_error=mc["mean_error"][n])
            rows.append(row)
    return columns(rows)


def coefficients_frame(self, method="least_squares"):
    """coefficients_columns(method) as a pandas DataFrame."""
    return frame(self.coefficients_columns(method), "IdentifyResult.coefficients_frame()", "coefficients_columns()")


def readings_columns(self):
    """The static test's readings (to_dict()['readings']), one row a reading: position, series,
    angle_deg, the nominal input per axis (a_nominal_IA_g, ...) and the output in the case's
    output unit (output_mA). A dict of NumPy columns."""
    j = self.to_dict()
    cols = columns(j["readings"], first=("position", "series", "angle_deg"))
    return {("output_" + j["readings_unit"] if n == "output" else n): v for n, v in cols.items()}


def readings_frame(self):
    """readings_columns() as a pandas DataFrame."""
    return frame(self.readings_columns(), "IdentifyResult.readings_frame()", "readings_columns()")


def attach(core):
    """The table methods onto the binding's result classes."""
    for cls, fns in ((core.Diagnosis, (runs_columns, runs_frame, effects_columns, effects_frame)),
                     (core.IdentifyResult, (coefficients_columns, coefficients_frame, readings_columns, readings_frame))):
        for fn in fns:
            setattr(cls, fn.__name__, fn)


# ---- predict over arrays

class PredictArrays:
    """vrelab.predict over arrays of frequency_Hz and amplitude_g: every attribute a NumPy array
    of the arrays' broadcast shape, element for element the scalar call's number
    (predict(case, frequency_Hz=f, amplitude_g=a)).

    frequency_Hz, amplitude_g: the values used (Hz; g peak along the case's direction);
    total_g: eq. (3) corrected, g; terms: {term: g}; printed_g: eq. (3) as printed (NaN for a
    sine on random); omitted_by_paper_g; with frequency_dependent=True frequency_dependent_g and
    frequency_terms (through the plant's dynamics), else None."""

    def __init__(self, arrays, shape):
        def shaped(x):
            return None if x is None else x.reshape(shape)
        self.shape = shape
        self.frequency_Hz, self.amplitude_g = shaped(arrays["frequency_Hz"]), shaped(arrays["amplitude_g"])
        self.total_g, self.printed_g = shaped(arrays["total_g"]), shaped(arrays["printed_g"])
        self.omitted_by_paper_g = shaped(arrays["omitted_by_paper_g"])
        self.terms = {k: shaped(v) for k, v in arrays["terms"].items()}
        self.frequency_dependent_g = shaped(arrays["frequency_dependent_g"])
        ft = arrays["frequency_terms"]
        self.frequency_terms = None if ft is None else {k: shaped(v) for k, v in ft.items()}

    def columns(self):
        """One row an element (flattened, C order): frequency_Hz, amplitude_g, total_g,
        printed_g, omitted_by_paper_g, each term as <term>_g, and with frequency_dependent=True
        frequency_dependent_g and frequency_dependent_<term>_g. A dict of NumPy columns."""
        out = {n: getattr(self, n).ravel() for n in ("frequency_Hz", "amplitude_g", "total_g", "printed_g", "omitted_by_paper_g")}
        out.update((t + "_g", v.ravel()) for t, v in self.terms.items())
        if self.frequency_dependent_g is not None:
            out["frequency_dependent_g"] = self.frequency_dependent_g.ravel()
            out.update(("frequency_dependent_%s_g" % t, v.ravel()) for t, v in self.frequency_terms.items())
        return out

    def frame(self):
        """columns() as a pandas DataFrame."""
        return frame(self.columns(), "PredictArrays.frame()", "columns()")

    def __repr__(self):
        return "<vrelab.PredictArrays shape=%s total_g=%s>" % (self.shape, np.array2string(self.total_g, precision=6, threshold=6))
