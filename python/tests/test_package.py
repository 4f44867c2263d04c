"""The installed package as a user meets it in a notebook in any folder: where it is imported
from, `cells` against the `cell` command and an atlas file (bit for bit), the GIL released,
bad input, the tables and the verdict against the commands, and the accessor."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import rubber_atlas as ra
from conftest import BIN, ROOT, assert_component_equals, run, same_double

COMPONENT_KEYS = ["theta_min", "theta_max", "period", "omega_theta", "omega_psi", "rotation_number",
                  "drift", "drift_radius", "error_estimate"]


def test_the_package_is_the_installed_one_and_not_the_repository():
    for module in (ra, ra._core):
        path = Path(module.__file__).resolve()
        assert ROOT / "python" not in path.parents, path
        assert "site-packages" in path.parts, path
    assert not Path.cwd().resolve().is_relative_to(ROOT)
    assert ra.__version__ == run("--version").split()[1]


def bits(x) -> np.ndarray:
    """The bytes of an array's values (NaN equal to NaN of the same bits)."""
    return np.atleast_1d(np.asarray(x)).view(np.uint8)


def test_cells_equal_the_cell_command_bit_for_bit_on_random_cells():
    rng = np.random.default_rng(20261123)
    n = 40
    alpha = rng.uniform(0.0, 0.95, n)
    beta = np.exp(rng.uniform(np.log(0.2), np.log(5.0), n))
    nu = rng.uniform(0.1, 2.0, n)
    eta = rng.uniform(0.1, 3.0, n)
    kappa = np.where(rng.random(n) < 0.15, 0.0, rng.uniform(0.0, 2.0, n))
    energy = rng.uniform(0.2, 6.0, n)
    # Components in increasing theta_min, as the command lists them.
    ds = ra.cells(alpha, beta, nu, eta, kappa, energy, layout="theta_min")
    assert ds.rotation_number.dims == ("cell", "component")
    assert ds.attrs["component_layout"] == "theta_min"
    flags = {name: ra.flag_names(ds[name]) for name in ("status", "motion", "family") if name in ds}
    with_motion = 0
    for i in range(n):
        args = ["cell", *[a for name, values in (("--alpha", alpha), ("--beta", beta), ("--nu", nu), ("--eta", eta),
                                                  ("--kappa", kappa), ("--energy", energy))
                          for a in (name, repr(float(values[i])))], "--json"]
        expected = json.loads(run(*args))["components"]
        cell = ds.isel(cell=i)
        assert int(cell.n_components) == len(expected), i
        with_motion += bool(expected)
        for slot, e in enumerate(expected):
            c = cell.isel(component=slot)
            assert_component_equals(c, e, COMPONENT_KEYS, i)
            for key, names in flags.items():
                if key in e:
                    assert names[int(c[key])] == e[key], (i, key)
            assert (None if int(c.bounded) == 255 else bool(c.bounded)) == e["bounded"], i
        # Slots beyond the components are NaN and the flags' no_value.
        for slot in range(len(expected), ds.sizes["component"]):
            assert np.isnan(float(cell.period.isel(component=slot)))
            assert int(cell.status.isel(component=slot)) == 255
    assert with_motion > n // 2


def test_cells_on_named_dimensions_equal_an_atlas_file(slice_atlas):
    """DataArrays broadcast by their dimension names: a (kappa, energy) grid gives the atlas's
    slice, with the same variables, attributes and values."""
    with ra.open_atlas(slice_atlas) as atlas:
        atlas = atlas.load()
    kappa = xr.DataArray(atlas.kappa.values, dims="kappa", coords={"kappa": atlas.kappa.values})
    energy = xr.DataArray(atlas.energy.values, dims="energy", coords={"energy": atlas.energy.values})
    layout = atlas.attrs.get("component_layout", "theta_min")
    ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa, energy, threads=2, layout=layout)
    assert ds.attrs["component_layout"] == layout
    cut = atlas.isel(alpha=0, beta=0)
    np.testing.assert_array_equal(ds.component, atlas.component)
    assert set(ds.data_vars) == set(atlas.data_vars)
    for name in atlas.data_vars:
        assert ds[name].dims == cut[name].dims, name
        np.testing.assert_array_equal(bits(ds[name]), bits(cut[name]), err_msg=name)
        assert ds[name].dtype == cut[name].dtype, name
        for key in ("long_name", "units", "comment", "flag_meanings"):
            assert ds[name].attrs.get(key) == cut[name].attrs.get(key), (name, key)
        if "flag_values" in cut[name].attrs:
            np.testing.assert_array_equal(ds[name].attrs["flag_values"], cut[name].attrs["flag_values"])
    for name in ("kappa", "energy", "alpha", "beta", "nu", "eta", "component"):
        for key in ("long_name", "units", "comment"):
            assert ds[name].attrs.get(key) == atlas[name].attrs.get(key), (name, key)
    assert ds.attrs["tolerance"] == atlas.attrs["tolerance"] and ds.attrs["Conventions"] == atlas.attrs["Conventions"]
    # Fewer fields: only theirs (and the cell's counts and status). Without the drift the quadrature
    # stops when N alone has converged: the same N within its error estimate (as an atlas
    # with these fields gives it), not bit for bit.
    few = ra.cells(0.5, 3.0, 0.5, 0.5, kappa, energy, fields=["rotation_number", "error_estimate"], layout=layout)
    assert set(few.data_vars) - {"family"} == {"n_components", "cell_status", "status", "rotation_number",
                                                "error_estimate"}
    np.testing.assert_array_equal(np.isnan(few.rotation_number), np.isnan(ds.rotation_number))
    gap = np.abs(few.rotation_number - ds.rotation_number).fillna(0)
    assert (gap <= few.error_estimate.fillna(0) + ds.error_estimate.fillna(0)).all()


def test_cells_release_the_gil():
    """Another Python thread keeps running while cells() works."""
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    kappa = np.linspace(0.05, 2.0, 20000)
    start = time.perf_counter()
    thread = threading.Thread(target=tick)
    thread.start()
    ra.cells(0.5, 3.0, 0.5, 0.5, kappa, 3.0, threads=1, fields=["rotation_number"])
    end = time.perf_counter()
    stop.set()
    thread.join()
    during = [t for t in ticks if start < t < end]
    # With the GIL held the thread would not tick at all during the call.
    assert end - start > 0.05
    assert len(during) > 0.25 * (end - start) / 0.002, (len(during), end - start)


@pytest.mark.parametrize("kwargs, words", [
    (dict(alpha=1.5), ["alpha", "1.5"]),
    (dict(beta=-1.0), ["beta", "-1"]),
    (dict(nu=3.0), ["nu", "3"]),
    (dict(energy=np.nan), ["energy", "NaN"]),
    (dict(kappa=[0.5, np.inf]), ["kappa[1]", "inf"]),
])
def test_bad_cells_raise_one_value_error_naming_the_value(kwargs, words):
    args = dict(alpha=0.5, beta=3.0, nu=0.5, eta=0.5, kappa=0.5, energy=2.0)
    args.update(kwargs)
    with pytest.raises(ValueError) as e:
        ra.cells(**args)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_inputs_that_would_be_misread_are_refused():
    k = xr.DataArray([0.1, 0.5], dims="energy")
    with pytest.raises(ValueError, match="named after the input energy"):
        ra.cells(0.5, 3.0, 0.5, 0.5, k, 2.5)
    a = xr.DataArray([0.1, 0.5], dims="x", coords={"x": [0, 1]})
    b = xr.DataArray([2.0, 3.0], dims="x", coords={"x": [1, 2]})
    with pytest.raises(ValueError, match="do not line up"):
        ra.cells(0.5, 3.0, 0.5, 0.5, a, b)
    labelled = xr.DataArray([0.5, 0.8], dims="kappa", coords={"kappa": [1.0, 1.5]})
    with pytest.raises(ValueError, match="coordinate differs from its values"):
        ra.cells(0.5, 3.0, 0.5, 0.5, labelled, 2.5)
    # Along its own dimension without a coordinate: its values become the coordinate.
    bare = ra.cells(0.5, 3.0, 0.5, 0.5, xr.DataArray([0.5, 0.8], dims="kappa"), 2.5)
    assert list(bare.kappa.values) == [0.5, 0.8] and bare.kappa.attrs["units"] == "1"
    with pytest.raises(ValueError, match=r"invalid energy\[600\] = NaN"):
        energies = np.full(700, 2.5)
        energies[600] = np.nan
        ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, energies, threads=1)
    with pytest.raises(TypeError, match="kappa is None"):
        ra.cells(0.5, 3.0, 0.5, 0.5, None, 2.5)
    with pytest.raises(TypeError, match="kappa is an xarray.Dataset"):
        ra.cells(0.5, 3.0, 0.5, 0.5, xr.Dataset({"k": ("kappa", [0.5, 0.8])}), 2.5)
    with pytest.raises(TypeError, match="complex"):
        ra.cells(0.5, 3.0, 0.5, 0.5, np.array([0.5 + 1j]), 2.5)
    with pytest.raises(ValueError, match="masked"):
        ra.cells(0.5, 3.0, 0.5, 0.5, np.ma.masked_array([0.5, 0.7], mask=[0, 1]), 2.5)
    # Masked values inside lists were read as their data, silently (an adversary pass).
    with pytest.raises(ValueError, match=r"kappa\[1\] is masked"):
        ra.cells(0.5, 3.0, 0.5, 0.5, [0.5, np.ma.masked], 2.5)
    with pytest.raises(ValueError, match=r"energy\[0\] is masked"):
        ra.cells(0.5, 3.0, 0.5, 0.5, [0.5], [np.ma.masked_array([2.5], mask=[1])])
    cells = ra.cells(0.5, 3.0, 0.5, 0.5, [0.5, 0.7], 2.5)
    for index in (1.7, -1, 2):
        with pytest.raises(KeyError, match="not an index"):
            cells.rubber.components(cell=index)
    with pytest.raises(ValueError, match="not a flag variable"):
        cells.rubber.flags("theta_min")
    # Flag values as text raised int()'s own words (an adversary pass).
    texts = cells.status.copy()
    texts.attrs["flag_values"] = ["a", "b"]
    with pytest.raises(ValueError, match="not one whole number per meaning"):
        ra.flag_names(texts)
    with pytest.raises(ValueError, match="plot_slice draws an atlas"):
        cells.rubber.plot_slice()


def test_requests_beyond_the_machine_are_refused_and_threads_capped():
    import rubber_atlas._core as core

    for call, name in ((lambda: ra.trajectory(0.5, 3, 0.5, 0.5, 0.8, 2.5, periods=1, samples=10**13), "samples"),
                       (lambda: ra.diagram(0.5, 3, samples=10**13), "samples")):
        with pytest.raises(ValueError, match="allow_large"):
            call()
    with pytest.raises(ValueError, match="invalid threads = -1"):
        ra.cells(0.5, 3, 0.5, 0.5, 0.5, 2.0, threads=-1)
    with pytest.raises(ValueError, match="invalid component = -1"):
        ra.trajectory(0.5, 3, 0.5, 0.5, 0.8, 2.5, component=-1, periods=1)
    # A thread count beyond the cores is capped, as the command line caps it: it returns at once.
    start = time.perf_counter()
    ra.cells(0.5, 3, 0.5, 0.5, 0.8, 2.5, threads=10**6)
    assert time.perf_counter() - start < 5
    assert core.COMPONENT_SLOTS == 3


LONG_CALLS = {
    "cells-ode": "ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.05, 2, 400)[:, None], np.linspace(0.5, 4.5, 400), "
                 "method='ode', progress=None)",
    "cells-ode-progress": "ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.05, 2, 400)[:, None], "
                          "np.linspace(0.5, 4.5, 400), method='ode', progress=True)",
    "cells-quadrature": "ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.05, 2, 1000)[:, None], "
                        "np.linspace(0.5, 4.5, 1000), progress=None)",
    # A verdict at resolution 1024 takes tens of seconds per body.
    "verdict": "ra.verdict([0.5, 0.5], [3.0, 0.5], 0.5, 0.5, resolution=1024)",
    "boundaries": "ra.boundaries(0.5, 0.5, 0.5, beta_min=0.05, beta_max=50, scan=200)",
    # About 15 s each on one core; they ran to the end under Ctrl-C.
    "trajectory": "ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, t_end=1e6, model='full')",
    # A billion periods of the reduced model (issue 22: not tried before).
    "trajectory_reduced": "ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, periods=1e9, samples=100, "
                          "allow_large=True)",
    # grid=400 took 1.55 s on a quiet machine: it could end before the signal at 1.5 s.
    "resonance": "ra.resonance(0.5, 3.0, 0.5, 0.5, '-1/7', grid=2000)",
    # 48 s; a SIGINT in the first call became a Rust panic.
    "diagram": "ra.diagram(0.5, 3.0, samples=50_000_000)",
}


@pytest.mark.parametrize("call", LONG_CALLS)
def test_ctrl_c_stops_a_long_call_at_once(tmp_path, call):
    """Inside one body of a verdict or one batch of cells, not after it (the bar is closed)."""
    import signal

    code = ("import numpy as np, rubber_atlas as ra, sys; print('start', flush=True)\n"
            "try:\n"
            f"    {LONG_CALLS[call]}\n"
            "except KeyboardInterrupt:\n"
            "    print('interrupted', flush=True); sys.exit(3)\n")
    child = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "start"
    time.sleep(1.5)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=60)
    assert child.returncode == 3 and "interrupted" in out, err
    # Not a timing test (the figures in docs/python.md are measured apart): it tells an
    # interrupt heard inside the call (0.02-0.2 s, up to 1.2 s on a loaded machine) from one
    # heard only after the body or the batch (13 s and more after the signal in every call).
    assert time.perf_counter() - sent < 5.0, time.perf_counter() - sent
    assert (err.endswith("\n") and "%" in err) if "progress" in call else "%" not in err


def test_a_trajectory_beyond_the_step_budget_is_refused_with_its_estimate():
    """A billion periods (some 80 hours) used to run on without a word."""
    with pytest.raises(ValueError, match=r"periods = 1000000000 needs about \d\.\de\d+ integrator steps.*allow_large=True"):
        ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, periods=1e9)


def test_components_names_the_keys_that_are_not_dimensions_and_those_missing():
    """It said "give the cell by lambda, s, not lambda, s, alpha, beta": both lists in full,
    the wrong keys not named, and `lambda` where the keyword is `lambda_`."""
    ds = ra.cells(0.5, 3.0, 0.5, 0.5, lambda_=np.array([[0.2], [0.4]]), s=[0.5, 1.0])
    with pytest.raises(KeyError, match=r"by lambda_, s \(this dataset's dimensions\): alpha, beta are not among them$"):
        ds.rubber.components(alpha=0.5, beta=3.0, lambda_=0.4, s=0.5)
    with pytest.raises(ValueError, match=r"kappa is not among them; lambda_ is missing$"):
        ds.rubber.components(kappa=0.4, s=0.5)
    assert ds.rubber.components(lambda_=0.4, s=0.5)


def test_diagram_takes_nu_and_eta_together_or_neither():
    """Either alone would record the other's default beside it (they do not change the set)."""
    with pytest.raises(ValueError, match="nu given without eta"):
        ra.diagram(0.5, 3.0, nu=0.7)
    with pytest.raises(ValueError, match="eta given without nu"):
        ra.diagram(0.5, 3.0, eta=2.0)
    assert json.loads(ra.diagram(0.5, 3.0, samples=10).attrs["critical_set_json"])["eta"] == 0.5
    assert json.loads(ra.diagram(0.5, 3.0, 0.7, 2.0, samples=10).attrs["critical_set_json"])["eta"] == 2.0


def test_a_failed_integration_raises_a_runtime_error_not_a_value_error():
    """The inputs are valid; the computation failed (the command exits 1, not 2)."""
    with pytest.raises(RuntimeError, match="integration failed at t = 0"):
        ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=1e-200, energy=2.5, periods=1)


def test_bad_options_raise_value_errors():
    with pytest.raises(ValueError, match="omega"):
        ra.cells(0.5, 3, 0.5, 0.5, 0.5, 2.0, fields=["omega"])
    with pytest.raises(ValueError, match="method"):
        ra.cells(0.5, 3, 0.5, 0.5, 0.5, 2.0, method="euler")
    with pytest.raises(ValueError, match="tol"):
        ra.cells(0.5, 3, 0.5, 0.5, 0.5, 2.0, tol=0.0)
    with pytest.raises(ValueError, match="threads"):
        ra.cells(0.5, 3, 0.5, 0.5, 0.5, 2.0, threads=0)


IMPORT_AND_ROUND_TRIP = """
import {first}, {second}, {third}
import numpy as np, xarray as xr, h5py, rubber_atlas as ra
ds = ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.1, 1.5, 7), 2.5)
ds.to_netcdf("round.nc", engine="h5netcdf")
back = xr.open_dataset("round.nc", engine="h5netcdf").load()
assert (back.rotation_number.values.view(np.uint8) == ds.rotation_number.values.view(np.uint8)).all()
assert back.status.dtype == np.uint8
with h5py.File("round.nc") as f:
    assert f["rotation_number"].shape == (7, ds.sizes["component"])
maps = open("/proc/self/maps").read()
libraries = {{line.split()[-1] for line in maps.splitlines() if "libhdf5" in line.split()[-1]}}
print(sorted(libraries))
"""


@pytest.mark.parametrize("order", [("h5py", "xarray", "rubber_atlas"), ("rubber_atlas", "xarray", "h5py"),
                                   ("xarray", "rubber_atlas", "h5py")])
def test_h5py_xarray_and_the_package_import_together_with_one_hdf5(order, tmp_path):
    code = IMPORT_AND_ROUND_TRIP.format(first=order[0], second=order[1], third=order[2])
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    libraries = eval(out.stdout.strip().splitlines()[-1])
    # Only h5py's own HDF5 (its wheel's libhdf5, and its high-level library) is loaded.
    assert libraries and all("h5py" in lib for lib in libraries), libraries
    core = Path(ra._core.__file__)
    ldd = subprocess.run(["ldd", str(core)], capture_output=True, text=True).stdout
    assert "hdf5" not in ldd, ldd


def table_values(ds: xr.Dataset) -> dict:
    return {name: v.values for name, v in ds.variables.items()}


def assert_same_tables(made: xr.Dataset, written: xr.Dataset):
    assert set(made.data_vars) == set(written.data_vars) and set(made.coords) == set(written.coords)
    for name, v in made.variables.items():
        w = written[name]
        assert v.dims == w.dims and v.dtype == w.dtype, name
        np.testing.assert_array_equal(bits(v.values), bits(w.values), err_msg=name)
        for key in ("long_name", "units", "comment", "flag_meanings"):
            assert v.attrs.get(key) == w.attrs.get(key), (name, key)


def test_trajectory_diagram_and_resonance_equal_the_commands(tmp_path):
    body = ["--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5"]
    t_file = tmp_path / "t.h5"
    run("trajectory", *body, "--kappa", "0.8", "--energy", "2.5", "--periods", "3", "--samples", "300",
        "--out", t_file)
    traj = ra.trajectory(0.5, 3, 0.5, 0.5, kappa=0.8, energy=2.5, periods=3, samples=300)
    written = ra.read_table(t_file)
    assert_same_tables(traj, written)
    for key in ("kappa", "energy", "theta0", "theta_dot0", "tolerance", "model"):
        assert traj.attrs[key] == written.attrs[key], key
    assert "t" in traj.indexes and traj.theta.dims == ("t",)

    d_file = tmp_path / "d.h5"
    run("diagram", *body, "--out", d_file)
    diagram = ra.diagram(0.5, 3)
    assert_same_tables(diagram, ra.read_table(d_file))
    assert json.loads(diagram.attrs["critical_set_json"])["diagram_type"] == "c"

    r_file = tmp_path / "r.h5"
    run("resonance", *body, "--rotation-number", "-1/7", "--grid", "16", "--out", r_file)
    curves = ra.resonance(0.5, 3, 0.5, 0.5, "-1/7", grid=16)
    assert_same_tables(curves, ra.read_table(r_file))
    assert curves.sizes["sample"] > 10
    assert np.all(np.abs(curves.rotation_number + 1 / 7) <= np.maximum(1e-10, curves.error_estimate))

    with pytest.raises(ValueError, match="periods"):
        ra.trajectory(0.5, 3, 0.5, 0.5, kappa=0.8, energy=2.5, periods=-1)
    with pytest.raises(ValueError, match="exactly one"):
        ra.trajectory(0.5, 3, 0.5, 0.5, kappa=0.8, energy=2.5, theta0=1.0, periods=1)


def test_verdicts_equal_the_command():
    alpha = xr.DataArray([0.5, 0.2], dims="body")
    beta = xr.DataArray([0.5, 3.0], dims="body")
    found = ra.verdict(alpha, beta, 0.5, 0.5, resolution=16)
    # A body axis with its own name.
    along = ra.verdict(xr.DataArray([0.5], dims="alpha"), 0.5, 0.5, 0.5, resolution=8)
    assert along.holds.dims == ("alpha",) and float(along.alpha[0]) == 0.5
    assert found.holds.dims == ("body",) and found.holds.dtype == np.uint8
    assert found.kappa.dims == ("body", "counterexample") and found.sizes["counterexample"] > 0
    for i in range(2):
        expected = json.loads(run("verdict", "--alpha", float(alpha[i]), "--beta", float(beta[i]), "--nu", "0.5",
                                  "--eta", "0.5", "--resolution", "16", "--json"))
        got = json.loads(found.verdict_json[i].item())
        assert got == expected
        holds = int(found.holds[i])
        assert ({0: False, 1: True, 255: None}[holds]) == expected["holds"]
        assert found.case[i].item().decode() == expected["case"]
        # The counterexamples as data, padded beyond the body's count.
        count = len(expected["counterexamples"])
        assert int(found.counterexamples[i]) == count
        for j in range(found.sizes["counterexample"]):
            row = found.isel(body=i, counterexample=j)
            if j < count:
                c = expected["counterexamples"][j]
                for key in ("kappa", "energy", "rotation_number", "theta_min", "theta_max", "drift"):
                    assert same_double(row[key], c[key]), (i, j, key)
                assert row.family.item().decode() == c.get("family", "")
                assert int(row.component) == c.get("component", -1)
            else:
                assert all(np.isnan(float(row[k])) for k in ("kappa", "energy", "rotation_number", "drift"))
                assert row.family.item() == b"" and int(row.component) == -1


def test_the_accessor_gives_components_and_a_figure(slice_atlas):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.figure

    with ra.open_atlas(slice_atlas) as ds:
        kappa, energy = float(ds.kappa[8]), float(ds.energy[10])
        got = ds.rubber.components(alpha=0.5, beta=3.0, kappa=kappa, energy=energy)
        expected = json.loads(run("cell", "--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5",
                                  "--kappa", repr(kappa), "--energy", repr(energy), "--json"))["components"]
        assert len(got) == len(expected) > 0
        for g, e in zip(got, expected):
            for key in ("rotation_number", "period", "drift", "status", "motion", "bounded"):
                assert g[key] == e[key], key
        assert ds.rubber.flags("status")[3] == "separatrix"
        fig = ds.rubber.plot_slice()
        assert isinstance(fig, matplotlib.figure.Figure) and len(fig.axes) >= 2
    # A cells result too.
    cells = ra.cells(0.5, 3.0, 0.5, 0.5, [kappa, 0.3], energy)
    assert cells.rubber.components(cell=0) == [
        {k: v for k, v in c.items()} for c in ra.components(cells, cell=0)
    ]
    assert cells.rubber.components(cell=0)[0]["rotation_number"] == got[0]["rotation_number"]


def test_rayon_num_threads_is_honoured_when_threads_is_absent(tmp_path):
    """Without threads=, cells runs on rayon's global pool, which RAYON_NUM_THREADS sizes:
    the process gains exactly that many threads."""
    count = "import os; print(len(os.listdir('/proc/self/task')))"
    probe = ("import numpy as np, rubber_atlas as ra; "
             "ra.cells(0.5, 3.0, 0.5, 0.5, np.linspace(0.05, 2, 200), 3.0, fields=['rotation_number']); ")
    threads = {}
    for n in (1, 3):
        env = dict(os.environ, RAYON_NUM_THREADS=str(n))
        after = subprocess.run([sys.executable, "-c", probe + count], cwd=tmp_path, env=env,
                               capture_output=True, text=True)
        assert after.returncode == 0, after.stderr
        threads[n] = int(after.stdout)
    assert threads[3] - threads[1] == 2, threads
    # One that is not a whole number is refused, as the program refuses it (it was ignored:
    # adversary pass 34), by every function that would run on rayon's global pool.
    for call in ("ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, 2.5)", "ra.verdict(0.5, 3.0, 0.5, 0.5)",
                 "ra.diagram(0.5, 3.0)"):
        refused = subprocess.run([sys.executable, "-c", f"import rubber_atlas as ra; {call}"], cwd=tmp_path,
                                 env=dict(os.environ, RAYON_NUM_THREADS="abc"), capture_output=True, text=True)
        last = refused.stderr.strip().splitlines()[-1]
        assert refused.returncode == 1 and last.startswith('ValueError: RAYON_NUM_THREADS = "abc"'), refused.stderr


def test_boundaries_equal_the_command():
    found = ra.boundaries(0.5, 0.5, 0.5, scan=6, resolution=32, beta_min=0.3, beta_max=3)
    expected = json.loads(run("verdict", "--alpha", "0.5", "--nu", "0.5", "--eta", "0.5", "--boundaries", "--scan", "6",
                              "--resolution", "32", "--beta-min", "0.3", "--beta-max", "3", "--json"))
    assert json.loads(found.attrs["boundaries_json"]) == expected
    assert found.sizes["boundary"] == len(expected["boundaries"]) > 0
    np.testing.assert_array_equal(found.boundary_beta, [b["beta"] for b in expected["boundaries"]])
    names = ra.flag_names(found.holds_below)
    assert [names[int(h)] for h in found.holds_below] == [
        {True: "holds", False: "fails", None: "no_value"}[b["holds_below"]] for b in expected["boundaries"]]
