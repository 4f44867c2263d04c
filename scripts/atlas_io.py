"""Open rubber-atlas atlases (the HDF5 files of `rubber-atlas run`) in Python.

    from atlas_io import open_atlas, components
    ds = open_atlas("atlas/demo.h5")          # an xarray.Dataset with named dimensions
    ds.rotation_number.sel(alpha=0.5, beta=3.0, component=0).plot(x="kappa", y="energy")
    components(ds, alpha=0.5, beta=3.0, kappa=0.8, energy=2.5)   # one cell, like `rubber-atlas cell`

Dimensions: alpha, beta, kappa, energy, component; a scene on another plane has
(kappa, excess_energy) or (lambda, s) instead of (kappa, energy), and then carries kappa and
energy per cell as coordinates (CF auxiliary coordinates). Per cell: n_components, cell_status
(ok / no_motion / failed). Per cell and component (NaN where the component does not exist):
the requested fields (theta_min, theta_max, period, omega_theta, omega_psi, rotation_number,
drift, drift_radius, bounded, motion, status, error_estimate) and the estimated absolute
errors `<field>_error`. Flag variables carry CF `flag_values` / `flag_meanings`;
`flag_names(ds.status)` maps them to names.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

DIMENSIONS = ("alpha", "beta", "kappa", "energy", "component")


def open_atlas(path: str | Path, **kwargs) -> xr.Dataset:
    """The atlas at `path` as an xarray Dataset (engine h5netcdf unless `engine=` says
    otherwise; other keywords go to `xarray.open_dataset`). Refuses files that are not
    complete rubber-atlas atlases (a run in progress writes `<out>.partial.h5` and renames it
    only when done, so an existing atlas path is always complete)."""
    path = Path(path)
    if path.name.endswith(".partial.h5"):
        raise ValueError(f"{path}: an unfinished run's file; resume the run with --resume")
    kwargs.setdefault("engine", "h5netcdf")
    ds = xr.open_dataset(path, **kwargs)
    if ds.attrs.get("program") != "rubber-atlas":
        ds.close()
        raise ValueError(f"{path}: not a rubber-atlas atlas (no program attribute)")
    return ds


def flag_names(variable: xr.DataArray) -> dict[int, str]:
    """The CF flag meanings of a flag variable, as {value: name}."""
    values = np.atleast_1d(variable.attrs["flag_values"])
    names = variable.attrs["flag_meanings"].split()
    return {int(v): n for v, n in zip(values, names)}


def components(ds: xr.Dataset, alpha: float, beta: float, **cell: float) -> list[dict]:
    """The components of one grid cell as dicts (keys as in `rubber-atlas cell --json`, with
    status and motion as names), sorted by theta_min. The cell is given by the grid values (to
    1e-12) of the file's own plane: `kappa=…, energy=…`, `kappa=…, excess_energy=…` or
    `lambda_=…, s=…` (`lambda_` since `lambda` is a Python keyword)."""
    cell = {("lambda" if k == "lambda_" else k): v for k, v in cell.items()}
    planes = [d for d in ds.rotation_number.dims if d not in ("alpha", "beta", "component")] \
        if "rotation_number" in ds else [d for d in ds.cell_status.dims if d not in ("alpha", "beta")]
    if sorted(cell) != sorted(planes):
        raise KeyError(f"give the cell by {', '.join(planes)} (this file's plane), not {', '.join(cell) or 'nothing'}")
    point = {"alpha": alpha, "beta": beta, **cell}
    index = {}
    for name, value in point.items():
        axis = ds[name].values
        i = int(np.argmin(np.abs(axis - value)))
        if abs(axis[i] - value) > 1e-12 * max(1.0, abs(value)):
            raise KeyError(f"{name} = {value} is not a grid value (nearest {axis[i]})")
        index[name] = i
    cell = ds.isel(index)
    count = int(cell.n_components)
    flags = {name: flag_names(ds[name]) for name in ("status", "motion") if name in ds}
    out = []
    for slot in range(min(count, ds.sizes["component"])):
        c = cell.isel(component=slot)
        entry = {}
        for name, var in c.data_vars.items():
            if "component" not in ds[name].dims:
                continue
            value = var.values.item()
            if name in flags:
                value = flags[name].get(int(value), "unknown")
            elif name == "bounded":
                value = None if np.isnan(value) else bool(value)
            entry[name] = value
        out.append(entry)
    return out
