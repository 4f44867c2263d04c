"""Every kind of file the program and the package write, against the CF checkers, and shards
that xarray combines into the merged atlas."""
from __future__ import annotations

import shutil
import sys

import h5py
import numpy as np
import pytest
import xarray as xr

import rubber_atlas as ra
from conftest import BIN, ROOT, run

sys.path.insert(0, str(ROOT / "scripts"))
from cf_check import check  # noqa: E402

BODY = ["--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5"]


@pytest.fixture(scope="module")
def files(make_scene, tmp_path_factory):
    """One file of each kind: atlas, shard, merged atlas, compact-plane atlas, trajectory,
    diagram, resonance; and the package's results written by xarray."""
    d = tmp_path_factory.mktemp("files")
    scene = make_scene("cf", alpha="[0.3, 0.5]", beta="[3.0]", kappa="{ start = 0.0, stop = 2.0, num = 11 }",
                       energy="{ start = 0.5, stop = 4.5, num = 9 }")
    out = {"atlas": d / "atlas.h5", "shard": d / "shard-1.h5", "merged": d / "merged.h5"}
    run("run", scene, "--out", out["atlas"], "--quiet")
    run("run", scene, "--out", out["shard"], "--shard", "1/2", "--quiet")
    run("run", scene, "--out", d / "shard-2.h5", "--shard", "2/2", "--quiet")
    run("merge", out["shard"], d / "shard-2.h5", "--out", out["merged"])
    compact = make_scene("compact", alpha="[0.5]", beta="[3.0]", kappa="[]", energy="[]").read_text()
    compact = compact.replace("kappa = []", "lambda = { start = 0.05, stop = 1.4, num = 5 }").replace(
        "energy = []", "s = { start = 0.0, stop = 0.8, num = 5 }")
    (d / "compact.toml").write_text(compact)
    out["compact"] = d / "compact.h5"
    run("run", d / "compact.toml", "--out", out["compact"], "--quiet")
    out["trajectory"] = d / "t.h5"
    run("trajectory", *BODY, "--kappa", "0.8", "--energy", "2.5", "--periods", "2", "--samples", "50",
        "--out", out["trajectory"])
    out["diagram"] = d / "d.h5"
    run("diagram", *BODY, "--samples", "200", "--out", out["diagram"])
    out["resonance"] = d / "r.h5"
    run("resonance", *BODY, "--rotation-number", "0", "--grid", "12", "--out", out["resonance"])
    out["cells (package)"] = d / "cells.nc"
    ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.1, 2, 6), 2.5).to_netcdf(out["cells (package)"], engine="h5netcdf")
    out["trajectory (package)"] = d / "tp.nc"
    ra.trajectory(0.5, 3, 0.5, 0.5, 0.8, 2.5, periods=1, samples=20).to_netcdf(out["trajectory (package)"],
                                                                               engine="h5netcdf")
    out["verdict (package)"] = d / "v.nc"
    ra.verdict(0.5, 3.0, 0.5, 0.5, resolution=8).to_netcdf(out["verdict (package)"], engine="h5netcdf")
    return out


KINDS = ["atlas", "shard", "merged", "compact", "trajectory", "diagram", "resonance", "cells (package)",
         "trajectory (package)", "verdict (package)"]


@pytest.mark.parametrize("kind", KINDS)
def test_every_kind_of_file_passes_both_cf_checkers(files, kind):
    assert check(files[kind]) == []


def test_the_checkers_do_find_faults(files, tmp_path):
    """The same atlas with the units the files had before (not UDUNITS) and flags with a
    wrong type of flag_values: the checkers must say so."""
    bad = tmp_path / "bad.h5"
    shutil.copy(files["atlas"], bad)
    with h5py.File(bad, "r+") as f:
        f["period"].attrs["units"] = "sqrt(b3/g)"
        del f["status"].attrs["flag_values"]
        f["status"].attrs["flag_values"] = np.array([0, 1, 2, 3, 4, 255], dtype=np.int32)
    problems = check(bad)
    assert any("units" in p for p in problems), problems
    assert any("flag_values" in p for p in problems), problems


def test_open_atlas_refuses_what_is_not_an_atlas(files, tmp_path):
    for kind in ("diagram", "trajectory", "cells (package)"):
        with pytest.raises(ValueError, match="not a rubber-atlas atlas"):
            ra.open_atlas(files[kind])
    garbage = tmp_path / "g.h5"
    garbage.write_bytes(b"not hdf5 at all")
    with pytest.raises(ValueError, match="not a rubber-atlas atlas"):
        ra.open_atlas(garbage)
    with ra.open_atlas(files["shard"]) as shard:
        assert shard.sizes["alpha"] == 1


def test_tables_have_a_dimension_coordinate_and_numeric_attributes(files):
    with xr.open_dataset(files["trajectory"], engine="h5netcdf") as t:
        assert "t" in t.indexes and t.theta.dims == ("t",)
        assert isinstance(t.attrs["kappa"], (float, np.floating)) and t.attrs["model"] == "reduced"
        assert t.attrs["history"].split(": ", 1)[1].startswith(BIN)
    for kind in ("diagram", "resonance"):
        with xr.open_dataset(files[kind], engine="h5netcdf") as table:
            assert "sample" in table.indexes and not any(d.startswith("phony") for d in table.dims)
            assert table.kappa.attrs["units"] == "1" and "paper's units" in table.kappa.attrs["comment"]


@pytest.mark.parametrize("axes, count", [
    # Shards split alpha and beta (2 x 2), beta (3), and the kappa rows (4 blocks).
    # (Slices of at least 256 cells: smaller ones are grouped along beta into one unit.)
    (dict(alpha="[0.2, 0.5]", beta="[0.8, 3.0]", kappa="{ start = 0.0, stop = 1.5, num = 16 }",
          energy="{ start = 0.5, stop = 4.0, num = 16 }"), 4),
    (dict(alpha="[0.5]", beta="[0.5, 1.5, 3.0]", kappa="{ start = 0.0, stop = 1.5, num = 16 }",
          energy="{ start = 0.5, stop = 4.0, num = 16 }"), 3),
    (dict(alpha="[0.5]", beta="[3.0]", kappa="{ start = 0.0, stop = 2.0, num = 700 }",
          energy="{ start = 0.5, stop = 4.5, num = 24 }"), 4),
])
def test_open_mfdataset_on_shards_equals_merge(make_scene, tmp_path, axes, count):
    scene = make_scene(f"mf{count}", **axes)
    shards = [tmp_path / f"s{i}.h5" for i in range(1, count + 1)]
    for i, s in enumerate(shards, 1):
        run("run", scene, "--out", s, "--shard", f"{i}/{count}", "--quiet")
    merged = tmp_path / "merged.h5"
    run("merge", *shards, "--out", merged)
    sizes = [dict(xr.open_dataset(s, engine="h5netcdf").sizes) for s in shards]
    # Each shard holds only its part.
    with ra.open_atlas(merged) as whole:
        total = whole.sizes
        assert all(np.prod([s[d] for d in ("alpha", "beta", "kappa")]) < np.prod(
            [total[d] for d in ("alpha", "beta", "kappa")]) for s in sizes)
        combined = xr.open_mfdataset(shards, combine="by_coords", engine="h5netcdf",
                                     combine_attrs="drop_conflicts")
        try:
            assert dict(combined.sizes) == dict(total)
            assert set(combined.data_vars) == set(whole.data_vars)
            for name in whole.variables:
                got, want = combined[name], whole[name]
                assert got.dims == want.dims, name
                assert got.dtype == want.dtype, name
                np.testing.assert_array_equal(np.atleast_1d(got.values).view(np.uint8),
                                              np.atleast_1d(want.values).view(np.uint8), err_msg=name)
        finally:
            combined.close()
