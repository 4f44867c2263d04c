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
import whole_domain  # noqa: E402

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


@pytest.mark.parametrize("energy", [0.414840889864706, 0.41484088982362055])
@pytest.mark.parametrize("tol", [1e-13, 1e-14])
def test_a_turning_point_just_past_a_joint_at_tight_tolerances(energy, tol, tmp_path):
    """The egg's level 1e-12 … 1e-8 above V at a joint of its arcs: at tol ≤ 1e-13 the gaps
    computed in double-double took the joint's U from the arc beyond it, and T came out
    2.2e-11 off with status ok and an estimate of 3.4e-13 (an adversary pass); a profile's
    gaps stay in double."""
    alpha, nu, eta, kappa = -0.6033, 1.961, 0.2389, 1.31e-10
    reference = ProfileCell(EGG, alpha, nu, eta, kappa).components(energy)
    table = write_table(tmp_path, EGG)
    args = [BIN, "cell", "--shape", "profile", "--profile", str(table), "--alpha", repr(alpha), "--nu", repr(nu),
            "--eta", repr(eta), "--kappa", repr(kappa), "--energy", repr(energy), "--tol", repr(tol), "--json"]
    comps = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)["components"]
    assert len(comps) == len(reference)
    for got, ref in zip(comps, reference):
        where = f"{energy} tol {tol}: {got} vs {ref}"
        assert abs(got["period"] - ref.period) <= got["errors"]["period"], where
        assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], where


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


def test_the_rounding_of_the_fit_is_in_the_estimates():
    """A profile's arcs are fitted through its points in doubles; their rounding is an error of
    U the estimates carry (8 eps times the table's largest coordinate, as an error of the
    level). Whole-domain seed 2 found this body (α 2e-6 below the top pole, a flat top arc of
    radius 431, N = 14.7) at tol 1e-12 with N 7.4e-13 off at status `ok`, its estimate
    1.4e-13: the fitted U is 1.8e-16 off there, where U itself is 3e-3."""
    rows = ((0.0, -1.0), (1.2724204597935098, -0.999576681768467), (3.8489382310430185, -0.8405716318461958),
            (4.275401140168607, -0.31977474178239496), (4.277171979843111, -0.2558786716368836),
            (4.225532546466111, 0.5752056388527097), (4.175428011033271, 0.6534554188145392),
            (4.012815919540386, 0.7762277878169084), (2.5169923331991386, 0.986199833077917), (0.0, 1.0))
    case = whole_domain.Case(0.999998, 1.0, 0.4107899917274661, 631.9529193744893, -0.0001595333133471339,
                             0.0038506335428092555, "random", None, "profile", 0.0, rows)
    for tol in (1e-10, 1e-12):
        outcome = whole_domain.check(case, tol=tol)
        assert not outcome.problems, (tol, outcome.problems)


def superellipse(p: float, width: float, height: float, points: int) -> list[list[float]]:
    """Points of |ρ/width|^p + |z/height|^p = 1, bottom pole first, evenly spaced in the angle
    of the parametrisation (p > 2: tops flatter than an ellipse's)."""
    rows = []
    for k in range(points + 1):
        phi = mpmath.pi * k / points
        s, c = float(mpmath.sin(phi)), -float(mpmath.cos(phi))
        rho = 0.0 if k in (0, points) else width * abs(s) ** (2 / p)
        rows.append([rho, height * float(mpmath.sign(c)) * abs(c) ** (2 / p)])
    return rows


# Wells by a flat top pole (κ small): the pole's arc turns a few 1e-4 rad, and its radius
# (thousands) divides by that turn. Taken as a difference of two angles near π (each to an
# absolute 4e-16) it was 8.6e-13 off, relative, and T ∝ r^−½ with it: whole-domain profile seed
# 5 found T 3.2e-13 off at status `ok`, its estimate 2.3e-13. (table, α, ν, η, κ, ε.)
SEED_5 = [[0.0, -1.0], [5.933276608482737, -0.9639628651409398], [8.712997577000316, -0.6551925576553639],
          [8.915757130443394, -0.529622410619184], [9.018949581908164, -0.34031901580793733],
          [9.034798192488878, -0.1341268603921141], [9.02149571215895, 0.32753265819449195],
          [8.991426243969011, 0.42455664450172603], [8.925079631677164, 0.5203060043789804],
          [8.882506885063513, 0.5586756867834685], [7.788694733284108, 0.8513644115915451],
          [7.665756509847862, 0.8648150557372478], [3.9623773487265455, 0.9944089117066456],
          [2.590887640448031, 0.9991747309186975], [0.0, 1.0]]
FLAT_TOPS = [
    (SEED_5, -0.7706426457109685, 1.8086412381759733, 0.002516421433609998, 3.512594423797863e-07,
     1.770787031292895),
    (superellipse(6, 9, 1, 20), -0.77, 1.8, 0.0025, 3.5e-7, 1e-4),
    (superellipse(6, 9, 1, 14), -0.5, 2.0, 1e-3, 1e-8, 2e-5),
]


@pytest.mark.parametrize("rows, alpha, nu, eta, kappa, level", FLAT_TOPS)
def test_a_well_by_a_flat_top_pole_is_as_accurate_as_its_arcs(rows, alpha, nu, eta, kappa, level, tmp_path):
    """T of the libration by the top pole within its estimate and within 32 ulps of the 50-digit
    value (the fitted radius is now good to a few ulps: T was 50 … 430 times that off before).
    A `level` below 1 is the distance from the pole of the angle whose V is ε."""
    cell = ProfileCell(rows, alpha, nu, eta, kappa)
    energy = level
    if level < 1:
        with mpmath.workdps(50):
            energy = float(cell.potential(at(mpmath.pi - level)))
    reference = [r for r in cell.components(energy) if r.theta_min > 3]
    assert len(reference) == 1
    table = write_table(tmp_path, rows)
    for tol in (1e-10, 1e-12):
        args = [BIN, "cell", "--shape", "profile", "--profile", str(table), "--alpha", repr(alpha), "--nu", repr(nu),
                "--eta", repr(eta), "--kappa", repr(kappa), "--energy", repr(energy), "--tol", repr(tol), "--json"]
        comps = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)["components"]
        got = [c for c in comps if c["theta_min"] > 3]
        assert len(got) == 1, comps
        error = abs(got[0]["period"] - float(reference[0].period))
        assert error <= got[0]["errors"]["period"], (tol, got[0], reference[0].period)
        assert error <= 32 * 2.0**-52 * got[0]["period"], (tol, error)
