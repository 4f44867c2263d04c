"""The demo atlas (atlas/demo.toml) as a user opens it: h5py and xarray see named dimensions
with their coordinates, CF attributes and provenance; a random sample of cells equals
`rubber-atlas cell` for the same parameters, bit for bit; the plot script draws it."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest

from rubber_atlas import components, flag_names, open_atlas

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from plot_atlas import plot  # noqa: E402

DIMENSIONS = ("alpha", "beta", "kappa", "energy", "component")

BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
SCENE = ROOT / "atlas" / "demo.toml"


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("atlas") / "demo.h5"
    subprocess.run([BIN, "run", str(SCENE), "--out", str(out), "--quiet"], check=True)
    return out


def axis(spec):
    if isinstance(spec, list):
        return np.array(spec, float)
    values = np.linspace(spec["start"], spec["stop"], spec["num"])
    return values


def test_h5py_sees_dimension_scales_and_cf_attributes(demo):
    scene = tomllib.loads(SCENE.read_text())
    with h5py.File(demo) as f:
        for name in DIMENSIONS:
            assert f[name].attrs["CLASS"] == b"DIMENSION_SCALE"
        for name in ("alpha", "beta", "kappa", "energy"):
            # The axis values are the scene's (within a rounding of the evenly spaced points).
            np.testing.assert_allclose(f[name][:], axis(scene["axes"][name]), rtol=0, atol=1e-15)
        for name in ("nu", "eta"):
            # The body's mass parameters: scalar coordinates of every variable.
            assert f[name].shape == () and f[name][()] == scene["body"][name]
            assert "long_name" in f[name].attrs and f[name].attrs["units"] == "1"
        for name, var in f.items():
            if name in DIMENSIONS or name in ("nu", "eta"):
                continue
            assert "long_name" in var.attrs and "units" in var.attrs, name
            assert "nu eta" in var.attrs["coordinates"], name
            dims = [var.dims[i][0].name.lstrip("/") for i in range(var.ndim)]
            assert dims == list(DIMENSIONS[: var.ndim]), name
            # Chunks tile one (alpha, beta) slice along kappa (whole rows of energy), compressed.
            assert var.chunks[:2] == (1, 1) and var.chunks[3] == f["energy"].size, name
            assert var.compression == "gzip", name
        for name in ("status", "motion", "bounded", "cell_status"):
            assert "flag_values" in f[name].attrs and "flag_meanings" in f[name].attrs
        for key in ("program_version", "git_commit", "scene", "command_line", "created", "tolerance",
                    "method", "nu", "eta"):
            assert key in f.attrs, key
        assert f.attrs["scene"] == SCENE.read_text()


def test_xarray_opens_it_with_named_dimensions(demo):
    ds = open_atlas(demo)
    assert tuple(ds.rotation_number.dims) == DIMENSIONS
    assert tuple(ds.n_components.dims) == DIMENSIONS[:4]
    assert not any(d.startswith("phony_dim") for d in ds.dims)
    # By family (the default): the demo has both wells and, at kappa = 0, rolling over the top.
    assert ds.attrs["component_layout"] == "family"
    assert list(ds.component.values) == [0, 1, 3]
    assert flag_names(ds.component) == {0: "well_0", 1: "well_pi", 3: "over_the_top"}
    assert flag_names(ds.status)[0] == "ok"
    # Flags stay integers in xarray (no _FillValue: 255 is a flag value of its own).
    for name in ("status", "motion", "bounded", "cell_status", "n_components"):
        assert ds[name].dtype == np.uint8, name
    assert flag_names(ds.status)[255] == "no_value"
    assert float(ds.nu) == 0.5 and float(ds.eta) == 0.5 and "nu" in ds.coords
    # Units that UDUNITS parses; the paper's scale in a comment.
    assert ds.period.attrs["units"] == "1" and "sqrt(b3/g)" in ds.period.attrs["comment"]
    assert ds.theta_min.attrs["units"] == "rad"
    assert ds.attrs["history"].startswith(ds.attrs["created"] + ": ")
    # The motion is where the scene says: N is finite exactly on the existing components.
    # (At kappa = 0 the mirror images of one family, the body leaning either way, share its
    # slot: one value for two components.)
    count = ds.n_components.values
    finite = np.isfinite(ds.rotation_number.values).sum(axis=-1)
    np.testing.assert_array_equal(finite, (ds.family.values != 255).sum(axis=-1))
    moving = ds.kappa.values != 0
    np.testing.assert_array_equal(finite[:, :, moving], count[:, :, moving])
    assert (finite[:, :, ~moving] <= count[:, :, ~moving]).all()
    # The paper's Fig. xy cell: kappa = 0.8 near the libration of N = -1/7, in the well of
    # sigma_spi.
    n = ds.rubber.family("well_pi").rotation_number.sel(alpha=0.5, beta=3.0, kappa=0.8)
    assert np.nanmin(n.values) < -1 / 7 < np.nanmax(n.values)
    ds.close()


def test_a_sample_of_cells_equals_the_cell_command(demo):
    ds = open_atlas(demo)
    rng = np.random.default_rng(20261121)
    with_motion = np.argwhere(ds.n_components.values[0, 0] > 0)
    picked = with_motion[rng.choice(len(with_motion), size=12, replace=False)]
    fields = ["theta_min", "theta_max", "period", "omega_theta", "omega_psi", "rotation_number",
              "drift", "drift_radius", "error_estimate", "status", "motion", "bounded"]
    for ik, ie in picked:
        kappa, energy = float(ds.kappa[ik]), float(ds.energy[ie])
        out = subprocess.run(
            [BIN, "cell", "--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5",
             "--kappa", repr(kappa), "--energy", repr(energy), "--tol", "1e-10", "--json"],
            check=True, capture_output=True, text=True,
        ).stdout
        expected = json.loads(out)["components"]
        got = components(ds, 0.5, 3.0, kappa=kappa, energy=energy)
        assert len(got) == len(expected), (kappa, energy)
        for g, e in zip(got, expected):
            for name in fields:
                if e[name] is None and name != "bounded":  # JSON null: NaN or ±inf
                    assert not np.isfinite(g[name]), (name, kappa, energy)
                elif isinstance(e[name], float):
                    assert np.float64(g[name]).tobytes() == np.float64(e[name]).tobytes(), (name, kappa, energy)
                else:
                    assert g[name] == e[name], (name, kappa, energy)
    ds.close()


def test_the_plot_script_draws_the_atlas(demo, tmp_path):
    png = tmp_path / "demo.png"
    plot(demo, png)
    assert png.stat().st_size > 20_000


def test_open_atlas_takes_an_engine_and_other_keywords(demo):
    with open_atlas(demo, engine="h5netcdf", decode_times=False) as ds:
        assert "rotation_number" in ds


STATUS_ONLY = """name = "status-only"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.5]
beta = [3.0]
kappa = { start = 0.0, stop = 1.0, num = 5 }
energy = { start = 1.0, stop = 3.0, num = 5 }
[outputs]
fields = ["status", "period"]
"""


def test_the_plot_script_says_what_is_missing_instead_of_a_traceback(make_atlas, tmp_path):
    atlas = make_atlas("status-only", STATUS_ONLY)
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "plot_atlas.py"), str(atlas), "--out",
                          str(tmp_path / "x.png")], capture_output=True, text=True)
    assert out.returncode != 0
    assert "neither rotation_number nor drift_radius" in out.stderr and "Traceback" not in out.stderr


@pytest.mark.parametrize("script", ["figures", "hypothesis", "plot_atlas", "plot_trajectory", "plot_work_precision",
                                    "resonance", "speed_comparison", "whole_domain", "work_precision_truth"])
def test_every_script_help_is_whole_sentences(script):
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / f"{script}.py"), "--help"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    description = out.stdout.split("\n\n")[1].strip()
    assert description.endswith((".", ":", ")")), description


def test_a_partial_file_is_not_opened_as_an_atlas(tmp_path):
    partial = tmp_path / "x.h5.partial.h5"
    partial.write_bytes(b"")
    with pytest.raises(ValueError, match="unfinished"):
        open_atlas(partial)


COMPACT = """name = "compact"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.5]
beta = [0.5, 3.0]
lambda = { start = 0.05, stop = 1.4, num = 8 }
s = { start = 0.0, stop = 0.8, num = 9 }
[outputs]
fields = ["rotation_number", "status", "error_estimate"]
"""


def test_compact_plane_has_kappa_and_energy_as_coordinates(make_atlas):
    """The (lambda, s) plane reaches energy = infinity at s = 0; kappa and energy per cell are
    CF auxiliary coordinates, which xarray shows as coordinates of every variable."""
    ds = open_atlas(make_atlas("compact", COMPACT))
    assert set(ds.rotation_number.dims) == {"alpha", "beta", "lambda", "s", "component"}
    assert {"kappa", "energy"} <= set(ds.coords) and "kappa" not in ds.data_vars
    cell = ds.sel(alpha=0.5, beta=3.0).isel(**{"lambda": 3, "s": 4})
    lam, s = float(cell["lambda"]), float(cell["s"])
    assert float(cell.kappa) == lam / s and float(cell.energy) == 1 / s**2
    got = components(ds, 0.5, 3.0, lambda_=lam, s=s)
    assert got and got[0]["rotation_number"] == float(cell.rubber.family(got[0]["family"]).rotation_number)
    with pytest.raises(KeyError):
        components(ds, 0.5, 3.0, kappa=1.0, energy=2.0)
    limit = ds.sel(alpha=0.5, beta=3.0, s=0.0)
    assert np.isinf(limit.energy).all()
    # At kappa = lambda sqrt(energy) -> infinity V is one well, that of sigma_spi (alpha > 0).
    at_infinity = limit.rubber.family("well_pi")
    assert (flag_names(ds.status)[int(at_infinity.status.isel(**{"lambda": 0}))] == "high_energy_limit")
