"""Shared by the script tests: the rubber-atlas binary, and atlases made from scene text."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))


@pytest.fixture(scope="session")
def make_atlas(tmp_path_factory):
    """A function (name, scene text) → the atlas `rubber-atlas run` makes of it."""

    def make(name: str, scene: str) -> Path:
        folder = tmp_path_factory.mktemp(name)
        (folder / f"{name}.toml").write_text(scene)
        out = folder / f"{name}.h5"
        subprocess.run([BIN, "run", str(folder / f"{name}.toml"), "--out", str(out), "--quiet"], check=True)
        return out

    return make
