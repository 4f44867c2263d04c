"""The files rubber-atlas writes, read from Python as a user would (h5py and the CSV), and the
plot script on them."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rubber_atlas import read_table

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from plot_trajectory import plot  # noqa: E402

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
BODY = ["--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5"]


def run(*args: str) -> None:
    subprocess.run([BIN, *args], check=True, capture_output=True, text=True)


@pytest.fixture(scope="module")
def trajectories(tmp_path_factory):
    d = tmp_path_factory.mktemp("traj")
    out = {}
    for ext in ("csv", "h5"):
        p = d / f"xy.{ext}"
        run("trajectory", *BODY, "--kappa", "0.8", "--theta0", "0.4670288", "--periods", "7",
            "--samples", "700", "--out", str(p))
        out[ext] = p
    return out


def test_hdf5_and_csv_trajectories_hold_the_same_numbers(trajectories):
    h5 = read_table(trajectories["h5"])
    csv = read_table(trajectories["csv"])
    assert list(csv.dims) == ["t"]
    assert set(csv.variables) == {"t", "theta", "theta_dot", "phi", "psi", "x_c", "y_c", "z_c", "x_p", "y_p"}
    for name in csv.variables:
        # CSV holds shortest round-trip decimals: the same doubles.
        np.testing.assert_array_equal(h5[name].values, csv[name].values)
    # Numbers stay numbers in both.
    assert h5.attrs["kappa"] == 0.8 and csv.attrs["kappa"] == 0.8
    assert h5.attrs["tolerance"] == csv.attrs["tolerance"] == 1e-12
    # t is the dimension coordinate.
    assert h5.theta.dims == ("t",) and "t" in h5.indexes
    import h5py

    with h5py.File(trajectories["h5"]) as f:
        assert f["theta"].attrs["units"] == "rad"
        assert f["x_c"].attrs["units"] == "1" and "b3" in f["x_c"].attrs["comment"]
        assert "centre of mass" in f["x_c"].attrs["long_name"]


def test_resonant_trajectory_closes(trajectories):
    cols = {k: v.values for k, v in read_table(trajectories["h5"]).variables.items()}
    size = np.hypot(np.ptp(cols["x_c"]), np.ptp(cols["y_c"]))
    gap = np.hypot(cols["x_c"][-1] - cols["x_c"][0], cols["y_c"][-1] - cols["y_c"][0])
    # θ0 = 0.4670288 is N = -1/7 to 7 digits: the path closes to far better than 1e-4.
    assert gap < 1e-4 * size
    # The height of the centre of mass is U(θ) = Z + α cos θ.
    z = np.sqrt(9 * np.sin(cols["theta"]) ** 2 + np.cos(cols["theta"]) ** 2) + 0.5 * np.cos(cols["theta"])
    np.testing.assert_allclose(cols["z_c"], z, rtol=1e-14)


def test_plot_script_writes_a_picture(trajectories, tmp_path):
    png = plot(trajectories["h5"], tmp_path / "xy.png")
    assert png.stat().st_size > 10_000
    res = subprocess.run([sys.executable, str(ROOT / "scripts" / "plot_trajectory.py"), str(trajectories["csv"]),
                          "--out", str(tmp_path / "xy2.png")], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "xy2.png").stat().st_size > 10_000


def test_diagram_file_opens_with_branches_and_summary(tmp_path):
    p = tmp_path / "d.h5"
    run("diagram", *BODY, "--out", str(p))
    table = read_table(p)
    cols = {k: v.values for k, v in table.variables.items()}
    summary = json.loads(table.attrs["critical_set_json"])
    # Flags and indices stay integers.
    assert table.branch.dtype == np.uint8 and table.stable.dtype == np.uint8
    assert table.segment.dtype == np.int32 and table.branch.dims == ("sample",)
    assert summary["diagram_type"] == "c"
    assert set(np.unique(cols["branch"]).astype(int)) == {0, 1, 2}
    # Along σ_u (code 1) every point is unstable; σ_s0 and σ_sπ are stable.
    assert np.all(cols["stable"][cols["branch"] == 1] == 0)
    assert np.all(cols["stable"][cols["branch"] != 1] == 1)
    assert np.max(cols["kappa"][cols["branch"] == 1]) == pytest.approx(summary["cusp"]["kappa"], abs=1e-12)


def test_update_leaves_a_file_open_in_h5py_for_writing_alone(tmp_path):
    """A researcher's file open in h5py to write ("a") is locked by HDF5, and this program
    cannot read it: `run --update` took that for a damaged atlas of its own and replaced the
    file (the data under the open h5py handle lost). It now refuses in one line, exit 2, and
    the file is as it was; an atlas open in h5py only to read is still updated as usual."""
    import h5py

    scene = tmp_path / "s.toml"
    scene.write_text('name = "s"\n[body]\nnu = 0.5\neta = 0.5\n[axes]\nalpha = [0.5]\nbeta = [3.0]\n'
                     "kappa = { start = 0.1, stop = 1.0, num = 4 }\nenergy = { start = 1.0, stop = 2.0, num = 4 }\n")
    mine = tmp_path / "mine.h5"
    with h5py.File(mine, "w") as f:
        f["precious"] = [1.0, 2.0, 3.0]
    with h5py.File(mine, "a") as f:
        o = subprocess.run([BIN, "run", str(scene), "--out", str(mine), "--update", "--quiet"],
                           capture_output=True, text=True)
        assert o.returncode == 2 and len(o.stderr.splitlines()) == 1, o.stderr
        assert "is open for writing in another program" in o.stderr
        assert list(f.keys()) == ["precious"] and f["precious"][2] == 3.0
    own = tmp_path / "own.h5"
    run("run", str(scene), "--out", str(own), "--quiet")
    with h5py.File(own, "r"):
        run("run", str(scene), "--out", str(own), "--update", "--quiet")
