#!/usr/bin/python3
"""Compare two result JSON files (diagnose --json, shake --json, ...) number by number.

usage: bench/json_compare.py BEFORE.json AFTER.json [TOLERANCE]

Every number is compared with |a - b| <= TOLERANCE * max(|a|, |b|) (default 0: bit for bit
as printed, 17 significant digits); strings, booleans, keys and list lengths must be equal.
Timings and the program's identity are skipped (keys: wall_s, cpu_s, program, command,
threads, and anything under "timing"). Prints each difference with its path and the largest
relative difference; exits 1 when any difference exceeds the tolerance, 0 otherwise.
"""
import json
import math
import sys

SKIPPED = {"wall_s", "cpu_s", "program", "command", "threads", "timing", "version", "created"}


def walk(a, b, path, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in SKIPPED:
                continue
            if k not in a or k not in b:
                out.append((path + "/" + k, "missing in " + ("before" if k not in a else "after"), math.inf))
                continue
            walk(a[k], b[k], path + "/" + k, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append((path, "length %d != %d" % (len(a), len(b)), math.inf))
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, "%s[%d]" % (path, i), out)
    elif isinstance(a, bool) or isinstance(b, bool) or not (isinstance(a, (int, float)) and isinstance(b, (int, float))):
        if a != b:
            out.append((path, "%r != %r" % (a, b), math.inf))
    else:
        if a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)):
            return
        scale = max(abs(a), abs(b))
        rel = abs(a - b) / scale if scale > 0 else math.inf
        out.append((path, "%r -> %r" % (a, b), rel))


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    tol = float(sys.argv[3]) if len(sys.argv) == 4 else 0.0
    with open(sys.argv[1]) as f:
        before = json.load(f)
    with open(sys.argv[2]) as f:
        after = json.load(f)
    out = []
    walk(before, after, "", out)
    bad = [d for d in out if d[2] > tol]
    for path, what, rel in sorted(out, key=lambda d: -d[2])[:40]:
        print("%-70s %s  (relative %.3g)" % (path, what, rel))
    worst = max((d[2] for d in out), default=0.0)
    print("%d numbers differ, %d beyond tolerance %g; largest relative difference %.3g" % (len(out), len(bad), tol, worst))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
