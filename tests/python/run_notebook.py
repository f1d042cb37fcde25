"""Runs a notebook's code cells in order, as Jupyter would (one namespace), without Jupyter:
the cells are read with the json module and executed from a temporary folder with the Agg
backend, so the notebook depends on neither the working directory nor a display. First checks
that the file is an nbformat 4 notebook (the keys the format requires of it and its cells).
Fails (exit 1, the cell's traceback) at the first cell that raises.

    MPLBACKEND=Agg PYTHONPATH=build/python /usr/bin/python3 tests/python/run_notebook.py examples/vrelab-tour.ipynb

Run by ctest as python_notebook (label python)."""
import json
import os
import sys
import tempfile
import time
import traceback


def code_cells(path):
    """The notebook's code cells' sources, after checking its nbformat 4 structure."""
    with open(path, encoding="utf-8") as f:
        nb = json.load(f)
    problems = []
    if nb.get("nbformat") != 4 or not isinstance(nb.get("nbformat_minor"), int):
        problems.append("nbformat is %r.%r, not 4.x" % (nb.get("nbformat"), nb.get("nbformat_minor")))
    if not isinstance(nb.get("metadata"), dict) or not isinstance(nb.get("cells"), list):
        problems.append("a notebook has a metadata dict and a cells list")
    sources = []
    for i, cell in enumerate(nb.get("cells") or []):
        kind = cell.get("cell_type")
        if kind not in ("code", "markdown", "raw") or not isinstance(cell.get("metadata"), dict):
            problems.append("cell %d: cell_type %r, metadata %r" % (i + 1, kind, cell.get("metadata")))
        source = cell.get("source")
        if not (isinstance(source, str) or (isinstance(source, list) and all(isinstance(s, str) for s in source))):
            problems.append("cell %d: source is a string or a list of strings" % (i + 1))
            continue
        if kind == "code":
            if not isinstance(cell.get("outputs"), list) or "execution_count" not in cell:
                problems.append("cell %d: a code cell has outputs (a list) and execution_count" % (i + 1))
            sources.append((i + 1, "".join(source)))
    if problems:
        sys.exit("%s: not an nbformat 4 notebook:\n  %s" % (path, "\n  ".join(problems)))
    if not sources:
        sys.exit("%s: no code cells" % path)
    return sources


def main(path):
    path = os.path.abspath(path)
    cells = code_cells(path)
    os.environ.setdefault("MPLBACKEND", "Agg")
    namespace = {"__name__": "__main__"}
    with tempfile.TemporaryDirectory(prefix="vrelab-notebook-") as d:
        os.chdir(d)
        for number, source in cells:
            start = time.perf_counter()
            try:
                exec(compile(source, "%s, cell %d" % (os.path.basename(path), number), "exec"), namespace)
            except Exception:
                traceback.print_exc()
                sys.exit("%s: cell %d raised (above)" % (path, number))
            print("cell %d: %.2f s" % (number, time.perf_counter() - start), flush=True)
        os.chdir(os.path.dirname(path))
    print("%s: %d code cells ran" % (os.path.basename(path), len(cells)))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: run_notebook.py NOTEBOOK.ipynb")
    main(sys.argv[1])
