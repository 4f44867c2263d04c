"""`rubber-atlas cell --shape profile` (a body of your own, docs/bodies.md) against the
independent 50-digit reference of scripts/reference.py, which fits the arc spline through the
table anew in mpmath by the rules docs/bodies.md states and shares no code with the solver: T
and N of every component within the solver's estimates, on tori that cross joints of the arcs
and the kink of a sharp edge, at tolerances 1e-8 and 1e-12."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import mpmath
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from reference import ProfileCell, at  # noqa: E402
from test_bodies import assert_ok_within_estimates  # noqa: E402

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))

# An egg with a sharp rim round its top (atlas/egg.toml).
EGG = [[0, -1], [0.45, -0.92], [0.8, -0.62], [0.98, -0.2], [0.97, 0.25], [0.8, 0.62, 1], [0.4, 0.8], [0, 0.86]]
# A smooth lens, flatter below than above, given top pole first.
LENS = [[0, 0.7], [0.5, 0.62], [0.9, 0.4], [1.2, 0.05], [1.1, -0.15], [0.7, -0.3], [0.3, -0.36], [0, -0.38]]
# A top: a sharp tip at the bottom pole, a rounded body, a flat face on top.
TOP = [[0, -1, 1], [0.35, -0.75], [0.7, -0.4], [0.9, 0.0], [0.85, 0.3], [0.6, 0.45, 1], [0, 0.45]]

# (table, α, ν, η, κ, θ at which the level ε = V(θ) is taken).
CASES = [
    ("egg", EGG, -0.1, 0.8, 1.7, 0.5, 0.6),
    ("egg", EGG, -0.1, 0.8, 1.7, 0.9, 2.3),
    ("egg", EGG, 0.2, 1.2, 3.0, 0.2, 1.2),
    ("lens", LENS, 0.1, 1.5, 2.0, 0.4, 0.5),
    ("lens", LENS, 0.1, 1.5, 2.0, 1.1, 2.3),
    ("lens", LENS, 0.1, 1.5, 2.0, 0.8, 1.2),
    ("top", TOP, -0.3, 0.6, 2.5, 0.5, 0.4),
    ("top", TOP, -0.3, 0.6, 2.5, 0.05, 2.0),
]


def write_table(tmp_path: Path, rows) -> Path:
    path = tmp_path / "profile.txt"
    path.write_text("rho z edge\n" + "\n".join(" ".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return path


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}-{c[5]}-{c[6]}" for c in CASES])
def test_cells_of_a_profile_against_50_digit_values(case, tmp_path):
    name, rows, alpha, nu, eta, kappa, theta = case
    cell = ProfileCell(rows, alpha, nu, eta, kappa)
    with mpmath.workdps(50):
        energy = float(cell.potential(at(theta)))
    reference = cell.components(energy)
    assert reference
    joints = [float(k.theta) for k in cell.kinks()]
    table = write_table(tmp_path, rows)
    crossed = 0
    for tol in (1e-8, 1e-12):
        args = [BIN, "cell", "--shape", "profile", "--profile", str(table), "--alpha", repr(alpha), "--nu", repr(nu),
                "--eta", repr(eta), "--kappa", repr(kappa), "--energy", repr(energy), "--tol", repr(tol), "--json"]
        out = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
        assert out["shape"] == "profile" and out["alpha"] == alpha and len(out["profile"]) == len(rows)
        assert_ok_within_estimates(out["components"], reference, tol, (name, kappa, theta))
        crossed += sum(r.theta_min < j < r.theta_max for r in reference for j in joints)
    # Each case has a torus across joints of the arcs (or the kink of an edge).
    assert crossed, f"{case}: joints {joints}"


def test_a_table_that_is_no_convex_meridian_is_refused_in_one_line(tmp_path):
    for rows, words in [
        ([[0, -1], [1, -0.5], [0.5, 0], [1, 0.5], [0, 1]], "not convex"),
        ([[0, -1], [1, -1], [1, 1], [0, 1]], "straight side"),
        ([[0.1, -1], [1, 0], [0, 1]], "on the axis"),
    ]:
        table = write_table(tmp_path, rows)
        run = subprocess.run([BIN, "cell", "--shape", "profile", "--profile", str(table), "--alpha", "0", "--nu", "1",
                              "--eta", "1", "--kappa", "0.5", "--energy", "2"], capture_output=True, text=True)
        assert run.returncode == 2 and run.stdout == "", run
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0] and str(table) in lines[0], run.stderr
    table = tmp_path / "words.txt"
    table.write_text("0 -1\n1 zero\n0 1\n")
    run = subprocess.run([BIN, "cell", "--shape", "profile", "--profile", str(table), "--alpha", "0", "--nu", "1",
                          "--eta", "1", "--kappa", "0.5", "--energy", "2"], capture_output=True, text=True)
    assert run.returncode == 2 and "line 2" in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
