#!/usr/bin/env python3
"""The confusion matrix of `vrelab blind`: rows the hidden truth, columns what diagnose called
it without the key. Reads DIR/confusion.csv, writes DIR/confusion.png and DIR/confusion.svg; rows and columns
without a campaign are left out of the figure (not of the CSV).
Usage: confusion.py DIR
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from atomic_figure import savefig_atomic  # noqa: E402


def main(out):
    with open(f"{out}/confusion.csv") as f:
        rows = list(csv.reader(r for r in f if not r.startswith("#")))
    cols, body = rows[0][1:], rows[1:]
    truths = [r[0] for r in body]
    m = [[int(x) for x in r[1:]] for r in body]
    # Only the truths and verdicts some campaign has (every campaign is in a drawn cell; the
    # empty rows and columns stay in the CSV): a small run's matrix stays legible.
    keep_r = [i for i, r in enumerate(m) if any(r)] or list(range(len(m)))
    keep_c = [j for j in range(len(cols)) if any(r[j] for r in m)] or list(range(len(cols)))
    truths, cols = [truths[i] for i in keep_r], [cols[j] for j in keep_c]
    m = [[m[i][j] for j in keep_c] for i in keep_r]
    fig, ax = plt.subplots(figsize=(max(7.0, 1.5 + 0.09 * max(map(len, truths)) + 0.8 * len(cols)),
                                    max(3.8, 2.4 + 0.45 * len(truths))))
    top = max(max(r) for r in m) or 1
    ax.imshow(m, cmap="Blues", vmin=0, vmax=top, aspect="auto")
    for i, r in enumerate(m):
        for j, v in enumerate(r):
            if v:
                ax.text(j, i, str(v), ha="center", va="center", fontsize=11,
                        color="white" if v > 0.6 * top else "black")
    ax.set_xticks(range(len(cols)), [c.replace("_", " ") for c in cols], rotation=35, ha="right", fontsize=10)
    ax.set_yticks(range(len(truths)), [t.replace("_", " ") for t in truths], fontsize=10)
    ax.set_xlabel("diagnose's verdict (without the key)", fontsize=11)
    ax.set_ylabel("hidden in the campaign", fontsize=11)
    ax.set_title(f"vrelab blind: {sum(map(sum, m))} campaigns")
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/confusion.png", dpi=150)
    savefig_atomic(fig, f"{out}/confusion.svg")
    print(f"confusion.py: wrote {out}/confusion.png, .svg")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: confusion.py DIR")
    main(sys.argv[1])
