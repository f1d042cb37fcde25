"""Each examples/*.py runs from a folder that is not the repository's (a temporary one): it finds
the cases beside itself, not in the working directory, and writes its figure under out/ there.
(The notebook, examples/vrelab-tour.ipynb, is run by ctest's python_notebook.)"""
import glob
import os
import subprocess
import sys

import pytest

import vrelab

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLES = sorted(glob.glob(os.path.join(SRC, "examples", "*.py")))
FIGURES = {"confirmation.py": "out/confirmation.png", "diagnose_campaign.py": "out/lab-example-gap.png"}


def test_every_example_is_listed():
    assert sorted(os.path.basename(e) for e in EXAMPLES) == sorted(FIGURES)


@pytest.mark.parametrize("example", EXAMPLES, ids=os.path.basename)
def test_example_runs_from_another_folder(example, tmp_path):
    # The vrelab this test imports (PYTHONPATH may be relative to the repository's folder).
    package_parent = os.path.dirname(os.path.dirname(os.path.abspath(vrelab.__file__)))
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.pathsep.join([package_parent, os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run([sys.executable, os.path.abspath(example)], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    figure = tmp_path / FIGURES[os.path.basename(example)]
    assert figure.stat().st_size > 1000, figure
