#!/usr/bin/env python3
"""Figures of `vrelab diagnose --report DIR`, read from DIR/diagnosis.json:
- gap_map.{png,svg}: the signed standardised gap z of every run over frequency, one labelled
  panel per direction of vibration, shared frequency and z axes, the significance threshold
  drawn; sine runs coloured by amplitude, random runs apart (hollow diamonds at their band's
  centre, labelled by rms);
- residuals.{png,svg}: each run's held-out gap (µg) before and after the chosen effect with
  the measurement's sigma band, against the run id (up to 40 runs) or else against frequency.
Usage: diagnose.py DIR   (Debian's /usr/bin/python3 with python3-matplotlib)
"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402
from atomic_figure import savefig_atomic  # noqa: E402

AXES = ["IA", "PA", "OA"]


def direction_name(d):
    parts = [f"{x:.2g} {n}" for x, n in zip(d, AXES) if abs(x) > 1e-9]
    return " + ".join(parts) if len(parts) > 1 else AXES[max(range(3), key=lambda i: abs(d[i]))]


def kind(r):
    return r.get("kind", "sine")


PLAIN = FuncFormatter(lambda v, _: f"{v:g}")


def plain_log_ticks(ax, values):
    """Frequency ticks as plain numbers: the runs' own frequencies when there are few of them,
    else the decades (10, 100, 1000); no crowded minor labels."""
    ax.set_xscale("log")
    distinct = sorted(set(values))
    if len(distinct) <= 8:
        ax.set_xticks(distinct)
    else:
        ax.xaxis.set_major_locator(LogLocator(base=10))
    ax.xaxis.set_major_formatter(PLAIN)
    ax.xaxis.set_minor_formatter(NullFormatter())


def symlog_y(ax, smallest):
    """A signed log y axis, linear within +-linthresh (a power of ten >= smallest), plain labels."""
    linthresh = 10.0 ** math.ceil(math.log10(max(smallest, 1e-12)))
    ax.set_yscale("symlog", linthresh=linthresh)
    ax.yaxis.set_major_formatter(PLAIN)


def gap_map(d, out):
    runs = d["runs"]
    sig = d.get("settings", {}).get("significance_sigma", 5.0)
    groups = {}
    for r in runs:
        groups.setdefault(direction_name(r["direction"]), []).append(r)
    amps = sorted({r["amplitude_g"] for r in runs if kind(r) == "sine"})
    colours = {a: plt.cm.viridis(0.15 + 0.7 * i / max(1, len(amps) - 1)) for i, a in enumerate(amps)}
    n = len(groups)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    # Panels and type large enough to read in a mailed report at page width.
    fig, grid = plt.subplots(rows, cols, figsize=(4.6 * cols + 1.0, 3.9 * rows + 1.3), sharex=True, sharey=True,
                             squeeze=False)
    axes = [ax for row in grid for ax in row]
    for ax in axes[n:]:
        ax.set_visible(False)
    for ax, (name, rs) in zip(axes, groups.items()):
        for a in amps:
            sel = [r for r in rs if kind(r) == "sine" and r["amplitude_g"] == a]
            if sel:
                ax.scatter([r["frequency_Hz"] for r in sel], [r["z"] for r in sel], s=14 + 22 * a / max(amps),
                           color=colours[a], label=f"sine {a:g} g", alpha=0.85, zorder=3)
        rnd = [r for r in rs if kind(r) != "sine"]
        if rnd:
            ax.scatter([r["frequency_Hz"] for r in rnd], [r["z"] for r in rnd], s=34, marker="D", facecolors="none",
                       edgecolors="tab:red", label="random ({})".format(
                           ", ".join(sorted({f"{r['input_rms_g']:.3g} g rms" for r in rnd}))), zorder=3)
        for y in (sig, -sig):
            ax.axhline(y, color="tab:red", ls="--", lw=0.9)
        ax.axhline(0, color="0.4", lw=0.6)
        plain_log_ticks(ax, [r["frequency_Hz"] for r in runs])
        symlog_y(ax, 1.0)
        ax.set_title(f"vibration along {name}  ({len(rs)} run{'s' if len(rs) > 1 else ''})", fontsize=12)
        ax.set_xlabel("frequency (Hz)", fontsize=11)
        ax.tick_params(labelsize=10)
        ax.xaxis.set_tick_params(labelbottom=True)
        ax.grid(alpha=0.3, which="major")
    handles = {}
    for ax in axes[:n]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), fontsize=11, loc="lower center", ncol=min(4, len(handles)),
               frameon=False, markerscale=1.4)
    for row in grid:
        row[0].set_ylabel(f"gap z = (measured − predicted) / σ\n(±{sig:g} σ dashed)", fontsize=11)
    name = d.get("campaign") or d.get("data")
    fig.suptitle(f"Gap map: {d['verdict']}\n{name}", fontsize=13)
    legend_rows = (len(handles) + 3) // 4
    fig.tight_layout(rect=(0, 0.07 * legend_rows / rows, 1, 1))
    savefig_atomic(fig, f"{out}/gap_map.png", dpi=150)
    savefig_atomic(fig, f"{out}/gap_map.svg")
    plt.close(fig)


def residuals(d, out):
    runs = d["runs"]
    chosen = d.get("chosen") or "the best effect"
    after_label = f"after {chosen}" if d.get("explained") else f"with {chosen} (does not explain the gap)"
    fig, ax = plt.subplots(figsize=(max(7.5, 0.22 * len(runs) + 4), 4.0))
    before = [r["heldout_before_g"] * 1e6 for r in runs]
    after = [r["heldout_after_g"] * 1e6 for r in runs]
    sigma = [r["sigma_measured_g"] * 1e6 for r in runs]
    if len(runs) <= 40:
        x = list(range(len(runs)))
        ax.fill_between(x, [-s for s in sigma], sigma, step="mid", color="0.85", label="± measurement σ")
        ax.set_xticks(x)
        ax.set_xticklabels([r["id"] for r in runs], rotation=60, ha="right", fontsize=7)
        ax.set_xlabel("run (campaign order)")
    else:
        x = [r["frequency_Hz"] for r in runs]
        ax.errorbar(x, [0] * len(x), yerr=sigma, fmt="none", ecolor="0.75", lw=2, label="± measurement σ")
        plain_log_ticks(ax, x)
        ax.set_xlabel("frequency (Hz)")
    ax.plot(x, before, "o", ms=4, mfc="none", color="tab:blue", label="nominal simulation")
    ax.plot(x, after, "s", ms=3.5, color="tab:orange", label=after_label)
    ax.axhline(0, color="0.4", lw=0.6)
    symlog_y(ax, min(sigma))
    ax.set_ylabel("held-out gap, measured − predicted (µg)")
    ax.set_title("Held-out gap before and after the chosen effect", fontsize=12)
    ax.legend(fontsize=10, loc="upper left", bbox_to_anchor=(1.01, 1))
    ax.grid(alpha=0.3, which="major")
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/residuals.png", dpi=150)
    savefig_atomic(fig, f"{out}/residuals.svg")
    plt.close(fig)


def main(out):
    with open(f"{out}/diagnosis.json", encoding="utf-8") as f:
        d = json.load(f)
    gap_map(d, out)
    residuals(d, out)
    print(f"diagnose.py: wrote {out}/gap_map.png, residuals.png (.svg)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: diagnose.py DIR")
    main(sys.argv[1])
