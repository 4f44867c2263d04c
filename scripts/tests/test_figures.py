"""Every figure of scripts/figures.py, drawn in a test from the program's output (small grids
and few levels, for speed): each is written and non-empty."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import figures  # noqa: E402

os.environ.setdefault("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
figures.BIN = os.environ["RUBBER_ATLAS_BIN"]

CASES = {
    "ab": lambda out: figures.fig_ab(out, n=5),
    "wvth": lambda out: figures.fig_wvth(out, n=8),
    "bif": lambda out: figures.fig_bif(out, n=31),
    "phase": lambda out: figures.fig_phase(out, levels=3),
    "res": lambda out: figures.fig_res(out, targets=("0", "-1/7"), grid=16),
    "xy": lambda out: figures.fig_xy(out),
    "bodies": lambda out: figures.fig_bodies(out, n=21, targets=("0", "1/4"), grid=16),
}


@pytest.mark.parametrize("name", list(CASES))
def test_each_figure_is_drawn(name, tmp_path):
    path = CASES[name](tmp_path)
    assert path == tmp_path / f"{name}.png"
    assert path.stat().st_size > 15_000


def test_the_command_line_draws_one_figure(tmp_path):
    import subprocess

    subprocess.run([sys.executable, str(ROOT / "scripts" / "figures.py"), "xy", "--out", str(tmp_path)], check=True,
                   capture_output=True)
    assert (tmp_path / "xy.png").stat().st_size > 15_000
