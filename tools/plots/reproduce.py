#!/usr/bin/env python3
"""Figures of the paper's experiment run on the virtual instrument. Reads what
`vrelab reproduce CASE --out DIR` wrote into DIR and writes, as DIR/<name>.png and DIR/<name>.svg:

  fig1_static        identified coefficients: normalised error (estimate - truth)/sigma per method
                     (static.csv)
  fig2_confirmation  the confirmation run: raw output, and the running integral of the deviation
                     with its least-squares slope and eq. (3) (confirmation.csv, confirmation.json)
  fig3_amplitude     measured vibration error against amplitude, eq. (3) corrected (+-1 sigma) and
                     as printed; rows: orientations, columns: directions
                     (amplitude.csv, amplitude_curves.csv)
  fig4_residuals     z = (measured - eq. (3))/combined sigma, and the residual in ug (amplitude.csv)
  fig5_frequency     the confirmation condition over frequency: measured, quasi-static and
                     frequency-dependent eq. (3) (frequency.csv, frequency_curves.csv; optional)
  fig6_invisible     the second instrument that no static test tells apart: residual against
                     amplitude and -c w^2/2 (invisible.csv, summary.json; optional)

A figure whose optional input is absent is skipped with a message on stderr. A missing required
input, or a figure that fails, is reported on stderr and makes the exit status 1; the other
figures are still written.
Usage: reproduce.py DIR
"""
import csv
import json
import math
import os
import sys
import traceback

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from atomic_figure import savefig_atomic  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator  # noqa: E402

UG = 1e6  # g -> ug
MU = "\u00b5"  # micro sign
plt.rcParams.update({
    "font.size": 8.5,
    "axes.titlesize": 9,
    "axes.labelsize": 8.5,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "legend.fontsize": 8,
    "figure.titlesize": 9.5,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "lines.linewidth": 1.3,
    "errorbar.capsize": 2,
})
DIRECTION_STYLE = [("tab:blue", "o"), ("tab:orange", "s"), ("tab:green", "^"), ("tab:red", "D"),
                   ("tab:purple", "v"), ("tab:brown", "P"), ("tab:pink", "X"), ("tab:gray", "h")]
METHOD_STYLE = {"paper_printed": ("tab:red", "v", "paper, formulas as printed"),
                "paper_corrected": ("tab:orange", "s", "paper, formulas corrected"),
                "least_squares": ("tab:blue", "o", "least squares")}
COEF_LABEL = {"K1": "$K_1$", "k0": "$k_0$", "k1_asym": "$k_1'$", "k2": "$k_2$", "k3": "$k_3$", "k4": "$k_4$",
              "delta_OA": r"$\delta_{OA}$", "delta_PA": r"$\delta_{PA}$", "k_IP": "$k_{IP}$", "k_IO": "$k_{IO}$",
              "k_PO": "$k_{PO}$", "k_PP": "$k_{PP}$", "k_OO": "$k_{OO}$"}


class MissingInput(Exception):
    pass


class BadInput(Exception):
    pass


def read(path):
    with open(path) as f:
        rows = list(csv.reader(row for row in f if not row.startswith("#")))
    if not rows:
        return []
    header, body = rows[0], []
    for r in rows[1:]:
        if not r:
            continue
        if len(r) != len(header):
            raise BadInput(f"{path}: a row has {len(r)} fields, the header {len(header)}: {','.join(r)[:80]}")
        body.append(dict(zip(header, r)))
    return body


_cache = {}


def load(out, name, columns):
    """Rows of DIR/name; MissingInput when the file or one of `columns` is absent."""
    path = os.path.join(out, name)
    if not os.path.isfile(path):
        raise MissingInput(f"{path} not found")
    if path not in _cache:
        _cache[path] = read(path)
    rows = list(_cache[path])
    if not rows:
        raise MissingInput(f"{path} has no data rows")
    missing = [c for c in columns if c not in rows[0]]
    if missing:
        raise MissingInput(f"{path} lacks column(s) {', '.join(missing)}")
    return rows


def load_json(out, name, keys=()):
    path = os.path.join(out, name)
    if not os.path.isfile(path):
        raise MissingInput(f"{path} not found")
    with open(path) as f:
        j = json.load(f)
    missing = [k for k in keys if k not in j]
    if missing:
        raise MissingInput(f"{path} lacks key(s) {', '.join(missing)}")
    return j


def num(s):
    """A cell as float; empty (not available) -> nan."""
    if s is None:
        return math.nan
    s = s.strip()
    return float(s) if s else math.nan


def col(rows, name):
    return np.array([num(r[name]) for r in rows])


def in_order(values):
    """Distinct values in order of first appearance."""
    seen = []
    for v in values:
        if v not in seen:
            seen.append(v)
    return seen


def vec(v):
    return "(" + ", ".join(f"{x:.2g}" if abs(x) > 1e-12 else "0" for x in v) + ")"


def sci(x, digits=3):
    """x as a x 10^n in mathtext."""
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    e = int(math.floor(math.log10(abs(x))))
    return rf"{x / 10**e:.{digits - 1}f}\times10^{{{e}}}"


def condition(c):
    """'along IA (1, 0, 0), IA at 60 deg: a = (0.5, 0, 0.87) g' from confirmation.json (names optional)."""
    d = " ".join(x for x in (c.get("direction_name", ""), vec(c.get("direction", []))) if x)
    o = c.get("orientation_name", "")
    return f"along {d}, {o + ': ' if o else 'static '}a = {vec(c.get('orientation_g', []))} g"


def header(fig, title, handles, labels, **legend_kw):
    """The title and a one-row legend above the panels, at fixed distances in inches; returns the
    top of the panels' area (figure fraction) for tight_layout."""
    h = fig.get_figheight()
    y = 1 - 0.05 / h
    fig.text(0.5, y, title, ha="center", va="top", fontsize=plt.rcParams["figure.titlesize"])
    y -= (0.165 * (title.count("\n") + 1) + 0.03) / h
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, y), ncol=len(handles), frameon=False,
               borderaxespad=0, **legend_kw)
    return y - 0.28 / h


def symlog_ticks(zmax, ones=True):
    """Ticks for a symlog axis of normalised errors (linthresh 3): 0, +-2 (+-1) and the decades."""
    dec = [10.0**k for k in range(1, int(math.ceil(math.log10(max(zmax * 1.5, 10)))) + 1)]
    return sorted([-d for d in dec] + ([-2, -1, 0, 1, 2] if ones else [-2, 0, 2]) + dec)


def symlog_label(v, _):
    if abs(v) < 10:
        return f"{v:.0f}".replace("-", "\u2212")
    e = int(round(math.log10(abs(v))))
    return ("\u2212" if v < 0 else "") + (f"$10^{{{e}}}$" if e > 1 else "10")


def save(fig, out, name, written):
    savefig_atomic(fig, os.path.join(out, name + ".png"), dpi=150)
    savefig_atomic(fig, os.path.join(out, name + ".svg"))
    plt.close(fig)
    written.append(name)


# --- fig1: static identification ------------------------------------------------------------

def fig_static(out):
    rows = load(out, "static.csv", ["method", "coefficient", "truth", "estimate", "error", "sigma", "assumed"])
    methods = in_order(r["method"] for r in rows)
    coefs = in_order(r["coefficient"] for r in rows)
    cell = {(r["method"], r["coefficient"]): r for r in rows}

    def state(m, c):
        r = cell.get((m, c))
        if r is None or math.isnan(num(r["estimate"])) or math.isnan(num(r["error"])):
            return "n/a", None
        if r["assumed"].strip().lower() in ("true", "1", "yes"):
            return "held", None
        s = num(r["sigma"])
        if not (s > 0):
            return "no sigma", None
        return "ok", num(r["error"]) / s

    shown = [c for c in coefs if any(state(m, c)[0] == "ok" for m in methods)]
    hidden = []
    for c in coefs:
        if c not in shown:
            why = in_order(state(m, c)[0] for m in methods)
            hidden.append(f"{COEF_LABEL.get(c, c)} ({' or '.join(why)})")
    fig, ax = plt.subplots(figsize=(7.2, 3.8))
    width = 0.8 / max(len(methods), 1)
    zhi, zlo = 3.0, 3.0  # largest positive / negative normalised error
    handles = []
    for j, m in enumerate(methods):
        color, marker, label = METHOD_STYLE.get(m, (f"C{j}", "o", m.replace("_", " ")))
        dx = (j - (len(methods) - 1) / 2) * width
        for i, c in enumerate(shown):
            st, z = state(m, c)
            x = i + dx
            if st == "ok":
                ax.plot([x, x], [0, z], color=color, lw=1.2, alpha=0.7)
                ax.plot(x, z, marker, color=color, ms=5, mec="k", mew=0.4, zorder=4)
                zhi, zlo = max(zhi, z), max(zlo, -z)
                if abs(z) >= 30:
                    ax.annotate(f"${sci(z, 2)}$" if abs(z) >= 1e4 else f"{z:.0f}".replace("-", "\u2212"), (x, z),
                                xytext=(0, 5 if z > 0 else -5), textcoords="offset points",
                                ha="center", va="bottom" if z > 0 else "top", fontsize=8, color=color)
            else:
                ax.text(x, 0.15, st, rotation=90, ha="center", va="bottom", fontsize=8, color="0.55")
        handles.append(Line2D([], [], color=color, marker=marker, mec="k", mew=0.4, lw=1.2, label=label))
    ax.axhspan(-2, 2, color="tab:green", alpha=0.10, lw=0)
    ax.axhspan(-1, 1, color="tab:green", alpha=0.18, lw=0)
    ax.axhline(0, color="k", lw=0.6)
    handles += [Patch(color="tab:green", alpha=0.28, label=r"$\pm1\sigma$"),
                Patch(color="tab:green", alpha=0.10, label=r"$\pm2\sigma$")]
    ax.set_yscale("symlog", linthresh=3, linscale=2.0)
    hi = 10 ** math.ceil(math.log10(zhi * 4))
    lo = 10 ** math.ceil(math.log10(zlo * 4))
    ax.set_ylim(-lo, hi)
    ticks = sorted([-10.0**k for k in range(1, int(round(math.log10(lo))) + 1)] + [-2, -1, 0, 1, 2]
                   + [10.0**k for k in range(1, int(round(math.log10(hi))) + 1)])
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_minor_locator(NullLocator())

    ax.yaxis.set_major_formatter(FuncFormatter(symlog_label))
    ax.set_xticks(range(len(shown)))
    ax.set_xticklabels([COEF_LABEL.get(c, c) for c in shown], fontsize=9)
    ax.set_xlim(-0.6, len(shown) - 0.4)
    ax.grid(axis="x", visible=False)
    ax.set_ylabel(r"normalised error  (estimate $-$ truth)/$\sigma$")
    title = "Static test on the dividing head: identified coefficients"
    if hidden:
        title += f"\nnot shown, estimated by no method: {', '.join(hidden)}"
    ax.set_title(title)
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=len(handles), fontsize=8,
              frameon=False, handlelength=1.6, columnspacing=1.0)
    fig.tight_layout()
    return fig


# --- fig2: the confirmation run -------------------------------------------------------------

def g_s(x):
    """A time integral of acceleration, x in g s, as text in a readable unit."""
    for scale, unit in ((1e6, f"{MU}g s"), (1e3, "mg s"), (1.0, "g s")):
        if abs(x) * scale < 1000 or unit == "g s":
            return f"{x * scale:.3g} {unit}"


def fig_confirmation(out):
    c = load_json(out, "confirmation.json", ["output_unit", "K1", "frequency_Hz", "amplitude_g", "t_measure_start_s",
                                             "t_end_s", "measured_g", "integral_slope_g", "predicted_g",
                                             "sigma_predicted_g"])
    rows = load(out, "confirmation.csv", ["t_s", "output", "integral_without_oscillation_g_s"])
    t, u = col(rows, "t_s"), col(rows, "output")
    unit, K1, f0, amp = c["output_unit"], float(c["K1"]), float(c["frequency_Hz"]), float(c["amplitude_g"])
    t0, t1 = float(c["t_measure_start_s"]), float(c["t_end_s"])
    slope, pred = float(c["integral_slope_g"]), float(c["predicted_g"])
    straight = c.get("integral_slope_straight_line_g")
    sp = float(c["sigma_predicted_g"] or 0.0)
    meas, smeas = float(c["measured_g"]), float(c.get("sigma_g") or 0.0)
    meas_mask = (t >= t0) & (t <= t1)
    # The integral with the vibration's own swing (fitted by vrelab: a line plus three
    # harmonics over the measured interval) taken off; the swing's size is in the JSON.
    shown = col(rows, "integral_without_oscillation_g_s")
    osc = float(c.get("oscillation_amplitude_g_s") or 0.0)
    intercept = float(np.mean(shown[meas_mask] - slope * t[meas_mask]))
    i0 = intercept + slope * t0
    scale, iunit = (UG, f"{MU}g s") if np.nanmax(np.abs(shown)) < 2e-3 else (1e3, "mg s")

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7.2, 5.6), gridspec_kw={"height_ratios": [1, 1.35]})
    ax1.plot(t, u, lw=0.3, color="tab:blue", rasterized=len(t) > 5000)
    ax1.set_ylabel(f"instrument output ({unit})")
    ax1.set_title(f"Confirmation run: {amp:g} g at {f0:g} Hz {condition(c)}")
    lo, hi = np.nanmin(u), np.nanmax(u)
    swing = float(np.ptp(u[meas_mask]) / 2) if meas_mask.any() else 0.0
    ax1.set_ylim(lo - 0.08 * (hi - lo), hi + 0.45 * (hi - lo))
    ax1.text(0.015, 0.95,
             f"vibration error {meas * UG:.3g} {MU}g, i.e. {K1 * meas:.2g} {unit} on a $\\pm${swing:.3g} {unit} "
             f"swing\n({abs(K1 * meas) / swing if swing > 0 else 0:.1e} of it)",
             transform=ax1.transAxes, va="top", ha="left", fontsize=8,
             bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="0.7", alpha=0.95))

    if osc > 0:
        lab = f"running integral of the deviation (its {f0:g} Hz oscillation, $\\pm${g_s(osc)}, taken off)"
    else:
        lab = "running integral of the deviation"
    ax2.plot(t, shown * scale, lw=0.8, color="k", label=lab, zorder=3, rasterized=len(t) > 5000)
    tl = np.array([t0, t1])
    ls_label = (f"least-squares fit: slope {slope * UG:.2f} {MU}g (whole-period mean {meas * UG:.2f}"
                + (f" $\\pm$ {smeas * UG:.2f}" if smeas > 0 else "") + f" {MU}g)")
    if straight is not None:
        ls_label += f"\n  (a straight line through the swing gives {float(straight) * UG:.2f} {MU}g)"
    ax2.plot(tl, (intercept + slope * tl) * scale, color="tab:blue", lw=3.5, alpha=0.55, zorder=2, label=ls_label)
    tt = np.linspace(t0, t1, 50)
    ax2.plot(tt, (i0 + pred * (tt - t0)) * scale, color="tab:red", lw=1.4, ls="--", zorder=4,
             label=f"eq. (3): slope {pred * UG:.2f} $\\pm$ {sp * UG:.2f} {MU}g")
    if sp > 0:
        ax2.fill_between(tt, (i0 + (pred - sp) * (tt - t0)) * scale, (i0 + (pred + sp) * (tt - t0)) * scale,
                         color="tab:red", alpha=0.18, lw=0, label=r"eq. (3) $\pm1\sigma$")
    ax2.set_ylabel(f"running integral ({iunit})")
    ax2.set_xlabel("time (s)")
    ax2.legend(loc="upper left", fontsize=8, framealpha=0.95)
    lo, hi = np.nanmin(shown) * scale, np.nanmax(shown) * scale
    ax2.set_ylim(lo - 0.05 * (hi - lo), hi + 0.55 * (hi - lo))
    for ax in (ax1, ax2):
        ax.axvline(0, color="k", lw=0.8, ls=":")
        ax.axvspan(t0, t1, color="tab:blue", alpha=0.05, lw=0)
        ax.axvline(t0, color="tab:blue", lw=0.8, ls="--")
    ax1.set_xlim(t[0], t[-1])
    trans = ax2.get_xaxis_transform()
    ax2.text(0, 0.58, "vibration on ", transform=trans, rotation=90, ha="right", va="top", fontsize=8)
    ax2.text(t0, 0.58, " measuring", transform=trans, rotation=90, ha="left", va="top", fontsize=8,
             color="tab:blue")
    ax2.text(t[0], 0.04, " at rest", transform=trans, ha="left", va="bottom", fontsize=8)
    fig.tight_layout(h_pad=0.6)
    return fig


# --- fig3 and fig4: the amplitude study -----------------------------------------------------

AMP_COLUMNS = ["orientation", "direction", "a_IA_g", "a_PA_g", "a_OA_g", "d_IA", "d_PA", "d_OA", "amplitude_g",
               "measured_g", "sigma_measured_g", "predicted_g", "sigma_predicted_g", "printed_g", "residual_g",
               "combined_sigma_g", "z"]


def amplitude_runs(out):
    rows = load(out, "amplitude.csv", AMP_COLUMNS)
    orients = in_order(r["orientation"] for r in rows)
    dirs = in_order(r["direction"] for r in rows)
    a_of = {r["orientation"]: (num(r["a_IA_g"]), num(r["a_PA_g"]), num(r["a_OA_g"])) for r in rows}
    d_of = {r["direction"]: (num(r["d_IA"]), num(r["d_PA"]), num(r["d_OA"])) for r in rows}
    freq = in_order(r.get("frequency_Hz", "") for r in rows)
    return rows, orients, dirs, a_of, d_of, freq


def fig_amplitude(out):
    rows, orients, dirs, a_of, d_of, freq = amplitude_runs(out)
    curves = load(out, "amplitude_curves.csv",
                  ["orientation", "direction", "amplitude_g", "predicted_g", "sigma_predicted_g", "printed_g"])
    nr, nc = len(orients), len(dirs)
    fig, axes = plt.subplots(nr, nc, sharex=True, squeeze=False,
                             figsize=(max(7.2, 1.75 * nc + 0.9), 1.85 * nr + 0.9))
    printed_drawn = False
    for i, o in enumerate(orients):
        for j, d in enumerate(dirs):
            ax = axes[i][j]
            cr = sorted((r for r in curves if r["orientation"] == o and r["direction"] == d),
                        key=lambda r: num(r["amplitude_g"]))
            pts = [r for r in rows if r["orientation"] == o and r["direction"] == d]
            span = []
            if cr:
                x, p = col(cr, "amplitude_g"), col(cr, "predicted_g") * UG
                s, q = np.nan_to_num(col(cr, "sigma_predicted_g")) * UG, col(cr, "printed_g") * UG
                ax.fill_between(x, p - s, p + s, color="tab:blue", alpha=0.22, lw=0)
                ax.plot(x, p, color="tab:blue", lw=1.3)
                span = [np.nanmin(p - s), np.nanmax(p + s)]
                diff = np.nanmax(np.abs(q - p)) if np.isfinite(q).any() else 0.0
                rng = max(np.nanmax(np.abs(p)), 1e-3)
                if diff > 0.02 * rng:
                    ax.plot(x, q, color="tab:red", lw=1.2, ls="--")
                    printed_drawn = True
            if pts:
                ax.errorbar(col(pts, "amplitude_g"), col(pts, "measured_g") * UG,
                            yerr=np.nan_to_num(col(pts, "sigma_measured_g")) * UG, fmt="o", ms=3.5, mfc="white",
                            mec="k", mew=0.8, ecolor="k", elinewidth=0.8, zorder=5)
            ax.axhline(0, color="k", lw=0.5)
            if i == 0:
                ax.set_title(f"along {d}\nd = {vec(d_of[d])}", fontsize=9)
            if i == nr - 1:
                ax.set_xlabel("amplitude (g)")
            if j == 0:
                ax.set_ylabel(f"vibration error ({MU}g)")
            if j == nc - 1:
                ax.annotate(f"{o}\na = {vec(a_of[o])} g", xy=(1, 0.5), xycoords="axes fraction",
                            xytext=(6, 0), textcoords="offset points", rotation=270, ha="left", va="center",
                            fontsize=9, fontweight="bold")
            ax.set_xlim(left=0)
    handles = [Line2D([], [], marker="o", ls="none", mfc="white", mec="k", ms=4, label=r"measured ($\pm\sigma$)"),
               (Patch(color="tab:blue", alpha=0.22), Line2D([], [], color="tab:blue")),
               ]
    labels = [handles[0].get_label(), r"eq. (3), identified coefficients ($\pm1\sigma$)"]
    if printed_drawn:
        handles.append(Line2D([], [], color="tab:red", ls="--"))
        labels.append("eq. (3) as printed (where it differs)")
    f = [x for x in freq if x]
    title = "Shaker runs" + (f" at {num(f[0]):g} Hz" if len(f) == 1 else "") + ": measured and predicted vibration error"
    fig.tight_layout(rect=(0, 0, 1, header(fig, title, handles, labels)), h_pad=0.5, w_pad=0.4)
    return fig


def dodge(dirs, x_span):
    """Small horizontal offsets, per direction, so points at the same amplitude do not overlap."""
    n = len(dirs)
    step = 0.018 * x_span
    return {d: (k - (n - 1) / 2) * step for k, d in enumerate(dirs)}


def fig_residuals(out):
    rows, orients, dirs, a_of, d_of, freq = amplitude_runs(out)
    amp_all = col(rows, "amplitude_g")
    off = dodge(dirs, np.nanmax(amp_all))
    nc = len(orients)
    fig, axes = plt.subplots(2, nc, sharex=True, sharey="row", squeeze=False,
                             figsize=(max(7.2, 2.3 * nc + 0.6), 5.0), gridspec_kw={"height_ratios": [1, 1.15]})
    zall = np.abs(col(rows, "z"))
    zm = np.nanmax(zall) if np.isfinite(zall).any() else 3.0
    big = zm > 10
    for j, o in enumerate(orients):
        az, ar = axes[0][j], axes[1][j]
        for k, d in enumerate(dirs):
            color, marker = DIRECTION_STYLE[k % len(DIRECTION_STYLE)]
            pts = [r for r in rows if r["orientation"] == o and r["direction"] == d]
            if not pts:
                continue
            x = col(pts, "amplitude_g") + off[d]
            res = col(pts, "residual_g")
            res = np.where(np.isnan(res), col(pts, "measured_g") - col(pts, "predicted_g"), res)
            az.plot(x, col(pts, "z"), marker, color=color, ms=4.5, mec="k", mew=0.4, ls="none")
            ar.errorbar(x, res * UG, yerr=np.nan_to_num(col(pts, "combined_sigma_g")) * UG, fmt=marker, color=color,
                        ms=4, mec="k", mew=0.4, elinewidth=0.9)
        for y in (-2, 2):
            az.axhline(y, color="tab:red", lw=0.9, ls="--")
        az.axhspan(-1, 1, color="tab:green", alpha=0.12, lw=0)
        az.axhline(0, color="k", lw=0.6)
        ar.axhline(0, color="k", lw=0.6)
        az.set_title(f"{o}, a = {vec(a_of[o])} g", fontsize=9)
        ar.set_xlabel("amplitude (g)")
        if big:
            az.set_yscale("symlog", linthresh=3)
            az.yaxis.set_major_locator(FixedLocator(symlog_ticks(zm)))
            az.yaxis.set_minor_locator(NullLocator())
            az.yaxis.set_major_formatter(FuncFormatter(symlog_label))
    axes[0][0].set_ylabel(r"z = residual / $\sigma_{comb}$")
    axes[1][0].set_ylabel(f"measured $-$ eq. (3) ({MU}g)")
    if big:
        axes[0][0].set_ylim(-10 ** math.ceil(math.log10(zm * 1.5)), 10 ** math.ceil(math.log10(zm * 1.5)))
    else:
        axes[0][0].set_ylim(-max(3.0, zm * 1.15), max(3.0, zm * 1.15))
    # Residuals in ug: a symlog axis when they span decades (large runs along IA beside
    # sub-ug ones along PA), linear through the smallest combined sigma.
    cs = np.abs(col(rows, "combined_sigma_g")) * UG
    rr = np.abs(col(rows, "residual_g")) * UG
    cs_pos = cs[np.isfinite(cs) & (cs > 0)]
    top = np.nanmax(rr + np.nan_to_num(cs)) if np.isfinite(rr).any() else 0.0
    if cs_pos.size and top / cs_pos.min() > 100:
        lin = 10 ** math.floor(math.log10(cs_pos.min()))
        axes[1][0].set_yscale("symlog", linthresh=lin, linscale=0.6)
        e0, e1 = int(round(math.log10(lin))), int(math.ceil(math.log10(top * 1.2)))
        dec = [10.0**k for k in range(e0, e1 + 1)]
        axes[1][0].yaxis.set_major_locator(FixedLocator(sorted([-d for d in dec] + [0] + dec)))
        axes[1][0].yaxis.set_minor_locator(NullLocator())
        axes[1][0].yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}".replace("-", "\u2212")))
        axes[1][0].set_ylim(-10.0**e1, 10.0**e1)
    for ax in axes[1]:
        ax.set_xlim(left=0)
    handles = [Line2D([], [], marker=DIRECTION_STYLE[k % len(DIRECTION_STYLE)][1],
                      color=DIRECTION_STYLE[k % len(DIRECTION_STYLE)][0], mec="k", mew=0.4, ls="none", ms=5,
                      label=f"along {d}" + ("" if d in ("IA", "PA", "OA") else f" {vec(d_of[d])}"))
               for k, d in enumerate(dirs)]
    handles += [Line2D([], [], color="tab:red", ls="--", label=r"$z=\pm2$"),
                Patch(color="tab:green", alpha=0.12, label=r"$|z|<1$")]
    f = [x for x in freq if x]
    title = ("Residuals of the shaker runs against eq. (3) with the identified coefficients"
             + (f" ({num(f[0]):g} Hz)" if len(f) == 1 else "")
             + "\nerror bars: combined standard uncertainty; directions offset slightly in amplitude")
    top = header(fig, title, handles, [hd.get_label() for hd in handles], handletextpad=0.3, columnspacing=1.2)
    fig.tight_layout(rect=(0, 0, 1, top), h_pad=0.5, w_pad=0.5)
    return fig


# --- fig5: frequency ------------------------------------------------------------------------

def fig_frequency(out):
    rows = load(out, "frequency.csv", ["frequency_Hz", "measured_g", "sigma_measured_g", "quasi_static_g",
                                       "at_frequency_g", "sigma_predicted_g"])
    rows.sort(key=lambda r: num(r["frequency_Hz"]))
    try:
        curves = load(out, "frequency_curves.csv", ["frequency_Hz", "quasi_static_g", "at_frequency_g",
                                                    "sigma_predicted_g"])
        curves.sort(key=lambda r: num(r["frequency_Hz"]))
    except MissingInput as e:
        print(f"reproduce.py: {e}; fig5 draws its curves through the measured frequencies", file=sys.stderr)
        curves = rows
    has_z = all(k in rows[0] for k in ("z_quasi_static", "z_at_frequency"))
    if has_z:
        fig, (ax, az) = plt.subplots(2, 1, sharex=True, figsize=(6.0, 5.2), gridspec_kw={"height_ratios": [2.2, 1.2]})
    else:
        fig, ax = plt.subplots(figsize=(6.0, 3.6))
    fc = col(curves, "frequency_Hz")
    qs, af = col(curves, "quasi_static_g") * UG, col(curves, "at_frequency_g") * UG
    s = np.nan_to_num(col(curves, "sigma_predicted_g")) * UG
    ax.plot(fc, qs, color="0.35", ls="--", lw=1.2, label="eq. (3), quasi-static")
    ax.fill_between(fc, af - s, af + s, color="tab:blue", alpha=0.22, lw=0)
    ax.plot(fc, af, color="tab:blue", lw=1.4)
    f = col(rows, "frequency_Hz")
    ax.errorbar(f, col(rows, "measured_g") * UG, yerr=np.nan_to_num(col(rows, "sigma_measured_g")) * UG, fmt="o",
                ms=4, mfc="white", mec="k", mew=0.8, ecolor="k", elinewidth=0.8, zorder=5,
                label=r"measured ($\pm\sigma$)")
    handles, labels = ax.get_legend_handles_labels()
    handles.insert(1, (Patch(color="tab:blue", alpha=0.22), Line2D([], [], color="tab:blue", lw=1.4)))
    labels.insert(1, r"eq. (3), frequency-dependent ($\pm1\sigma$)")
    ax.set_xscale("log")
    ax.set_ylabel(f"vibration error ({MU}g)")
    title = "Departure from eq. (3) with frequency (confirmation condition)"
    try:
        c = load_json(out, "confirmation.json")
        title = f"Confirmation condition over frequency\n{float(c['amplitude_g']):g} g {condition(c)}"
    except (MissingInput, KeyError, ValueError, TypeError):
        pass
    last = ax
    if has_z:
        az.plot(f, col(rows, "z_quasi_static"), "s", color="0.35", ms=4, mfc="none", label="against quasi-static")
        az.plot(f, col(rows, "z_at_frequency"), "o", color="tab:blue", ms=4, mec="k", mew=0.4,
                label="against frequency-dependent")
        for y in (-2, 2):
            az.axhline(y, color="tab:red", lw=0.9, ls="--")
        az.axhline(0, color="k", lw=0.6)
        zs = np.abs(np.concatenate([col(rows, "z_quasi_static"), col(rows, "z_at_frequency")]))
        zm = np.nanmax(zs) if np.isfinite(zs).any() else 3
        if zm > 10:
            az.set_yscale("symlog", linthresh=3)
            az.yaxis.set_major_locator(FixedLocator(symlog_ticks(zm, ones=False)))
            az.yaxis.set_minor_locator(NullLocator())
            az.yaxis.set_major_formatter(FuncFormatter(symlog_label))
            az.set_ylim(-10 ** math.ceil(math.log10(zm * 1.5)), 10 ** math.ceil(math.log10(zm * 1.5)))
        else:
            az.set_ylim(-max(3, 1.15 * zm), max(3, 1.15 * zm))
        az.set_ylabel(r"residual/$\sigma_{comb}$")
        az.legend(loc="best", fontsize=8, ncol=2, framealpha=0.95)
        last = az
    last.set_xlabel("vibration frequency (Hz)")
    last.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    fig.tight_layout(rect=(0, 0, 1, header(fig, title, handles, labels, columnspacing=1.2)), h_pad=0.5)
    return fig


# --- fig6: what no static test can see ------------------------------------------------------

def fig_invisible(out):
    rows = load(out, "invisible.csv", ["direction", "amplitude_g", "sigma_measured_g", "sigma_predicted_g",
                                       "expected_residual_g", "residual_g"])
    dirs = in_order(r["direction"] for r in rows)
    amp = col(rows, "amplitude_g")
    res = col(rows, "residual_g")
    if "measured_g" in rows[0] and "predicted_g" in rows[0]:
        res = np.where(np.isnan(res), col(rows, "measured_g") - col(rows, "predicted_g"), res)
    sig = np.hypot(np.nan_to_num(col(rows, "sigma_measured_g")), np.nan_to_num(col(rows, "sigma_predicted_g")))
    expected = col(rows, "expected_residual_g")
    # c, c_fit: from summary.json; otherwise from the file (c from the expected residuals, c_fit
    # by weighted least squares on -w^2/2).
    ok = amp > 0
    c = float(np.nanmedian(-2 * expected[ok] / amp[ok] ** 2)) if ok.any() else math.nan
    xx = -amp**2 / 2
    wgt = np.where(sig > 0, 1 / np.where(sig > 0, sig, 1) ** 2, 0.0)
    den = float(np.nansum(wgt * xx * xx))
    cfit = float(np.nansum(wgt * xx * res)) / den if den > 0 else math.nan
    cfit_s = 1 / math.sqrt(den) if den > 0 else math.nan
    try:
        inv = load_json(out, "summary.json").get("invisible", {})
        c = float(inv.get("c_per_g", c))
        cfit = float(inv.get("c_fit_per_g", cfit))
        cfit_s = float(inv.get("c_fit_sigma_per_g", cfit_s))
    except MissingInput as e:
        print(f"reproduce.py: {e}; c and its fit taken from invisible.csv", file=sys.stderr)

    fig, ax = plt.subplots(figsize=(6.0, 3.9))
    x = np.linspace(0, np.nanmax(amp) * 1.03, 200)
    if math.isfinite(cfit) and math.isfinite(cfit_s):
        ax.fill_between(x, -(cfit - cfit_s) * x**2 / 2 * UG, -(cfit + cfit_s) * x**2 / 2 * UG, color="tab:gray",
                        alpha=0.25, lw=0)
    ax.plot(x, -c * x**2 / 2 * UG, color="k", lw=1.3, label=r"expected $-c\,w^2/2$")
    if math.isfinite(cfit):
        ax.plot(x, -cfit * x**2 / 2 * UG, color="tab:gray", lw=1.3, ls="--")
    off = dodge(dirs, np.nanmax(amp))
    for k, d in enumerate(dirs):
        color, marker = DIRECTION_STYLE[k % len(DIRECTION_STYLE)]
        m = np.array([r["direction"] == d for r in rows])
        ax.errorbar(amp[m] + off[d], res[m] * UG, yerr=sig[m] * UG, fmt=marker, color=color, ms=4.5, mec="k", mew=0.4,
                    elinewidth=0.9, label=f"shaken along {d}", zorder=4)
    handles, labels = ax.get_legend_handles_labels()
    if math.isfinite(cfit):
        handles.insert(1, (Patch(color="tab:gray", alpha=0.25), Line2D([], [], color="tab:gray", ls="--")))
        labels.insert(1, r"fitted $-\hat c\,w^2/2$ ($\pm1\sigma$)")
    ax.legend(handles, labels, loc="lower left", framealpha=0.95)
    ax.axhline(0, color="k", lw=0.6)
    # The scale of the residuals and the curve, not of the largest error bars (those of the IA
    # runs carry the prediction's k2/k4 uncertainty and are clipped).
    span = max(np.nanmax(np.abs(res)), c * x[-1] ** 2 / 2) * UG
    ax.set_ylim(-1.6 * span, 0.5 * span)
    ax.set_xlim(0, x[-1])
    ax.set_xlabel("vibration amplitude |w| (g)")
    ax.set_ylabel(f"measured $-$ eq. (3) ({MU}g)")
    ct = rf"$c = {sci(c)}$ g$^{{-1}}$"
    if math.isfinite(cfit):
        e = int(math.floor(math.log10(abs(cfit)))) if cfit else 0
        ct += (rf",  $\hat c = ({cfit / 10**e:.3f} \pm {cfit_s / 10**e:.3f})\times10^{{{e}}}$ g$^{{-1}}$")
    ax.set_title("Second instrument: $(k_0, k_2, k_{PP}, k_{OO})$ shifted by $c\\,(1,-1,-1,-1)$,\n"
                 "identical to the first in every static position\n" + ct)
    fig.tight_layout()
    return fig


FIGURES = [  # name, function, required
    ("fig1_static", fig_static, True),
    ("fig2_confirmation", fig_confirmation, True),
    ("fig3_amplitude", fig_amplitude, True),
    ("fig4_residuals", fig_residuals, True),
    ("fig5_frequency", fig_frequency, False),
    ("fig6_invisible", fig_invisible, False),
]


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr)
        return 2
    out = argv[1]
    if not os.path.isdir(out):
        print(f"reproduce.py: {out} is not a directory", file=sys.stderr)
        return 1
    written, failed = [], []
    for name, make, required in FIGURES:
        try:
            save(make(out), out, name, written)
        except MissingInput as e:
            if required:
                print(f"reproduce.py: error: {name} not written: {e}", file=sys.stderr)
                failed.append(name)
            else:
                print(f"reproduce.py: {name} skipped: {e}", file=sys.stderr)
            plt.close("all")
        except BadInput as e:
            print(f"reproduce.py: error: {name} not written: {e}", file=sys.stderr)
            failed.append(name)
            plt.close("all")
        except Exception:  # a bad input must not cost the other figures
            print(f"reproduce.py: error: {name} failed:", file=sys.stderr)
            traceback.print_exc()
            failed.append(name)
            plt.close("all")
    print(f"reproduce.py: wrote {', '.join(written) if written else 'nothing'} (.png, .svg) in {out}"
          + (f"; FAILED: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
