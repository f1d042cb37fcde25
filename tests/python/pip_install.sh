#!/usr/bin/env bash
# `pip install` of the package (pyproject.toml, setup.py) as a user does it, with Debian's
# setuptools and pybind11 and no network: a fresh venv (--system-site-packages: NumPy and the
# build tools from Debian), `pip install --no-build-isolation --no-index SRC`, then from
# another folder: the installed package is the one imported (not build/python or setup.sh's
# .pth), its version is CMake's, its plot scripts are found, and a prediction is eq. (3) by hand.
# The module is taken from BUILD as built (VRELAB_BUILD_DIR: the build ctest runs in; nothing compiled);
# pip's own build from nothing, CMake and all, is the same setup.py without it (docs/python.md).
# Usage: pip_install.sh SRC BUILD PYTHON VERSION
set -euo pipefail
src=$1 build=$2 python=$3 version=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$python" -m venv --system-site-packages "$tmp/venv"
VRELAB_BUILD_DIR="$build" "$tmp/venv/bin/pip" install --no-build-isolation --no-index --quiet "$src"
cd "$tmp"
env -u PYTHONPATH -u VRELAB_PLOTS_DIR "$tmp/venv/bin/python" - "$tmp/venv" "$version" <<'PY'
import os, sys
venv, version = sys.argv[1], sys.argv[2]
import vrelab
assert os.path.realpath(vrelab.__file__).startswith(os.path.realpath(venv) + os.sep), vrelab.__file__
assert vrelab.__version__ == version, (vrelab.__version__, version)
plots = os.environ.get("VRELAB_PLOTS_DIR", "")
assert os.path.isfile(os.path.join(plots, "reproduce.py")), plots
# eq. (3) by hand: k2 only, a sine of 4 g peak along IA, gravity along OA: k2 A^2 / 2.
zero = {k: 0.0 for k in ("k0", "k1_asym", "k3", "k4", "delta_OA", "delta_PA", "k_IP", "k_IO", "k_PO", "k_PP", "k_OO")}
case = {"g_m_per_s2": 9.81, "instrument": {"output_unit": "mA"},
        "coefficients": dict(zero, K1=1.25, k2=1.5e-5), "orientation": {"a_g": [0.0, 0.0, 1.0]},
        "vibration": {"type": "sine", "amplitude_g": [4.0, 0.0, 0.0], "phase_deg": [0.0, 0.0, 0.0], "frequency_Hz": 20.0}}
total = vrelab.predict(case).to_dict()["total_g"]
assert abs(total - 1.5e-5 * 4.0**2 / 2) <= 1e-15, total
print("pip_install: vrelab %s from %s; eq. (3) %.6g g (by hand %.6g g)" % (vrelab.__version__, vrelab.__file__, total, 1.2e-4))
PY
