"""Shared fixtures of the Python bindings' tests: a small cantilever scene, the CLI to compare
with, a scratch folder. ctest runs these with the build's module on PYTHONPATH
(tests/CMakeLists.txt, "python.pytest")."""

import json
import os
import subprocess

import pytest

import elastolearn as el

# A corotated bar fixed at x = 0, sagging under gravity: 4 × 1 × 1 cells, 20 steps of 2 ms
# (the CLI tests' small scene).
SMALL_SCENE = {
    "format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [4, 1, 1]},
    "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000,
                 "damping": {"alpha0": 0.1, "alpha1": 0.001}},
    "gravity": [0, -9.81, 0],
    "fixed": [{"min": "x"}],
    "time": {"dt": 0.002, "frames": 20},
}


@pytest.fixture
def small_scene(tmp_path):
    """The path of SMALL_SCENE written to a scratch folder."""
    path = tmp_path / "bar.json"
    path.write_text(json.dumps(SMALL_SCENE))
    return path


TRUE_YOUNG = 1.5e5  # the truth's E; SMALL_SCENE's nominal says 1e5


@pytest.fixture
def truth(small_scene, tmp_path):
    """The true motion of the small scene: its material 1.5 × stiffer."""
    material = el.Material.from_json({"format": "elastolearn-material/1", "correction": None,
                                      "material": dict(SMALL_SCENE["material"],
                                                       young=TRUE_YOUNG)})
    path = tmp_path / "truth.h5"
    el.simulate(small_scene, material=material, output=path)
    return path


@pytest.fixture
def cli():
    """Run the `elastolearn` executable of the same build; returns the completed process."""
    exe = os.environ.get("ELASTOLEARN_EXECUTABLE")
    if not exe:
        pytest.skip("ELASTOLEARN_EXECUTABLE not set (ctest sets it)")

    def run(*args):
        return subprocess.run([exe, *map(str, args)], capture_output=True, text=True)

    return run
