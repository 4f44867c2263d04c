"""scripts/hypothesis.py on a small (α, β) atlas made in the test: one body of each case of
the hypothesis, κ_max of the paper's type (c) body from the fold command, the verdict files,
and the trajectory check of a resonance (the evidence a failure would carry)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from hypothesis import Verdict, confirm, integer_crossings, judge, save  # noqa: E402

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
SCENE = """name = "hyp"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.0, 0.5]
beta = [0.5, 3.0]
kappa = { start = 0.0, stop = 2.0, num = 41 }
energy = { start = 0.3, stop = 4.5, num = 43 }
[solver]
tolerance = 1e-9
[outputs]
fields = ["rotation_number", "drift_radius", "bounded", "status", "error_estimate"]
"""


@pytest.fixture(scope="module")
def atlas(make_atlas):
    return make_atlas("hyp", SCENE)


def test_verdicts_by_case_and_kappa_max(atlas, tmp_path):
    verdicts = {(v.alpha, v.beta): v for v in judge(atlas)}
    assert verdicts[(0.0, 0.5)].diagram_type == "d" and verdicts[(0.0, 0.5)].case == 1
    assert verdicts[(0.5, 0.5)].diagram_type == "a" and verdicts[(0.5, 0.5)].case == 1
    assert verdicts[(0.0, 3.0)].verdict == "not covered"
    c = verdicts[(0.5, 3.0)]
    assert c.diagram_type == "c" and c.case == 2
    assert abs(c.kappa_max - 1.10784) < 1e-4
    # The integer resonances of type (c) lie below κ_max, and the atlas's highest one is near
    # the fold: a brute-force reading of the atlas. (Cells are 0.05 in κ and 0.1 in ε; near
    # its fold the N = 0 tongue is thinner than an ε-cell, so the grid sees it end at
    # κ = 1.0. tests/resonance.rs brackets the fold with a fine scan.)
    assert c.integer_resonance and c.resonance_kappa <= c.kappa_max + 0.05
    assert c.kappa_max - c.resonance_kappa < 0.15, c
    for key in [(0.5, 0.5), (0.5, 3.0)]:
        assert verdicts[key].verdict == "holds", verdicts[key]
    # α = 0, β < 1 (type d): every libration is symmetric about the equator, so N = 0 exactly
    # and the body rolls off in a straight line, though β² < 1 + α: the hypothesis fails.
    d = verdicts[(0.0, 0.5)]
    assert d.verdict == "fails" and d.evidence_integer == 0.0 and abs(d.evidence_n) < 1e-12, d
    c = confirm(d, 0.5, 0.5)
    assert c["confirmed"], c
    save(list(verdicts.values()), tmp_path / "out" / "h", 0.5, 0.5)
    with h5py.File(tmp_path / "out" / "h.h5") as f:
        assert f["verdict"].shape == (2, 2)
        assert np.isfinite(f["kappa_max"][()]).sum() == 1
    assert (tmp_path / "out" / "h.png").stat().st_size > 10_000
    assert (tmp_path / "out" / "h.csv").read_text().count("\n") == 5


def test_integer_crossings_ignore_jumps_and_kappa_zero():
    kappa = np.array([0.0, 0.5, 1.0])
    energy = np.array([1.0, 2.0, 3.0])
    n = np.full((3, 3, 1), np.nan)
    n[:, :, 0] = [[0.2, -0.2, 0.3], [0.4, 0.9, 1.1], [-0.7, 0.9, 0.3]]
    found = integer_crossings(kappa, energy, n, np.ones_like(n))
    # κ = 0 row is skipped; 0.9 → 1.1 crosses 1 (the cell nearer 1 is kept: 0.9 by a rounding);
    # 0.4 → -0.7 is a jump of 1.1 (a separatrix).
    assert {(k, e, i) for k, e, _, _, i, _ in found} == {(0.5, 2.0, 1.0)}


def test_the_trajectory_check_sees_a_resonance_drift_away():
    # A cell next to the N = 0 curve of the type (c) body: the check traces the curve there and
    # follows the centre of mass for 10 and 40 periods; on the resonance it drifts 4 times as far.
    v = Verdict(0.5, 3.0, "c", 2, True, 0.5, 1.10784, "fails", evidence_kappa=0.5, evidence_energy=3.18,
                evidence_n=0.01, evidence_drift_radius=10.0, evidence_integer=0.0)
    c = confirm(v, 0.5, 0.5)
    assert c["confirmed"], c
    assert abs(c["rotation_number"]) < 1e-9
