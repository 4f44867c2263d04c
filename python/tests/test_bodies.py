"""`cells(shape=…)` for the disk, the truncated ball and the wheel (docs/bodies.md): the values
of `rubber-atlas cell --shape …` bit for bit, the coordinates named after the shape's
parameters, and the parameters a shape does not take refused in one line."""
from __future__ import annotations

import json

import numpy as np
import pytest

import rubber_atlas as ra
from conftest import assert_component_equals, run, same_double

KEYS = ["theta_min", "theta_max", "period", "omega_theta", "omega_psi", "rotation_number", "drift",
        "drift_radius", "error_estimate"]


# A body of your own (docs/bodies.md): an egg with a sharp rim round its top (atlas/egg.toml).
EGG = [[0.0, -1.0], [0.45, -0.92], [0.8, -0.62], [0.98, -0.2], [0.97, 0.25], [0.8, 0.62, 1], [0.4, 0.8],
       [0.0, 0.86]]


@pytest.mark.parametrize("shape", ["disk", "truncated_ball", "wheel", "profile"])
def test_cells_of_each_shape_equal_the_cell_command_bit_for_bit(shape, tmp_path):
    rng = np.random.default_rng(20261124)
    n = 12
    alpha = rng.uniform(-0.8, 0.8, n)
    cut = rng.uniform(0.05, 0.95, n) if shape in ("truncated_ball", "wheel") else None
    # The egg's table, rows (ρ, z, edge) of one length, and as a file for the command.
    profile = np.array([r + [0.0] * (3 - len(r)) for r in EGG]) if shape == "profile" else None
    if profile is not None:
        table = tmp_path / "egg.txt"
        table.write_text("\n".join(" ".join(repr(float(x)) for x in row) for row in profile) + "\n")
    nu = rng.uniform(0.2, 2.0, n)
    eta = rng.uniform(0.3, 4.0, n)
    kappa = rng.uniform(0.05, 2.0, n)
    energy = rng.uniform(0.5, 5.0, n)
    ds = ra.cells(alpha, None, nu, eta, kappa, energy, shape=shape, cut=cut, profile=profile, layout="theta_min")
    assert "beta" not in ds.coords
    assert ("cut" in ds.coords) == (cut is not None)
    with_motion = 0
    for i in range(n):
        args = ["cell", "--shape", shape, "--alpha", repr(float(alpha[i])), "--nu", repr(float(nu[i])),
                "--eta", repr(float(eta[i])), "--kappa", repr(float(kappa[i])), "--energy", repr(float(energy[i])),
                "--json"]
        if cut is not None:
            args += ["--cut", repr(float(cut[i]))]
        if profile is not None:
            args += ["--profile", table]
        out = json.loads(run(*args))
        assert out["shape"] == shape
        expected = out["components"]
        cell = ds.isel(cell=i)
        assert int(cell.n_components) == len(expected), i
        with_motion += bool(expected)
        for slot, e in enumerate(expected):
            assert_component_equals(cell.isel(component=slot), e, KEYS, i)
    assert with_motion >= n // 2


def test_the_excess_energy_plane_of_the_symmetric_disk():
    """Its bottom found by the core for the disk's own V: the torus round the equator
    (κ ≥ 1, one well) has N = 0 to rounding."""
    ds = ra.cells(0.0, None, 2.0, 4.0, kappa=[1.0, 2.0, 3.0], excess_energy=[0.1, 1.0], shape="disk",
                  fields=["rotation_number", "theta_min", "theta_max"])
    assert set(ds.energy.dims) == {"kappa", "excess_energy"}
    n = ds.rotation_number.values
    assert np.nanmax(np.abs(n)) < 1e-14
    spans = ds.theta_min + ds.theta_max
    assert float(abs(spans - np.pi).max()) < 1e-12


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(shape="disk", cut=0.3), ValueError, "takes no cut"),
    (dict(shape="wheel"), TypeError, "needs cut"),
    (dict(shape="wheel", cut=1.5), ValueError, "invalid cut = 1.5"),
    (dict(shape="truncated_ball", cut=[0.2, -1.0]), ValueError, "cut[1]"),
    (dict(shape="cube", cut=0.2), ValueError, "shape 'cube'"),
    (dict(shape=None, cut=0.2), TypeError, "shape must be"),
    (dict(shape="wheel", cut=0.5, method="ode"), ValueError, "method ode"),
])
def test_what_a_shape_does_not_take_is_refused(kwargs, error, words):
    with pytest.raises(error) as caught:
        ra.cells(0.25, None, 0.7, 1.3, kappa=0.5, energy=[2.0, 2.5], **kwargs)
    assert words in str(caught.value) and "\n" not in str(caught.value)
    with pytest.raises(ValueError, match="takes no beta"):
        ra.cells(0.25, 2.0, 0.7, 1.3, kappa=0.5, energy=2.0, shape="wheel", cut=0.5)
    with pytest.raises(ValueError, match="not of the ellipsoid"):
        ra.cells(0.25, 2.0, 0.7, 1.3, kappa=0.5, energy=2.0, cut=0.5)


def test_a_cut_along_a_dimension_named_beta_is_refused():
    import xarray as xr
    with pytest.raises(ValueError, match="dimension 'beta'"):
        ra.cells(0.5, None, 0.5, 0.5, kappa=0.8, energy=2.5, shape="wheel",
                 cut=xr.DataArray([0.3, 0.5], dims="beta"))
    ds = ra.cells(0.5, None, 0.5, 0.5, kappa=0.8, energy=2.5, shape="wheel", cut=xr.DataArray([0.3, 0.5], dims="cut"))
    assert ds.rotation_number.dims[0] == "cut"


def test_trajectory_and_diagram_of_an_edged_body_equal_the_commands(tmp_path):
    """`trajectory(shape=…)` gives the table of `rubber-atlas trajectory --shape …` (the same
    values, to the CSV's 17 digits), and `diagram(shape=…)` the JSON of `diagram --json`."""
    t = ra.trajectory(0.25, None, 0.7, 1.3, 0.5, theta0=0.4, periods=1, samples=40, shape="wheel", cut=0.7)
    assert t.attrs["shape"] == "wheel" and t.attrs["cut"] == 0.7 and "beta" not in t.attrs
    out = tmp_path / "w.csv"
    run("trajectory", "--shape", "wheel", "--alpha", "0.25", "--cut", "0.7", "--nu", "0.7", "--eta", "1.3",
        "--kappa", "0.5", "--theta0", "0.4", "--periods", "1", "--samples", "40", "--out", out)
    table = ra.read_table(out)
    np.testing.assert_array_equal(t.theta.values, table.theta.values)
    np.testing.assert_array_equal(t.x_c.values, table.x_c.values)
    d = ra.diagram(0.2, None, shape="truncated_ball", cut=0.4, samples=300)
    assert json.loads(d.attrs["critical_set_json"]) == json.loads(
        run("diagram", "--shape", "truncated_ball", "--alpha", "0.2", "--cut", "0.4", "--samples", "300", "--json"))


def test_a_planar_trajectory_onto_a_face_is_refused():
    with pytest.raises(ValueError, match="reaches a flat face"):
        ra.trajectory(0.2, None, 0.7, 1.3, 0.0, energy=0.7, periods=1, shape="truncated_ball", cut=0.4)
    with pytest.raises(ValueError, match="takes no beta"):
        ra.diagram(0.2, 3.0, shape="disk")


def test_resonance_of_an_edged_body_equals_the_command(tmp_path):
    """`resonance(shape=…)` gives the curves of `rubber-atlas resonance --shape …`, named after
    the shape's parameters; what a shape does not take is refused."""
    curves = ra.resonance(0.1, None, 1.0, 2.0, "1/4", shape="wheel", cut=0.5, grid=24, kappa_max=3.0,
                          energy_max=8.0)
    assert curves.attrs["shape"] == "wheel" and curves.attrs["cut"] == 0.5 and "beta" not in curves.attrs
    out = tmp_path / "w.csv"
    run("resonance", "--shape", "wheel", "--alpha", "0.1", "--cut", "0.5", "--nu", "1", "--eta", "2",
        "--rotation-number", "1/4", "--grid", "24", "--kappa-max", "3", "--energy-max", "8", "--out", out)
    table = ra.read_table(out)
    assert table.attrs["shape"] == "wheel" and curves.sizes["sample"] > 10
    for name in ("kappa", "energy", "rotation_number", "theta_min"):
        np.testing.assert_array_equal(curves[name].values, table[name].values)
    # Each point is on N = P/Q to within its estimate (and the tolerance).
    assert (abs(curves.rotation_number - 0.25) <= curves.error_estimate + 1e-10).all()
    with pytest.raises(ValueError, match="takes no beta"):
        ra.resonance(0.1, 3.0, 1.0, 2.0, 0, shape="disk")
    with pytest.raises(TypeError, match="needs cut"):
        ra.resonance(0.1, None, 1.0, 2.0, 0, shape="truncated_ball")


@pytest.mark.parametrize("shape", ["disk", "wheel"])
def test_an_atlas_of_an_edged_body_opens_with_its_own_dimensions_and_equals_cells(shape, tmp_path):
    """`rubber-atlas run` on a scene with `[body] shape`: dimensions named after the shape's
    parameters, values equal to `cells(shape=…)` bit for bit, and the accessor takes them."""
    import matplotlib
    matplotlib.use("Agg")
    second = "cut = [0.3, 0.6]\n" if shape == "wheel" else ""
    scene = tmp_path / "s.toml"
    scene.write_text(f'name = "s"\n[body]\nshape = "{shape}"\nnu = 0.5\neta = 2.0\n[axes]\nalpha = [-0.3, 0.1]\n'
                     f"{second}kappa = {{ start = 0.0, stop = 1.5, num = 7 }}\n"
                     "energy = { start = 0.5, stop = 3.0, num = 9 }\n")
    run("run", scene, "--out", tmp_path / "s.h5", "--quiet")
    with ra.open_atlas(tmp_path / "s.h5", check=True) as atlas:
        body_dims = ["alpha", "cut"] if shape == "wheel" else ["alpha"]
        assert list(atlas.cell_status.dims) == [*body_dims, "kappa", "energy"]
        assert atlas.attrs["shape"] == shape
        cut = atlas.cut if shape == "wheel" else None
        grid = ra.cells(atlas.alpha, None, 0.5, 2.0, atlas.kappa, atlas.energy, shape=shape, cut=cut)
        for name in ("rotation_number", "period", "drift_radius", "theta_min"):
            a = atlas[name].transpose(*grid[name].dims).values
            b = grid[name].values
            assert a.shape == b.shape
            assert np.array_equal(a, b, equal_nan=True), name
        body = {"alpha": 0.1, **({"cut": 0.6} if shape == "wheel" else {})}
        found = atlas.rubber.components(**body, kappa=float(atlas.kappa[3]), energy=float(atlas.energy[8]))
        assert found and all(np.isfinite(c["rotation_number"]) for c in found)
        with pytest.raises(KeyError, match="give the cell by"):
            atlas.rubber.components(alpha=0.1, beta=3.0, kappa=float(atlas.kappa[3]), energy=float(atlas.energy[8]))
        top = 1 if shape == "wheel" else 0
        fig = atlas.rubber.plot_slice(alpha_index=1, cut_index=top)
        assert shape in fig._suptitle.get_text()
        with pytest.raises(ValueError, match=f"cut_index = {top + 1}"):
            atlas.rubber.plot_slice(cut_index=top + 1)
        # A dimension the atlas lacks is named as missing, not as having one value.
        with pytest.raises(ValueError, match="beta_index = 1: the dataset has no dimension beta"):
            atlas.rubber.plot_slice(beta_index=1)


def test_diagram_trajectory_and_resonance_take_a_profile():
    body = dict(alpha=-0.1, beta=None, nu=0.8, eta=1.7, shape="profile", profile=EGG)
    d = ra.diagram(**body, samples=300)
    summary = json.loads(d.attrs["critical_set_json"])
    assert summary["shape"] == "profile" and d.attrs["shape"] == "profile"
    assert [e["name"] for e in summary["equilibria"]] == ["sigma_0", "inclined", "sigma_pi"]
    # The full model runs one θ-period back to its start's θ.
    cell = ra.cells(**body, kappa=0.5, energy=1.2, fields=["period", "theta_min"])
    period = float(cell.period.isel(component=0))
    t = ra.trajectory(**body, kappa=0.5, energy=1.2, t_end=period, model="full", samples=400)
    assert abs(float(t.theta[-1]) - float(t.theta[0])) < 1e-6
    assert abs(float(t.theta[0]) - float(cell.theta_min.isel(component=0))) < 1e-9
    r = ra.resonance(**body, rotation_number=0, grid=24)
    assert r.sizes["sample"] > 10 and r.attrs["shape"] == "profile"
    assert bool((abs(r.rotation_number) <= r.error_estimate + 1e-10).all())


@pytest.mark.parametrize("call, error, words", [
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile"), TypeError, "needs profile="),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="disk", profile=EGG), ValueError, "takes no profile"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile="0 -1\n1 0\n0 1"), TypeError, "rows"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[[0, -1], [1, 0, 0, 1], [0, 1]]),
     ValueError, "row 1 has 4 values"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[0, -1, 1, 0, 0, 1]), ValueError,
     "(n, 2) or (n, 3)"),
    # Found by an adversary: True taken as 1, masked points used, a short row named by its shape.
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[[0, -1], [True, -0.5], [1, 0], [0, 1]]),
     TypeError, "not True or False"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile",
                      profile=np.ma.masked_array([[0, -1], [1, 0], [0, 1]], mask=[[0, 0], [0, 1], [0, 0]])),
     ValueError, "masked"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[[0, -1], [1, np.ma.masked], [0, 1]]),
     ValueError, "profile[1, 1] is masked"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[[0, -1], [0.8], [1, 0, 1], [0, 1]]),
     ValueError, "row 1 has 1 value;"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=[[0, -1], [0.8, -0.5], [0.9, 0, 1],
                                                                        [1.0, 0.3], [0, 1]]),
     ValueError, "not convex"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile",
                      profile=[[0, -1], [1, -0.5], [0.5, 0], [1, 0.5], [0, 1]]), ValueError, "not convex"),
    (lambda: ra.cells(0.0, 1.0, 1, 1, 0.5, 1.5, shape="profile", profile=EGG), ValueError, "no beta"),
    (lambda: ra.cells(0.9, None, 1, 1, 0.5, 1.5, shape="profile", profile=EGG), ValueError, "between the profile's poles"),
    (lambda: ra.diagram(0.0, None, shape="profile", profile=[[0, -1], [1, -1], [1, 1], [0, 1]]), ValueError,
     "straight side"),
    (lambda: ra.cells(0.0, None, 1, 1, 0.5, 1.5, shape="profile", profile=EGG, method="ode"), ValueError, "ode"),
])
def test_a_profile_is_refused_where_it_does_not_fit(call, error, words):
    with pytest.raises(error) as e:
        call()
    assert words in str(e.value) and "\n" not in str(e.value), str(e.value)


# A barrel with faces, symmetric about its equator: at kappa = 0 its four wells on the circle
# (the faces' and the equator's mirror images) are four components.
BARREL = [[0.0, -1.0], [0.8, -1.0, 1], [0.97, -0.5], [1.0, 0.0], [0.97, 0.5], [0.8, 1.0, 1], [0.0, 1.0]]


def test_cells_in_theta_min_order_have_room_for_every_component_of_a_profile(tmp_path):
    # (The room was the ellipsoid's three slots: the barrel's kappa = 0 cells came out failed in
    # Python only, while `run` sized its axis from the census: an adversary pass.)
    table = tmp_path / "barrel.txt"
    table.write_text("\n".join(" ".join(repr(float(x)) for x in r) for r in BARREL) + "\n")
    kappa, energy = np.array([0.0, 0.0, 0.05]), np.array([1.1, 1.2, 1.2])
    ds = ra.cells(0.0, None, 0.9, 2.0, kappa, energy, shape="profile", profile=BARREL, layout="theta_min",
                  threads=1)
    assert ds.sizes["component"] == 4
    for i in range(len(kappa)):
        out = json.loads(run("cell", "--shape", "profile", "--profile", table, "--alpha", "0", "--nu", "0.9",
                             "--eta", "2", "--kappa", repr(float(kappa[i])), "--energy", repr(float(energy[i])),
                             "--json"))
        cell = ds.isel(cell=i)
        assert int(cell.cell_status) == 0, cell.cell_status  # ok
        assert int(cell.n_components) == len(out["components"]) == (4 if kappa[i] == 0 else 3)
        for slot, e in enumerate(out["components"]):
            assert_component_equals(cell.isel(component=slot), e, KEYS, i)


def test_two_wells_on_one_side_are_two_families(tmp_path):
    # The egg at alpha = 0.1, kappa = 0.25: a shallow well (near the rim, theta ~ 2.1) opens at
    # energy ~ 1.0 beside the main well (theta ~ 2.5), both beyond pi/2. The family layout kept
    # one torus and marked the cell failed (an adversary pass); now the main well's torus stays
    # well_pi, and N of well_pi goes on continuously through the level where the second opens.
    energy = np.array([0.99, 0.995, 0.9985, 1.0, 1.001])
    common = dict(nu=0.8, eta=1.7, kappa=0.25, energy=energy, shape="profile", profile=EGG, threads=1)
    by_family = ra.cells(0.1, None, **common)
    by_theta = ra.cells(0.1, None, layout="theta_min", **common)
    assert (by_family.cell_status.values == 0).all(), by_family.cell_status.values
    assert list(by_family.component.values) == [1, 5]
    assert by_family.rubber.families() == ["well_pi", "well_pi_second"]
    two = int(np.argmax(by_theta.n_components.values == 2))
    assert two == 3 and (by_theta.n_components.values[:3] == 1).all()
    # The main well's torus is the one farther from the equator (larger theta_min) there.
    cell_f, cell_t = by_family.isel(cell=two), by_theta.isel(cell=two)
    main, shallow = cell_f.sel(component=1), cell_f.sel(component=5)
    assert float(main.theta_min) == float(cell_t.isel(component=1).theta_min) > float(shallow.theta_min)
    for slot_f, slot_t in [(1, 1), (5, 0)]:
        for key in KEYS:
            assert same_double(cell_f.sel(component=slot_f)[key], cell_t.isel(component=slot_t)[key]), key
    # Continuity: N of well_pi moves by less than it does over the three cells before.
    n = by_family.sel(component=1).rotation_number.values
    steps = np.abs(np.diff(n[:4]))
    assert steps[-1] < 3 * steps[:-1].max(), n
    table = tmp_path / "egg.txt"
    table.write_text("\n".join(" ".join(repr(float(x)) for x in r + [0.0] * (3 - len(r))) for r in EGG) + "\n")
    out = json.loads(run("cell", "--shape", "profile", "--profile", table, "--alpha", "0.1", "--nu", "0.8",
                         "--eta", "1.7", "--kappa", "0.25", "--energy", repr(float(energy[two])), "--json"))
    assert [c["family"] for c in out["components"]] == ["well_pi_second", "well_pi"]


def test_a_profile_is_recorded_from_its_lower_pole_whichever_way_it_is_given():
    """As the command's files and JSON hold it (files.md): the Python result held it top first."""
    down = ra.cells(-0.1, None, 0.8, 1.7, kappa=0.5, energy=1.5, shape="profile", profile=EGG[::-1],
                    fields=["rotation_number"])
    up = ra.cells(-0.1, None, 0.8, 1.7, kappa=0.5, energy=1.5, shape="profile", profile=EGG,
                  fields=["rotation_number"])
    assert down.attrs["profile"] == up.attrs["profile"] and down.attrs["profile"].startswith("0.0 -1.0 0")
    assert float(down.rotation_number[0]) == float(up.rotation_number[0])


@pytest.mark.parametrize("shape", ["disk", "truncated_ball", "profile"])
def test_census_equals_verdict_of_the_shape(shape, tmp_path):
    """`census` is `verdict --shape … --json` as a dict, equal to the command's."""
    cut = 0.4 if shape == "truncated_ball" else None
    alpha = -0.1 if shape == "profile" else 0.3
    profile = EGG if shape == "profile" else None
    got = ra.census(alpha, 0.7, 1.3, shape=shape, cut=cut, profile=profile, resolution=16)
    args = ["verdict", "--shape", shape, "--alpha", alpha, "--nu", "0.7", "--eta", "1.3", "--resolution", "16",
            "--json"]
    if cut is not None:
        args += ["--cut", cut]
    if profile is not None:
        table = tmp_path / "egg.txt"
        table.write_text("".join(" ".join(str(x) for x in row) + "\n" for row in profile))
        args += ["--profile", str(table)]
    assert got == json.loads(run(*args))
    assert got["shape"] == shape and 0 in got["integers"] and got["unbounded_motion"] is True


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(shape="ellipsoid"), ValueError, "use verdict"),
    (dict(shape="wheel"), TypeError, "needs cut"),
    (dict(shape="disk", resolution=4), ValueError, "resolution"),
    (dict(shape="disk", tol=1.0), ValueError, "tol"),
    (dict(shape="disk", resolution=16.5), TypeError, "resolution"),
])
def test_census_refuses_what_it_does_not_take(kwargs, error, words):
    with pytest.raises(error, match=words):
        ra.census(0.3, 0.7, 1.3, **kwargs)
