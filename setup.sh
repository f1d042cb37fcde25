#!/usr/bin/env bash
# Sets vrelab up on a fresh Debian (12) machine and runs the main job:
#   1. installs the Debian packages it builds with (apt-get, with sudo when not root);
#   2. configures and builds into build/ (the program is build/vrelab, the Python module
#      build/python/vrelab, made importable by /usr/bin/python3 with a .pth file);
#   3. runs the main job on the shipped default case.
# Options: --no-run (skip step 3). CMake options can be passed in VRELAB_CMAKE_ARGS.
set -euo pipefail
cd "$(dirname "$0")"

packages=(build-essential cmake ninja-build git pkg-config
          libeigen3-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libfmt-dev libfftw3-dev libsundials-dev libhdf5-dev
          libgtest-dev libbenchmark-dev python3-matplotlib python3-pandas
          python3-dev python3-numpy pybind11-dev python3-pybind11 python3-pytest python3-venv python3-pip python3-setuptools python3-wheel
          libopenmpi-dev openmpi-bin
          libboost-dev
          chromium)  # headless: tests/cli/report_render.sh renders the HTML reports

run_main=1
[ "${1:-}" = "--no-run" ] && run_main=0

if ! dpkg -s "${packages[@]}" >/dev/null 2>&1; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "== Installing Debian packages: ${packages[*]}"
  $sudo apt-get update
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y "${packages[@]}"
fi

echo "== Building into build/"
# The MPI build (sweep, blind, identify --monte-carlo, diagnose --summary across the ranks of
# mpirun; docs/mpi.md) when Open MPI is installed, unless VRELAB_CMAKE_ARGS says otherwise.
mpi_arg=""
if command -v mpicxx >/dev/null 2>&1 && command -v mpirun >/dev/null 2>&1 && [[ "${VRELAB_CMAKE_ARGS:-}" != *VRELAB_MPI* ]]; then
  mpi_arg="-DVRELAB_MPI=ON"
fi
# Ninja for a new build folder (it keeps both cores busy where Make waits for each library to
# link; docs/performance.md, "Build time"); an existing folder keeps the generator it has.
gen_arg=""
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then
  gen_arg="-G Ninja"
fi
# shellcheck disable=SC2086
cmake -S . -B build $gen_arg -DCMAKE_BUILD_TYPE=Release $mpi_arg ${VRELAB_CMAKE_ARGS:-}
cmake --build build -j"$(nproc)"

# `import vrelab` for Debian's /usr/bin/python3: a .pth file in its site directory for local
# installs (/usr/local/lib/python3.X/dist-packages, not dpkg's) naming build/python, so every
# rebuild is what Python imports (README, "Python").
# Only when this build made the module (pybind11-dev missing or -DVRELAB_PYTHON=OFF: no module,
# nothing written); sudo only when the file changes, so a rerun asks for nothing.
if compgen -G "build/python/vrelab/_core*.so" >/dev/null && ! grep -q '^VRELAB_PYTHON:BOOL=OFF' build/CMakeCache.txt; then
  site=$(/usr/bin/python3 -c 'import site; print(site.getsitepackages()[0])')
  if [ "$(cat "$site/vrelab.pth" 2>/dev/null)" != "$PWD/build/python" ]; then
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo mkdir -p "$site"
    echo "$PWD/build/python" | $sudo tee "$site/vrelab.pth" >/dev/null
  fi
  echo "== Python: $site/vrelab.pth -> $PWD/build/python"
  (cd / && /usr/bin/python3 -c 'import vrelab' 2>/dev/null) || echo "== Python: warning: /usr/bin/python3 cannot import vrelab (docs/python.md)"
else
  echo "== Python: no module in this build (pybind11-dev, python3-dev; docs/python.md)"
fi

if [ "$run_main" -eq 1 ]; then
  # The main job: the paper's experiment reproduced on the shipped default case; the
  # report and its data in out/paper (report.html, report.md, figures, CSV/JSON).
  echo "== Main job: build/vrelab reproduce cases/paper.toml --out out/paper"
  build/vrelab reproduce cases/paper.toml --out out/paper
fi
