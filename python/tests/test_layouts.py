"""The shapes of the package's results, none of which needs the command: the inputs of `cells`
(grids, numpy axes, the other planes of a scene), its progress bar and batches, the two
layouts of the components (families of tori, checked against the minima of V found on a
fine grid), the accessor's `family` and figure, the verdict's counterexamples as data,
and the figure of scripts/plot_trajectory.py."""
from __future__ import annotations

import json
import math
import sys
import types

import numpy as np
import pytest
import xarray as xr

import rubber_atlas as ra
from conftest import ROOT

BODY = (0.5, 3.0, 0.5, 0.5)
KAPPA = np.linspace(0.05, 2.0, 12)
ENERGY = np.linspace(0.5, 4.5, 10)


def bits(x) -> np.ndarray:
    return np.atleast_1d(np.ascontiguousarray(np.asarray(x))).view(np.uint8)


def assert_same_values(a: xr.Dataset, b: xr.Dataset):
    """The same variables and coordinates, dimensions and values (bit for bit)."""
    assert set(a.data_vars) == set(b.data_vars)
    assert set(a.coords) == set(b.coords)
    for name in a.variables:
        assert a[name].dims == b[name].dims, name
        assert a[name].dtype == b[name].dtype, name
        np.testing.assert_array_equal(bits(a[name].values), bits(b[name].values), err_msg=name)


def same_entry(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(
        (isinstance(a[k], float) and math.isnan(a[k]) and math.isnan(b[k])) or a[k] == b[k] for k in a)


THETA = np.linspace(1e-4, np.pi - 1e-4, 20001)


def minima(alpha: float, beta: float, kappa: float) -> np.ndarray:
    """The local minima of V(θ) = κ²/(2 sin²θ) + Z(θ) + α cos θ on (0, π), to a fine grid's
    resolution: an independent check of the families' wells."""
    s, c = np.sin(THETA), np.cos(THETA)
    v = kappa**2 / (2 * s**2) + np.sqrt(beta**2 * s**2 + c**2) + alpha * c
    i = np.flatnonzero((v[1:-1] < v[:-2]) & (v[1:-1] <= v[2:])) + 1
    return THETA[i]


class _CountingCore:
    """The installed core, counting its `cells` calls (a spy: every call goes to the core)."""

    def __init__(self, real):
        self._real = real
        self.calls = 0

    def __getattr__(self, name):
        return getattr(self._real, name)

    def cells(self, *args, **kwargs):
        self.calls += 1
        return self._real.cells(*args, **kwargs)


@pytest.fixture
def counting_core(monkeypatch):
    core = _CountingCore(ra._api._core)
    monkeypatch.setattr(ra._api, "_core", core)
    return core


# Inputs and their dimensions.

def test_vectors_of_different_lengths_make_a_grid():
    k, e = np.linspace(0.2, 1.0, 5), np.linspace(1.5, 3.5, 3)
    grid = ra.cells(*BODY, k, e, fields=["rotation_number"])
    assert grid.n_components.dims == ("kappa", "energy")
    assert grid.rotation_number.dims == ("kappa", "energy", "component")
    assert "kappa" in grid.indexes and "energy" in grid.indexes
    np.testing.assert_array_equal(grid.kappa, k)
    np.testing.assert_array_equal(grid.energy, e)
    assert grid.kappa.attrs["units"] == "1" and "long_name" in grid.energy.attrs
    named = ra.cells(*BODY, xr.DataArray(k, dims="kappa"), xr.DataArray(e, dims="energy"), fields=["rotation_number"])
    assert_same_values(grid, named)
    # kappa[:, None] with energy[None, :]: the same, dimensions named after the one input
    # that varies along each.
    assert_same_values(grid, ra.cells(*BODY, k[:, None], e[None, :], fields=["rotation_number"]))
    assert_same_values(grid, ra.cells(*BODY, k[:, None], e, fields=["rotation_number"]))
    # Vectors of one length are paired cell by cell.
    paired = ra.cells(*BODY, k[:3], e, fields=["rotation_number"])
    assert paired.n_components.dims == ("cell",)
    assert paired.kappa.dims == ("cell",) and paired.energy.dims == ("cell",)


def test_axes_along_which_several_inputs_vary_keep_cell_names_and_get_coordinates():
    alpha = np.array([0.3, 0.5])[:, None]
    kappa = np.array([0.5, 0.8])[:, None]
    energy = np.array([2.0, 2.5, 3.0])
    ds = ra.cells(alpha, 3.0, 0.5, 0.5, kappa, energy, fields=["rotation_number"])
    assert ds.n_components.dims == ("cell_0", "energy")
    assert ds.alpha.dims == ("cell_0",) and ds.kappa.dims == ("cell_0",) and ds.energy.dims == ("energy",)
    np.testing.assert_array_equal(ds.alpha, [0.3, 0.5])
    assert ds.beta.dims == ()
    # An input that varies along both axes is a coordinate over both.
    both = ra.cells(0.5, 3.0, 0.5, 0.5, np.array([[0.5, 0.6, 0.7], [0.8, 0.9, 1.0]]), 2.5,
                    fields=["rotation_number"])
    assert both.n_components.dims == ("cell_0", "cell_1") and both.kappa.dims == ("cell_0", "cell_1")


def test_inputs_that_do_not_broadcast_say_so_in_one_line():
    with pytest.raises(ValueError) as e:
        ra.cells(np.array([0.3, 0.5, 0.6]), 3.0, 0.5, 0.5, np.linspace(0.2, 1, 5), np.linspace(1.5, 3.5, 4))
    message = str(e.value)
    assert "\n" not in message
    for words in ("do not broadcast", "alpha (3,)", "kappa (5,)", "energy (4,)", "DataArray"):
        assert words in message, message
    with pytest.raises(ValueError, match="do not broadcast"):
        ra.cells(*BODY, np.zeros((2, 3)), np.zeros(4))


def test_lambda_and_s_are_kappa_over_s_and_one_over_s_squared():
    lam, s = np.array([0.2, 0.5, 0.9]), np.array([0.3, 0.6])
    ds = ra.cells(*BODY, lambda_=lam, s=s)
    assert ds.n_components.dims == ("lambda", "s")
    np.testing.assert_array_equal(ds["lambda"], lam)
    np.testing.assert_array_equal(ds.s, s)
    assert ds.kappa.dims == ("lambda", "s") and ds.energy.dims == ("s",)
    np.testing.assert_array_equal(ds.kappa, lam[:, None] / s[None, :])
    np.testing.assert_array_equal(ds.energy, 1.0 / (s * s))
    for name in ("lambda", "s", "kappa", "energy"):
        assert ds[name].attrs["units"] == "1" and ds[name].attrs["long_name"], name
    flat = ra.cells(*BODY, ds.kappa.values.ravel(), np.broadcast_to(ds.energy.values, (3, 2)).ravel())
    for name in flat.data_vars:
        np.testing.assert_array_equal(bits(ds[name].values.reshape(flat[name].shape)), bits(flat[name].values),
                                      err_msg=name)
    assert "lambda_=" in ds.attrs["history"]
    # DataArrays along their own dimensions.
    along = ra.cells(*BODY, lambda_=xr.DataArray(lam, dims="lambda"), s=xr.DataArray(s, dims="s"))
    assert_same_values(along, ds)


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(lambda_=0.5, s=0.0), ValueError, "s = 0 is the high-energy limit"),
    (dict(lambda_=0.5, s=[0.5, -0.1]), ValueError, "invalid s[1] = -0.1"),
    (dict(lambda_=[0.5, np.nan], s=0.5), ValueError, "invalid lambda_[1] = NaN"),
    (dict(lambda_=0.5), TypeError, "s is None"),
    (dict(s=0.5), TypeError, "lambda_ is None"),
    (dict(kappa=0.5), TypeError, "energy is None"),
    (dict(energy=2.5), TypeError, "kappa is None"),
    (dict(kappa=0.5, s=0.5), TypeError, "kappa with energy, kappa with excess_energy, or lambda_ with s"),
    (dict(kappa=0.5, energy=2.5, excess_energy=0.1), TypeError, "got kappa, energy, excess_energy"),
])
def test_a_plane_given_wrong_is_refused_with_one_line(kwargs, error, words):
    with pytest.raises(error) as e:
        ra.cells(*BODY, **kwargs)
    assert words in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_a_dimension_named_after_a_computed_coordinate_is_refused():
    with pytest.raises(ValueError, match="computed here from lambda and s"):
        ra.cells(*BODY, lambda_=xr.DataArray([0.5, 0.6], dims="kappa"), s=0.5)


def test_excess_energy_lays_out_like_the_atlas_plane(monkeypatch):
    """The plumbing of excess_energy, with a stand-in for the bottom of V."""

    def bottom(alpha, beta, nu, eta, kappa, excess, core):
        # The ellipsoid's: no shape keywords for the core.
        assert all(len(a) == len(excess) for a in (alpha, beta, nu, eta, kappa)) and not core
        return 1.0 + kappa**2 + excess

    monkeypatch.setattr(ra._api, "_excess_to_energy", bottom)
    k, x = np.array([0.3, 0.8, 1.2]), np.array([0.1, 0.5])
    ds = ra.cells(*BODY, kappa=k, excess_energy=x, fields=["rotation_number"])
    assert ds.n_components.dims == ("kappa", "excess_energy")
    assert ds.energy.dims == ("kappa", "excess_energy")
    np.testing.assert_array_equal(ds.energy, 1.0 + k[:, None] ** 2 + x[None, :])
    assert "excess" in ds.excess_energy.attrs["long_name"]
    direct = ra.cells(*BODY, kappa=xr.DataArray(k, dims="kappa"),
                      energy=xr.DataArray(ds.energy.values, dims=("kappa", "excess_energy")),
                      fields=["rotation_number"])
    np.testing.assert_array_equal(bits(ds.rotation_number.values), bits(direct.rotation_number.values))


def test_excess_energy_is_measured_from_the_bottom_of_v():
    """ε = V_min(κ) + e, against the bottom of V found on a fine grid."""
    k = np.array([0.3, 0.8, 1.5])
    excess = np.array([-0.01, 1e-3, 0.5, 2.0])  # another length: a (kappa, excess_energy) grid
    ds = ra.cells(*BODY, kappa=k, excess_energy=excess, fields=["rotation_number"])
    assert ds.rotation_number.dims[:2] == ("kappa", "excess_energy")
    theta = np.linspace(1e-4, np.pi - 1e-4, 400001)
    for i, kappa in enumerate(k):
        v = kappa**2 / (2 * np.sin(theta) ** 2) + np.sqrt(9 * np.sin(theta) ** 2 + np.cos(theta) ** 2) \
            + 0.5 * np.cos(theta)
        np.testing.assert_allclose(ds.energy[i].values, v.min() + excess, rtol=0, atol=1e-8)
        assert int(ds.n_components[i, 0]) == 0 and int(ds.n_components[i, 1]) >= 1


# Progress and batches.

def test_progress_batches_give_the_values_of_one_call(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # the package's own bar
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 7)
    k = np.linspace(0.05, 2.0, 50)
    one = ra.cells(*BODY, k, 3.0, progress=False)
    assert capsys.readouterr().err == ""
    batched = ra.cells(*BODY, k, 3.0, progress=True)
    err = capsys.readouterr().err
    assert "100%" in err and "50/50" in err and err.endswith("\n"), err
    assert_same_values(one, batched)


def test_a_bad_cell_is_named_by_its_index_in_the_whole_input_when_batched(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 64)
    energies = np.full(700, 2.5)
    energies[600] = np.nan
    with pytest.raises(ValueError, match=r"invalid energy\[600\] = NaN"):
        ra.cells(*BODY, 0.8, energies, threads=1, progress=True)
    assert capsys.readouterr().err.endswith("\n")  # the bar is closed


def test_progress_uses_tqdm_when_installed(monkeypatch):
    bars = []

    class Bar:
        def __init__(self, total, **options):
            self.total, self.options, self.done, self.closed = total, options, 0, False
            bars.append(self)

        def update(self, n):
            self.done += n

        def close(self):
            self.closed = True

    auto = types.ModuleType("tqdm.auto")
    auto.tqdm = Bar
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", auto)
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 10)
    ra.cells(*BODY, np.linspace(0.05, 2.0, 35), 3.0, fields=["rotation_number"], progress=True)
    assert len(bars) == 1 and bars[0].total == 35 and bars[0].done == 35 and bars[0].closed


def test_progress_is_shown_by_default_only_for_many_cells_in_a_terminal_or_jupyter(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setattr(ra._api, "_PROGRESS_CELLS", 20)
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 10)
    k = np.linspace(0.05, 2.0, 30)
    ra.cells(*BODY, k, 3.0, fields=["rotation_number"])  # standard error is not a terminal here
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(ra._api, "_stderr_is_terminal", lambda: True)
    ra.cells(*BODY, k[:20], 3.0, fields=["rotation_number"])  # not more than the threshold
    assert capsys.readouterr().err == ""
    ra.cells(*BODY, k, 3.0, fields=["rotation_number"])
    assert "30/30" in capsys.readouterr().err
    ra.cells(*BODY, k, 3.0, fields=["rotation_number"], progress=False)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(ra._api, "_stderr_is_terminal", lambda: False)
    kernel = types.SimpleNamespace(kernel=object())
    monkeypatch.setitem(sys.modules, "IPython", types.SimpleNamespace(get_ipython=lambda: kernel))
    assert ra._api._in_jupyter()
    ra.cells(*BODY, k, 3.0, fields=["rotation_number"])
    assert "30/30" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "IPython", types.SimpleNamespace(get_ipython=lambda: None))
    assert not ra._api._in_jupyter()


def test_batched_calls_refuse_what_would_not_fit_in_memory():
    with pytest.raises(ValueError, match="allow_large=True"):
        ra._api._check_memory(10**15, None, False)
    ra._api._check_memory(10**15, None, True)
    ra._api._check_memory(1000, None, False)


# Families of tori.

def test_the_family_layout_of_the_cells():
    ds = ra.cells(*BODY, KAPPA, ENERGY)
    assert ds.attrs["component_layout"] == "family" and "family" in ds
    # As in the files: the families' codes as uint8 flags.
    assert ds.component.dtype == np.uint8 and ds.component.values.tolist() == [0, 1]
    assert ds.component.attrs["long_name"] == "torus family"
    assert ds.component.attrs["flag_meanings"] == "well_0 well_pi"
    np.testing.assert_array_equal(ds.component.attrs["flag_values"], [0, 1])
    assert ds.component.attrs["flag_values"].dtype == ds.component.dtype
    assert ds.rubber.families() == ["well_0", "well_pi"]
    by_rank = ra.cells(*BODY, KAPPA, ENERGY, layout="theta_min")
    assert by_rank.attrs["component_layout"] == "theta_min" and by_rank.component.values.tolist() == [0, 1]
    assert by_rank.rubber.families() == ["well_0", "well_pi"]
    for name in ds.rubber.families():
        one, other = ds.rubber.family(name), by_rank.rubber.family(name)
        assert_same_values(one, other)
        assert one.rotation_number.dims == ("kappa", "energy") and "component" not in one.dims
        assert one.attrs["family"] == name
        assert one.rotation_number.attrs == ds.rotation_number.attrs
        code = dict(zip(ds.rubber.families(), ds.component.values.tolist()))[name]
        present = (one.family != 255).values
        assert present.any() and (one.family.values[present] == code).all()
        assert np.isnan(one.rotation_number.values[~present]).all()
    # The same components, by either layout, each with its family's name.
    for kappa in KAPPA[::3]:
        for energy in ENERGY[::3]:
            a = ds.rubber.components(kappa=kappa, energy=energy)
            b = by_rank.rubber.components(kappa=kappa, energy=energy)
            assert len(a) == len(b) == int(ds.n_components.sel(kappa=kappa, energy=energy))
            assert all(same_entry(x, y) for x, y in zip(a, b))
            assert [c["theta_min"] for c in a] == sorted(c["theta_min"] for c in a)
            assert all(c["family"] in ("well_0", "well_pi") for c in a)


def test_family_of_one_well_is_the_component_around_that_minimum():
    kappas = np.linspace(0.05, 1.6, 12)
    ds = ra.cells(*BODY, kappas, np.linspace(1.0, 4.5, 15))
    judged = 0
    for name, side in (("well_0", -1), ("well_pi", 1)):
        f = ds.rubber.family(name)
        for i, kappa in enumerate(kappas):
            wells = minima(0.5, 3.0, kappa)
            for j in range(ds.sizes["energy"]):
                if np.isnan(f.theta_min[i, j]):
                    continue
                inside = wells[(wells >= float(f.theta_min[i, j])) & (wells <= float(f.theta_max[i, j]))]
                if len(inside) == 1:
                    assert np.sign(inside[0] - np.pi / 2) == side, (name, kappa)
                else:
                    # Above the saddle, round both wells: the family of the well V keeps at
                    # large kappa (well_pi for alpha > 0).
                    assert len(inside) == 2 and name == "well_pi", (name, kappa, inside)
                judged += 1
    assert judged > 100


def test_family_refuses_what_it_cannot_give():
    ds = ra.cells(*BODY, KAPPA, ENERGY, fields=["rotation_number"])
    with pytest.raises(KeyError, match="no torus of the family 'over_the_top' in this dataset: it has "
                                       "well_0, well_pi"):
        ds.rubber.family("over_the_top")
    with pytest.raises(KeyError, match="no torus family 'wells'.*well_0, well_pi"):
        ds.rubber.family("wells")
    old = ds.drop_vars("family")
    old.attrs.pop("component_layout")
    for call in (lambda: old.rubber.family("well_0"), old.rubber.families):
        with pytest.raises(ValueError, match="no `family` variable: it was written by a version"):
            call()


def test_batches_with_different_families_join_into_one_call(counting_core, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 5)
    for layout in ("family", "theta_min"):
        one = ra.cells(*BODY, KAPPA, ENERGY, layout=layout, progress=False)
        calls = counting_core.calls
        batched = ra.cells(*BODY, KAPPA, ENERGY, layout=layout, progress=True)
        assert counting_core.calls - calls == 24
        assert_same_values(one, batched)
        for name in ("component",):
            assert one[name].attrs.keys() == batched[name].attrs.keys()
    capsys.readouterr()


def test_a_batch_without_motion_adds_no_component(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setattr(ra._api, "_BATCH_CELLS", 5)
    kappa = np.r_[np.full(5, 1.5), np.linspace(0.3, 0.8, 5)]
    energy = np.r_[np.full(5, 0.3), np.full(5, 2.5)]
    for layout in ("family", "theta_min"):
        one = ra.cells(*BODY, kappa, energy, layout=layout, progress=False)
        assert_same_values(one, ra.cells(*BODY, kappa, energy, layout=layout, progress=True))
        assert 255 not in one.component.values
        # No motion anywhere: one empty slot (no_value in the family layout).
        none = ra.cells(*BODY, kappa[:5], energy[:5], layout=layout)
        assert none.sizes["component"] == 1 and (none.n_components == 0).all()
        assert none.rubber.families() == []
        if layout == "family":
            assert none.component.values.tolist() == [255] and none.component.attrs["flag_meanings"] == "no_value"
    capsys.readouterr()


def test_an_atlas_slice_per_family_and_its_figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ds = ra.cells(*BODY, KAPPA, ENERGY)
    atlas = ds.drop_vars(["alpha", "beta"]).expand_dims(alpha=[0.5], beta=[3.0])
    f = atlas.rubber.family("well_pi")
    assert f.rotation_number.dims == ("alpha", "beta", "kappa", "energy")
    fig = atlas.rubber.plot_slice()
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == ["well_0: N", "well_pi: N", "log10 R (largest)"]
    for ax, name in zip(panels, ds.rubber.families()):
        mesh = ax.collections[0]
        low, high = mesh.get_clim()
        n = ds.rubber.family(name).rotation_number
        # Centred on 0, over the whole range of N, each side over its own range.
        assert mesh.norm.vcenter == 0
        assert low == pytest.approx(min(float(n.min()), -1e-6 * float(np.abs(n).max())))
        assert high == pytest.approx(max(float(n.max()), 1e-6 * float(np.abs(n).max())))
        assert mesh.get_cmap().name == "RdBu_r"
        assert ax.get_xlabel() == "κ" and ax.get_ylabel() == "ε"
        assert len(ax.collections) >= 2  # the contours N = p/q
    plt.close(fig)


def test_plot_slice_draws_the_other_planes_and_older_datasets():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    compact = ra.cells(*BODY, lambda_=np.linspace(0.05, 1.4, 8), s=np.linspace(0.1, 0.8, 6))
    fig = compact.rubber.plot_slice()
    assert fig.axes[0].get_xlabel().startswith("λ") and fig.axes[0].get_ylabel().startswith("s")
    plt.close(fig)
    old = ra.cells(*BODY, KAPPA, ENERGY, layout="theta_min").drop_vars("family")
    fig = old.rubber.plot_slice()
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles == ["component 0: N", "component 1: N", "log10 R (largest)"]
    plt.close(fig)
    with pytest.raises(ValueError, match="two dimensions"):
        ra.cells(*BODY, lambda_=[0.1, 0.2], s=0.5).rubber.plot_slice()


# The verdict's counterexamples.

def test_the_verdict_gives_its_case_as_text_and_counterexamples_as_data(tmp_path):
    bodies = xr.DataArray([0.5, 0.2, 0.0], dims="body"), xr.DataArray([0.5, 3.0, 3.0], dims="body")
    v = ra.verdict(*bodies, 0.5, 0.5, resolution=8)
    found = [json.loads(x.item()) for x in v.verdict_json]
    assert [c.decode() for c in v.case.values] == [f["case"] for f in found] == ["1", "2", "not_covered"]
    assert v.kappa.dims == ("body", "counterexample")
    assert v.sizes["counterexample"] == max(len(f["counterexamples"]) for f in found)
    for i, f in enumerate(found):
        assert int(v.counterexamples[i]) == len(f["counterexamples"])
        for j in range(v.sizes["counterexample"]):
            row = v.isel(body=i, counterexample=j)
            if j < len(f["counterexamples"]):
                c = f["counterexamples"][j]
                for key in ("kappa", "energy", "rotation_number", "theta_min", "theta_max", "drift"):
                    assert float(row[key]) == c[key], (i, j, key)
                assert row.family.item().decode() == c.get("family", "")
                assert int(row.component) == c.get("component", -1)
            else:
                assert np.isnan([float(row[k]) for k in ("kappa", "energy", "theta_min", "drift")]).all()
                assert row.family.item() == b"" and int(row.component) == -1
    assert found[0]["counterexamples"] and v.kappa.attrs["units"] == "1" and v.theta_min.attrs["units"] == "rad"
    path = tmp_path / "v.nc"
    v.to_netcdf(path, engine="h5netcdf")
    with xr.open_dataset(path, engine="h5netcdf") as back:
        assert [c.decode() for c in back.case.values] == ["1", "2", "not_covered"]
        np.testing.assert_array_equal(back.component, v.component)


def test_counterexamples_carry_their_family():
    """Needs the core's `family` and `component` in each counterexample of the verdict."""
    v = ra.verdict(0.5, 0.5, 0.5, 0.5, resolution=8)
    found = json.loads(v.verdict_json.item())
    assert found["counterexamples"]
    for j, c in enumerate(found["counterexamples"]):
        assert c["family"] in ("well_0", "well_pi", "well_equator", "over_the_top")
        assert v.family[j].item().decode() == c["family"] and int(v.component[j]) == c["component"] >= 0


# The trajectory figure.

def test_a_drifting_path_is_not_drawn_flat(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from plot_trajectory import figure
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    v = ra.verdict(0.5, 0.5, 0.5, 0.5, resolution=8)
    drifting = ra.trajectory(0.5, 0.5, 0.5, 0.5, kappa=float(v.kappa[0]), energy=float(v.energy[0]),
                             periods=20, samples=2000)
    bounded = ra.trajectory(*BODY, kappa=0.8, energy=2.5, periods=14, samples=2000)
    for name, t, equal in (("drifting", drifting, False), ("bounded", bounded, True)):
        path = tmp_path / f"{name}.h5"
        t.to_netcdf(path, engine="h5netcdf")
        fig = figure(path)
        fig.canvas.draw()
        ax = fig.axes[0]
        assert (ax.get_aspect() == 1.0) is equal, name
        assert ("not to scale" in ax.get_title()) is not equal, name
        # The path fills the axes both ways: neither extent shrinks to a line.
        box = ax.get_window_extent()
        lines = [line.get_window_extent() for line in ax.get_lines()]
        assert max(b.height for b in lines) > 0.5 * box.height and max(b.width for b in lines) > 0.5 * box.width
        # The legend is outside the axes.
        legend = ax.get_legend().get_window_extent()
        assert legend.y0 >= box.y1, name
        plt.close(fig)
