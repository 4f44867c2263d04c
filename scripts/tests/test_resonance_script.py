"""scripts/resonance.py on a small atlas made in the test: the N = 0 curve contoured from the
atlas lies where `rubber-atlas resonance` traces it; refined points fed back to
`rubber-atlas cell` give N = 0 within the tolerance; CSV and HDF5 hold the same rows."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from resonance import atlas_window, extract, load, refine, save  # noqa: E402

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
SCENE = """name = "res"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.5]
beta = [3.0]
kappa = { start = 0.0, stop = 1.4, num = 71 }
energy = { start = 2.8, stop = 4.0, num = 61 }
[solver]
tolerance = 1e-10
[outputs]
fields = ["theta_min", "theta_max", "rotation_number", "status", "error_estimate"]
"""


@pytest.fixture(scope="module")
def atlas(make_atlas):
    return make_atlas("res", SCENE)


def test_contoured_and_traced_n0_agree_and_traced_points_are_on_resonance(atlas, tmp_path):
    rough = extract(atlas, [Fraction(0)])
    assert rough, "no N = 0 contour in the atlas"
    precise = refine(rough, nu=0.5, eta=0.5, window=atlas_window(atlas), tol=1e-10)
    assert precise
    k = np.concatenate([c.kappa for c in precise])
    e = np.concatenate([c.energy for c in precise])
    # Every contour point lies within two grid cells of the traced curve.
    dk, de = 1.4 / 70, 1.2 / 60
    for c in rough:
        for kk, ee in zip(c.kappa, c.energy):
            d = np.min(np.hypot((k - kk) / dk, (e - ee) / de))
            assert d < 2.0, (kk, ee, d)
    # The traced curve turns round the cusp (κ_c = 1.0802): its top is the fold 1.10784.
    assert abs(k.max() - 1.10784) < 1e-3
    # Traced points, fed back to the cell command, give N = 0 within the tolerance.
    c = max(precise, key=lambda c: len(c.kappa))
    for i in range(0, len(c.kappa), max(1, len(c.kappa) // 8)):
        out = subprocess.run(
            [BIN, "cell", "--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5", "--kappa", repr(float(c.kappa[i])),
             "--energy", repr(float(c.energy[i])), "--tol", "1e-10", "--json"],
            check=True, capture_output=True, text=True).stdout
        comp = json.loads(out)["components"][int(c.extra["component"][i])]
        assert abs(comp["rotation_number"]) <= max(1e-10, comp["error_estimate"]), comp


def test_csv_and_hdf5_hold_the_same_rows(atlas, tmp_path):
    curves = extract(atlas, None, qmax=2)
    assert len(curves) >= 2
    save(curves, tmp_path / "c.csv")
    save(curves, tmp_path / "c.h5")
    a, b = load(tmp_path / "c.csv"), load(tmp_path / "c.h5")
    for name in ("kappa", "energy", "target", "curve", "point", "component"):
        np.testing.assert_array_equal(a[name].astype(float), b[name].astype(float))
    assert set(np.unique(a["target"])) <= {float(Fraction(p, q)) for q in (1, 2) for p in range(-4, 5)}


def test_the_command_line(atlas, tmp_path):
    out = tmp_path / "c0.csv"
    env = dict(os.environ, RUBBER_ATLAS_BIN=BIN)
    subprocess.run([sys.executable, str(ROOT / "scripts" / "resonance.py"), str(atlas), "--pq", "0", "--refine", "--out",
                    str(out)], check=True, env=env, capture_output=True)
    rows = load(out)
    assert len(rows["kappa"]) > 10 and set(rows["source"]) == {"refined"}


def test_the_resonance_command_writes_tables_and_refuses_bad_input(tmp_path):
    from rubber_atlas import read_table

    body = ["--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5"]
    for ext in ("csv", "h5"):
        out = tmp_path / f"n0.{ext}"
        subprocess.run([BIN, "resonance", *body, "--rotation-number", "0", "--out", str(out)], check=True,
                       capture_output=True)
        table = read_table(out)
        cols, attrs = {k: v.values for k, v in table.variables.items()}, table.attrs
        assert len(cols["kappa"]) > 20 and table.kappa.dims == ("sample",)
        assert np.all(np.abs(cols["rotation_number"]) <= np.maximum(1e-10, cols["error_estimate"]))
        assert json.loads(attrs["header_json"])["rotation_number"] == 0.0
    for bad, name in ((["--rotation-number", "one"], "--rotation-number"), (["--rotation-number", "1/0"], "--rotation-number"),
                      (["--rotation-number", "0", "--kappa-min", "0"], "kappa_min"),
                      (["--rotation-number", "0", "--energy-max", "-9"], "energy_max")):
        r = subprocess.run([BIN, "resonance", *body, *bad], capture_output=True, text=True)
        assert r.returncode == 2, (bad, r.stderr)
        assert name in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
