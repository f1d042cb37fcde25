#!/usr/bin/env python3
"""Figures of `vrelab diagnose --report DIR`: the gap map (z per run over frequency, marker
size by amplitude, one panel per direction) and the held-out residuals before and after the
chosen effect. Reads DIR/diagnosis.json, writes DIR/gap_map.{png,svg}, DIR/residuals.{png,svg}.
Usage: diagnose.py DIR
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from atomic_figure import savefig_atomic  # noqa: E402


def direction_name(d):
    names = ["IA", "PA", "OA"]
    parts = [f"{x:.2g} {n}" for x, n in zip(d, names) if abs(x) > 1e-9]
    return " + ".join(parts) if len(parts) > 1 else names[max(range(3), key=lambda i: abs(d[i]))]


def main(out):
    with open(f"{out}/diagnosis.json") as f:
        d = json.load(f)
    runs = d["runs"]
    groups = {}
    for r in runs:
        groups.setdefault(direction_name(r["direction"]), []).append(r)
    amps = sorted({r["amplitude_g"] for r in runs})
    n = len(groups)
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n + 0.6, 3.6), sharey=True, squeeze=False)
    for ax, (name, rs) in zip(axes[0], groups.items()):
        for a in amps:
            sel = [r for r in rs if r["amplitude_g"] == a]
            ax.scatter([r["frequency_Hz"] for r in sel], [abs(r["z"]) for r in sel], s=12 + 18 * a / max(amps),
                       label=f"{a:g} g", alpha=0.8)
        ax.axhline(5, color="tab:red", ls="--", lw=0.9)
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=1)
        ax.set_title(f"along {name}", fontsize=9)
        ax.set_xlabel("frequency (Hz)")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("|z| of the gap (standardised)")
    axes[0][-1].legend(title="amplitude", fontsize=8, title_fontsize=8)
    fig.suptitle(f"Gap map: {d['verdict']}", fontsize=10)
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/gap_map.png", dpi=150)
    savefig_atomic(fig, f"{out}/gap_map.svg")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    x = range(len(runs))
    ax.plot(x, [abs(r["heldout_before_g"]) * 1e6 for r in runs], "o", ms=3.5, label="nominal simulation")
    best = d["effects"][0]["name"] if d["effects"] else "effect"
    ax.plot(x, [abs(r["heldout_after_g"]) * 1e6 for r in runs], "s", ms=3.5, label=f"with {best}")
    ax.plot(x, [r["sigma_measured_g"] * 1e6 for r in runs], "-", color="0.5", lw=0.8, label="measurement sigma")
    ax.set_yscale("log")
    ax.set_xlabel("run (campaign order)")
    ax.set_ylabel("|held-out gap| (ug)")
    ax.set_title("Held-out gap before and after the chosen effect", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/residuals.png", dpi=150)
    savefig_atomic(fig, f"{out}/residuals.svg")
    print(f"diagnose.py: wrote {out}/gap_map.png, residuals.png (.svg)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: diagnose.py DIR")
    main(sys.argv[1])
