"""Shared by the package tests, which run on the *installed* package from a folder outside
the repository (scripts/test.sh): the rubber-atlas binary to compare with, and atlases."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))


def run(*args) -> str:
    """Runs the binary; returns its standard output (it must succeed)."""
    out = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout


def same_double(a, b) -> bool:
    """The same float64, bit for bit."""
    return np.float64(a).tobytes() == np.float64(b).tobytes()


def assert_component_equals(component, expected: dict, keys, where) -> None:
    """A component of a `cells` result (one cell, one slot) against the object `cell --json`
    prints for it: each of `keys` bit for bit, JSON null (NaN or an infinity) as a value that
    is not finite."""
    for key in keys:
        if expected[key] is None:
            assert not np.isfinite(float(component[key])), (where, key)
        else:
            assert same_double(component[key], expected[key]), (where, key, float(component[key]), expected[key])


SCENE = """name = "{name}"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = {alpha}
beta = {beta}
kappa = {kappa}
energy = {energy}
[solver]
tolerance = 1e-10
[outputs]
fields = ["theta_min", "theta_max", "period", "omega_theta", "omega_psi", "rotation_number",
          "drift", "drift_radius", "bounded", "motion", "status", "error_estimate"]
"""


@pytest.fixture(scope="session")
def make_scene(tmp_path_factory):
    """A function (name, alpha=…, beta=…, kappa=…, energy=…) → the path of a scene file."""

    def make(name: str, **axes) -> Path:
        text = SCENE.format(name=name, **axes)
        path = tmp_path_factory.mktemp(name) / f"{name}.toml"
        path.write_text(text)
        return path

    return make


@pytest.fixture(scope="session")
def slice_atlas(make_scene):
    """A small atlas of one body: (kappa, energy) 21 x 17, all outputs."""
    scene = make_scene("slice", alpha="[0.5]", beta="[3.0]",
                       kappa="{ start = 0.0, stop = 2.0, num = 21 }",
                       energy="{ start = 0.5, stop = 4.5, num = 17 }")
    out = scene.with_suffix(".h5")
    run("run", scene, "--out", out, "--quiet")
    return out
