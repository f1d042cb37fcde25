#!/usr/bin/env python3
"""Figure of the frequency study: e(f)/e_eq3 per mechanism (curves: the frequency-dependent
eq. (3); points: the ODE on the virtual shaker), and e(f) in ug for the effects that eq. (3)
does not contain. Reads DIR/frequency.csv and DIR/ode_points.csv written by
`vrelab frequency`, writes DIR/frequency.png and DIR/frequency.svg.
Usage: frequency.py DIR
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from atomic_figure import savefig_atomic  # noqa: E402


def read(path):
    with open(path) as f:
        return list(csv.DictReader(row for row in f if not row.startswith("#")))


def main(out):
    curves = defaultdict(lambda: ([], [], []))
    eq3 = {}
    for r in read(f"{out}/frequency.csv"):
        f, e, q = float(r["frequency_Hz"]), float(r["predicted_g"]), float(r["eq3_g"])
        c = curves[r["mechanism"]]
        c[0].append(f)
        c[1].append(e)
        eq3[r["mechanism"]] = q
    points = defaultdict(lambda: ([], []))
    for r in read(f"{out}/ode_points.csv"):
        p = points[r["mechanism"]]
        p[0].append(float(r["frequency_Hz"]))
        p[1].append(float(r["measured_g"]))

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [1.35, 1]})
    cmap = plt.get_cmap("tab10")
    # Mechanisms whose ratio curves coincide (e.g. a term in the loop and at the output, or
    # every frequency-independent one) share one line and one legend entry.
    groups = []
    for m in [m for m in curves if eq3[m] != 0]:
        ratio = [x / eq3[m] for x in curves[m][1]]
        for g in groups:
            if max(abs(a - b) for a, b in zip(g["ratio"], ratio)) < 1e-6:
                g["members"].append(m)
                break
        else:
            groups.append({"ratio": ratio, "members": [m], "f": curves[m][0]})
    floor = 1e-4
    for i, g in enumerate(groups):
        color = cmap(i % 10)
        flat = max(abs(r - 1) for r in g["ratio"]) < 1e-6
        label = ", ".join(g["members"]) if len(g["members"]) <= 4 else f"{g['members'][0]} and {len(g['members']) - 1} more"
        if flat:
            label += " (frequency-independent)"
        ax1.plot(g["f"], [max(r, floor) for r in g["ratio"]], color=color, lw=1.8, label=label)
        for m in g["members"]:
            pf, pe = points[m]
            ax1.plot(pf, [max(x / eq3[m], floor) for x in pe], "o", color=color, ms=5, mfc="none")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_ylim(floor, 4)
    ax1.axhline(1.0, color="k", lw=0.8, ls=":")
    ax1.set_xlabel("vibration frequency (Hz)")
    ax1.set_ylabel("e(f) / e_eq.(3)  (quasi-static)")
    ax1.set_title("Terms of model (1), by the place they act\ncurves: frequency-dependent eq. (3); circles: ODE")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7, loc="lower left")

    others = [m for m in curves if eq3[m] == 0]
    for i, m in enumerate(others):
        f, e, _ = curves[m]
        color = cmap((i + 6) % 10)
        ax2.plot(f, [x * 1e6 for x in e], color=color, lw=1.6, label=m)
        pf, pe = points[m]
        ax2.plot(pf, [x * 1e6 for x in pe], "o", color=color, ms=4.5, mfc="none")
    ax2.set_xscale("log")
    ax2.set_yscale("symlog", linthresh=1e-2)
    ax2.set_xlabel("vibration frequency (Hz)")
    ax2.set_ylabel("vibration error (ug)")
    ax2.set_title("Pendulum-deflection effects (not in eq. (3))\ncurves: prediction; circles: ODE")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/frequency.png", dpi=150)
    savefig_atomic(fig, f"{out}/frequency.svg")


if __name__ == "__main__":
    main(sys.argv[1])
