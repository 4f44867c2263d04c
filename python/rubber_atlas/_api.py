"""The package's functions: the Rust core's results shaped into xarray objects with the
names, units and flags of the files `rubber-atlas` writes."""

from __future__ import annotations

import json
import sys
from fractions import Fraction
from pathlib import Path
from typing import Iterable

import numpy as np
import xarray as xr

from . import _core

FIELDS: tuple[str, ...] = tuple(_core.FIELDS)
"""The fields a scene (and `cells`) may ask for, in file order."""

_INPUTS = ("alpha", "beta", "nu", "eta", "kappa", "energy")


def _call(name: str, arguments: dict) -> str:
    """`name(arguments)` as text, for the `history` attribute."""
    shown = ", ".join(
        f"{k}={v!r}" if np.ndim(v) == 0 else f"{k}=<{np.shape(v)} array>"
        for k, v in arguments.items()
    )
    return f"python {sys.version.split()[0]}: rubber_atlas.{name}({shown})"


def _root_attrs(name: str, arguments: dict, **own) -> dict:
    """Provenance (Conventions, program, version, commit, history) and `own`."""
    attrs = dict(_core.provenance(_call(name, arguments)))
    attrs.update(own)
    return attrs


def _variable_attrs(meta: dict) -> dict:
    attrs = {"long_name": meta["long_name"], "units": meta["units"]}
    if meta.get("comment"):
        attrs["comment"] = meta["comment"]
    if "flag_values" in meta:
        attrs["flag_values"] = np.asarray(list(meta["flag_values"]), dtype=np.uint8)
        attrs["flag_meanings"] = meta["flag_meanings"]
    return attrs


def _coordinate_attrs(name: str) -> dict:
    long_name, units, comment = _core.coordinate(name)
    attrs = {"long_name": long_name, "units": units}
    if comment:
        attrs["comment"] = comment
    return attrs


def _check_input(name: str, value) -> None:
    """Refuses inputs that would be read as something the user did not give."""
    if value is None:
        raise TypeError(f"{name} is None: give a number or an array of numbers")
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        raise ValueError(f"{name} has masked values: give only the cells to compute")
    dtype = value.dtype if isinstance(value, (np.ndarray, xr.DataArray)) else np.asarray(value).dtype
    if np.issubdtype(dtype, np.complexfloating):
        raise TypeError(f"{name} is complex: give real numbers")


def _broadcast(given: dict[str, object]) -> tuple[tuple[str, ...], list[np.ndarray], dict]:
    """Broadcasts the inputs together: DataArrays by their dimension names (xarray's rules),
    anything else by numpy's (dimensions `cell`, or `cell_0`, `cell_1`, … for several).
    Returns the dimensions, the arrays in that layout, and the coordinates of the result:
    each input over the dimensions it varies along (scalar where it is one number)."""
    for name, v in given.items():
        _check_input(name, v)
    if any(isinstance(v, xr.DataArray) for v in given.values()):
        arrays = {}
        for name, v in given.items():
            if isinstance(v, xr.DataArray):
                arrays[name] = v.astype(np.float64)
            elif np.ndim(v) == 0:
                arrays[name] = xr.DataArray(np.float64(v))
            else:
                raise TypeError(
                    f"{name}: give every array input as an xarray.DataArray (with named "
                    "dimensions) when any is one, or none as one"
                )
        try:
            aligned = xr.align(*arrays.values(), join="exact")
        except ValueError as e:
            raise ValueError(f"the DataArray inputs' coordinates do not line up: {e}") from None
        broadcast = xr.broadcast(*aligned)
        dims = broadcast[0].dims
        for name in given:
            # A dimension named after an input is that input's axis, or a mistake.
            if name in dims and arrays[name].dims != (name,):
                raise ValueError(f"the dimension {name!r} is named after the input {name}, which is not given "
                                 f"along it: rename the dimension, or give {name} as a DataArray along {name!r}")
        layout = [b.transpose(*dims).values for b in broadcast]
        coords = {}
        for name, source in arrays.items():
            if name in dims and name in source.coords and not np.array_equal(
                    np.asarray(source.coords[name].values, dtype=np.float64), source.values):
                # The values computed at would differ from the labels shown.
                raise ValueError(f"{name}: the DataArray's {name!r} coordinate differs from its values; "
                                 "give the values as the coordinate, or none")
            coords[name] = (source.dims, source.values) if source.ndim else ((), source.values)
        for b in broadcast:
            for cname, c in b.coords.items():
                coords.setdefault(cname, c)
        return dims, layout, coords
    values = {k: np.asarray(v, dtype=np.float64) for k, v in given.items()}
    layout = np.broadcast_arrays(*values.values())
    shape = layout[0].shape
    dims = ("cell",) if len(shape) == 1 else tuple(f"cell_{i}" for i in range(len(shape)))
    coords = {}
    for (name, v), full in zip(values.items(), layout):
        coords[name] = ((), v) if v.ndim == 0 else (dims, np.array(full))
    return dims, list(layout), coords


def cells(
    alpha,
    beta,
    nu,
    eta,
    kappa,
    energy,
    *,
    tol: float = 1e-10,
    method: str = "quadrature",
    fields: Iterable[str] | None = None,
    resonance_tol: float = 1e-9,
    threads: int | None = None,
    allow_large: bool = False,
) -> xr.Dataset:
    """Solves cells (α, β, ν, η, κ, ε) given as numbers, numpy arrays or xarray DataArrays,
    broadcast together, in parallel in Rust with the GIL released (`threads` threads; by
    default rayon's, which honours RAYON_NUM_THREADS).

    Returns the variables an atlas file holds for `fields` (default: all of `FIELDS`) and
    `rubber-atlas cell` prints, bit for bit: `n_components` and `cell_status` per cell, and
    per cell and `component` the fields and their `<field>_error`, NaN (floats) or 255
    (flags, `no_value`) where a component does not exist. The inputs are coordinates.
    Bad input raises ValueError naming the cell and the value; a request larger than 80 % of
    the memory available is refused unless `allow_large`. Ctrl-C stops it within
    milliseconds (KeyboardInterrupt)."""
    given = {"alpha": alpha, "beta": beta, "nu": nu, "eta": eta, "kappa": kappa, "energy": energy}
    if isinstance(fields, str):
        fields = [fields]
    field_list = None if fields is None else [str(f) for f in fields]
    dims, layout, coords = _broadcast(given)
    shape = layout[0].shape
    flat = [np.ascontiguousarray(a, dtype=np.float64).reshape(-1) for a in layout]
    slots = _core.COMPONENT_SLOTS
    computed = _core.cells(*flat, float(tol), str(method), float(resonance_tol), field_list, threads,
                           bool(allow_large))
    meta = {m["name"]: m for m in _core.variables(field_list)}
    data_vars = {}
    for name, values in computed:
        m = meta[name]
        if m["per_component"]:
            data_vars[name] = (dims + ("component",), values.reshape(shape + (slots,)), _variable_attrs(m))
        else:
            data_vars[name] = (dims, values.reshape(shape), _variable_attrs(m))
    for name in _INPUTS:
        if isinstance(coords.get(name), tuple):
            cdims, cvalues = coords[name]
            coords[name] = xr.Variable(cdims, cvalues, _coordinate_attrs(name), {"_FillValue": None})
    coords["component"] = xr.Variable(
        "component", np.arange(slots, dtype=np.int32), _coordinate_attrs("component"), {"_FillValue": None}
    )
    arguments = dict(given, tol=tol, method=method, fields=field_list, resonance_tol=resonance_tol)
    attrs = _root_attrs(
        "cells",
        arguments,
        title="rubber-atlas cells",
        tolerance=float(tol),
        method=str(method),
        resonance_tol=float(resonance_tol),
    )
    ds = xr.Dataset(data_vars, coords, attrs)
    for name in _INPUTS:
        # Dimension coordinates that came with DataArray inputs get the files' attributes.
        if name in ds.dims:
            ds[name].attrs = _coordinate_attrs(name)
            ds[name].encoding["_FillValue"] = None
    return ds


def open_atlas(path: str | Path, **kwargs) -> xr.Dataset:
    """The atlas at `path` (`rubber-atlas run` or `merge`; a shard too) as an xarray Dataset:
    dimensions alpha, beta, kappa, energy (or the scene's plane) and component; ν and η as
    scalar coordinates; flags as uint8 with CF `flag_values`/`flag_meanings`. Engine
    h5netcdf unless `engine=` says otherwise; other keywords go to `xarray.open_dataset`.
    Refuses files that are not complete rubber-atlas atlases."""
    path = Path(path)
    if path.name.endswith(".partial.h5"):
        raise ValueError(f"{path}: an unfinished run's file; resume the run with --resume")
    kwargs.setdefault("engine", "h5netcdf")
    try:
        ds = xr.open_dataset(path, **kwargs)
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: not a rubber-atlas atlas: {e}") from None
    if ds.attrs.get("program") != "rubber-atlas" or "scene" not in ds.attrs or "cell_status" not in ds:
        ds.close()
        raise ValueError(f"{path}: not a rubber-atlas atlas (a file of `rubber-atlas run` or `merge` has the "
                         "attributes program and scene and the variable cell_status)")
    return ds


def flag_names(variable: xr.DataArray) -> dict[int, str]:
    """The CF flag meanings of a flag variable, as {value: name}."""
    if "flag_values" not in variable.attrs:
        raise ValueError(f"{variable.name} is not a flag variable (it has no flag_values)")
    values = np.atleast_1d(variable.attrs["flag_values"])
    names = variable.attrs["flag_meanings"].split()
    return {int(v): n for v, n in zip(values, names)}


def components(ds: xr.Dataset, alpha: float | None = None, beta: float | None = None, **cell: float) -> list[dict]:
    """The components of one cell of an atlas (or of a `cells` result) as dicts, keys as in
    `rubber-atlas cell --json`, status and motion as names, sorted by theta_min.

    The cell is given by grid values (to 1e-12 relative) of the dataset's dimensions: for an
    atlas `alpha=…, beta=…` and `kappa=…, energy=…` (or the file's own plane:
    `excess_energy=…`, or `lambda_=…, s=…`; `lambda_` since `lambda` is a Python keyword);
    for a `cells` result, the index along its dimensions (`cell=3`)."""
    cell = {("lambda" if k == "lambda_" else k): v for k, v in cell.items()}
    if alpha is not None:
        cell["alpha"] = alpha
    if beta is not None:
        cell["beta"] = beta
    dims = [d for d in ds.cell_status.dims]
    if sorted(cell) != sorted(dims):
        raise KeyError(f"give the cell by {', '.join(dims)} (this dataset's dimensions), not {', '.join(cell) or 'nothing'}")
    index = {}
    for name, value in cell.items():
        if name not in ds.coords:
            size = ds.sizes[name]
            if not float(value).is_integer() or not 0 <= int(value) < size:
                raise KeyError(f"{name} = {value} is not an index of the dimension {name} (0 … {size - 1})")
            index[name] = int(value)
            continue
        axis = ds[name].values
        i = int(np.argmin(np.abs(axis - value)))
        if abs(axis[i] - value) > 1e-12 * max(1.0, abs(value)):
            raise KeyError(f"{name} = {value} is not a grid value (nearest {axis[i]})")
        index[name] = i
    one = ds.isel(index)
    count = int(one.n_components)
    flags = {name: flag_names(ds[name]) for name in ("status", "motion") if name in ds}
    out = []
    for slot in range(min(count, ds.sizes["component"])):
        c = one.isel(component=slot)
        entry = {}
        for name, var in c.data_vars.items():
            if "component" not in ds[name].dims:
                continue
            value = var.values.item()
            if name in flags:
                value = flags[name].get(int(value), "unknown")
            elif name == "bounded":
                value = None if int(value) == 255 else bool(value)
            entry[name] = value
        out.append(entry)
    return out


def _table(table: dict, attrs: dict) -> xr.Dataset:
    """A table of the core (columns along one dimension) as a Dataset: the dimension's column
    is its coordinate, every other column a variable; CF attributes as in the files."""
    dim = table["dimension"]
    coords, data_vars = {}, {}
    for c in table["columns"]:
        if c["name"] == dim:
            # A coordinate has no _FillValue (CF 5): none when xarray writes it.
            coords[dim] = xr.Variable(dim, c["values"], _variable_attrs(c), {"_FillValue": None})
        else:
            data_vars[c["name"]] = xr.Variable(dim, c["values"], _variable_attrs(c))
    return xr.Dataset(data_vars, coords, {**attrs, **table["attributes"]})


def read_table(path: str | Path) -> xr.Dataset:
    """A table file of `rubber-atlas trajectory`, `diagram --out` or `resonance --out`, as a
    Dataset along its dimension (`t` or `sample`): HDF5 through h5netcdf with every
    attribute, CSV through pandas with the `# key: value` lines as attributes (numbers
    parsed)."""
    path = Path(path)
    if path.suffix.lower() == ".csv":
        import pandas as pd

        attrs: dict = {}
        with path.open() as f:
            for line in f:
                if not line.startswith("# "):
                    break
                key, _, value = line[2:].rstrip("\n").partition(": ")
                try:
                    attrs[key] = float(value)
                except ValueError:
                    attrs[key] = value
        frame = pd.read_csv(path, comment="#")
        dim = frame.columns[0]
        ds = xr.Dataset.from_dataframe(frame.set_index(dim))
        ds.attrs.update(attrs)
        return ds
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def diagram(alpha: float, beta: float, nu: float = 0.5, eta: float = 0.5, *, samples: int = 2000,
            kappa_max: float = 3.0, allow_large: bool = False) -> xr.Dataset:
    """The critical set of one body (paper §4, Fig. `bif`): its fixed-point curves along
    `sample` (branch, θ0, κ, ε, stability, the radii ρ_c and ρ_p, N at the bottom of the
    well), as `rubber-atlas diagram --out` writes them; `attrs["critical_set_json"]` holds
    the summary (`diagram --json`). ν and η do not change the set; they are recorded."""
    table, summary = _core.diagram(float(alpha), float(beta), float(nu), float(eta), int(samples), float(kappa_max),
                                   bool(allow_large))
    arguments = dict(alpha=alpha, beta=beta, nu=nu, eta=eta, samples=samples, kappa_max=kappa_max)
    attrs = _root_attrs("diagram", arguments,
                        alpha=float(alpha), beta=float(beta), nu=float(nu), eta=float(eta),
                        critical_set_json=summary)
    return _table(table, attrs)


def trajectory(alpha: float, beta: float, nu: float, eta: float, kappa: float, energy: float | None = None, *,
               component: int = 0, theta0: float | None = None, theta_dot0: float = 0.0,
               periods: float | None = None, t_end: float | None = None, samples: int = 2000,
               model: str = "reduced", tol: float = 1e-12, allow_large: bool = False) -> xr.Dataset:
    """A trajectory along `t` (θ, θ̇, φ, ψ, the centre of mass and the contact point), as
    `rubber-atlas trajectory` writes it: from the lower turning point of `component` at
    `energy`, or from `theta0`, `theta_dot0`; for `periods` θ-periods or up to `t_end`;
    `samples + 1` times; `model` "reduced" or "full" (paper `eqred`)."""
    table, (k, e, t0, td0) = _core.trajectory(
        float(alpha), float(beta), float(nu), float(eta), float(kappa),
        None if energy is None else float(energy), int(component),
        None if theta0 is None else float(theta0), float(theta_dot0),
        None if periods is None else float(periods), None if t_end is None else float(t_end),
        int(samples), str(model), float(tol), bool(allow_large))
    arguments = dict(alpha=alpha, beta=beta, nu=nu, eta=eta, kappa=kappa, energy=energy, component=component,
                     theta0=theta0, theta_dot0=theta_dot0, periods=periods, t_end=t_end, samples=samples,
                     model=model, tol=tol)
    attrs = _root_attrs("trajectory", arguments, model=str(model),
                        alpha=float(alpha), beta=float(beta), nu=float(nu), eta=float(eta),
                        kappa=k, energy=e, theta0=t0, theta_dot0=td0, tolerance=float(tol))
    return _table(table, attrs)


def _rotation_number(value) -> float:
    return float(Fraction(value)) if isinstance(value, str) else float(value)


def resonance(alpha: float, beta: float, nu: float, eta: float, rotation_number, *, kappa_min: float = 0.01,
              kappa_max: float = 2.0, energy_min: float | None = None, energy_max: float = 5.0,
              grid: int = 48, tol: float = 1e-10) -> xr.Dataset:
    """The curves N = `rotation_number` (a number or "p/q") of the (κ, ε) plane in the
    window, traced by continuation, along `sample` (curve, point, κ, ε, N and its error,
    the component and its turning points), as `rubber-atlas resonance --out` writes them."""
    target = _rotation_number(rotation_number)
    table, e_min = _core.resonance(float(alpha), float(beta), float(nu), float(eta), target, float(kappa_min),
                                   float(kappa_max), None if energy_min is None else float(energy_min),
                                   float(energy_max), int(grid), float(tol))
    arguments = dict(alpha=alpha, beta=beta, nu=nu, eta=eta, rotation_number=rotation_number,
                     kappa_min=kappa_min, kappa_max=kappa_max, energy_min=energy_min,
                     energy_max=energy_max, grid=grid, tol=tol)
    attrs = _root_attrs("resonance", arguments,
                        alpha=float(alpha), beta=float(beta), nu=float(nu), eta=float(eta),
                        rotation_number=target, tolerance=float(tol),
                        kappa_window=np.array([kappa_min, kappa_max], dtype=float),
                        energy_window=np.array([e_min, energy_max], dtype=float))
    return _table(table, attrs)


_CASES = {"1": 0, "2": 1, "not_covered": 2}


def verdict(alpha, beta, nu, eta, *, tol: float = 1e-10, resolution: int = 64,
            threads: int | None = None) -> xr.Dataset:
    """The verdict of the boundedness hypothesis (SPEC §4) for each body (α, β, ν, η),
    broadcast as in `cells`, computed in parallel: `holds` (a flag: fails, holds, or
    no_value where the hypothesis does not cover the body or it is undecided), `case`,
    `kappa_max` and its error, `fail_margin` and the number of `counterexamples`;
    `verdict_json` keeps each body's whole `rubber-atlas verdict --json` object."""
    given = {"alpha": alpha, "beta": beta, "nu": nu, "eta": eta}
    dims, layout, coords = _broadcast(given)
    shape = layout[0].shape
    flat = [np.asarray(a, dtype=np.float64).reshape(-1).tolist() for a in layout]
    found = [json.loads(v) for v in _core.verdicts(*flat, float(tol), int(resolution), threads)]

    def column(get, dtype):
        return np.array([get(v) for v in found], dtype=dtype).reshape(shape)

    number = {"units": "1"}
    data_vars = {
        "holds": (dims, column(lambda v: 255 if v["holds"] is None else int(v["holds"]), np.uint8),
                  {"long_name": "whether the boundedness hypothesis holds for the body", "units": "1",
                   "flag_values": np.array([0, 1, 255], dtype=np.uint8),
                   "flag_meanings": "fails holds no_value"}),
        "case": (dims, column(lambda v: _CASES[v["case"]], np.uint8),
                 {"long_name": "part of the hypothesis that covers the body", "units": "1",
                  "flag_values": np.array([0, 1, 2], dtype=np.uint8),
                  "flag_meanings": "case_1 case_2 not_covered"}),
        "kappa_max": (dims, column(lambda v: np.nan if v["kappa_max"] is None else v["kappa_max"], float),
                      {"long_name": "fold kappa_max of the N = 0 curve (case 2)", **_coordinate_attrs("kappa")}),
        "kappa_max_error": (dims, column(lambda v: np.nan if v["kappa_max_error"] is None else v["kappa_max_error"], float),
                            {"long_name": "estimated absolute error of kappa_max", **_coordinate_attrs("kappa")}),
        "fail_margin": (dims, column(lambda v: v["fail_margin"], float),
                        {"long_name": "fail margin: positive where N reaches an integer", **number}),
        "counterexamples": (dims, column(lambda v: len(v["counterexamples"]), np.int32),
                            {"long_name": "number of counterexamples found", **number}),
        "verdict_json": (dims, column(lambda v: json.dumps(v, ensure_ascii=True).encode(), np.bytes_),
                         {"long_name": "the verdict as `rubber-atlas verdict --json` prints it"}),
    }
    for name in given:
        cdims, cvalues = coords[name]
        coords[name] = xr.Variable(cdims, cvalues, _coordinate_attrs(name), {"_FillValue": None})
    arguments = dict(given, tol=tol, resolution=resolution)
    attrs = _root_attrs("verdict", arguments, title="rubber-atlas verdicts of the boundedness hypothesis",
                        tolerance=float(tol), resolution=int(resolution))
    return xr.Dataset(data_vars, coords, attrs)



def _flag(values, meanings: str) -> dict:
    return {"units": "1", "flag_values": np.asarray(values, dtype=np.uint8), "flag_meanings": meanings}


def boundaries(alpha: float, nu: float, eta: float, *, beta_min: float = 0.05, beta_max: float = 50.0,
               scan: int = 48, tol: float = 1e-10, resolution: int = 64, threads: int | None = None) -> xr.Dataset:
    """The β at which the verdict of the boundedness hypothesis changes along β at one α
    (`rubber-atlas verdict --boundaries`), each by root-finding on a quantity that changes
    sign there: along `boundary`, `beta` with its error bound, the `quantity`, and the case
    and verdict on either side; along `scan`, the log-spaced bodies scanned first. The
    whole `--json` object is `attrs["boundaries_json"]`."""
    found = json.loads(_core.boundaries(float(alpha), float(nu), float(eta), float(beta_min), float(beta_max),
                                        int(scan), float(tol), int(resolution), threads))
    holds = lambda h: 255 if h is None else int(h)  # noqa: E731
    holds_attrs = _flag([0, 1, 255], "fails holds no_value")
    case_attrs = _flag([0, 1, 2], "case_1 case_2 not_covered")
    b, sc = found["boundaries"], found["scan"]
    data_vars = {
        "boundary_beta": ("boundary", np.array([x["beta"] for x in b], dtype=float),
                          {"long_name": "beta at which the verdict changes", **_coordinate_attrs("beta")}),
        "boundary_error": ("boundary", np.array([x["error"] for x in b], dtype=float),
                           {"long_name": "bound on the error of boundary_beta", "units": "1"}),
        "quantity": ("boundary", np.array([x["quantity"].encode("ascii", "replace") for x in b], dtype=np.bytes_),
                     {"long_name": "what changes sign at the boundary"}),
        "case_below": ("boundary", np.array([_CASES[x["case_below"]] for x in b], dtype=np.uint8),
                       {"long_name": "case below the boundary", **case_attrs}),
        "holds_below": ("boundary", np.array([holds(x["holds_below"]) for x in b], dtype=np.uint8),
                        {"long_name": "verdict below the boundary", **holds_attrs}),
        "case_above": ("boundary", np.array([_CASES[x["case_above"]] for x in b], dtype=np.uint8),
                       {"long_name": "case above the boundary", **case_attrs}),
        "holds_above": ("boundary", np.array([holds(x["holds_above"]) for x in b], dtype=np.uint8),
                        {"long_name": "verdict above the boundary", **holds_attrs}),
        "scan_beta": ("scan", np.array([x["beta"] for x in sc], dtype=float),
                      {"long_name": "beta of the scanned body", **_coordinate_attrs("beta")}),
        "scan_case": ("scan", np.array([_CASES[x["case"]] for x in sc], dtype=np.uint8),
                      {"long_name": "case of the scanned body", **case_attrs}),
        "scan_holds": ("scan", np.array([holds(x["holds"]) for x in sc], dtype=np.uint8),
                       {"long_name": "verdict of the scanned body", **holds_attrs}),
    }
    arguments = dict(alpha=alpha, nu=nu, eta=eta, beta_min=beta_min, beta_max=beta_max, scan=scan, tol=tol,
                     resolution=resolution)
    attrs = _root_attrs("boundaries", arguments, title="rubber-atlas boundaries of the boundedness hypothesis",
                        alpha=float(alpha), nu=float(nu), eta=float(eta),
                        beta_range=np.asarray(found["beta_range"], dtype=float), tolerance=float(tol),
                        resolution=int(resolution), boundaries_json=json.dumps(found))
    return xr.Dataset(data_vars, attrs=attrs)
