"""`rubber-atlas verdict` through its command line (the docs/hypothesis.md contract, bad input) and
scripts/hypothesis.py on a small (α, β) grid: the map, the boundary curves, and the
trajectory evidence of each failure region (the full model's centre of mass runs away by
n·|Δζ| after n periods)."""
from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import h5py
import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
SCRIPT = ROOT / "scripts" / "hypothesis.py"


def verdict(*args: str) -> dict:
    out = subprocess.run([BIN, "verdict", *args, "--json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def test_contract_keys_and_the_issue_bodies():
    v = verdict("--alpha=0.5", "--beta=0.5", "--nu=0.5", "--eta=0.5")
    assert v["case"] == "1" and v["holds"] is False and v["kappa_max"] is None
    for key in ["slope", "n_min", "lambda_at_min", "n_max", "lambda_at_max"]:
        assert isinstance(v["high_energy"][key], float), key
    c = v["counterexamples"][0]
    for key in ["kappa", "energy", "rotation_number", "theta_min", "theta_max"]:
        assert isinstance(c[key], float), key
    # Re-solved by the cell command: N on the integer, the path unbounded.
    cell = json.loads(subprocess.run(
        [BIN, "cell", "--alpha=0.5", "--beta=0.5", "--nu=0.5", "--eta=0.5", f"--kappa={c['kappa']!r}",
         f"--energy={c['energy']!r}", "--json"], check=True, capture_output=True, text=True).stdout)
    comp = min(cell["components"], key=lambda x: abs(x["theta_min"] - c["theta_min"]))
    assert abs(comp["rotation_number"] - c["integer"]) < 1e-9 and comp["bounded"] is False
    assert c["status"] == comp["status"] == "ok"
    v = verdict("--alpha=0.9", "--beta=20", "--nu=0.5", "--eta=0.5")
    assert v["case"] == "2" and v["holds"] is False and abs(v["kappa_max"] - 3.919) < 1e-3
    assert all(c["kappa"] > v["kappa_max"] for c in v["counterexamples"])
    v = verdict("--alpha=0.5", "--beta=3", "--nu=0.5", "--eta=0.5")
    assert v["holds"] is True and v["counterexamples"] == []
    v = verdict("--alpha=0", "--beta=2", "--nu=0.5", "--eta=0.5")
    assert v["case"] == "not_covered" and v["holds"] is None


def test_boundaries_contract():
    b = verdict("--alpha=0.5", "--nu=0.5", "--eta=0.5", "--boundaries", "--beta-min=0.6", "--beta-max=0.9",
                "--scan=4")
    assert b["alpha"] == 0.5 and len(b["boundaries"]) == 1
    one = b["boundaries"][0]
    assert abs(one["beta"] - 0.744478) < 1e-5 and 0 < one["error"] < 1e-4


def test_bodies_just_above_the_n_minus_one_boundary_fail_at_50_digits():
    """Just above the N = −1 boundary in β the resonance lies in a sliver above κ_max that the
    sampling grid steps over (adversary pass 32: these bodies held). Each now fails, and its
    counterexample is on N = −1 by the 50-digit reference of scripts/reference.py (the Rust
    test of the same bodies follows its path with the full model)."""
    sys.path.insert(0, str(ROOT / "scripts"))
    from reference import reference

    # (α = 0.9, β = 1.6773, ν = 1.5, η = 5: N at the bottom dips below −1 between two κ-lines,
    # adversary pass 33.)
    for alpha, beta, nu, eta in [(0.5, 19.7931, 0.5, 0.5), (0.999999999999, 10.417, 0.5, 0.5),
                                 (0.9, 1.6773, 1.5, 5.0)]:
        v = verdict(f"--alpha={alpha}", f"--beta={beta}", f"--nu={nu}", f"--eta={eta}")
        assert v["holds"] is False and v["fail_margin"] > 0, v
        c = next(c for c in v["counterexamples"] if c["integer"] == -1)
        assert c["kappa"] > v["kappa_max"]
        comps = reference(alpha, beta, nu, eta, c["kappa"], c["energy"])
        comp = min(comps, key=lambda x: abs(x.theta_min - c["theta_min"]) + abs(x.theta_max - c["theta_max"]))
        assert abs(comp.rotation_number + 1) <= 1e-10 + c["error_estimate"], (alpha, beta, c, comp)


@pytest.mark.parametrize("args", [
    ["--alpha=-inf", "--beta=1", "--nu=0.5", "--eta=0.5"],
    ["--alpha=1", "--beta=1", "--nu=0.5", "--eta=0.5"],
    ["--alpha=0.5", "--beta=nan", "--nu=0.5", "--eta=0.5"],
    ["--alpha=0.5", "--beta=1", "--nu=3", "--eta=0.5"],
    ["--alpha=0.5", "--beta=1", "--nu=0.5", "--eta=0.5", "--resolution=2"],
    ["--alpha=0.5", "--beta=1", "--nu=0.5", "--eta=0.5", "--scan=4"],
    ["--alpha=0.5", "--beta=1", "--nu=0.5", "--eta=0.5", "--boundaries"],
    ["--alpha=0.5", "--nu=0.5", "--eta=0.5", "--boundaries", "--beta-min=5", "--beta-max=1"],
    ["--alpha=0.5", "--beta=1", "--eta=0.5"],
])
def test_bad_input_is_one_line_and_exit_2(args):
    p = subprocess.run([BIN, "verdict", *args], capture_output=True, text=True)
    assert p.returncode == 2, p
    assert p.stdout == "" and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "panicked" not in p.stderr


def test_map_boundaries_and_evidence(tmp_path):
    out = tmp_path / "hyp"
    p = subprocess.run([sys.executable, str(SCRIPT), "--out", str(out), "--alphas", "2", "--betas", "5",
                        "--beta-min", "0.3", "--beta-max", "30", "--others", "0.1,1", "--other-alphas", "1",
                        "--other-betas", "4", "--resolution", "32"], capture_output=True, text=True, env={**os.environ, "RUBBER_ATLAS_BIN": BIN})
    assert p.returncode == 0, p.stderr
    rows = list(csv.DictReader(open(out.with_suffix(".csv"))))
    # α = 0 and 0.975, five β each plus the two sides of the case line.
    assert len(rows) == 2 * 7
    by = {(float(r["alpha"]), round(float(r["beta"]), 6)): r for r in rows}
    assert by[(0.0, 0.3)]["verdict"] == "fails" and by[(0.0, 30.0)]["verdict"] == "not covered"
    boundaries = list(csv.DictReader(open(tmp_path / "hyp-boundaries.csv")))
    assert any(b["quantity"].startswith("case") and abs(float(b["beta"]) - 1.0) < 1e-12 for b in boundaries)
    assert any(float(b["nu"]) == 0.1 for b in boundaries)
    evidence = list(csv.DictReader(open(tmp_path / "hyp-evidence.csv")))
    assert evidence and all(e["confirmed"] == "True" for e in evidence)
    for e in evidence:
        d = json.loads(e["distance"])
        assert abs(d[1] / d[0] - 2.0) < 1e-5
    with h5py.File(out.with_suffix(".h5")) as f:
        assert set(f) == {"map", "boundaries", "evidence"} and f.attrs["nu"] == 0.5 and f.attrs["resolution"] == 32
    assert out.with_suffix(".png").stat().st_size > 10_000


def test_curves_join_one_mechanism_whatever_band_lies_beside_it():
    """A boundary beside a hair-thin undecided band (its side judged undecided) stays on its
    curve; the band's own edge (bisection on the verdict) is no curve; a case-1 body without a
    verdict is `undecided`, and only α = 0, β ≥ 1 is `not covered`."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import hypothesis

    def row(quantity, below, above):
        return dict(quantity=quantity, below=below, above=above)

    n0 = "fail_margin: N takes both signs (N = 0) (sampled plane)"
    n1 = "fail_margin: N reaches -1 (sampled plane)"
    assert hypothesis.curve_kind(row(n0, "case 1 fails", "case 1 holds")) == hypothesis.curve_kind(
        row(n0, "case 1 fails", "case 1 undecided"))
    assert hypothesis.curve_kind(row(n1, "case 2 holds", "case 2 fails")) == hypothesis.curve_kind(
        row(n1.replace("sampled plane", "high-energy limit"), "case 2 undecided", "case 2 fails"))
    assert hypothesis.curve_kind(row(n1, "case 2 holds", "case 2 fails")) != hypothesis.curve_kind(
        row(n1, "case 2 fails", "case 2 holds"))
    assert hypothesis.curve_kind(row("verdict", "case 2 undecided", "case 2 holds")) is None
    assert hypothesis.label(None, "1") == hypothesis.label(None, "2") == "undecided"
    assert hypothesis.label(None, "not_covered") == "not covered"
