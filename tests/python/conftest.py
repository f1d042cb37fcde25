"""Fixtures shared by the Python tests (pytest finds this file beside them)."""
import os

import pytest

import vrelab

SRC = os.environ.get("VRELAB_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


@pytest.fixture(scope="session")
def lab_example():
    """vrelab.diagnose of cases/lab-example, once for every test that reads it (~3 s of CPU each)."""
    return vrelab.diagnose(os.path.join(SRC, "cases", "lab-example"))
