"""Shared fixtures of the Python tests: the module under test (PYTHONPATH=build/python,
set by ctest), the command-line executable to compare against, and small scenes."""
import copy
import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]

# The workshop scene (scenes/workshop.json) as a dict, small enough to render in a test.
WORKSHOP = {
    "format": "scene/1",
    "render": {"width": 32, "height": 24, "spp": 4, "max_depth": 8},
    "camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "up": [0, 0, 1], "vfov": 90},
    "background": {"type": "gradient", "bottom": [1, 1, 1], "top": [0.5, 0.7, 1.0], "up": [0, 0, 1]},
    "materials": {
        "red": {"type": "lambertian", "albedo": [0.8, 0.1, 0.1]},
        "green": {"type": "lambertian", "albedo": [0.2, 0.7, 0.2]},
    },
    "objects": [
        {"type": "sphere", "center": [0, 10, 0], "radius": 5, "material": "red"},
        {"type": "sphere", "center": [0, 10, -100], "radius": 95, "material": "green"},
    ],
}


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
