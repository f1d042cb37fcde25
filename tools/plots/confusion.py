#!/usr/bin/env python3
"""The confusion matrix of `vrelab blind`: rows the hidden truth, columns what diagnose called
it without the key. Reads DIR/confusion.csv, writes DIR/confusion.png and DIR/confusion.svg.
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
    fig, ax = plt.subplots(figsize=(1.0 + 0.75 * len(cols), 1.2 + 0.5 * len(truths)))
    top = max(max(r) for r in m) or 1
    ax.imshow(m, cmap="Blues", vmin=0, vmax=top, aspect="auto")
    for i, r in enumerate(m):
        for j, v in enumerate(r):
            if v:
                ax.text(j, i, str(v), ha="center", va="center", fontsize=9,
                        color="white" if v > 0.6 * top else "black")
    ax.set_xticks(range(len(cols)), [c.replace("_", " ") for c in cols], rotation=35, ha="right", fontsize=8)
    ax.set_yticks(range(len(truths)), [t.replace("_", " ") for t in truths], fontsize=8)
    ax.set_xlabel("diagnose's verdict (without the key)")
    ax.set_ylabel("hidden in the campaign")
    ax.set_title(f"vrelab blind: {sum(map(sum, m))} campaigns")
    fig.tight_layout()
    savefig_atomic(fig, f"{out}/confusion.png", dpi=150)
    savefig_atomic(fig, f"{out}/confusion.svg")
    print(f"confusion.py: wrote {out}/confusion.png, .svg")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: confusion.py DIR")
    main(sys.argv[1])
