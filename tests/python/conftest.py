"""Shared fixtures of the Python tests: the module under test (PYTHONPATH=build/python,
set by ctest), the command-line executable to compare against, and small scenes."""
import copy
import json
import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]

# The shipped workshop scene as a dict, made small enough to render in a test.
WORKSHOP = json.loads((REPO / "scenes" / "workshop.json").read_text())
WORKSHOP["render"] = {"width": 32, "height": 24, "spp": 4, "max_depth": 8}


@pytest.fixture
def workshop():
    """A fresh copy of the small workshop dict (tests may change it)."""
    return copy.deepcopy(WORKSHOP)


@pytest.fixture(scope="session")
def sahara_exe():
    """The `sahara` executable of the same build (ctest sets SAHARA_EXE)."""
    exe = os.environ.get("SAHARA_EXE")
    if not exe:
        candidates = [REPO / "build" / "sahara", REPO / "build-dev" / "sahara"]
        exe = next((str(c) for c in candidates if c.exists()), shutil.which("sahara"))
    if not exe or not os.path.exists(exe):
        pytest.skip("the sahara executable was not found (set SAHARA_EXE)")
    return exe


@pytest.fixture(scope="session")
def repo():
    return REPO
