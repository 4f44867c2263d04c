"""`rubber-atlas cell --shape …` for the edged bodies (docs/bodies.md) against the independent
50-digit reference of scripts/reference.py (mpmath; it shares no code with the solver, only the
formulas of docs/bodies.md): T and N of every component within the solver's estimates, on
tori that cross a kink of U and on tori that do not."""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import whole_domain  # noqa: E402
from reference import EdgedCell, at  # noqa: E402

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))

# (shape, α, cut, ν, η, κ, θ at which the level is taken, whether its torus crosses a kink):
# the level ε = V(θ).
CASES = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 0.6, 0.45, True),
    ("truncated_ball", -0.3, -0.5, 0.7, 1.3, 0.9, 2.3, True),
    ("truncated_ball", 0.5, 0.9, 1.0, 2.5, 0.3, 0.3, True),
    ("truncated_ball", 0.5, 0.9, 1.0, 2.5, 0.3, 2.0, False),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.5, 0.4, True),
    ("wheel", 0.0, 0.3, 0.5, 3.0, 1.2, 0.9, True),
    ("disk", 0.3, None, 2.0, 4.0, 0.7, 0.5, False),
    ("disk", -0.6, None, 1.5, 2.0, 0.05, 0.2, False),
]


def level(shape, alpha, cut, nu, eta, kappa, theta):
    cell = EdgedCell(shape, alpha, cut or 0, nu, eta, kappa)
    with mpmath.workdps(50):
        return cell, float(cell.potential(at(theta)))


def run_cell(shape, alpha, cut, nu, eta, kappa, energy, tol):
    args = [BIN, "cell", "--shape", shape, "--alpha", repr(alpha), "--nu", repr(nu), "--eta", repr(eta),
            "--kappa", repr(kappa), "--energy", repr(energy), "--tol", repr(tol), "--json"]
    if cut is not None:
        args += ["--cut", repr(cut)]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}-{c[1]}-{c[5]}" for c in CASES])
def test_cells_of_edged_bodies_against_50_digit_values(case):
    shape, alpha, cut, nu, eta, kappa, theta, crosses = case
    cell, energy = level(shape, alpha, cut, nu, eta, kappa, theta)
    reference = cell.components(energy)
    assert reference
    kinks = [float(k.theta) for k in cell.kinks()]
    crossed = 0
    for tol in (1e-8, 1e-12):
        out = run_cell(shape, alpha, cut, nu, eta, kappa, energy, tol)
        assert out["shape"] == shape and out["alpha"] == alpha
        assert_ok_within_estimates(out["components"], reference, tol, case)
        crossed += sum(any(r.theta_min < k < r.theta_max for k in kinks) for r in reference)
    assert bool(crossed) == crosses, f"{case}: kinks {kinks}"


def assert_ok_within_estimates(comps: list, reference: list, tol: float, case) -> None:
    """The components of `cell --json` against the 50-digit reference: the same turning points,
    every one `ok`, T and N within their estimates, the estimates within the tolerance
    (relative for T, absolute for N)."""
    assert len(comps) == len(reference), (comps, reference)
    for got, ref in zip(comps, reference):
        where = f"{case} tol {tol}: {got} vs {ref}"
        assert abs(got["theta_min"] - ref.theta_min) < 1e-12 and abs(got["theta_max"] - ref.theta_max) < 1e-12, where
        assert ref.period_error < 1e-25 and ref.rotation_error < 1e-25, ref
        assert got["status"] == "ok", where
        assert abs(got["period"] - ref.period) <= got["errors"]["period"], where
        assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], where
        assert got["errors"]["rotation_number"] <= tol and got["errors"]["period"] <= tol * ref.period, where


def test_the_cut_balls_refuse_what_they_do_not_take():
    """One line, exit 2, naming the parameter: a cut for the disk, a beta for a cut ball, a cut
    out of range, a missing cut or beta."""
    base = ["cell", "--nu", "0.5", "--eta", "0.5", "--kappa", "0.5", "--energy", "3"]
    for extra, words in [
        (["--shape", "disk", "--alpha", "0", "--cut", "0.5"], "takes no --cut"),
        (["--shape", "wheel", "--alpha", "0", "--cut", "0.5", "--beta", "2"], "takes no --beta"),
        (["--shape", "wheel", "--alpha", "0", "--cut", "-0.2"], "invalid cut = -0.2"),
        (["--shape", "truncated_ball", "--alpha", "0", "--cut", "1"], "invalid cut = 1"),
        (["--shape", "truncated_ball", "--alpha", "1", "--cut", "0.5"], "invalid alpha = 1"),
        (["--shape", "truncated_ball", "--alpha", "0.1"], "--cut is required"),
        (["--alpha", "0.1"], "--beta is required"),
        (["--shape", "ellipsoid", "--alpha", "0.1", "--beta", "2", "--cut", "0.3"], "takes no --cut"),
    ]:
        p = subprocess.run([BIN, *base, *extra], capture_output=True, text=True)
        assert p.returncode == 2, (extra, p.stderr)
        assert words in p.stderr and len(p.stderr.strip().splitlines()) == 1, (extra, p.stderr)


# (shape, α, cut, ν, η, N, extra options): resonance curves of each edged body.
RESONANCES = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, "0", []),
    ("disk", 0.1, None, 0.5, 2.0, "1/7", []),
    ("wheel", 0.1, 0.5, 1.0, 2.0, "1/4", ["--kappa-max", "3", "--energy-max", "8"]),
]


@pytest.mark.parametrize("case", RESONANCES, ids=[c[0] for c in RESONANCES])
def test_resonance_curves_of_edged_bodies_are_on_resonance_at_50_digits(case):
    """`rubber-atlas resonance --shape …`: points of every curve (first, middle, last) have the
    50-digit N of their component within the point's estimate, and that N is P/Q to the
    tolerance."""
    shape, alpha, cut, nu, eta, target, extra = case
    tol = 1e-10
    args = [BIN, "resonance", "--shape", shape, "--alpha", repr(alpha), "--nu", repr(nu), "--eta", repr(eta),
            "--rotation-number", target, "--grid", "24", "--tol", repr(tol), "--json", *extra]
    if cut is not None:
        args += ["--cut", repr(cut)]
    out = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
    assert out["shape"] == shape and out["alpha"] == alpha and out["curves"], out
    p, q = (int(x) for x in target.split("/")) if "/" in target else (int(target), 1)
    checked = 0
    for curve in out["curves"]:
        points = curve["points"]
        for point in (points[0], points[len(points) // 2], points[-1]):
            cell = EdgedCell(shape, alpha, cut or 0, nu, eta, point["kappa"])
            ref = [c for c in cell.components(point["energy"]) if abs(c.theta_min - point["theta_min"]) < 1e-9]
            assert len(ref) == 1, (point, [c.theta_min for c in cell.components(point["energy"])])
            where = f"{case}: {point} vs {ref[0]}"
            assert abs(ref[0].rotation_number - point["rotation_number"]) <= point["error_estimate"] + 1e-15, where
            assert abs(ref[0].rotation_number - p / q) <= tol + point["error_estimate"], where
            checked += 1
    assert checked >= 3


# (shape, α, cut, ν, η, κ, which kink, δ): the level ε = V(θ_t) with the turning point θ_t a
# distance |δ| from a kink, on its far side for δ > 0 (the kink inside the torus, the hard case:
# θ_k − δ for the truncated ball's well above its kink, θ_k + δ for the wheel's well below its
# upper kink), on the torus's own side for δ < 0.
NEAR_KINK = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.26, 0, 1e-3),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.26, 0, 1e-7),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.26, 0, 1e-11),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.26, 0, 3e-16),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.26, 0, -1e-13),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.5, 1, 1e-9),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.5, 1, 4e-16),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.5, 1, -1e-12),
]


@pytest.mark.parametrize("case", NEAR_KINK, ids=[f"{c[0]}-{c[6]}-{c[7]:g}" for c in NEAR_KINK])
def test_a_turning_point_next_to_a_kink_keeps_the_full_accuracy(case):
    """A kink within a few ulps to 1e-3 of a turning point: the pieces' gaps are measured from
    the turning point, so N and T meet 1e-12 with estimates near 1e-14 (they were 3e-9 at
    1e-13 from the kink, and N was wrong, 0.35 instead of -0.09, within an ulp of it)."""
    shape, alpha, cut, nu, eta, kappa, which, delta = case
    cell = EdgedCell(shape, alpha, cut, nu, eta, kappa)
    with mpmath.workdps(50):
        kink = cell.kinks()[which]
        theta_k = kink.theta
        theta = theta_k - delta if which == 0 else theta_k + delta
        energy = float(cell.potential(at(theta)))
    reference = cell.components(energy)
    out = run_cell(shape, alpha, cut, nu, eta, kappa, energy, 1e-12)
    comps = out["components"]
    assert len(comps) == len(reference), (out, reference)
    near = 0
    for got, ref in zip(comps, reference):
        where = f"{case}: {got} vs {ref}"
        assert got["status"] == "ok", where
        assert abs(got["period"] - ref.period) <= got["errors"]["period"], where
        assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], where
        assert got["errors"]["rotation_number"] <= 1e-13 and got["errors"]["period"] <= 1e-13 * ref.period, where
        near += min(abs(got["theta_min"] - float(theta_k)), abs(got["theta_max"] - float(theta_k))) < 2e-3
    assert near, f"{case}: no turning point next to the kink {float(theta_k)}"


# The truncated ball whose edge part has its minimum on the kink at this κ: V rises through
# the kink (a shoulder, the sphere part's concave side meeting the edge part's well), and
# ε = V there. The build before this test found the torus [0.894, π/2] with N = 0.50 (true
# 3.85), and its estimates were up to 29× short within 1e-10 … 1e-13 of that level.
SHOULDER = ("truncated_ball", -0.2, 0.4, 0.7, 1.3, 0.5939696961967001)
SHOULDER_LEVEL = 1.1300000000000001


def test_the_level_of_a_shoulder_on_a_kink_is_a_separatrix():
    out = run_cell(*SHOULDER, SHOULDER_LEVEL, 1e-10)
    (comp,) = out["components"]
    kink = math.acos(SHOULDER[2])
    assert comp["status"] == "separatrix", comp
    assert abs(comp["theta_max"] - kink) <= 4e-16, comp
    assert comp["period"] is None and comp["omega_theta"] == 0.0, comp


@pytest.mark.parametrize("offset", [1e-3, -1e-3, 1e-6, -1e-6, 1e-10, -1e-10, 1e-13, -1e-13])
def test_values_next_to_a_shoulder_on_a_kink_keep_within_their_estimates(offset):
    """Near the shoulder's level the time piles up at the kink as at a saddle (T grows like
    the logarithm of the distance): the estimates count that and cover the true errors."""
    cell = EdgedCell(*SHOULDER)
    energy = SHOULDER_LEVEL * (1 + offset)
    reference = cell.components(energy)
    out = run_cell(*SHOULDER, energy, 1e-10)
    comps = out["components"]
    assert len(comps) == len(reference) == 1, (out, reference)
    got, ref = comps[0], reference[0]
    assert got["status"] in ("ok", "tolerance_not_reached"), got
    assert abs(got["theta_max"] - ref.theta_max) <= 1e-9, (got, ref)
    assert abs(got["period"] - ref.period) <= got["errors"]["period"], (got, ref)
    assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], (got, ref)


# Bodies with a kink on which V′ vanishes at κ_k² = sin³θ_k U′(θ_k)/cosθ_k: a shoulder (the
# first: V″ = −0.26 before the kink, 0.74 after) or a corner minimum (the others: convex on
# both sides, with different curvatures; the last on the wheel's upper kink).
# (shape, α, cut, ν, η, which kink)
KINK_CRITICAL = [
    ("truncated_ball", -0.2, 0.4, 0.7, 1.3, 0),
    ("truncated_ball", 0.3, -0.6, 1.5, 3.0, 0),
    ("wheel", -0.3, 0.3, 0.5, 2.0, 0),
    ("wheel", 0.4, 0.5, 1.2, 0.8, 1),
]


def _kink_critical_cases():
    cases = []
    for shape, alpha, cut, nu, eta, which in KINK_CRITICAL:
        with mpmath.workdps(50):
            kink = EdgedCell(shape, alpha, cut, nu, eta, 1.0).kinks()[which]
            s, c = mpmath.sin(kink.theta), mpmath.cos(kink.theta)
            kappa_k = float(mpmath.sqrt(s**3 * EdgedCell(shape, alpha, cut, nu, eta, 1.0)._u_prime(s, c) / c))
        for shift in (0.0, 1e-7, -1e-7, -1e-13):
            for offset in (0.0, -1e-12):
                cases.append((shape, alpha, cut, nu, eta, which, kappa_k * (1 + shift), offset))
    return cases


@pytest.mark.parametrize("case", _kink_critical_cases())
def test_cells_where_v_is_flat_on_a_kink_keep_within_their_estimates(case):
    """Near the κ where V′ vanishes on a kink and near the level there, against 50 digits:
    every value within its estimate (the slow passage at a near-shoulder counts as a saddle's;
    a minimum on a kink swings with each side's frequency for half a period; one beside a
    kink may cross it). The build before this test had errors up to 5000x its estimates."""
    shape, alpha, cut, nu, eta, which, kappa, offset = case
    with mpmath.workdps(50):
        cell = EdgedCell(shape, alpha, cut, nu, eta, kappa)
        energy = float(cell.potential(cell.kinks()[which])) * (1 + offset)
    outcome = whole_domain.check(whole_domain.Case(alpha, 1.0, nu, eta, kappa, energy, "kink", None, shape, cut))
    assert not outcome.problems, (case, energy, outcome.problems)


def _ordinary_crossings(count: int, seed: int):
    """Seeded random truncated balls and wheels (α ∈ (−0.8, 0.8), |h| ∈ (0.05, 0.95),
    ν ∈ [0.2, 2], η ∈ [0.1, 10], κ ∈ [0.05, 3]) at levels 0.05 … 4 above the bottom of V whose
    lowest torus crosses a kink: the cells the Clenshaw–Curtis pieces are for."""
    rng = random.Random(seed)
    cases = []
    while len(cases) < count:
        shape = rng.choice(["truncated_ball", "wheel"])
        alpha = rng.uniform(-0.8, 0.8)
        cut = rng.uniform(0.05, 0.95) * (rng.choice([-1, 1]) if shape == "truncated_ball" else 1)
        nu, eta = rng.uniform(0.2, 2.0), 10 ** rng.uniform(-1, 1)
        kappa = 10 ** rng.uniform(math.log10(0.05), math.log10(3.0))
        with mpmath.workdps(30):
            cell = EdgedCell(shape, alpha, cut, nu, eta, kappa)
            grid = [mpmath.mpf(k) / 400 * mpmath.pi for k in range(1, 400)]
            bottom = min(cell.potential(at(t)) for t in grid)
            energy = float(bottom) + 10 ** rng.uniform(math.log10(0.05), math.log10(4.0))
            kinks = [float(k.theta) for k in cell.kinks()]
            reference = cell.components(energy)
        if any(any(r.theta_min < k < r.theta_max for k in kinks) for r in reference):
            cases.append(whole_domain.Case(alpha, 1.0, nu, eta, kappa, energy, "kink", None, shape, cut))
    return cases


@pytest.mark.parametrize("case", _ordinary_crossings(16, 2026_11_27), ids=lambda c: f"{c.shape}-{c.alpha:.3f}-{c.kappa:.3f}")
def test_ordinary_librations_across_kinks_keep_within_their_estimates(case):
    """Librations across kinks are integrated in pieces by Clenshaw–Curtis (docs/accuracy.md):
    against 50 digits at tol 1e-10 and 1e-13 every `ok` value is within its estimate, every
    other status honest, and at 1e-10 every one is `ok`."""
    for tol in (1e-10, 1e-13):
        outcome = whole_domain.check(case, tol=tol)
        assert not outcome.problems, (case, tol, outcome.problems)
        if tol == 1e-10:
            assert outcome.ok_components == outcome.components, (case, outcome)


def test_ordinary_librations_across_kinks_are_cheap():
    """The same cells at tol 1e-10 cost a median of at most 160 integrand evaluations, the
    near-pole ones (small κ, still by tanh-sinh) included: a torus across a kink has two
    pieces or more, and the tanh-sinh rule's first level alone is 129 nodes a piece (the
    build before the Clenshaw–Curtis pieces had a median of 387 here, this one 131)."""
    works = sorted(c["work"] for case in _ordinary_crossings(16, 2026_11_27)
                   for c in whole_domain.run_cell(case, tol=1e-10)["components"])
    assert works[len(works) // 2] <= 160, works


# Tori of cut balls with a turning point near a pole (κ ≤ 0.1) that cross the kink: their
# pieces take the Clenshaw–Curtis rule in Mercator's s = ln tan(θ/2) (docs/accuracy.md).
NEAR_POLE = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 0.0413385826771654, 1.1739624371995567),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 0.0413385826771654, 1.4),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 0.01, 1.0),
    ("truncated_ball", -0.3, -0.5, 1.0, 2.5, 0.08, 2.0),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.03, 1.5),
    ("wheel", 0.0, 0.3, 0.5, 3.0, 0.1, 2.0),
]


@pytest.mark.parametrize("case", NEAR_POLE, ids=lambda c: f"{c[0]}-{c[1]}-{c[5]:.3f}-{c[6]}")
def test_pieces_by_a_pole_keep_within_their_estimates_and_are_cheap(case):
    """Against 50 digits at tol 1e-10 and 1e-13: every `ok` value within its estimate and the
    rest honest; at 1e-10 every component `ok` and at most 320 evaluations (the first, by the
    tanh-sinh rule, took 548)."""
    shape, alpha, cut, nu, eta, kappa, energy = case
    c = whole_domain.Case(alpha, 1.0, nu, eta, kappa, energy, "near pole", None, shape, cut)
    for tol in (1e-10, 1e-13):
        outcome = whole_domain.check(c, tol=tol)
        assert not outcome.problems, (case, tol, outcome.problems)
        if tol == 1e-10:
            assert outcome.ok_components == outcome.components, (case, outcome)
    works = [x["work"] for x in whole_domain.run_cell(c, tol=1e-10)["components"]]
    assert max(works) <= 320, works


def test_a_level_within_rounding_of_a_kink_holds_both_sides():
    """A centred truncated ball (α = 0: its sphere neutral, V′ = 2e-11 on both sides of the
    kink at κ = 7.8e-6) at a level within an ulp of V at the kink: rounding decides on which
    side the turning point lies, and T is 120.4 on the edge's side, 2866 on the sphere's. The
    estimates now hold the change to levels beyond the kink's on either side; before, T was
    2866 ± 48.9 (whole-domain `--bodies --seed 26`)."""
    case = whole_domain.Case(0.0, 1.0, 1.4763982134217415, 0.1229224391436799, 7.798736413777416e-06,
                             1.0000000000328788, "next to a kink", None, "truncated_ball", -0.27401628361660224)
    for tol in (1e-6, 1e-10):
        outcome = whole_domain.check(case, tol=tol)
        assert not outcome.problems, (tol, outcome.problems)


# (shape, α, cut or profile table, ν, η): a face down, faces at both poles, a disk with α ≠ 0,
# the egg (kinks only) and a profile with a face down.
EGG = [[0.0, -1.0], [0.45, -0.92], [0.8, -0.62], [0.98, -0.2], [0.97, 0.25], [0.8, 0.62, 1], [0.4, 0.8], [0.0, 0.86]]
FACED = [[0.0, -0.6], [0.5, -0.6, 1], [0.9, -0.2], [1.0, 0.1], [0.8, 0.6], [0.0, 1.0]]
HIGH_ENERGY = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3),
    ("truncated_ball", -0.3, -0.5, 1.0, 2.0),
    ("wheel", 0.1, 0.5, 1.0, 2.0),
    ("disk", 0.3, None, 2.0, 4.0),
    ("profile", 0.05, EGG, 0.8, 1.5),
    ("profile", 0.1, FACED, 0.8, 1.5),
    # Nearly its own mirror image: Q = P(θ) − P(π − θ) cancels (its rounding was short 120×).
    ("disk", 1e-8, None, 1.0, 1.0),
]


@pytest.mark.parametrize("case", HIGH_ENERGY, ids=[f"{c[0]}-{c[1]}" for c in HIGH_ENERGY])
def test_the_high_energy_limit_of_edged_bodies_against_50_digits(case, make_atlas):
    """The s = 0 row of a (λ, s) scene (ε = ∞: N∞(λ), docs/model.md) of a body with edges,
    faces or kinks, against the reference's own quadrature of N∞'s θ-integral as it stands
    (scripts/reference.py), at tol 1e-12: within the estimate, status high_energy_limit; at
    λ = 0 a body with a face reaches it (status reaches_face, no N)."""
    from rubber_atlas import flag_names, open_atlas
    from reference import ProfileCell, high_energy_rotation_number

    shape, alpha, second, nu, eta = case
    # The last one ulp below √2, where 1 − λ/√2 must keep its digits (it was 25 % off).
    lambdas = [0.0, 1e-6, 1e-3, 0.05, 0.3, 0.8, 1.2, 1.41, 1.4142135623730949]
    if shape == "profile":
        body = f"profile = {json.dumps(second)}\n"
        axes = f"alpha = [{alpha}]\n"
        cell = ProfileCell(second, alpha, nu, eta, 1)
    else:
        body = ""
        axes = f"alpha = [{alpha}]\n" + ("" if second is None else f"cut = [{second}]\n")
        cell = EdgedCell(shape, alpha, second or 0, nu, eta, 1)
    scene = (f'name = "limit"\n[body]\nshape = "{shape}"\nnu = {nu}\neta = {eta}\n{body}'
             f"[axes]\n{axes}lambda = {lambdas}\ns = [0.0, 0.5]\n[solver]\ntolerance = 1e-12\n"
             '[outputs]\nfields = ["rotation_number", "status", "error_estimate"]\n')
    ds = open_atlas(make_atlas(f"limit-{shape}", scene))
    row = ds.isel(s=0).squeeze()
    names = flag_names(ds.status)
    faces = shape != "profile" or second is FACED
    for i, lam in enumerate(lambdas):
        at_lambda = row.isel({"lambda": i})
        present = np.flatnonzero(np.asarray(at_lambda.status) != 255)
        statuses = [names[int(at_lambda.status[k])] for k in present]
        if lam == 0.0:
            assert statuses == (["reaches_face"] if faces else ["high_energy_limit"]), statuses
            continue
        assert statuses == ["high_energy_limit"], (lam, statuses)
        k = present[0]
        n, err = float(at_lambda.rotation_number[k]), float(at_lambda.error_estimate[k])
        ref, ref_err = high_energy_rotation_number(cell, lam)
        assert ref_err < 1e-20
        assert abs(n - float(ref)) <= err, (lam, n, err, float(ref))
        assert err <= 1e-12, (lam, err)


# κ = 0 (the reference covers it since 2026-11-27): levels ε = U(θ) of bodies whose planar
# motions cross a kink (the truncated ball's libration round θ = π reaching past θ_c = 1.159
# onto the edge, θ = 1.1 and 1.05) or reach a face (every other component here).
KAPPA_ZERO = [
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 2.5),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.1),
    ("truncated_ball", 0.2, 0.4, 0.7, 1.3, 1.05),
    ("truncated_ball", -0.3, -0.5, 0.7, 1.3, 2.9),
    ("wheel", 0.25, 0.7, 0.7, 1.3, 0.7),
    ("disk", 0.3, None, 2.0, 4.0, 1.0),
]


@pytest.mark.parametrize("case", KAPPA_ZERO, ids=[f"{c[0]}-{c[1]}-{c[5]}" for c in KAPPA_ZERO])
def test_planar_motions_of_edged_bodies_against_50_digit_values(case):
    """At κ = 0 the same components as the reference, on the lifted circle: those that reach a
    face `reaches_face` with no values, the others `ok` with T within its estimate and N = 0."""
    shape, alpha, cut, nu, eta, theta = case
    cell, energy = level(shape, alpha, cut, nu, eta, 0.0, theta)
    reference = cell.components(energy)
    assert reference
    for tol in (1e-10, 1e-12):
        comps = run_cell(shape, alpha, cut, nu, eta, 0.0, energy, tol)["components"]
        assert len(comps) == len(reference), (comps, reference)
        for got, ref in zip(comps, reference):
            where = f"{case} tol {tol}: {got} vs {ref}"
            assert abs(got["theta_min"] - ref.theta_min) < 1e-12 and abs(got["theta_max"] - ref.theta_max) < 1e-12, where
            if ref.kind == "reaches_face":
                assert got["status"] == "reaches_face" and got["period"] is None, where
                continue
            assert got["status"] == "ok" and got["rotation_number"] == 0.0, where
            assert ref.period_error < 1e-25, ref
            assert abs(got["period"] - ref.period) <= got["errors"]["period"] <= tol * ref.period, where


# Disks whose U = sinθ + α cosθ crosses 0 under a large η: 1/J peaks there, as narrowly as
# √((cos²θ + ν sin²θ)/η)/|U′| (down to 5e-4), and a reference quadrature that is not cut there
# steps over it (N 1e-9 off at the first, its own error bar 1e-27). (shape, α, ν, η, κ, ε, tol)
NARROW_PEAKS = [
    ("disk", 68.1761, 0.1523, 3805.0, 0.006834, 2102.71443018, 1e-10),
    ("disk", -6.59146, 0.02207, 1032.0, 0.002454, 17.5938006046, 1e-13),
    ("disk", 9.53415, 0.01281, 799.1, 0.1303, 368798.352348, 1e-10),
    ("disk", 45.0472, 0.02447, 306.6, 0.002183, 428.165607889, 1e-13),
]


@pytest.mark.parametrize("case", NARROW_PEAKS, ids=[f"{c[0]}-{c[1]}" for c in NARROW_PEAKS])
def test_a_narrow_peak_of_1_over_j_against_a_reference_cut_there(case):
    """The reference cuts its integrals at each zero of U (and on a ladder either side), as
    the solver does where the peak is narrow: the two agree within the solver's estimates."""
    shape, alpha, nu, eta, kappa, energy, tol = case
    cell = EdgedCell(shape, alpha, 0, nu, eta, kappa)
    assert cell.potential_zeros(), case
    reference = cell.components(energy)
    comps = run_cell(shape, alpha, None, nu, eta, kappa, energy, tol)["components"]
    assert len(comps) == len(reference), (comps, reference)
    for got, ref in zip(comps, reference):
        where = f"{case}: {got} vs {ref}"
        assert ref.period_error < 1e-25 and ref.rotation_error < 1e-25, ref
        assert abs(got["period"] - ref.period) <= got["errors"]["period"], where
        assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], where


@pytest.mark.parametrize("tol", [0.1, 0.05])
def test_loose_tolerances_do_not_trust_the_first_levels_of_a_piece(tol):
    """A truncated ball's libration next to a maximum at tol 0.1: the Clenshaw–Curtis sums of
    T on 16 … 128 intervals (61.5, 50.9, 52.27, 52.282) fell in one rate by the test, and
    d₁ max(√r, 1/10) put T's error at 4.5e-3 where it was 6.7e-3 (and N's at 5.3e-7 for
    7.3e-7), status `ok` (an adversary pass): the rate is trusted only once the last
    difference is below 1e-6 of the piece's size."""
    shape, alpha, cut, nu, eta = "truncated_ball", 0.999999, 0.6020076709670582, 1.593800703324628, 0.014844987593768618
    kappa, energy = 0.001351764490219358, 1.7899800938357955
    reference = EdgedCell(shape, alpha, cut, nu, eta, kappa).components(energy)
    comps = run_cell(shape, alpha, cut, nu, eta, kappa, energy, tol)["components"]
    assert len(comps) == len(reference) == 1, (comps, reference)
    got, ref = comps[0], reference[0]
    assert ref.period_error < 1e-25 and ref.rotation_error < 1e-25, ref
    assert abs(got["period"] - ref.period) <= got["errors"]["period"], got
    assert abs(got["rotation_number"] - ref.rotation_number) <= got["errors"]["rotation_number"], got
