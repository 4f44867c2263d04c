"""The package's functions: the Rust core's results shaped into xarray objects with the
names, units and flags of the files `rubber-atlas` writes."""

from __future__ import annotations

import contextlib
import json
import math
import numbers
import re
import os
import sys
import time
import functools
import gc
import warnings
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Iterable

import numpy as np
import xarray as xr


class _NoCore:
    """Stands for the compiled core where it is not built (the source tree on the path, as the
    quick start uses it): opening, reading and drawing atlas files need no core; anything that
    computes says how to get it."""

    def __getattr__(self, name):
        raise ImportError(
            "rubber_atlas's compiled core is not installed: `pip install .` in the repository builds "
            "it (it needs the Rust toolchain; bash scripts/setup.sh does it). Opening and drawing "
            "atlas files works without it."
        )


try:
    from . import _core
except ImportError:
    _core = _NoCore()

HAS_CORE = not isinstance(_core, _NoCore)
"""Whether the compiled core is installed (everything but reading and drawing files needs it)."""

FIELDS: tuple[str, ...] = tuple(_core.FIELDS) if HAS_CORE else ()
"""The fields a scene (and `cells`) may ask for, in file order (empty without the core)."""

_BODY = ("alpha", "beta", "nu", "eta")
# The planes of a scene: the two inputs that give (κ, ε), and what each derived value needs.
_PLANES = (("kappa", "energy"), ("kappa", "excess_energy"), ("lambda", "s"))
# The keywords of inputs whose coordinate has another name.
_KEYWORDS = {"lambda": "lambda_"}
_DERIVED = {
    "excess_energy": {"energy": ("alpha", "beta", "kappa", "excess_energy")},
    "s": {"kappa": ("lambda", "s"), "energy": ("s",)},
}
@functools.cache
def _family_names() -> dict[int, str]:
    """{code: name} of the torus families, as the core's `family` variable flags them."""
    meta = next(m for m in _core.variables(None) if m["name"] == "family")
    return {int(v): n for v, n in zip(meta["flag_values"], meta["flag_meanings"].split()) if int(v) != 255}
_LAYOUTS = ("family", "theta_min")
# `cells` shows progress by default above this many cells (in a terminal or in Jupyter), in
# about _PROGRESS_STEPS batches of at least _BATCH_CELLS cells each.
_PROGRESS_CELLS = 200_000
_PROGRESS_STEPS = 100
_BATCH_CELLS = 16_384


def _call(name: str, arguments: dict) -> str:
    """`name(arguments)` as text, for the `history` attribute."""
    def show(v) -> str:
        try:
            return repr(v) if np.ndim(v) == 0 else f"<{np.shape(v)} array>"
        except ValueError:  # rows of unequal lengths (a profile's)
            return f"<{len(v)} rows>"

    shown = ", ".join(f"{k}={show(v)}" for k, v in arguments.items())
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


# The axes of the other planes, described as the atlas files describe them (for cores that do
# not know them by name).
_OTHER_COORDINATES = {
    "lambda": ("lambda = kappa / sqrt(energy), fixed along the high-energy limit", "kappa"),
    "s": ("s = 1 / sqrt(energy): s = 0 is energy = infinity (the high-energy limit)", "kappa"),
    "excess_energy": ("excess energy: energy minus the bottom of V (its deepest minimum) at this kappa",
                      "energy"),
}


def _coordinate_attrs(name: str) -> dict:
    try:
        long_name, units, comment = _core.coordinate(name)
    except ValueError:
        if name not in _OTHER_COORDINATES:
            raise
        long_name, like = _OTHER_COORDINATES[name]
        _, units, comment = _core.coordinate(like)
    attrs = {"long_name": long_name, "units": units}
    if comment:
        attrs["comment"] = comment
    return attrs


class NotInDataset(KeyError, ValueError):
    """A cell, index or variable a dataset does not have: a KeyError, as xarray's lookups
    raise, and a ValueError, as every bad input of the package."""

    def __str__(self) -> str:
        return str(self.args[0])


def _shown(x) -> str:
    """A number as a message shows it: short (no 300-digit integers), NaN as NaN."""
    if isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_)) and abs(int(x)) >= 10**16:
        return f"{Decimal(int(x)):.3g}"
    if isinstance(x, (float, np.floating)):
        return "NaN" if np.isnan(x) else repr(float(x))
    return repr(x)


def _at(index: tuple) -> str:
    return f"[{', '.join(str(int(i)) for i in index)}]" if index else ""


def _numbers(name: str, value) -> np.ndarray:
    """`value` (a number, array_like or DataArray) as float64, refused in one line naming
    `name` when it is not real numbers: None, text, booleans, dates or durations, complex or
    masked values, nested lists of different lengths, integers beyond float64. A broadcast
    view (``np.broadcast_to``) stays one: nothing is materialised."""
    if value is None:
        raise TypeError(f"{name} is None: give a number or an array of numbers")
    # (xarray's own error, naming no input, before: an adversary pass.)
    if isinstance(value, xr.Dataset):
        raise TypeError(f"{name} is an xarray.Dataset: give a DataArray (one of its variables) or numbers")
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        raise ValueError(f"{name} has masked values: give only the cells to compute")
    if isinstance(value, (list, tuple)):
        masked = _first_masked(value)
        if masked is not None:
            raise ValueError(f"{name}{_at(masked)} is masked: give only the cells to compute")
        # numpy reads a boolean among numbers as 0 or 1 ([0.8, True] is [0.8, 1.0]).
        flagged = _first_boolean(value)
        if flagged is not None:
            index, x = flagged
            raise TypeError(f"{name}{_at(index)} is {x!r}: give real numbers")
    try:
        array = np.asarray(value.values if isinstance(value, xr.DataArray) else value)
    except ValueError:
        raise ValueError(f"{name} is nested lists of different lengths: give a number, or an array with "
                         "rows of one length") from None
    kind = array.dtype.kind
    if kind == "O":
        for index, x in np.ndenumerate(array):
            if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
                raise TypeError(f"{name}{_at(index)} is {x!r}: give real numbers")
            if isinstance(x, np.floating) and x.dtype.itemsize > 8:
                _numbers(f"{name}{_at(index)}", np.asarray(x))  # a long double: its range
            try:
                float(x)
            except OverflowError:
                # (To 17 digits: 2**1024 and the largest float64 agree to 16, and read as one
                # number at 3; adversary pass of 2026-11-28.)
                shown = f"{Decimal(int(x)):.17g}" if isinstance(x, (int, np.integer)) else _shown(x)
                raise ValueError(f"invalid {name}{_at(index)} = {shown}: beyond the largest float64 "
                                 f"({float(np.finfo(np.float64).max)!r})") from None
        return np.array([float(x) for x in array.flat], dtype=np.float64).reshape(array.shape)
    if kind not in "iuf":
        what = {"b": "boolean", "c": "complex", "U": "text", "S": "text", "M": "date", "m": "duration"}
        first = array.flat[0] if array.size else None
        example = "none" if first is None else repr(first.item()) if kind in "US" else str(first)
        more = ", …" if array.size > 1 else ""
        raise TypeError(f"{name} has {what.get(kind, str(array.dtype))} values ({example}{more}): give real numbers")
    if array.dtype == np.float64:
        return array
    # Converted where the values are stored: a broadcast view stays a view.
    stored = array[tuple(slice(None) if stride else slice(0, 1) for stride in array.strides)]
    if kind == "f" and array.dtype.itemsize > 8:
        # A long double beyond float64's range would become inf (with numpy's overflow
        # warning), or 0 (another input: κ = 0 is the planar case).
        with np.errstate(over="ignore", under="ignore"):
            converted = stored.astype(np.float64)
        for bad, why in ((np.isfinite(stored) & np.isinf(converted), "beyond the largest float64 (1.8e+308)"),
                         ((stored != 0) & (converted == 0), "underflows to 0 in float64 (below 4.9e-324)")):
            if bad.any():
                index = tuple(int(i) for i in np.argwhere(bad)[0]) if stored.ndim else ()
                shown = np.format_float_scientific(stored[index], precision=3, trim="-")
                raise ValueError(f"invalid {name}{_at(index)} = {shown}: {why}")
    if stored.shape == array.shape:
        return array.astype(np.float64)
    return np.broadcast_to(stored.astype(np.float64), array.shape)


def _first_in(items, test, index: tuple = ()):
    """The index and value of the first item that passes `test` in nested lists or tuples,
    else None."""
    for i, x in enumerate(items):
        if test(x):
            return index + (i,), x
        if isinstance(x, (list, tuple)):
            found = _first_in(x, test, index + (i,))
            if found is not None:
                return found
    return None


def _first_boolean(items):
    """The index and value of the first boolean in nested lists or tuples, else None."""
    return _first_in(items, lambda x: isinstance(x, (bool, np.bool_)))


def _is_masked(x) -> bool:
    """Whether `x` is numpy's masked constant or an array with a masked value."""
    return x is np.ma.masked or (np.ma.isMaskedArray(x) and bool(np.ma.is_masked(x)))


def _first_masked(items):
    """The index of the first masked value in nested lists or tuples, else None: numpy
    reads them as their data, silently (an adversary pass: ``kappa=[np.ma.masked, 0.8]``)."""
    found = _first_in(items, _is_masked)
    return None if found is None else found[0]


def _real(name: str, value) -> float:
    """One number (an option or a parameter of one body), refused naming `name` otherwise."""
    array = _numbers(name, value)
    if array.ndim:
        raise TypeError(f"{name} must be one number, not an array of shape {array.shape}")
    return float(array)


def _optional_real(name: str, value) -> float | None:
    return None if value is None else _real(name, value)


def _reals(**parameters) -> dict[str, float]:
    """Parameters that are one number each (a body's α, β, ν, η, a window), by name."""
    return {name: _real(name, value) for name, value in parameters.items()}


def _count(name: str, value) -> int:
    """A whole number (threads, samples, …) as the core takes it, a 64-bit integer; refused
    naming `name` otherwise (its range is the core's to check). A 0-d array counts as the
    number it holds, as it does for the other parameters."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    # (np.timedelta64 is an Integral whose int() fails with a message naming no input; a
    # long double 1e-400 is not whole though float() rounds it to 0: adversary pass 37.)
    whole = isinstance(value, numbers.Integral) or (
        isinstance(value, (float, np.floating)) and np.isfinite(value)
        and value == np.floor(value))
    if isinstance(value, (bool, np.bool_, np.timedelta64, np.datetime64)) or not whole:
        shown = repr(value)
        if "\n" in shown:
            shown = f"a {type(value).__name__}"
        raise TypeError(f"{name} must be a whole number, not {shown}")
    if abs(int(value)) >= 2**63:
        # Near the limit every digit matters (2**63 is one past it); far beyond, 3 do.
        shown = str(int(value)) if abs(int(value)) < 10**20 else _shown(int(value))
        raise ValueError(f"invalid {name} = {shown}: beyond the largest signed 64-bit integer, "
                         f"{2**63 - 1} (in size)")
    return int(value)


def _text(name: str, value, choices: str) -> str:
    """A word option (method, model): text only, so that None is not taken for "None"."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be {choices}, not {value!r}")
    return value


def _optional_count(name: str, value) -> int | None:
    return None if value is None else _count(name, value)


def _switch(name: str, value) -> bool:
    """True or False, and nothing else taken for them ("no" would be True)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, not {value!r}")
    return bool(value)


def _plane(kappa, energy, excess_energy, lambda_, s) -> dict:
    """The two inputs that span the (κ, ε) plane, by their coordinate names: kappa with
    energy or excess_energy, or lambda with s."""
    given = {n: v for n, v in (("kappa", kappa), ("energy", energy), ("excess_energy", excess_energy),
                                 ("lambda", lambda_), ("s", s)) if v is not None}
    for pair in _PLANES:
        if set(given) == set(pair):
            return {n: given[n] for n in pair}
    names = ", ".join(_KEYWORDS.get(n, n) for n in given) or "none of them"
    if len(given) == 1:
        (only,) = given
        missing = {"energy": "kappa", "excess_energy": "kappa", "s": "lambda_", "lambda": "s",
                   "kappa": "energy"}[only]
        raise TypeError(f"{missing} is None: give a number or an array of numbers (the plane is kappa with "
                        "energy, kappa with excess_energy, or lambda_ with s)")
    raise TypeError("give the plane as kappa with energy, kappa with excess_energy, or lambda_ with s; "
                    f"got {names}")


def _dims_of(coordinate) -> tuple:
    return tuple(coordinate[0]) if isinstance(coordinate, tuple) else tuple(coordinate.dims)


def _numpy_dims(shape: tuple, values: dict[str, np.ndarray]) -> tuple[tuple[str, ...], dict]:
    """Names of the dimensions of inputs broadcast by numpy's rules, and each input's
    coordinate over the dimensions it varies along. One dimension is `cell`; of several, one
    along which a single input varies (and that input along no other) takes the input's
    name, the others are `cell_0`, `cell_1`, …"""
    ndim = len(shape)
    along = {}
    for name, v in values.items():
        padded = v.reshape((1,) * (ndim - v.ndim) + v.shape)
        # An axis the input spans: it varies along it, or the axis has one value and the
        # input was given along it.
        along[name] = [i for i in range(ndim)
                       if padded.shape[i] != 1 or (shape[i] == 1 and i >= ndim - v.ndim)]
    if ndim == 1:
        dims = ("cell",)
    else:
        dims = []
        for i in range(ndim):
            varying = [n for n, axes in along.items() if i in axes]
            if len(varying) == 1 and along[varying[0]] == [i]:
                dims.append(varying[0])
            else:
                dims.append(f"cell_{i}")
        dims = tuple(dims)
    coords = {}
    for name, v in values.items():
        padded = v.reshape((1,) * (ndim - v.ndim) + v.shape)
        axes = along[name]
        squeezed = padded.reshape([padded.shape[i] for i in axes]) if axes else padded.reshape(())
        coords[name] = (tuple(dims[i] for i in axes), np.array(squeezed))
    return dims, coords


def _broadcast(given: dict[str, object], plane: tuple[str, str] | None = None, outputs: Iterable[str] = (),
               check=None) -> tuple[tuple[str, ...], list[np.ndarray], dict, dict]:
    """Broadcasts the inputs together: DataArrays by their dimension names (xarray's rules),
    anything else by numpy's (see `_numpy_dims` for the names of the dimensions); the two
    inputs of `plane`, 1-D of different lengths with every other input a number, as a grid.
    A dimension named after one of `outputs` (the result's variables) is refused, and
    `check` is called with the number of cells before anything of that size is made.
    Returns the dimensions, the arrays in that layout (views), the coordinates of the result
    (each input over the dimensions it varies along, scalar where it is one number), and
    where each input lies: {name: (its shape, the result's axis of each of its axes)}."""
    # Each input holds at least as many values as there are cells: sized from its shape
    # before it is read (a dask-backed κ of 3e8 cells was computed, 2.4 GB, before the
    # refusal; an adversary pass).
    if check is not None:
        for v in given.values():
            size = getattr(v, "size", None)
            if isinstance(size, numbers.Integral) and not isinstance(size, bool) and size > 1:
                check(int(size))
    values = {name: _numbers(name, v) for name, v in given.items()}
    if any(isinstance(v, xr.DataArray) for v in given.values()):
        arrays = {}
        for name, v in given.items():
            if isinstance(v, xr.DataArray):
                arrays[name] = v.copy(data=values[name])
            elif values[name].ndim == 0:
                arrays[name] = xr.DataArray(values[name])
            else:
                raise TypeError(
                    f"{name}: give every array input as an xarray.DataArray (with named "
                    "dimensions) when any is one, or none as one"
                )
        lengths: dict[str, dict[str, int]] = {}
        for name, a in arrays.items():
            for d, size in a.sizes.items():
                lengths.setdefault(d, {})[name] = size
        for d, by in lengths.items():
            if len(set(by.values())) > 1:
                raise ValueError(f"the DataArray inputs' dimension {d!r} has different lengths: "
                                 f"{', '.join(f'{size} in {name}' for name, size in by.items())}; give it one length")
        # The order xarray's broadcast gives the first input.
        first = next(iter(arrays.values()))
        dims = first.dims + tuple(d for d in lengths if d not in first.dims)
        for name in given:
            # A dimension named after an input is that input's axis, or a mistake.
            if name in dims and arrays[name].dims != (name,):
                raise ValueError(f"the dimension {name!r} is named after the input {name}, which is not given "
                                 f"along it: rename the dimension, or give {name} as a DataArray along {name!r}")
        _refuse_outputs(dims, outputs)
        for name, a in arrays.items():
            for c in a.coords:
                if c in outputs and c not in a.dims:
                    raise ValueError(f"the coordinate {c!r} of {name} is named after a variable of the result: "
                                     "rename or drop it")
        if check is not None:
            check(math.prod(next(iter(by.values())) for by in lengths.values()))
        try:
            aligned = xr.align(*arrays.values(), join="exact")
        except ValueError as e:
            raise ValueError(f"the DataArray inputs' coordinates do not line up: {_one_line(e)}") from None
        broadcast = xr.broadcast(*aligned)
        layout = [b.transpose(*dims).values for b in broadcast]
        coords = {}
        for name, source in arrays.items():
            labels = source.coords[name].values if name in dims and name in source.coords else None
            if labels is not None and (labels.dtype.kind not in "iuf" or not np.array_equal(labels, source.values)):
                # The values computed at would differ from the labels shown.
                raise ValueError(f"{name}: the DataArray's {name!r} coordinate differs from its values; "
                                 "give the values as the coordinate, or none")
            coords[name] = (source.dims, source.values) if source.ndim else ((), source.values)
        for b in broadcast:
            for cname, c in b.coords.items():
                coords.setdefault(cname, c)
        places = {name: (a.shape, tuple(dims.index(d) for d in a.dims)) for name, a in arrays.items()}
        return dims, layout, coords, places
    shapes = {name: v.shape for name, v in values.items()}
    # (numpy broadcasts at most 32 dimensions: beyond, its own RuntimeError; an adversary pass.)
    for name, s in shapes.items():
        if len(s) > 32:
            raise ValueError(f"{name} has {len(s)} dimensions: at most 32 are taken")
    vectors = {k: s for k, s in shapes.items() if s}
    # The two axes of the plane as 1-D vectors of different lengths (a length-1 one too, which
    # numpy would broadcast), every other input a number: their grid.
    grid = (plane is not None and set(vectors) == set(plane) and all(len(s) == 1 for s in vectors.values())
            and vectors[plane[0]] != vectors[plane[1]])
    try:
        if grid:
            raise ValueError("a grid")
        shape = np.broadcast_shapes(*shapes.values())
        places = {name: (s, tuple(range(len(shape) - len(s), len(shape)))) for name, s in shapes.items()}
    except ValueError:
        if not grid:
            shown = ", ".join(f"{k} {s}" for k, s in vectors.items())
            raise ValueError(
                f"the inputs do not broadcast together ({shown}): numpy pairs their last dimensions, "
                "which must be equal or 1; give them as xarray.DataArrays with named dimensions (one "
                "dimension per axis of the grid), or only the two axes of the plane as vectors"
            ) from None
        # Two axes of different lengths: their grid, dimensions named after them.
        shape = (shapes[plane[0]][0], shapes[plane[1]][0])
        places = {name: (s, (plane.index(name),) if s else ()) for name, s in shapes.items()}
        values[plane[0]] = values[plane[0]][:, None]
        values[plane[1]] = values[plane[1]][None, :]
    if check is not None:
        check(math.prod(shape))
    layout = np.broadcast_arrays(*values.values())
    if grid:
        # (numpy's rules would not name a length-1 axis after its input)
        dims = tuple(plane)
        coords = {name: ((plane[plane.index(name)],), np.asarray(v).reshape(-1)) if name in plane
                  else ((), np.asarray(v).reshape(())) for name, v in values.items()}
    else:
        dims, coords = _numpy_dims(shape, values)
    _refuse_outputs(dims, outputs)
    return dims, list(layout), coords, places


def _refuse_outputs(dims: tuple, outputs: Iterable[str]) -> None:
    """Refuses a dimension named after a variable of the result (it would become a coordinate)."""
    for d in dims:
        if d in outputs:
            raise ValueError(f"the dimension {d!r} is named after a variable of the result: rename the dimension")


def _located(error: ValueError, shape: tuple, places: dict, sources: dict) -> ValueError:
    """The core's "cell i: invalid name = value: why" with the cell named where it was given:
    by its index in the input `name` in that input's own shape (``kappa[1, 2]``; no index for
    a number), or for a value computed from the inputs (κ from λ and s) by the inputs it
    comes from (`sources`: {name: the inputs' names})."""
    found = re.fullmatch(r"cell (\d+): invalid (\w+) = ([^:]*): (.*)", str(error), re.S)
    if not found:
        return error
    cell = np.unravel_index(int(found[1]), shape)
    name, value, why = found[2], found[3], found[4]

    def where(source: str) -> str:
        own, axes = places[source]
        return _KEYWORDS.get(source, source) + _at(tuple(cell[a] if n != 1 else 0 for n, a in zip(own, axes)))

    if name in places:
        return ValueError(f"invalid {where(name)} = {value}: {why}")
    if name in sources:
        return ValueError(f"invalid {name} = {value} (computed from {', '.join(map(where, sources[name]))}): {why}")
    return ValueError(f"cell {_at(cell)}: invalid {name} = {value}: {why}")


def _one_line(error: BaseException) -> str:
    """An error's message on one line (HDF5's span several)."""
    return " ".join(str(error).split())


def _derived(full: np.ndarray, dims: tuple, coords: dict, sources: Iterable[str]) -> tuple:
    """A value computed per cell (`full`, in the layout of `dims`) as a coordinate over the
    dimensions its `sources` vary along."""
    spanned = set().union(*(_dims_of(coords[s]) for s in sources))
    keep = tuple(d for d in dims if d in spanned)
    if full.size == 0:  # an empty input: no cell to take the value from
        return keep, np.empty(tuple(n for n, d in zip(full.shape, dims) if d in keep), dtype=full.dtype)
    index = tuple(slice(None) if d in keep else 0 for d in dims)
    return keep, np.array(full[index])


def _excess_to_energy(alpha: np.ndarray, beta: np.ndarray, nu: np.ndarray, eta: np.ndarray, kappa: np.ndarray,
                      excess_energy: np.ndarray, core: dict | None = None) -> np.ndarray:
    """ε = V_min(κ) + `excess_energy` per cell (flat float64 arrays of one length), V_min the
    bottom (deepest minimum) of V(θ) = κ²/(2 sin²θ) + U(θ) at each body and κ, as the atlas's
    `kappa`/`excess_energy` plane computes it (the Rust core, in parallel)."""
    _first_bad("excess_energy", excess_energy, ~np.isfinite(excess_energy), "must be a finite number")
    arrays = (np.ascontiguousarray(a, dtype=np.float64) for a in (alpha, beta, nu, eta, kappa))
    bottom = _core.bottoms(*arrays, **(core or {}))
    return bottom + excess_energy


def _first_bad(name: str, values: np.ndarray, bad: np.ndarray, why: str) -> None:
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        value = float(values[i])
        raise ValueError(f"cell {i}: invalid {name} = {'NaN' if np.isnan(value) else repr(value)}: {why}")


# The most points a profile's table may have (the core's MAX_PROFILE_POINTS).
_MAX_PROFILE_POINTS = 2000


def _profile_rows(profile) -> list[list[float]]:
    """The rows (ρ, z) or (ρ, z, edge) of a profile's table as lists of floats; a table of
    another form is refused naming `profile` (the core checks the meridian itself)."""
    what = "profile must be rows (rho, z) or (rho, z, edge) of numbers"
    if isinstance(profile, (str, bytes)):
        raise TypeError(f"{what}, not {type(profile).__name__}")
    if np.ma.isMaskedArray(profile):
        if np.ma.getmaskarray(profile).any():
            raise ValueError("profile has masked values: give the points themselves (np.ma.filled)")
        profile = np.ma.getdata(profile)
    # The count first, from the length alone: a zero-memory view (np.broadcast_to) of 1e8 rows
    # grew to 5 GB as lists of floats before the core refused it (an adversary pass).
    try:
        count = len(profile)
    except TypeError:
        count = None
    if count is not None and count > _MAX_PROFILE_POINTS:
        raise ValueError(f"profile has {count} points; at most {_MAX_PROFILE_POINTS} are taken")
    if isinstance(profile, (list, tuple)) and any(
            isinstance(x, (bool, np.bool_)) for row in profile if isinstance(row, (list, tuple)) for x in row):
        raise TypeError(f"{what}, not True or False")
    if isinstance(profile, (list, tuple)):
        masked = _first_masked(profile)
        if masked is not None:
            raise ValueError(f"profile{_at(masked)} is masked: give the points themselves (np.ma.filled)")
    try:
        array = np.asarray(profile)
    except (ValueError, TypeError):
        # Rows of both lengths (an edge marked on some): each row on its own.
        rows = []
        for i, row in enumerate(profile):
            values = np.asarray(row)
            if values.ndim != 1 or len(values) not in (2, 3):
                count = f"{values.size} value" + ("" if values.size == 1 else "s")
                raise ValueError(f"profile row {i} has {count}; each row is (rho, z) or (rho, z, edge)") from None
            rows.extend(_profile_rows([row]))
        return rows
    if array.dtype.kind not in "fiu":
        raise TypeError(f"{what}, not of {array.dtype}")
    if array.ndim != 2 or array.shape[1] not in (2, 3):
        raise ValueError(f"{what}: an array of shape (n, 2) or (n, 3), not {array.shape}")
    # (A long double beyond float64 becomes inf here, which the core refuses by name.)
    with np.errstate(over="ignore"):
        return array.astype(np.float64).tolist()


def _profile_text(rows: list[list[float]]) -> str:
    """A profile's table as the files hold it: one `rho z edge` row a line, from the lower
    pole, in the program's number form (the core writes it)."""
    return _core.profile_text(rows)


def _shape_attrs(core: dict) -> dict:
    """The core's keywords for the shape as a result's attributes (a profile as its text)."""
    return {k: _profile_text(v) if k == "profile" else v for k, v in core.items()}


def _shape_inputs(shape: str, beta, cut, profile=None) -> dict:
    """The inputs that give the shape beside α: β of the ellipsoid, the cut of a cut ball,
    nothing for the disk and a profile; a parameter the shape does not take, or one it lacks,
    is refused."""
    if shape != "profile" and profile is not None:
        raise ValueError(f"shape {shape!r} takes no profile (only shape=\"profile\" does)")
    if shape == "ellipsoid":
        if cut is not None:
            raise ValueError("cut is a parameter of shape=\"truncated_ball\" and \"wheel\", not of the ellipsoid")
        return {"beta": beta}
    if shape not in ("disk", "truncated_ball", "wheel", "profile"):
        raise ValueError(f"shape {shape!r}: use \"ellipsoid\", \"disk\", \"truncated_ball\", \"wheel\" or \"profile\"")
    if beta is not None:
        raise ValueError(f"shape {shape!r} takes no beta (only the ellipsoid does); give None")
    if shape == "profile":
        if cut is not None:
            raise ValueError("shape 'profile' takes no cut (only truncated_ball and wheel do)")
        if profile is None:
            raise TypeError("shape 'profile' needs profile=, its meridian's points: rows (rho, z) or (rho, z, edge)")
        return {}
    if shape == "disk":
        if cut is not None:
            raise ValueError("shape 'disk' takes no cut (only truncated_ball and wheel do)")
        return {}
    if cut is None:
        raise TypeError(f"shape {shape!r} needs cut (h: the plane z = -h cuts the ball)")
    return {"cut": cut}


def _core_shape(shape: str, profile) -> dict:
    """The keywords the core takes for the shape: none for the ellipsoid, its name, and a
    profile's rows."""
    if shape == "ellipsoid":
        return {}
    return {"shape": shape, "profile": _profile_rows(profile)} if shape == "profile" else {"shape": shape}


def _one_body(shape, alpha, beta, nu, eta, cut, profile=None) -> tuple[dict, str, dict, list, dict]:
    """The checked numbers of one body, the shape's name, the keywords the core takes, the
    core's positional numbers (the ellipsoid's alpha, beta, nu, eta, or another body's with
    its cut, or 0, in beta's place), and the call's own keywords for the body beside alpha
    (beta, or shape and cut or profile) as the caller gave them."""
    shape = _text("shape", shape, '"ellipsoid", "disk", "truncated_ball", "wheel" or "profile"')
    second = _shape_inputs(shape, beta, cut, profile)
    body = _reals(alpha=alpha, **second, nu=nu, eta=eta)
    values = list(body.values())
    if shape in ("disk", "profile"):
        values.insert(1, 0.0)
    extra = _core_shape(shape, profile)
    named = {"shape": shape, **second} if shape != "ellipsoid" else second
    if shape == "profile":
        named["profile"] = profile
    return body, shape, extra, values, named


def _to_kappa_energy(plane: tuple[str, str], flat: list[np.ndarray], core: dict | None = None) -> list[np.ndarray]:
    """The six flat inputs (α, β or the cut, ν, η and the plane's two) as α, β, ν, η, κ, ε."""
    a, b = flat[4], flat[5]
    if plane == ("kappa", "energy"):
        return flat
    if plane == ("lambda", "s"):
        _first_bad("lambda", a, ~np.isfinite(a), "lambda = kappa / sqrt(energy) must be a finite number")
        _first_bad("s", b, b == 0, "s = 0 is the high-energy limit energy = infinity, which cells does "
                   "not compute; give s > 0 (energy = 1/s^2)")
        _first_bad("s", b, ~(b > 0) | ~np.isfinite(b), "s = 1 / sqrt(energy) must be a finite number > 0")
        # As a scene's (λ, s) plane: λ ≥ 0, s ≥ 1e-150 (ε ≤ 1e300), λ/s not below 2.2e-308.
        _first_bad("lambda", a, a < 0, "lambda = kappa / sqrt(energy) must be >= 0 (the sign of kappa is "
                   "the direction of rolling: give kappa and energy for kappa < 0)")
        _first_bad("s", b, b < 1e-150, "s below 1e-150 is energy = 1/s^2 above 1e300")
        # Overflows give inf, refused below with the inputs named.
        with np.errstate(over="ignore", divide="ignore", under="ignore"):
            kappa = a / b
            _first_bad("lambda", a, (a > 0) & (kappa < 2.2250738585072014e-308),
                       "lambda / s is below 2.2250738585072014e-308 (subnormal, or 0 by underflow): keep it at least that")
            return flat[:4] + [kappa, 1.0 / (b * b)]
    return flat[:4] + [a, _excess_to_energy(*flat[:4], a, b, core)]


def _show_bytes(n: float) -> str:
    for name, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.1f} {name}"
    return f"{n:.0f} B"


def _refuse_memory(what: str, needed: float, allow_large: bool, remedy: str) -> None:
    """Refuses (unless `allow_large`) a call that would take over 80 % of the memory the
    kernel could give now, by the core's own rule (the machine's available memory, the
    control group's limit and the address-space limit, whichever is least)."""
    if allow_large:
        return
    short = _core.memory_short(float(needed))
    if short is not None:
        raise ValueError(f"{what} needs {short}: {remedy}, or allow_large=True")


def _check_memory(cells: int, fields: list[str] | None, allow_large: bool) -> None:
    """Refuses (unless `allow_large`) results that would take over 80 % of the memory the
    kernel could give now, for the whole of a call the package splits into batches."""
    per_cell = sum(np.dtype(m["dtype"]).itemsize * (max(_core.COMPONENT_SLOTS, len(_family_names()))
                                                   if m["per_component"] else 1)
                   for m in _core.variables(fields))
    _refuse_memory("cells", cells * (6 * 8 + 2 * per_cell), allow_large, "give fewer cells at a time")


# Memory a body's verdict takes in this package: its JSON object as text and as Python
# objects, and its share of the dataset (114 kB measured at resolution 8, 200 bodies).
_VERDICT_BYTES = 128e3


def _in_jupyter() -> bool:
    """Whether this runs in a Jupyter kernel (a notebook, JupyterLab, VS Code's)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except Exception:  # noqa: BLE001 - any failure means no kernel
        return False
    return shell is not None and getattr(shell, "kernel", None) is not None


def _stderr_is_terminal() -> bool:
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):
        return False


class _TextBar:
    """A progress bar on standard error, for when tqdm is not installed."""

    def __init__(self, total: int, desc: str):
        self.total, self.desc, self.done = total, desc, 0
        self.start = self.shown = time.monotonic()
        self._draw()

    def update(self, n: int) -> None:
        self.done += n
        now = time.monotonic()
        if now - self.shown >= 0.1 or self.done >= self.total:
            self.shown = now
            self._draw()

    def _draw(self) -> None:
        fraction = self.done / self.total if self.total else 1.0
        elapsed = time.monotonic() - self.start
        left = elapsed / fraction - elapsed if fraction > 0 else float("nan")
        clock = lambda t: "--:--" if not np.isfinite(t) else f"{int(t) // 60:02d}:{int(t) % 60:02d}"  # noqa: E731
        filled = int(round(30 * fraction))
        sys.stderr.write(f"\r{self.desc}: {100 * fraction:3.0f}% |{'#' * filled}{' ' * (30 - filled)}| "
                         f"{self.done}/{self.total} [{clock(elapsed)}<{clock(left)}]")
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()


def _progress_bar(total: int):
    """tqdm's bar (a widget in Jupyter, text in a terminal) if tqdm is installed, else a text bar."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _TextBar(total, "rubber_atlas.cells")
    return tqdm(total=total, desc="rubber_atlas.cells", unit="cell", unit_scale=True)


def _fill(dtype: np.dtype):
    """What a per-component variable holds where the component does not exist."""
    dtype = np.dtype(dtype)
    if dtype.kind == "f":
        return np.nan
    if dtype.kind == "u":
        return np.iinfo(dtype).max
    return -1


def _solve_batch(flat: list[np.ndarray], start: int, options: tuple, layout: str, core: dict | None = None) -> dict:
    """One call of the core: {"columns": [(name, flat array)], "component": [labels],
    "layout": …, and for the family layout possibly the component's "flag_values" and
    "flag_meanings"}."""
    try:
        result = _core.cells(*flat, *options, layout=layout, **(core or {}))
    except ValueError as e:
        if start == 0:
            raise
        # The index of a bad cell in the whole input, not in this batch.
        message = re.sub(r"\bcell (\d+)", lambda m: f"cell {int(m.group(1)) + start}", str(e), count=1)
        raise ValueError(message) from None
    out = dict(result)
    out["columns"] = list(result["columns"])
    out["component"] = [int(c) for c in result["component"]]
    out["layout"] = str(result["layout"])
    return out


def _solve(flat: list[np.ndarray], options: tuple, layout: str, meta: dict, progress: bool,
           core: dict | None = None) -> dict:
    """Solves the flat cells, in batches when `progress` shows how far it got; returns what
    one call of the core over all of them would (see `_solve_batch`): per-component arrays
    with the component fastest, over the union of the batches' components less those empty
    in every cell."""
    n = len(flat[0])
    if not progress:
        return _solve_batch(flat, 0, options, layout, core)
    size = max(_BATCH_CELLS, -(-n // _PROGRESS_STEPS))
    parts = []
    bar = _progress_bar(n)
    try:
        for start in range(0, max(n, 1), size):
            stop = min(n, start + size)
            parts.append((stop - start, _solve_batch([a[start:stop] for a in flat], start, options, layout, core)))
            bar.update(stop - start)
    finally:
        bar.close()
    if len(parts) == 1:
        return parts[0][1]
    # The union of the batches' components (sorted: families by code, ranks in order).
    component = sorted(set().union(*(p["component"] for _, p in parts)))
    where = {c: i for i, c in enumerate(component)}
    columns = []
    for k, (name, _) in enumerate(parts[0][1]["columns"]):
        pieces = []
        for count, part in parts:
            values = np.asarray(part["columns"][k][1])
            per_component = meta.get(name, {}).get("per_component", values.size != count)
            if not per_component:
                pieces.append(values)
                continue
            full = np.full((count, len(component)), _fill(values.dtype), dtype=values.dtype)
            full[:, [where[c] for c in part["component"]]] = values.reshape(count, len(part["component"]))
            pieces.append(full.reshape(-1))
        columns.append((name, np.concatenate(pieces)))
    found = dict(columns)
    if "family" in found:
        # As the core does: no slot that is empty in every cell (one when all are).
        family = found["family"].reshape(n, len(component))
        used = [i for i in range(len(component)) if (family[:, i] != 255).any()]
        if used and len(used) < len(component):
            columns = [(name, v.reshape(n, len(component))[:, used].reshape(-1)
                        if meta.get(name, {}).get("per_component", v.size != n) else v)
                       for name, v in columns]
            component = [component[i] for i in used]
    out = {key: value for key, value in parts[0][1].items() if key not in ("flag_values", "flag_meanings")}
    out.update(columns=columns, component=component)
    return out


def _family_meanings(meta: dict) -> dict[int, str]:
    family = meta.get("family")
    names = dict(_family_names())
    if family and "flag_values" in family:
        names = {int(v): n for v, n in zip(family["flag_values"], family["flag_meanings"].split())}
    names.setdefault(255, "no_value")
    return names


# The component coordinate's names in the files, by layout.
_COMPONENT_NAMES = {"family": "torus family", "theta_min": "rank of the component in increasing theta_min"}


def _component_coordinate(solved: dict, meta: dict) -> xr.Variable:
    """The `component` coordinate of a result, as the files have it: the ranks (int32) in
    the theta_min layout; the families' codes (uint8 flags) in the family layout."""
    layout = solved["layout"]
    attrs = {"long_name": solved.get("long_name", _COMPONENT_NAMES[layout]), "units": "1"}
    if layout != "family":
        return xr.Variable("component", np.asarray(solved["component"], dtype=np.int32), attrs,
                           {"_FillValue": None})
    values = np.asarray(solved["component"], dtype=np.uint8)
    if "flag_values" in solved and "flag_meanings" in solved:
        flag_values = np.asarray(list(solved["flag_values"]), dtype=np.uint8)
        meanings = str(solved["flag_meanings"])
    else:
        names = _family_meanings(meta)
        flag_values = values
        meanings = " ".join(names.get(int(c), f"family_{int(c)}") for c in values)
    attrs.update(flag_values=flag_values, flag_meanings=meanings)
    return xr.Variable("component", values, attrs, {"_FillValue": None})


def cells(
    alpha,
    beta,
    nu,
    eta,
    kappa=None,
    energy=None,
    *,
    excess_energy=None,
    lambda_=None,
    s=None,
    tol: float = 1e-10,
    method: str = "quadrature",
    fields: Iterable[str] | None = None,
    resonance_tol: float = 1e-9,
    threads: int | None = None,
    allow_large: bool = False,
    layout: str = "family",
    progress: bool | None = None,
    shape: str = "ellipsoid",
    cut=None,
    profile=None,
) -> xr.Dataset:
    """Solve cells (α, β, ν, η and a point of the (κ, ε) plane) in parallel.

    The values are those an atlas file of the same fields holds, bit for bit (with all fields,
    or any of drift, drift_radius and bounded, also those ``rubber-atlas cell`` prints): the
    computation runs in Rust with the GIL released. Units are the paper's: length b3,
    mass m, time sqrt(b3/g) (each variable's ``comment`` says so); see docs/model.md for
    the model.

    Parameters
    ----------
    alpha : float, array_like or xarray.DataArray
        α = a/b3, offset of the centre of mass along the symmetry axis, -1 < α < 1
        (α < 0 is the mirror image θ → π − θ of -α).
    beta : float, array_like or xarray.DataArray
        β = b1/b3 > 0, ratio of the semi-axes (< 1 prolate, 1 a ball, > 1 oblate).
    nu : float, array_like or xarray.DataArray
        ν = i3/i1, axial over equatorial moment of inertia, 0 < ν ≤ 2.
    eta : float, array_like or xarray.DataArray
        η = m b3²/i1 > 0.
    kappa : float, array_like or xarray.DataArray, optional
        κ, the value of the linear integral F2 = J(θ) ω3 (its sign is the direction of
        rolling), 0 or any real number from 2.2e-308 (the least normal double) up to 1e150 in
        size; with `energy` or `excess_energy`.
    energy : float, array_like or xarray.DataArray, optional
        ε, the energy in units of m g b3, any real number up to 1e300 in size (below the
        bottom of V there is no motion).
    excess_energy : float, array_like or xarray.DataArray, optional
        ε − V_min(κ), the energy above the bottom of V at each κ (m g b3); instead of
        `energy` (the bottom is found by the Rust core, as an atlas's
        ``kappa``/``excess_energy`` plane finds it).
    lambda_ : float, array_like or xarray.DataArray, optional
        λ = κ/√ε ≥ 0, finite; with `s` instead of `kappa` and `energy` (κ = λ/s, so λ/s is held
        to κ's range). Motion at high energy needs λ ≤ √2.
    s : float, array_like or xarray.DataArray, optional
        s = 1/√ε ≥ 1e-150 (ε = 1/s² ≤ 1e300), as in scenes. s = 0, the high-energy limit
        ε = ∞, is refused for now.
    tol : float, default 1e-10
        Relative tolerance of the solver, 1e-15 ≤ tol ≤ 0.1.
    method : {"quadrature", "ode"}, default "quadrature"
        Quadrature of the period integrals, or integration of the reduced equations of
        motion over one period.
    fields : iterable of str, optional
        The fields to compute, from `FIELDS` (default: all of them), each once; ``status``
        is always added, as a scene's ``[outputs] fields`` adds it. A field left out costs
        no time (the drift integrals only run for ``drift``, ``drift_radius`` or
        ``bounded``).
    resonance_tol : float, default 1e-9
        0 ≤ resonance_tol ≤ 0.5: a component with drift whose rotation number is within this
        of an integer is flagged unbounded.
    threads : int, optional
        Number of threads, ≥ 1 (capped at the number of cores); by default rayon's pool,
        which honours ``RAYON_NUM_THREADS``.
    allow_large : bool, default False
        Compute even when the result would take over 80 % of the available memory (True or
        False, nothing else).
    layout : {"family", "theta_min"}, default "family"
        How the ``component`` dimension is laid out, as in the atlas files: one entry per
        torus family present (the coordinate holds their codes, uint8 flags with the
        families' names), or the components of each cell by rank in increasing theta_min
        (0 … n-1, n the most components of a cell). A core built before families of tori
        gives "theta_min" whatever is asked; the attribute ``component_layout`` says which
        one the result has.
    progress : bool, optional
        Show a progress bar (tqdm's if it is installed: a widget in Jupyter, text in a
        terminal; else a text bar on standard error). By default shown when there are more
        than 200,000 cells and standard error is a terminal or the call runs in Jupyter.
    shape : {"ellipsoid", "disk", "truncated_ball", "wheel", "profile"}, default "ellipsoid"
        The body (docs/bodies.md). For any but the ellipsoid, `beta` is None; α places the
        centre of mass at α e3 from the ball's (disk's) centre in units of its radius, and
        the method "ode" is refused for the cut balls (their U has kinks).
    cut : float, array_like or xarray.DataArray, optional
        h of the cut balls, in units of the ball's radius: the plane z = -h
        (``truncated_ball``, -1 < h < 1) or the planes z = ±h (``wheel``, 0 < h < 1); a
        coordinate of the result as ``beta`` is for the ellipsoid.
    profile : array_like, optional
        With ``shape="profile"``, a body of your own (docs/bodies.md): rows (ρ, z) or
        (ρ, z, edge) of its meridian from one pole (ρ = 0) to the other, edge 1 at a sharp
        edge; the points are joined by circular arcs tangent where they meet, and `alpha` is
        the height of the centre of mass on the axis, strictly between the poles (the method "ode"
        is refused for a profile: its U has kinks where the arcs meet).

    Inputs broadcast together. DataArrays broadcast by their dimension names (then every
    array input must be a DataArray; numbers mix with either). Other arrays broadcast by
    numpy's rules: the result has the dimension ``cell`` when it is 1-D (vectors of one length
    are paired cell by cell), else one dimension per axis, named after the one input that
    varies along it (``kappa[:, None]`` and ``energy[None, :]`` give dimensions ``kappa`` and
    ``energy``) or ``cell_0``, ``cell_1``, … when several do. The two inputs of the plane
    given as 1-D vectors of different lengths (every other input a number) are laid out as
    their grid, with dimensions named after them.

    Returns
    -------
    xarray.Dataset
        Over the broadcast dimensions (below ``...``) and ``component``:

        - ``n_components`` (...), uint8: number of components of {V ≤ ε}, 0, 1 or 2;
        - ``cell_status`` (...), uint8 flags: ok, no_motion, failed, not_computed;
        - per component (..., component), for each of `fields`: the value, NaN where the
          component does not exist, and ``<field>_error``, its error estimate; flags
          (``bounded``, ``motion``, ``status``, and ``family`` when the core gives it) are
          uint8 with CF ``flag_values``/``flag_meanings``, 255 (``no_value``) where the
          component does not exist.

        The inputs are coordinates over the dimensions they vary along; with `lambda_` and
        `s` (or `excess_energy`), κ and ε of each cell are coordinates too. Root attributes:
        provenance (program, version, commit, ``history``), ``tolerance``, ``method``,
        ``resonance_tol`` and ``component_layout``.

    Raises
    ------
    ValueError
        A value out of range, named where it was given (``invalid kappa[1, 2] = NaN: …``,
        the index in that input's own shape; none for a number), inputs that do not
        broadcast (named with their shapes), a dimension named after a variable of the
        result, unknown fields or method, a bad tol or threads, an integer beyond float64,
        or a result over 80 % of the available memory without `allow_large` (checked from
        the shapes, before any input is copied).
    TypeError
        An input that is not real numbers (None, text, booleans, dates, complex), or an
        array mixed with DataArrays; a plane given by other than kappa with energy, kappa
        with excess_energy, or lambda_ with s; `allow_large` or `progress` not True or
        False; `threads` not a whole number.
    KeyboardInterrupt
        Ctrl-C stops a call within one cell's time (0.2 s measured on 4 million cells; an ODE
        cell can take several seconds: 5.7 s the slowest of 249 random ones).

    See Also
    --------
    components : the components of one cell as dicts.
    RubberAccessor.family : the fields of one torus family over the plane.

    Examples
    --------
    Two cells of the paper's body (α = 0.5, β = 3, ν = η = 0.5) at ε = 2.5:

    >>> import numpy as np
    >>> import rubber_atlas as ra
    >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=[0.8, 1.0], energy=2.5)
    >>> ds.n_components.dims, ds.n_components.values.tolist()
    (('cell',), [1, 0])
    >>> [round(c["rotation_number"], 6) for c in ds.rubber.components(cell=0)]
    [-0.815177]

    A grid: κ and ε as vectors of different lengths.

    >>> grid = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=np.linspace(0.2, 1.0, 5),
    ...                 energy=np.linspace(1.5, 3.5, 3), fields=["rotation_number"])
    >>> dict(grid.n_components.sizes)
    {'kappa': 5, 'energy': 3}
    >>> grid.n_components.values.tolist()
    [[1, 2, 1], [0, 2, 1], [0, 1, 1], [0, 1, 1], [0, 0, 1]]

    The compact plane (λ, s): κ = λ/s and ε = 1/s² come as coordinates.

    >>> far = ra.cells(0.5, 3.0, 0.5, 0.5, lambda_=0.5, s=[0.1, 0.01], fields=["rotation_number"])
    >>> far.kappa.values.round(6).tolist(), far.energy.values.round(6).tolist()
    ([5.0, 50.0], [100.0, 10000.0])

    A truncated ball (docs/bodies.md): no β, a cut instead.

    >>> ball = ra.cells(0.2, None, 0.7, 1.3, kappa=0.6, energy=[1.9, 2.5], shape="truncated_ball",
    ...                 cut=0.4, fields=["rotation_number"])
    >>> float(ball.cut), ball.rotation_number.values.round(6).tolist()
    (0.4, [[0.040354], [0.050904]])
    """
    plane = _plane(kappa, energy, excess_energy, lambda_, s)
    shape = _text("shape", shape, '"ellipsoid", "disk", "truncated_ball", "wheel" or "profile"')
    given = {"alpha": alpha, **_shape_inputs(shape, beta, cut, profile), "nu": nu, "eta": eta, **plane}
    core = _core_shape(shape, profile)
    names = tuple(plane)
    if layout not in _LAYOUTS:
        raise ValueError(f"layout {layout!r}: use \"family\" or \"theta_min\"")
    try:
        field_list = None if fields is None else [str(f) for f in ([fields] if isinstance(fields, str) else fields)]
    except TypeError:
        raise TypeError(f"fields must be names of fields (a str or a list of them), not {fields!r}") from None
    options = (_real("tol", tol), _text("method", method, '"quadrature" or "ode"'),
               _real("resonance_tol", resonance_tol), field_list,
               _optional_count("threads", threads), _switch("allow_large", allow_large))
    progress = None if progress is None else _switch("progress", progress)
    outputs = [m["name"] for m in _core.variables(None)] + ["component"]
    dims, arrays, coords, places = _broadcast(given, names, outputs,
                                              check=lambda n: _check_memory(n, field_list, options[-1]))
    shape_name, shape = shape, arrays[0].shape
    if shape_name != "ellipsoid" and "beta" in dims:
        raise ValueError(f"the dimension 'beta' is named after the ellipsoid's beta, which shape={shape_name!r} "
                         "does not take: rename the dimension")
    # The input beside α: β, the cut, or none (the disk).
    second = {"ellipsoid": "beta", "disk": None, "profile": None}.get(shape_name, "cut")
    no_second = second is None
    derived = {name: tuple(second if src == "beta" else src for src in sources if src != "beta" or second)
               for name, sources in _DERIVED.get(names[1], {}).items()}
    for name in derived:
        if name in dims:
            raise ValueError(f"the dimension {name!r} is named after {name}, which is computed here from "
                             f"{' and '.join(names)}: rename the dimension")
    flat = [np.ascontiguousarray(a, dtype=np.float64).reshape(-1) for a in arrays]
    if no_second:
        flat.insert(1, np.zeros_like(flat[0]))
    n = flat[0].size
    show = (n > _PROGRESS_CELLS and (_stderr_is_terminal() or _in_jupyter())) if progress is None else progress
    meta = {m["name"]: m for m in _core.variables(field_list)}
    try:
        flat = _to_kappa_energy(names, flat, core)
        solved = _solve(flat, options, layout, meta, show, core)
    except ValueError as e:
        raise _located(e, shape, places, derived) from None
    for name, sources in derived.items():
        full = flat[4 if name == "kappa" else 5].reshape(shape)
        coords[name] = _derived(full, dims, coords, sources)
    slots = len(solved["component"])
    used = solved["layout"]
    data_vars = {}
    for name, values in solved["columns"]:
        values = np.asarray(values)
        m = meta.get(name)
        attrs = _variable_attrs(m) if m else {}
        per_component = m["per_component"] if m else values.size != n
        if per_component:
            data_vars[name] = (dims + ("component",), values.reshape(shape + (slots,)), attrs)
        else:
            data_vars[name] = (dims, values.reshape(shape), attrs)
    for name, c in list(coords.items()):
        if isinstance(c, tuple):
            cdims, cvalues = c
            coords[name] = xr.Variable(cdims, cvalues, _coordinate_attrs(name), {"_FillValue": None})
    coords["component"] = _component_coordinate(solved, meta)
    arguments = dict({_KEYWORDS.get(k, k): v for k, v in given.items()}, tol=tol, method=method, fields=field_list,
                     resonance_tol=resonance_tol, layout=layout)
    if shape_name != "ellipsoid":
        arguments["shape"] = shape_name
    if shape_name == "profile":
        arguments["profile"] = profile
    attrs = _root_attrs(
        "cells",
        arguments,
        **({"shape": "profile", "profile": _profile_text(core["profile"])} if shape_name == "profile" else {}),
        title="rubber-atlas cells",
        tolerance=options[0],
        method=str(method),
        resonance_tol=options[2],
        component_layout=used,
    )
    ds = xr.Dataset(data_vars, coords, attrs)
    for name in ds.dims:
        # Dimension coordinates that came with DataArray inputs get the files' attributes.
        if name in given:
            ds[name].attrs = _coordinate_attrs(name)
            ds[name].encoding["_FillValue"] = None
    return ds


def open_atlas(path: str | Path, check: bool = False, **kwargs) -> xr.Dataset:
    """Open an atlas written by ``rubber-atlas run`` or ``merge`` (a shard too).

    Parameters
    ----------
    path : str or pathlib.Path
        The atlas file (HDF5). An unfinished run's ``*.partial.h5`` is refused.
    check : bool, default False
        Read every stored value once, chunk by chunk, before returning, and refuse a file
        whose values cannot all be read (a corrupted chunk) with a ValueError naming the
        variable. It reads the whole file (about as long as ``.load()``; its memory stays at
        one chunk), first in a child process (some damaged headers crash HDF5 itself; the
        check then raises instead). It finds what HDF5 cannot decode, not every changed byte: the file has no
        checksums, so a byte changed inside an uncompressed coordinate (α, β) or an
        attribute reads as another value.
    **kwargs
        Passed to `xarray.open_dataset`; ``engine`` defaults to "h5netcdf".

    Returns
    -------
    xarray.Dataset
        Lazily loaded, over ``alpha``, ``beta``, the scene's plane (``kappa`` and ``energy``;
        ``kappa`` and ``excess_energy``; or ``lambda`` and ``s``, with κ and ε of each cell as
        2-D auxiliary coordinates) and ``component``; ν and η as scalar coordinates. The
        variables are those of `cells` (per cell, and per cell and component); flags are
        uint8 with CF ``flag_values``/``flag_meanings``. The root attribute
        ``component_layout`` ("family" or "theta_min") says what ``component`` counts (see
        `cells`); files from before families of tori have components in increasing
        theta_min and no ``family`` variable. Use it as a context manager, or close it.

    Raises
    ------
    ValueError
        The file is not a complete rubber-atlas atlas (a table, a `cells` result written by
        xarray, an unfinished run, not HDF5 at all, a folder, missing); with `check`, a value
        in it cannot be read.
    TypeError
        `path` is not a file's name.

    Notes
    -----
    The values are read when they are used: a file damaged after it was written (a
    corrupted chunk) opens, and reading the damaged values raises HDF5's OSError ("Can't
    synchronously read data"), from xarray (``.load()``, ``.values``); from the ``.rubber``
    accessor, a ValueError that names the file as damaged. ``check=True`` finds the damage on
    opening instead, at the price of reading the whole file.

    See Also
    --------
    RubberAccessor : ``ds.rubber.components``, ``.family``, ``.plot_slice``.

    Examples
    --------
    The quick start's atlas (``rubber-atlas run atlas/demo.toml`` writes it):

    >>> import rubber_atlas as ra
    >>> with ra.open_atlas("atlas/out/demo.h5") as atlas:  # doctest: +SKIP
    ...     print(dict(atlas.rotation_number.sizes))
    {'alpha': 1, 'beta': 1, 'kappa': 401, 'energy': 401, 'component': 3}

    Anything else is refused with one line:

    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "cells.nc")
    ...     ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, 2.5).to_netcdf(path, engine="h5netcdf")
    ...     try:
    ...         ra.open_atlas(path)
    ...     except ValueError as e:
    ...         print(str(e).split(": ", 1)[1][:26])
    not a rubber-atlas atlas (
    """
    path = _file(path)
    if path.name.endswith(".partial.h5"):
        raise ValueError(f"{path}: an unfinished run's file; resume the run with --resume")
    check = _switch("check", check)
    if check:
        _survives_reading(path)
    kwargs.setdefault("engine", "h5netcdf")
    try:
        # Warnings are held until the file is known to be an atlas: on another file, xarray's
        # words about it would come before the one line that refuses it.
        with warnings.catch_warnings(record=True) as heard:
            warnings.simplefilter("always")
            ds = xr.open_dataset(path, **kwargs)
    except TypeError as e:
        if "keyword" in str(e):
            raise  # a keyword open_dataset does not take: the caller's mistake, as it is
        raise ValueError(f"{path}: not a rubber-atlas atlas, or a damaged one: {_dropped(e)}") from None
    except (OSError, ValueError, KeyError, RuntimeError, AttributeError, IndexError) as e:
        # (A damaged object header makes h5py raise almost anything: KeyError, RuntimeError,
        # TypeError "Unknown string encoding", …)
        raise ValueError(f"{path}: not a rubber-atlas atlas, or a damaged one: {_dropped(e)}") from None
    if not _is_atlas(ds):
        ds.close()
        raise ValueError(f"{path}: not a rubber-atlas atlas (a file of `rubber-atlas run` or `merge` has the "
                         "attributes program and scene and the variable cell_status)")
    _check_layout(ds, path)
    for warning in heard:
        warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
    if check:
        try:
            _read_every_chunk(path)
        except ValueError:
            ds.close()
            raise
    return ds


def _check_layout(ds: xr.Dataset, path: Path) -> None:
    """Refuses an atlas whose variables do not lie along its grid: a dataset whose dimension
    scales were removed (h5netcdf then matches its axes by size, and on a square plane κ and ε
    came back swapped, every value silently at another cell: adversary pass 43), or one of
    another shape (the accessor then failed in xarray's internals). `cell_status` lies along
    the named axes of the grid (four, three for the disk), `n_components` along them too,
    every other variable along them and ``component`` (docs/files.md)."""
    import h5py

    def damaged(why: str) -> ValueError:
        ds.close()
        return ValueError(f"{path}: the file is damaged: {why}; compute it again")

    try:
        with h5py.File(path, "r") as f:
            lost = []
            for name, item in f.items():
                if not isinstance(item, h5py.Dataset) or item.ndim == 0:
                    continue
                scale = item.attrs.get("CLASS") in (b"DIMENSION_SCALE", "DIMENSION_SCALE")
                if not scale and "DIMENSION_LIST" not in item.attrs:
                    lost.append(name)
    except (OSError, KeyError, RuntimeError, ValueError, TypeError) as e:
        raise damaged(f"its structure cannot be read ({_one_line(e)})") from None
    if lost:
        raise damaged(f"{lost[0]!r} has lost its dimension scales (which of its axes is which is unknown)")
    grid = ds["cell_status"].dims
    # (Four axes, or three for the disk, which has no second shape parameter.)
    if len(grid) not in (3, 4) or any(str(d).startswith("phony_dim") for d in grid):
        raise damaged(f"'cell_status' lies along {grid}, not the axes of an atlas's cells")
    for name, variable in ds.data_vars.items():
        dims = grid if name in ("cell_status", "n_components") else grid + ("component",)
        if variable.dims != dims:
            raise damaged(f"{name!r} lies along {variable.dims}, where the file's grid gives it {dims}")


def _dropped(error: BaseException) -> str:
    """`error` in one line, its traceback dropped at once: a file h5netcdf failed to open lives
    on in those frames, half made, and its finaliser's own AttributeError ('File' object has no
    attribute '_writable') was printed as "Exception ignored in …" after the one line that
    refuses the file. Those finaliser errors are dropped here; any other still reaches
    sys.unraisablehook."""
    message = _one_line(error)
    previous = sys.unraisablehook

    def quiet(report):
        finaliser = str(getattr(report.object, "__module__", "")).startswith("h5netcdf")
        if not (isinstance(report.exc_value, AttributeError) and finaliser):
            previous(report)

    sys.unraisablehook = quiet
    try:
        error.__traceback__ = None
        error.__context__ = None
        gc.collect()
    finally:
        sys.unraisablehook = previous
    return message


def _survives_reading(path: Path) -> None:
    """Opens `path` as open_atlas does and reads every chunk, in a child process first: some
    damaged headers crash HDF5 itself (a segmentation fault in h5py's dimension scales), which
    would end this process. A crash is a ValueError naming the file."""
    import subprocess

    code = ("import sys, xarray as xr\n"
            "from rubber_atlas._api import _read_every_chunk\n"
            "from pathlib import Path\n"
            "try:\n"
            "    xr.open_dataset(sys.argv[1], engine='h5netcdf').close()\n"
            "    _read_every_chunk(Path(sys.argv[1]))\n"
            "except Exception:\n"
            "    pass\n")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True)
    if done.returncode < 0:
        raise ValueError(f"{path}: the file is damaged: reading it crashed HDF5 (signal {-done.returncode}); "
                         "compute it again")


def _read_every_chunk(path: Path) -> None:
    """Reads every value of the HDF5 file `path` once, a chunk at a time; a ValueError names
    the first variable whose values cannot be read."""
    import h5py

    name = "the file's index"
    try:
        with h5py.File(path, "r") as f:
            datasets = []
            f.visititems(lambda n, item: datasets.append(n) if isinstance(item, h5py.Dataset) else None)
            for name in datasets:
                data = f[name]
                if data.chunks is None:
                    data[()]
                else:
                    for block in data.iter_chunks():
                        data[block]
            name = "the text attributes"
            written = f.attrs.get("text_attributes_crc32")
            if written is None:
                raise ValueError("the file has no text_attributes_crc32 to check them against (it was "
                                 "removed, or the file is older than the checksum); open it without check")
            if int(written) != _text_attributes_crc32(f):
                # The CRC covers every variable's text attributes: a variable removed or added
                # changes it as a changed letter does.
                raise ValueError("their CRC-32, taken over every variable, is not the one the file was "
                                 "written with: a letter of them changed, or a variable was removed or added")
    except (OSError, KeyError, RuntimeError, ValueError, TypeError, AttributeError, IndexError) as e:
        raise ValueError(f"{path}: the file is damaged: {name if name.startswith('the text') else repr(name)} "
                         f"cannot be read as written ({_one_line(e)}); compute it again") from None


def _text_attributes_crc32(f) -> int:
    """The CRC-32 of the variable-length text attributes of an atlas file's root and of its
    datasets (HDF5's global heap, which keeps their letters, has no checksum of its own), as
    `rubber-atlas` writes it in the root attribute `text_attributes_crc32` (docs/files.md)."""
    import zlib
    import h5py

    crc = 0
    for object_name, obj in [("", f)] + [(n, f[n]) for n in sorted(f.keys())]:
        for name in sorted(obj.attrs.keys()):
            info = h5py.check_string_dtype(obj.attrs.get_id(name).dtype)
            if info is None or info.length is not None:
                continue
            text = obj.attrs[name]
            text = text if isinstance(text, bytes) else text.encode()
            for part in (object_name.encode(), name.encode(), text):
                crc = zlib.crc32(part + b"\0", crc)
    return crc


def _file(path) -> Path:
    """`path` as a Path to a file that exists, refused in one line otherwise."""
    # (Path("") is ".": an empty name was refused as the folder ".".)
    if isinstance(path, str) and not path:
        raise ValueError("path is empty: give a file's name")
    given = path
    try:
        path = Path(path)
    except TypeError:
        raise TypeError(f"path must be a file's name (str or pathlib.Path), not {path!r}") from None
    # The name as given, quoted where it holds a character a terminal would not show (a NUL
    # was shown as a space), and not normalised by Path ("http://" was shown as "http:/").
    text = os.fspath(given) if isinstance(given, (str, os.PathLike)) else str(path)
    text = os.fsdecode(text)
    shown = text if text.isprintable() else repr(text)
    if "\0" in text:
        raise ValueError(f"{shown}: a file's name cannot hold a NUL character")
    if "://" in text:
        raise ValueError(f"{shown}: a URL; give the name of a local file")
    if path.is_dir():
        raise ValueError(f"{shown}: a folder, not a file")
    if not path.exists():
        raise ValueError(f"{shown}: no such file")
    if not path.is_file():
        # A FIFO would block the reader until someone writes to it.
        raise ValueError(f"{shown}: not a regular file (a device, FIFO or socket)")
    return path


def _is_atlas(ds: xr.Dataset) -> bool:
    """Whether `ds` is a file of ``rubber-atlas run`` or ``merge``."""
    return ds.attrs.get("program") == "rubber-atlas" and "scene" in ds.attrs and "cell_status" in ds


@contextlib.contextmanager
def _reading(ds: xr.Dataset):
    """Says which file is damaged when HDF5 cannot read the values of a lazily opened one (a
    corrupted chunk): a ValueError naming it, not HDF5's OSError."""
    try:
        yield
    except OSError as e:
        source = ds.encoding.get("source", "the dataset's file")
        raise ValueError(f"{source}: the file is damaged: its values cannot be read ({_one_line(e)}); "
                         "compute it again") from None


def _cells_dataset(ds, what: str) -> None:
    """Refuses what is not an atlas or a `cells` result (they have ``cell_status``), and one
    selected along its ``component`` dimension."""
    if not isinstance(ds, xr.Dataset) or "cell_status" not in ds:
        raise ValueError(f"{what} reads an atlas (open_atlas) or a cells result; this is not one (it has no "
                         "cell_status)")
    _with_components(ds, what)


def _with_components(ds: xr.Dataset, what: str) -> None:
    """Refuses a dataset whose ``component`` dimension was selected away (``isel(component=1)``
    had given numpy's "iteration over a 0-d array": an adversary pass)."""
    if "component" not in ds.dims:
        raise ValueError(f"{what} needs the dataset's component dimension, and this one has none (it was "
                         "selected along it, e.g. isel(component=1)): call it on the dataset before that "
                         "selection")


def flag_names(variable: xr.DataArray) -> dict[int, str]:
    """The CF flag meanings of a flag variable.

    Parameters
    ----------
    variable : xarray.DataArray
        A variable with CF ``flag_values`` and ``flag_meanings`` attributes (``status``,
        ``motion``, ``bounded``, ``family``, ``cell_status``, ``holds`` …).

    Returns
    -------
    dict of int to str
        {flag value: meaning}.

    Raises
    ------
    ValueError
        The variable has no ``flag_values``, or they are not one whole number per meaning.
    TypeError
        `variable` is not a DataArray.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, 2.5)
    >>> ra.flag_names(ds.cell_status)
    {0: 'ok', 1: 'no_motion', 2: 'failed', 3: 'not_computed'}
    """
    if not isinstance(variable, xr.DataArray):
        raise TypeError(f"flag_names takes a flag variable of a dataset (an xarray.DataArray), not "
                        f"{type(variable).__name__}")
    if "flag_values" not in variable.attrs:
        raise ValueError(f"{variable.name} is not a flag variable (it has no flag_values)")
    meanings = variable.attrs.get("flag_meanings")
    if not isinstance(meanings, str):
        raise ValueError(f"{variable.name} is not a flag variable (its flag_meanings are not one text)")
    values = np.atleast_1d(variable.attrs["flag_values"])
    names = meanings.split()
    # (Flag values as text, or not whole numbers, raised int()'s own words: an adversary pass.)
    if values.dtype.kind not in "iub" or values.ndim != 1 or len(values) != len(names):
        raise ValueError(f"{variable.name} is not a flag variable (its flag_values are not one whole "
                         f"number per meaning: {values.tolist()!r} for {len(names)} meanings)")
    return {int(v): n for v, n in zip(values, names)}


def _component_layout(ds: xr.Dataset) -> str:
    """"family" or "theta_min": what the `component` dimension of `ds` counts."""
    layout = ds.attrs.get("component_layout")
    if layout in _LAYOUTS:
        return str(layout)
    if "component" in ds.coords and "flag_meanings" in ds["component"].attrs:
        return "family"
    return "theta_min"


def _existing_slots(ds: xr.Dataset, one: xr.Dataset) -> list[int]:
    """The component slots of the cell `one` (a cell of `ds`) that hold a component."""
    if _component_layout(ds) == "theta_min":
        count = min(int(one.n_components), ds.sizes["component"])
        # Unmarked (the attributes dropped): slots that contradict that layout (a torus
        # beyond the first n_components slots, or an empty one among them) are another's.
        # (Without this, drop_attrs() on a dataset by families gave the empty slot of
        # well_0 for a cell of one well_pi torus: an adversary pass.)
        if "component_layout" not in ds.attrs and "family" in one:
            held = [int(v) != 255 for v in np.asarray(one["family"].values)]
            if held != [i < count for i in range(len(held))]:
                raise ValueError("which component slots hold this cell's tori is unknown: the dataset has lost "
                                 "its attributes (component_layout; e.g. drop_attrs()): open the atlas or "
                                 "compute the cells again")
        return list(range(count))
    for name, empty in (("family", 255), ("status", 255)):
        if name in one:
            return [i for i, v in enumerate(np.asarray(one[name].values)) if int(v) != empty]
    floats = [v for v in one.data_vars.values() if "component" in v.dims and v.dtype.kind == "f"]
    return [i for i in range(ds.sizes["component"]) if any(np.isfinite(v.values[i]) for v in floats)]


def components(ds: xr.Dataset, alpha: float | None = None, beta: float | None = None, **cell: float) -> list[dict]:
    """The components of one cell of an atlas or of a `cells` result, as dicts.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas (`open_atlas`) or a `cells` result.
    alpha, beta : float, optional
        The body, as grid values of the dimensions ``alpha`` and ``beta`` (an atlas).
    **cell : float
        The rest of the cell, one keyword per remaining dimension of ``cell_status``: a
        grid value (to 1e-12 relative) of a dimension with a coordinate (``kappa=…,
        energy=…``, ``excess_energy=…``, or ``lambda_=…, s=…``; ``lambda_`` since
        ``lambda`` is a Python keyword), or the index along a dimension without one
        (``cell=3`` for a 1-D `cells` result).

    Returns
    -------
    list of dict
        One dict per component, sorted by theta_min, keys as in ``rubber-atlas cell
        --json``: every per-component variable of `ds` (``theta_min`` and ``theta_max`` in
        rad, ``period`` in sqrt(b3/g), ``rotation_number``, ``drift`` in b3, … and their
        ``_error``), with ``status``, ``motion`` and ``family`` as names (e.g. "ok",
        "libration", "well_pi") and ``bounded`` as True, False or None. Empty when the cell
        has no motion.

    Raises
    ------
    KeyError
        The cell is not given by exactly the dataset's dimensions, or a value is not a grid
        value (NaN and ±inf never are) or an index out of range; the exception is a
        ValueError too.
    TypeError
        A value that is not one number.
    ValueError
        `ds` is not an atlas or a `cells` result (it has no ``cell_status``), or the file
        behind it is damaged.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=[0.8, 0.05], energy=2.5)
    >>> for c in ra.components(ds, cell=1):
    ...     print(f"{c['theta_min']:.4f} {c['theta_max']:.4f} {c['rotation_number']:.4f} {c['motion']}")
    0.0354 0.7233 0.5321 libration
    2.0334 3.1166 -0.5442 libration
    """
    _cells_dataset(ds, "components")
    cell = {("lambda" if k == "lambda_" else k): v for k, v in cell.items()}
    if alpha is not None:
        cell["alpha"] = alpha
    if beta is not None:
        cell["beta"] = beta
    dims = [d for d in ds.cell_status.dims]
    if sorted(cell) != sorted(dims):
        # Name what is wrong: the keys that are no dimension of it, and those left out.
        extra = [_KEYWORDS.get(k, k) for k in cell if k not in dims]
        missing = [_KEYWORDS.get(d, d) for d in dims if d not in cell]
        wrong = "; ".join(part for part in (
            extra and f"{', '.join(extra)} {'is' if len(extra) == 1 else 'are'} not among them",
            missing and f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} missing") if part)
        raise NotInDataset(f"give the cell by {', '.join(_KEYWORDS.get(d, d) for d in dims)} (this dataset's "
                           f"dimensions): {wrong}")
    index = {}
    for name, value in cell.items():
        shown = _KEYWORDS.get(name, name)
        if name not in ds.coords:
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
                raise TypeError(f"{shown} is {value!r}: give an index along {name} (a whole number)")
            size = ds.sizes[name]
            whole = isinstance(value, numbers.Integral) or float(value).is_integer()
            if not whole or not 0 <= int(value) < size:
                raise NotInDataset(f"{shown} = {_shown(value)} is not an index of the dimension {name} "
                                    f"(0 … {size - 1})")
            index[name] = int(value)
            continue
        value = _real(shown, value)
        if not np.isfinite(value):
            raise NotInDataset(f"{shown} = {_shown(value)} is not a grid value: give a finite number")
        with _reading(ds):
            axis = np.asarray(ds[name].values, dtype=np.float64)
        with np.errstate(invalid="ignore", over="ignore"):
            distance = np.abs(axis - value)
        # (NaN in the axis is near nothing.)
        distance[np.isnan(distance)] = np.inf
        i = int(np.argmin(distance)) if distance.size else -1
        # (Relative to the values themselves: an absolute 1e-12 below 1 took κ = 1e-12 for a
        # grid's 1e-13, and 5e-13 for its 0; an adversary pass.)
        if i < 0 or not distance[i] <= 1e-12 * max(abs(value), abs(float(axis[i]))):
            nearest = f" (nearest {_shown(float(axis[i]))})" if i >= 0 else ""
            raise NotInDataset(f"{shown} = {_shown(value)} is not a grid value{nearest}")
        index[name] = i
    with _reading(ds):
        try:
            one = ds.isel(index).load()
        except IndexError:
            # xarray (2026.9) cannot index a lazily transposed file variable.
            raise ValueError("this dataset's variables are read lazily in another order than the file's "
                             "(a transpose) and xarray cannot index them so: load it first (ds.load()) or "
                             "transpose after selecting") from None
    flags = {name: flag_names(ds[name]) for name in ("status", "motion", "family")
             if name in ds and "flag_values" in ds[name].attrs}
    out = []
    for slot in _existing_slots(ds, one):
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
    if out and "theta_min" in out[0]:
        out.sort(key=lambda e: (np.isnan(e["theta_min"]), e["theta_min"]))
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
    """Read a table file of ``rubber-atlas trajectory``, ``diagram --out`` or ``resonance --out``.

    Parameters
    ----------
    path : str or pathlib.Path
        An HDF5 file (read through h5netcdf with every attribute) or a CSV file (read
        through pandas; its leading ``# key: value`` lines become attributes, numbers
        parsed).

    Returns
    -------
    xarray.Dataset
        The columns along the table's dimension (``t`` for a trajectory, ``sample`` for a
        diagram or resonance curves), loaded into memory, with their ``long_name``,
        ``units`` and flags (HDF5); the same as `trajectory`, `diagram` or `resonance` give.

    Raises
    ------
    ValueError
        The file is missing, a folder or not a regular file, not a table of rubber-atlas (an
        atlas: `open_atlas` opens those; an HDF5 file without the root attribute
        ``program = "rubber-atlas"``), or damaged; the message names it.
    TypeError
        `path` is not a file's name.

    Examples
    --------
    >>> import os, tempfile
    >>> import rubber_atlas as ra
    >>> t = ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, periods=1, samples=20)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "t.h5")
    ...     t.to_netcdf(path, engine="h5netcdf")
    ...     back = ra.read_table(path)
    >>> back.sizes["t"], bool((back.theta == t.theta).all())
    (21, True)
    """
    path = _file(path)
    tables = "read_table reads the tables of trajectory, diagram --out and resonance --out"
    try:
        if path.suffix.lower() == ".csv":
            return _read_csv(path)
        with warnings.catch_warnings():
            # (A foreign file's unnamed dimensions: it is refused below in one line.)
            warnings.filterwarnings("ignore", message=".*phony_dims", category=UserWarning)
            ds = xr.open_dataset(path, engine="h5netcdf")
    except _DamagedTable as e:
        raise ValueError(str(e)) from None
    except (OSError, ValueError, KeyError, RuntimeError, TypeError, AttributeError, IndexError) as e:
        # (A column deleted with h5py left its dimension's reference behind: h5py's KeyError
        # "Unable to open object by token", which named neither file nor column: adversary
        # pass 43.)
        raise ValueError(f"{path}: not a table, or a damaged one ({_one_line(e)}); {tables}") from None
    with ds:
        if _is_atlas(ds):
            raise ValueError(f"{path}: an atlas (a file of rubber-atlas run or merge), not a table; {tables}, "
                             "and open_atlas opens an atlas")
        if ds.attrs.get("program") != "rubber-atlas":
            raise ValueError(f"{path}: not a table of rubber-atlas (no root attribute program = "
                             f"'rubber-atlas'); {tables}")
        _check_table(ds, path)
        with _reading(ds):
            return ds.load()


class _DamagedTable(ValueError):
    """A CSV table refused by its own checks: its message is already the one line to give."""


def _read_csv(path: Path) -> xr.Dataset:
    """A CSV table: its leading ``# key: value`` lines as attributes (numbers parsed), the
    columns along the first one."""
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
    # A rubber-atlas table names its program, ends with a newline and (since the row count
    # was added) says how many rows it has: a foreign or cut-short file is refused.
    if attrs.get("program") != "rubber-atlas":
        raise _DamagedTable(f"{path}: not a rubber-atlas table (its header has no '# program: rubber-atlas' line)")
    with path.open("rb") as f:
        f.seek(0, 2)
        size = f.tell()
        f.seek(max(size - 1, 0))
        if size == 0 or f.read(1) != b"\n":
            raise _DamagedTable(f"{path}: the table is cut short (its last line is not complete); write it again")
    # (Every table rubber-atlas writes has both lines: one without either was edited. A table
    # whose '# columns' line was deleted had been read as untyped: an adversary pass.)
    for key in ("columns", "rows"):
        if key not in attrs:
            raise _DamagedTable(f"{path}: the table's header has no '# {key}' line: the table was edited or "
                                "damaged; write it again")
    rows = attrs.pop("rows")
    if not (isinstance(rows, float) and rows >= 0 and rows == int(rows)):
        raise _DamagedTable(f"{path}: the table's '# rows' line is not a count ({rows!r}): the table was edited "
                            "or damaged; write it again")
    types = _csv_types(path, attrs.pop("columns"))
    _check_csv_fields(path)
    frame = pd.read_csv(path, comment="#", low_memory=False)
    if len(frame) != rows:
        raise _DamagedTable(f"{path}: the table is cut short or damaged: {len(frame)} rows where its header "
                            f"says {rows:.0f}; write it again")
    if list(frame.columns) != list(types):
        raise _DamagedTable(f"{path}: the column names {','.join(map(str, frame.columns))} differ from the table's "
                            f"'# columns' line ({','.join(types)}): the table was edited or damaged; write it again")
    if len(frame) == 0:
        frame = frame.astype(np.float64)
    _check_csv_numbers(path, frame)
    frame = _typed_columns(path, frame, types)
    dim = frame.columns[0]
    ds = xr.Dataset.from_dataframe(frame.set_index(dim))
    # (A pandas index is int64 whatever its column was.)
    ds = ds.assign_coords({dim: ds[dim].to_numpy().astype(types[dim])})
    ds.attrs.update(attrs)
    return ds


# The index (int32) and flag (uint8) columns of the tables rubber-atlas writes (docs/files.md);
# every other column is float64.
_TABLE_COLUMN_TYPES = {"sample": "int32", "segment": "int32", "curve": "int32", "point": "int32",
                       "component": "int32", "branch": "uint8", "stable": "uint8", "family": "uint8",
                       "closed": "uint8"}


# The columns of each table rubber-atlas writes (docs/files.md), by the column that tells
# them apart; the first is the table's dimension.
_TABLE_COLUMNS = {
    "t": ("t", "theta", "theta_dot", "phi", "psi", "x_c", "y_c", "z_c", "x_p", "y_p"),
    "segment": ("sample", "segment", "branch", "theta0", "kappa", "energy", "stable", "rho_c", "rho_p",
                "rotation_number"),
    "curve": ("sample", "curve", "point", "kappa", "energy", "rotation_number", "error_estimate", "component",
              "family", "theta_min", "theta_max", "well", "closed"),
}


def _check_table(ds: xr.Dataset, path: Path) -> None:
    """Refuses an HDF5 table whose columns are not those the program writes: one missing or
    added, not along the table's one dimension, or of another type (an index, a flag, a
    value), as `_read_csv` refuses a CSV table so edited. (The HDF5 reader took every such
    edit as given: adversary pass 43.)"""
    def edited(why: str) -> ValueError:
        return ValueError(f"{path}: {why}: the table was edited or damaged; write it again")

    kind = next((k for k in _TABLE_COLUMNS if k in ds.variables), None)
    if kind is None:
        raise edited("its columns are not those of a trajectory, diagram or resonance table")
    expected = _TABLE_COLUMNS[kind]
    dim = expected[0]
    present = set(map(str, ds.variables))
    missing = [c for c in expected if c not in present]
    extra = sorted(present - set(expected))
    if missing or extra:
        parts = ([f"no column {', '.join(missing)}"] if missing else []) + \
            ([f"a column {', '.join(extra)} it never has"] if extra else [])
        raise edited(f"the table has {' and '.join(parts)}")
    for name in expected:
        column = ds[name]
        if column.dims != (dim,):
            raise edited(f"its column {name!r} lies along {column.dims}, not ({dim!r},)")
        written = _TABLE_COLUMN_TYPES.get(name, "float64")
        if column.dtype != np.dtype(written):
            raise edited(f"its column {name!r} is {column.dtype}, where rubber-atlas writes it as {written}")


def _csv_types(path: Path, line) -> dict:
    """The column names and types of a CSV table's ``# columns: name:type …`` line, each the
    type rubber-atlas writes that column with (a type edited there had the column read as
    another: an adversary pass)."""
    types = {}
    for item in str(line).split():
        name, _, kind = item.partition(":")
        if kind not in ("float64", "int32", "uint8") or name in types:
            raise _DamagedTable(f"{path}: the table's '# columns' line is damaged at {item!r}; write it again")
        written = _TABLE_COLUMN_TYPES.get(name, "float64")
        if kind != written:
            raise _DamagedTable(f"{path}: the table's '# columns' line gives {name!r} as {kind}, where rubber-atlas "
                                f"writes it as {written}: the table was edited or damaged; write it again")
        types[name] = kind
    return types


def _csv_columns(f) -> int:
    """Reads a CSV table's file `f` past its ``# …`` lines and its column names; returns how
    many columns these name."""
    line = f.readline()
    while line.startswith(b"#"):
        line = f.readline()
    return line.count(b",") + 1


def _check_csv_fields(path: Path) -> None:
    """Refuses a CSV table with a data row of another number of fields than its column names,
    or with an empty field (pandas fills a missing or empty field with NaN, which a table may
    hold). A count of commas and line ends, and a search for an empty field, in blocks (0.2 s
    for a million rows); only a damaged table is scanned row by row, to name the row."""
    with path.open("rb") as f:
        columns = _csv_columns(f)
        commas = ends = 0
        before = b"\n"
        damaged = False
        while chunk := f.read(1 << 22):
            b = np.frombuffer(before + chunk, dtype=np.uint8)
            comma, end = b == 44, b == 10
            following = b[1:]
            damaged = damaged or bool(
                (comma[:-1] & (end[1:] | (following == 44) | (following == 13)) | end[:-1] & comma[1:]).any()
                or ((b == 32) | (b == 9)).any())
            commas += int(np.count_nonzero(comma[1:]))
            ends += int(np.count_nonzero(end[1:]))
            before = chunk[-1:]
    if damaged or commas != ends * (columns - 1):
        _locate_csv_damage(path)


def _locate_csv_damage(path: Path) -> None:
    """Names the first data row of a CSV table with another number of fields than its column
    names or an empty field, reading it in blocks of whole lines."""
    with path.open("rb") as f:
        columns = _csv_columns(f)
        row = 0
        rest = b""
        while True:
            chunk = f.read(1 << 22)
            data = rest + chunk
            cut = data.rfind(b"\n") + 1 if chunk else len(data)
            block, rest = data[:cut], data[cut:]
            if block:
                b = np.frombuffer(block, dtype=np.uint8)
                ends = np.flatnonzero(b == 10)
                commas = np.cumsum(b == 44, dtype=np.int64)[ends]
                per_row = np.diff(commas, prepend=0) + 1
                bad = np.flatnonzero(per_row != columns)
                if bad.size:
                    r = row + int(bad[0])
                    start = 0 if bad[0] == 0 else int(ends[bad[0] - 1]) + 1
                    if block[start:int(ends[bad[0]])].strip() == b"":
                        # (A blank line was named as a row of one field: an adversary pass.)
                        raise _DamagedTable(f"{path}: data row {r} is a blank line: the table was edited or "
                                            "damaged; write it again")
                    raise _DamagedTable(f"{path}: data row {r} has {per_row[bad[0]]} fields where the header "
                                        f"names {columns}: the table was edited or damaged; write it again")
                line_starts = np.concatenate(([0], ends[:-1] + 1))
                comma = np.flatnonzero(b == 44)
                following = b[np.minimum(comma + 1, b.size - 1)]
                empty = np.concatenate((comma[np.isin(following, (44, 10, 13))],
                                        line_starts[b[line_starts] == 44]))
                if empty.size:
                    r = row + int(np.searchsorted(ends, empty.min()))
                    raise _DamagedTable(f"{path}: data row {r} has an empty field: the table was edited or damaged; "
                                        "write it again")
                # (rubber-atlas writes no spaces; pandas reads " 1.0" as 1.0.)
                space = np.flatnonzero((b == 32) | (b == 9))
                if space.size:
                    r = row + int(np.searchsorted(ends, space[0]))
                    raise _DamagedTable(f"{path}: data row {r} has a space in a field: the table was edited or "
                                        "damaged; write it again")
                row += ends.size
            if not chunk:
                break


def _check_csv_numbers(path: Path, frame) -> None:
    """Refuses a CSV table with a field that is not a number: every column rubber-atlas writes
    is numeric (NaN and inf included). A NaN or an infinity must be written as rubber-atlas
    writes them (``NaN``, ``inf``, ``-inf``), and no field has a space: pandas also reads
    ``1e999`` as inf, ``NA`` or ``null`` as NaN and `` 1.0`` as 1.0 (an adversary pass)."""
    import pandas as pd

    for name in frame.columns:
        if frame[name].dtype.kind not in "iuf":
            values = pd.to_numeric(frame[name], errors="coerce")
            row = int(np.flatnonzero(values.isna() & frame[name].notna())[0])
            raise _DamagedTable(f"{path}: column {name!r}, data row {row}: {frame[name].iloc[row]!r} is not a "
                                "number: the table was edited or damaged; write it again")
    special = [name for name in frame.columns
               if frame[name].dtype.kind == "f" and not np.isfinite(frame[name].to_numpy()).all()]
    if not special:
        return
    # (Only the columns that hold one, as text: a second read of those alone.)
    text = pd.read_csv(path, comment="#", usecols=special, dtype=str, keep_default_na=False, low_memory=False)
    for name in special:
        odd = ~np.isfinite(frame[name].to_numpy()) & ~text[name].isin(("NaN", "inf", "-inf")).to_numpy()
        if odd.any():
            row = int(np.flatnonzero(odd)[0])
            raise _DamagedTable(f"{path}: column {name!r}, data row {row}: {text[name].iloc[row]!r} is not a "
                                "number as rubber-atlas writes them: the table was edited or damaged; write it again")


def _typed_columns(path: Path, frame, types: dict):
    """The index and flag columns back in their types (int32, uint8), as the HDF5 table has
    them; a value that is not a whole number in range is refused."""
    for name, kind in types.items():
        if kind == "float64":
            continue
        values = frame[name].to_numpy(dtype=np.float64)
        info = np.iinfo(kind)
        bad = np.flatnonzero(~(np.isfinite(values) & (values == np.round(values)) & (values >= info.min)
                               & (values <= info.max)))
        if bad.size:
            raise _DamagedTable(f"{path}: column {name!r}, data row {int(bad[0])}: {float(values[bad[0]])!r} is not "
                                f"a whole number of {kind}: the table was edited or damaged; write it again")
        frame[name] = values.astype(kind)
    return frame


def diagram(alpha: float, beta: float | None, nu: float | None = None, eta: float | None = None, *,
            samples: int = 2000,
            kappa_max: float = 3.0, allow_large: bool = False, shape: str = "ellipsoid",
            cut: float | None = None, profile=None) -> xr.Dataset:
    """The critical set of one body: its fixed-point curves (the paper's bifurcation diagram).

    Parameters
    ----------
    alpha : float
        α = a/b3, -1 < α < 1.
    beta : float
        β = b1/b3 > 0.
    nu, eta : float, optional
        ν = i3/i1 (0 < ν ≤ 2) and η = m b3²/i1 > 0: they do not change the set and are
        recorded. Both or neither (then 0.5 each), so that no value you did not give is
        recorded beside one you gave.
    samples : int, default 2000
        Number of θ0 samples along the curves, ≥ 2.
    kappa_max : float, default 3.0
        The largest |κ| the curves are drawn to, from 1e-20 to 1e150.
    allow_large : bool, default False
        Allow `samples` beyond 80 % of the available memory.
    shape : {"ellipsoid", "disk", "truncated_ball", "wheel", "profile"}, default "ellipsoid"
        The body (docs/bodies.md); for any but the ellipsoid `beta` is None, and the cut
        balls take `cut`.
    cut : float, optional
        h of a cut ball: -1 < h < 1 (``truncated_ball``), 0 < h < 1 (``wheel``).
    profile : array_like, optional
        With ``shape="profile"``, a body of your own (docs/bodies.md): rows (ρ, z) or
        (ρ, z, edge) of its meridian from one pole (ρ = 0) to the other, edge 1 at a sharp
        edge; the points are joined by circular arcs tangent where they meet, and `alpha` is
        the height of the centre of mass on the axis, strictly between the poles.

    Returns
    -------
    xarray.Dataset
        Along ``sample``: ``segment`` and ``branch`` (of the curve), ``theta0`` (rad), the
        permanent rotation's ``kappa`` and ``energy``, ``stable`` (flags), the radii of the
        circles of the centre of mass ``rho_c`` and the contact point ``rho_p`` (b3), and
        ``rotation_number``, N at the bottom of the well, as ``rubber-atlas diagram --out``
        writes them. ``attrs["critical_set_json"]`` holds the summary of ``diagram --json``:
        the diagram type (a … e), θ*, ε_min, the equilibria, the cusp.

    Raises
    ------
    ValueError
        A parameter out of range, `nu` without `eta` or the reverse, or too many samples
        without `allow_large`.
    TypeError
        A parameter that is not one number, `samples` not a whole number, `allow_large`
        not True or False.

    Examples
    --------
    >>> import json
    >>> import rubber_atlas as ra
    >>> d = ra.diagram(0.5, 3.0, samples=200)
    >>> summary = json.loads(d.attrs["critical_set_json"])
    >>> summary["diagram_type"], round(summary["energy_min"], 5)
    ('c', 3.04651)
    """
    if (nu is None) != (eta is None):
        given, other = ("nu", "eta") if eta is None else ("eta", "nu")
        raise ValueError(f"{given} given without {other}: give both (they do not change the critical set, "
                         "only the record) or neither (0.5 each)")
    if nu is None:
        nu = eta = 0.5
    body, shape, extra, values, named = _one_body(shape, alpha, beta, nu, eta, cut, profile)
    table, summary = _core.diagram(*values, _count("samples", samples), _real("kappa_max", kappa_max),
                                   _switch("allow_large", allow_large), **extra)
    arguments = dict(alpha=alpha, **named, nu=nu, eta=eta, samples=samples, kappa_max=kappa_max)
    attrs = _root_attrs("diagram", arguments, **_shape_attrs(extra), **body, critical_set_json=summary)
    return _table(table, attrs)


def trajectory(alpha: float, beta: float, nu: float, eta: float, kappa: float, energy: float | None = None, *,
               component: int | None = None, theta0: float | None = None, theta_dot0: float | None = None,
               periods: float | None = None, t_end: float | None = None, samples: int = 2000,
               model: str = "reduced", tol: float = 1e-12, allow_large: bool = False, shape: str = "ellipsoid",
               cut: float | None = None, profile=None) -> xr.Dataset:
    """A trajectory of the body over time, as ``rubber-atlas trajectory`` writes it.

    Parameters
    ----------
    alpha, beta, nu, eta : float
        The body: -1 < α < 1, β > 0, 0 < ν ≤ 2, η > 0.
    kappa : float
        κ, the value of F2 = J(θ) ω3.
    energy : float, optional
        ε (m g b3): start at the lower turning point θ_min of `component` (θ̇ = 0).
        Exactly one of `energy` and `theta0`.
    component : int, optional
        With `energy`: which component of {V ≤ ε} to start on, ≥ 0, in increasing
        theta_min (default 0).
    theta0 : float, optional
        Start at θ = theta0 (rad, 0 < θ0 < π) instead of a turning point.
    theta_dot0 : float, optional
        With `theta0`: θ̇ at the start (rad per unit of time sqrt(b3/g), default 0).
    periods : float, optional
        Duration in θ-periods (> 0). Exactly one of `periods` and `t_end`.
    t_end : float, optional
        Duration in units of sqrt(b3/g) (> 0).
    samples : int, default 2000
        Number of time steps: the table has ``samples + 1`` rows.
    model : {"reduced", "full"}, default "reduced"
        The reduced one-degree-of-freedom system, or the full equations of motion (ω, γ)
        with the positions.
    tol : float, default 1e-12
        Tolerance of the integrator, 1e-15 … 0.1.
    allow_large : bool, default False
        Allow `samples` beyond 80 % of the available memory, and a length that needs more
        than 1e9 integrator steps (some 40 minutes; estimated from the first θ-period).
    shape : {"ellipsoid", "disk", "truncated_ball", "wheel", "profile"}, default "ellipsoid"
        The body (docs/bodies.md); for any but the ellipsoid `beta` is None, and the cut
        balls take `cut`. A planar start (κ = 0) whose motion reaches a face is refused.
    cut : float, optional
        h of a cut ball: -1 < h < 1 (``truncated_ball``), 0 < h < 1 (``wheel``).
    profile : array_like, optional
        With ``shape="profile"``, a body of your own (docs/bodies.md): rows (ρ, z) or
        (ρ, z, edge) of its meridian from one pole (ρ = 0) to the other, edge 1 at a sharp
        edge; the points are joined by circular arcs tangent where they meet, and `alpha` is
        the height of the centre of mass on the axis, strictly between the poles.

    Returns
    -------
    xarray.Dataset
        Along ``t`` (sqrt(b3/g)): ``theta``, ``theta_dot``, ``phi``, ``psi`` (rad, rad per
        unit time), the centre of mass ``x_c``, ``y_c`` (on the plane) and ``z_c`` (its
        height) and the contact point ``x_p``, ``y_p`` (b3); attributes record the body,
        κ, ε, θ(0), θ̇(0), the model, the tolerance and ``energy_drift``, the largest
        |ε(t) − ε(0)| / (1 + |ε(0)|) over the samples (beyond max(1e3·tol, 1e-6) the
        trajectory is refused: the steps no longer resolve the motion).

    Raises
    ------
    ValueError
        A parameter out of range, no motion at `energy`, a component that does not exist,
        not exactly one of `energy`/`theta0` or of `periods`/`t_end`, a length beyond the
        step budget without `allow_large`.
    RuntimeError
        The integration failed: its steps fell below the rounding of t (a motion too fast
        for `tol`, e.g. near a pole at tiny κ in the reduced model), or the energy drifted
        beyond what the samples allow, or (with `periods`) the θ-period could not be
        computed in double precision at an extreme κ or ε (give `t_end`; the command exits
        1 for these).
    TypeError
        A parameter that is not one number, `component` or `samples` not a whole number,
        `allow_large` not True or False.

    Examples
    --------
    One θ-period of the paper's near-resonant case (κ = 0.8, ε = 2.5), from θ_min:

    >>> import rubber_atlas as ra
    >>> t = ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, periods=1, samples=100)
    >>> t.sizes["t"], sorted(k for k in t.data_vars if k.endswith("_c"))
    (101, ['x_c', 'y_c', 'z_c'])
    >>> round(float(t.theta[0]), 4) == round(float(t.attrs["theta0"]), 4)
    True
    """
    body, shape, extra, values, named = _one_body(shape, alpha, beta, nu, eta, cut, profile)
    tol = _real("tol", tol)
    # As the command: each start option goes with its start (it used to be ignored silently).
    if energy is not None and theta_dot0 is not None:
        raise ValueError("theta_dot0 goes with theta0 (a start at energy= has theta_dot = 0 at its turning point)")
    if theta0 is not None and component is not None:
        raise ValueError("component goes with energy= (theta0= picks the component that holds it)")
    component = 0 if component is None else component
    theta_dot0 = 0.0 if theta_dot0 is None else theta_dot0
    table, (k, e, t0, td0, drift) = _core.trajectory(
        *values, _real("kappa", kappa), _optional_real("energy", energy), _count("component", component),
        _optional_real("theta0", theta0), _real("theta_dot0", theta_dot0), _optional_real("periods", periods),
        _optional_real("t_end", t_end), _count("samples", samples), _text("model", model, '"reduced" or "full"'), tol,
        _switch("allow_large", allow_large), **extra)
    arguments = dict(alpha=alpha, **named, nu=nu, eta=eta, kappa=kappa, energy=energy, component=component,
                     theta0=theta0, theta_dot0=theta_dot0, periods=periods, t_end=t_end, samples=samples,
                     model=model, tol=tol)
    attrs = _root_attrs("trajectory", arguments, model=str(model), **_shape_attrs(extra), **body,
                        kappa=k, energy=e, theta0=t0, theta_dot0=td0, tolerance=tol, energy_drift=drift)
    return _table(table, attrs)


def _rotation_number(value) -> float:
    """A number, or a fraction "p/q" as text."""
    if not isinstance(value, str):
        return _real("rotation_number", value)
    try:
        # (ASCII digits without '_' separators, as the command line reads them: Python's
        # Fraction alone takes "1_0/7" as 10/7 and other scripts' digits.)
        if not value.isascii() or "_" in value:
            raise ValueError(value)
        return float(Fraction(value))
    except (ValueError, ZeroDivisionError, OverflowError):
        shown = repr(value) if len(value) <= 40 else repr(value[:30]) + f" … ({len(value)} characters)"
        raise ValueError(f"invalid rotation_number = {shown}: give a number or a fraction \"p/q\" with q != 0, "
                         "e.g. \"-1/7\"") from None


def resonance(alpha: float, beta: float, nu: float, eta: float, rotation_number, *, kappa_min: float = 0.01,
              kappa_max: float = 2.0, energy_min: float | None = None, energy_max: float = 5.0,
              grid: int = 48, tol: float = 1e-10, shape: str = "ellipsoid", cut: float | None = None,
              profile=None) -> xr.Dataset:
    """The curves N = p/q of the (κ, ε) plane in a window, traced by continuation.

    Parameters
    ----------
    alpha, beta, nu, eta : float
        The body: -1 < α < 1, β > 0, 0 < ν ≤ 2, η > 0.
    rotation_number : float or str
        The rotation number N of the curves, a number or a fraction "p/q" (e.g. "-1/7").
    kappa_min, kappa_max : float, default 0.01 and 2.0
        The κ window, 0 < kappa_min < kappa_max.
    energy_min : float, optional
        Bottom of the ε window (m g b3); default the bottom of V over the κ window.
    energy_max : float, default 5.0
        Top of the ε window (m g b3).
    grid : int, default 48
        Cells per side of the coarse grid on which the curves are first bracketed, ≥ 4.
    tol : float, default 1e-10
        Solver tolerance (1e-15 … 0.1); points are located to it.
    shape : {"ellipsoid", "disk", "truncated_ball", "wheel", "profile"}, default "ellipsoid"
        The body (docs/bodies.md). The edged bodies take no `beta` (give None): the disk has
        α alone, the cut balls α and `cut`.
    cut : float, optional
        h of the cut balls (required for them, refused for the others).
    profile : array_like, optional
        With ``shape="profile"``, a body of your own (docs/bodies.md): rows (ρ, z) or
        (ρ, z, edge) of its meridian from one pole (ρ = 0) to the other, edge 1 at a sharp
        edge; the points are joined by circular arcs tangent where they meet, and `alpha` is
        the height of the centre of mass on the axis, strictly between the poles.

    Returns
    -------
    xarray.Dataset
        Along ``sample``: ``curve`` and ``point`` (indices), ``kappa``, ``energy``,
        ``rotation_number`` and its ``error_estimate``, the ``component`` and its turning
        points ``theta_min``, ``theta_max`` (rad), the bottom of its ``well`` (rad) and
        ``closed`` (a flag: the curve closes on itself), as ``rubber-atlas resonance --out``
        writes them.

    Raises
    ------
    ValueError
        A parameter out of range, an empty window, or a `rotation_number` that is not a
        number or a fraction "p/q" (q ≠ 0).
    TypeError
        A parameter that is not one number, `grid` not a whole number.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> curves = ra.resonance(0.5, 3.0, 0.5, 0.5, "-1/7", grid=12)
    >>> bool(abs(curves.rotation_number + 1 / 7).max() < 1e-6)
    True
    >>> sorted(set(curves.component.values.tolist()))
    [0, 1]

    The N = 0 curve of a truncated ball:

    >>> ball = ra.resonance(0.2, None, 0.7, 1.3, 0, shape="truncated_ball", cut=0.4, grid=24)
    >>> ball.attrs["shape"], bool((abs(ball.rotation_number) <= ball.error_estimate + 1e-10).all())
    ('truncated_ball', True)
    """
    target = _rotation_number(rotation_number)
    body, shape, extra, values, named = _one_body(shape, alpha, beta, nu, eta, cut, profile)
    window = _reals(kappa_min=kappa_min, kappa_max=kappa_max, energy_max=energy_max)
    tol = _real("tol", tol)
    table, e_min = _core.resonance(*values, target, window["kappa_min"], window["kappa_max"],
                                   _optional_real("energy_min", energy_min), window["energy_max"],
                                   _count("grid", grid), tol, **extra)
    arguments = dict(alpha=alpha, **named, nu=nu, eta=eta, rotation_number=rotation_number,
                     kappa_min=kappa_min, kappa_max=kappa_max, energy_min=energy_min, energy_max=energy_max,
                     grid=grid, tol=tol)
    attrs = _root_attrs("resonance", arguments, **_shape_attrs(extra), **body, rotation_number=target, tolerance=tol,
                        kappa_window=np.array([window["kappa_min"], window["kappa_max"]], dtype=float),
                        energy_window=np.array([e_min, window["energy_max"]], dtype=float))
    return _table(table, attrs)


def census(alpha: float, nu: float, eta: float, *, shape: str, cut: float | None = None, profile=None,
           tol: float = 1e-10, resolution: int = 64) -> dict:
    """Which integers N reaches over the whole (κ, ε) plane of a body other than the ellipsoid
    (docs/bodies.md, "Which integers N reaches"): `rubber-atlas verdict --shape … --json`.

    The paper's hypothesis is the ellipsoid's (`verdict`); for the disk, the cut balls and a
    profile this reports the integer resonances found, each with a point where the path runs
    away, and what the high-energy limit proves. It claims no boundedness.

    Parameters
    ----------
    alpha, nu, eta : float
        The body: α its centre of mass (docs/bodies.md), 0 < ν ≤ 2, η > 0.
    shape : str
        "disk", "truncated_ball", "wheel" or "profile".
    cut : float, optional
        h of the cut balls.
    profile : rows of (rho, z) or (rho, z, edge), optional
        The meridian of shape="profile", as for `cells`.
    tol : float, default 1e-10
        The cell solver's tolerance (1e-13 … 1e-4): N at a point equals the integer to this.
    resolution : int, default 64
        κ-lines of each kind and base energies per line (8 … 4096).

    Returns
    -------
    dict
        ``shape``, the shape's parameters, ``nu``, ``eta``; ``integers`` (reached where the
        path runs away), ``bracketed`` (between samples, no point confirmed),
        ``counterexamples`` (κ, ε, N, θ range, drift and its error, family, component),
        ``from_limits``, ``unbounded_motion`` (True, or None when none was found),
        ``high_energy`` (N∞'s limit at λ → 0, extrema, sign changes) and ``evidence``.

    Raises
    ------
    ValueError
        A parameter out of range, or shape="ellipsoid" (use `verdict`).
    TypeError
        A parameter that is not one number, `resolution` not a whole number.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> c = ra.census(0.2, 0.7, 1.3, shape="truncated_ball", cut=0.4, resolution=16)
    >>> 0 in c["integers"], c["unbounded_motion"]
    (True, True)
    """
    if isinstance(shape, str) and shape == "ellipsoid":
        raise ValueError("census: shape = \"ellipsoid\" has the paper's hypothesis: use verdict(alpha, beta, nu, eta)")
    body, shape, extra, values, named = _one_body(shape, alpha, None, nu, eta, cut, profile)
    return json.loads(_core.census(*values, _real("tol", tol), _count("resolution", resolution), **extra))


_CASES = {"1": 0, "2": 1, "not_covered": 2}


def _padded(rows: list[list], fill, dtype, shape: tuple, width: int) -> np.ndarray:
    """Per-body lists padded with `fill` to `width`, shaped `shape + (width,)`."""
    if dtype is np.bytes_:
        # Fixed-width text as wide as the longest entry (np.full of b"" would give one byte).
        dtype = np.dtype(f"S{max([len(x) for row in rows for x in row] + [len(fill), 1])}")
    out = np.full((len(rows), width), fill, dtype=dtype)
    for i, row in enumerate(rows):
        out[i, :len(row)] = row
    return out.reshape(shape + (width,))


# The variables and dimension of `verdict`'s result besides the bodies' dimensions.
_VERDICT_OUTPUTS = ("holds", "case", "kappa_max", "kappa_max_error", "fail_margin", "counterexamples", "kappa",
                    "energy", "rotation_number", "theta_min", "theta_max", "family", "component", "drift",
                    "verdict_json", "counterexample")


def verdict(alpha, beta, nu, eta, *, tol: float = 1e-10, resolution: int = 64,
            threads: int | None = None, allow_large: bool = False) -> xr.Dataset:
    """The verdict of the paper's boundedness hypothesis for each body, computed in parallel.

    The hypothesis: paths are bounded (case 1) for β² < 1 + α except rolling over the top at
    κ = 0, and (case 2) for β² > 1 + α, α > 0, when κ > κ_max, the fold of the N = 0
    resonance curve. A counterexample is a torus on an integer resonance N ∈ ℤ with a drift
    Δζ ≠ 0 (its path runs away) where the hypothesis says bounded. See docs/model.md.

    Parameters
    ----------
    alpha, beta, nu, eta : float, array_like or xarray.DataArray
        The bodies (-1 < α < 1, β > 0, 0 < ν ≤ 2, η > 0), broadcast together as in `cells`.
    tol : float, default 1e-10
        Solver tolerance (1e-13 … 1e-4).
    resolution : int, default 64
        Sampling of the (κ, ε) plane: κ-lines and energies per line, 8 … 4096; higher finds
        narrower resonance regions, and costs about its square in time (the paper's body:
        0.5 s at 64, about 9 minutes at 4096) and memory (counted as
        about 280 r² bytes a body while it is sampled, and 100 MB besides: 400 MB at 1024,
        4.8 GB at 4096).
    threads : int, optional
        Number of threads (≥ 1); by default rayon's pool.
    allow_large : bool, default False
        Compute even when the bodies' results (about 128 kB a body), or the samples of the
        bodies computed at once (one a thread), would take over 80 % of the available memory.
        A single body's samples that would not fit are refused whatever this says.

    Returns
    -------
    xarray.Dataset
        Over the broadcast dimensions (below ``...``), with the inputs as coordinates:

        - ``holds`` (...), uint8 flags: fails, holds, or no_value where the hypothesis does
          not cover the body or the verdict is undecided;
        - ``case`` (...), fixed-width bytes: "1", "2" or "not_covered";
        - ``kappa_max`` (...) and ``kappa_max_error`` (...): κ_max (case 2, else NaN);
        - ``fail_margin`` (...): positive where N reaches an integer in the region the
          hypothesis covers (continuous in the body's parameters);
        - ``counterexamples`` (...), int32: the number of counterexamples found;
        - along ``counterexample`` (..., counterexample), one entry per counterexample,
          padded where a body has fewer than the most: ``kappa``, ``energy``,
          ``rotation_number``, ``theta_min``, ``theta_max`` (rad) and ``drift`` (|Δζ| per
          θ-period, b3), NaN as padding; ``family`` (bytes, the torus family's name, "" as
          padding) and ``component`` (int32, the rank of the component among its cell's
          components in increasing theta_min, as `trajectory` takes it; -1 as padding);
        - ``verdict_json`` (...): each body's whole ``rubber-atlas verdict --json`` object
          (the high-energy limit, the margins, the evidence).

    Raises
    ------
    ValueError
        A parameter out of range, inputs that do not broadcast, a dimension named after
        a variable of the result, or more bodies than the memory holds (without
        `allow_large`).
    TypeError
        An input that is not real numbers (as in `cells`), `resolution` or `threads` not a
        whole number.

    See Also
    --------
    boundaries : the β at which the verdict changes, at one α.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> v = ra.verdict([0.5, 0.2], [0.5, 3.0], 0.5, 0.5, resolution=8)
    >>> v.case.values.astype(str).tolist(), ra.flag_names(v.holds)[int(v.holds[0])]
    (['1', '2'], 'fails')
    >>> v.counterexamples.values.tolist(), dict(v.kappa.sizes)
    ([2, 0], {'cell': 2, 'counterexample': 2})
    >>> [round(float(k), 3) for k in v.kappa[0]], bool(v.kappa[1].isnull().all())
    ([1.0, 10000.0], True)
    """
    given = {"alpha": alpha, "beta": beta, "nu": nu, "eta": eta}
    tol, resolution, threads = _real("tol", tol), _count("resolution", resolution), _optional_count("threads", threads)
    allow_large = _switch("allow_large", allow_large)
    dims, layout, coords, places = _broadcast(
        given, outputs=_VERDICT_OUTPUTS,
        check=lambda n: _refuse_memory("verdict", n * _VERDICT_BYTES, allow_large, "give fewer bodies at a time"))
    shape = layout[0].shape
    flat = [np.asarray(a, dtype=np.float64).reshape(-1).tolist() for a in layout]
    try:
        found = [json.loads(v) for v in _core.verdicts(*flat, tol, resolution, threads, allow_large)]
    except ValueError as e:
        raise _located(e, shape, places, {}) from None

    def column(get, dtype):
        return np.array([get(v) for v in found], dtype=dtype).reshape(shape)

    number = {"units": "1"}
    examples = [v["counterexamples"] for v in found]
    width = max((len(c) for c in examples), default=0)
    along = dims + ("counterexample",)

    def per_example(key, fill, dtype, get=None):
        get = get or (lambda c: c[key])
        return _padded([[get(c) for c in row] for row in examples], fill, dtype, shape, width)

    def text(value: str) -> bytes:
        return str(value).encode("ascii", "replace")

    def described(long_name: str, source: dict) -> dict:
        """`long_name` with the units (and their comment) of the variable or coordinate `source`."""
        return {"long_name": long_name, **{k: source[k] for k in ("units", "comment") if source.get(k)}}

    fields = {m["name"]: m for m in _core.variables(None)}
    data_vars = {
        "holds": (dims, column(lambda v: 255 if v["holds"] is None else int(v["holds"]), np.uint8),
                  {"long_name": "whether the boundedness hypothesis holds for the body", "units": "1",
                   "flag_values": np.array([0, 1, 255], dtype=np.uint8),
                   "flag_meanings": "fails holds no_value"}),
        "case": (dims, column(lambda v: text(v["case"]), np.bytes_),
                 {"long_name": "part of the hypothesis that covers the body: 1 (beta^2 < 1 + alpha), "
                               "2 (beta^2 > 1 + alpha, alpha > 0) or not_covered"}),
        "kappa_max": (dims, column(lambda v: np.nan if v["kappa_max"] is None else v["kappa_max"], float),
                      {"long_name": "fold kappa_max of the N = 0 curve (case 2)", **_coordinate_attrs("kappa")}),
        "kappa_max_error": (dims, column(lambda v: np.nan if v["kappa_max_error"] is None else v["kappa_max_error"], float),
                            {"long_name": "estimated absolute error of kappa_max", **_coordinate_attrs("kappa")}),
        "fail_margin": (dims, column(lambda v: v["fail_margin"], float),
                        {"long_name": "fail margin: positive where N reaches an integer", **number}),
        "counterexamples": (dims, column(lambda v: len(v["counterexamples"]), np.int32),
                            {"long_name": "number of counterexamples found", **number}),
        "kappa": (along, per_example("kappa", np.nan, float),
                  described("kappa of the counterexample", _coordinate_attrs("kappa"))),
        "energy": (along, per_example("energy", np.nan, float),
                   described("energy of the counterexample", _coordinate_attrs("energy"))),
        "rotation_number": (along, per_example("rotation_number", np.nan, float),
                            described("rotation number N of the counterexample (an "
                                      "integer to the solver's tolerance)", fields["rotation_number"])),
        "theta_min": (along, per_example("theta_min", np.nan, float),
                      described("lower turning point of theta of the counterexample",
                                fields["theta_min"])),
        "theta_max": (along, per_example("theta_max", np.nan, float),
                      described("upper turning point of theta of the counterexample",
                                fields["theta_max"])),
        "family": (along, per_example("family", b"", np.bytes_, lambda c: text(c.get("family", ""))),
                   {"long_name": "torus family of the counterexample (empty: none, or not given)"}),
        "component": (along, per_example("component", -1, np.int32, lambda c: int(c.get("component", -1))),
                      {"long_name": "rank of the counterexample's component among its cell's components in "
                                    "increasing theta_min (-1: none, or not given)", **number}),
        "drift": (along, per_example("drift", np.nan, float),
                  described("drift |delta zeta| of the centre of mass over one theta-period of "
                            "the counterexample", fields["drift"])),
        "verdict_json": (dims, column(lambda v: json.dumps(v, ensure_ascii=True).encode(), np.bytes_),
                         {"long_name": "the verdict as `rubber-atlas verdict --json` prints it"}),
    }
    for name in given:
        cdims, cvalues = coords[name]
        coords[name] = xr.Variable(cdims, cvalues, _coordinate_attrs(name), {"_FillValue": None})
    arguments = dict(given, tol=tol, resolution=resolution)
    attrs = _root_attrs("verdict", arguments, title="rubber-atlas verdicts of the boundedness hypothesis",
                        tolerance=tol, resolution=resolution)
    return xr.Dataset(data_vars, coords, attrs)


def _flag(values, meanings: str) -> dict:
    return {"units": "1", "flag_values": np.asarray(values, dtype=np.uint8), "flag_meanings": meanings}


def boundaries(alpha: float, nu: float, eta: float, *, beta_min: float = 0.05, beta_max: float = 50.0,
               scan: int = 48, tol: float = 1e-10, resolution: int = 64, threads: int | None = None) -> xr.Dataset:
    """The β at which the verdict of the boundedness hypothesis changes, at one α.

    As ``rubber-atlas verdict --boundaries``: a log-spaced scan of β, then each change
    located by root-finding on the quantity that changes sign there (the fail margin, or
    β² − 1 − α where the case changes).

    Parameters
    ----------
    alpha : float
        α, -1 < α < 1.
    nu, eta : float
        ν (0 < ν ≤ 2) and η > 0.
    beta_min, beta_max : float, default 0.05 and 50.0
        The β range, 0 < beta_min < beta_max.
    scan : int, default 48
        Number of log-spaced bodies scanned first, 4 … 10000.
    tol : float, default 1e-10
        Solver tolerance (1e-13 … 1e-4).
    resolution : int, default 64
        Sampling of each body's (κ, ε) plane, as in `verdict` (32 … 4096).
    threads : int, optional
        Number of threads (≥ 1); by default rayon's pool.

    Returns
    -------
    xarray.Dataset
        Along ``boundary``: ``boundary_beta`` and its error bound ``boundary_error``,
        ``quantity`` (bytes: what changes sign), and the case and verdict below and above
        (``case_below``, ``holds_below``, ``case_above``, ``holds_above``: uint8 flags; the
        verdicts judged just beyond the boundary's error bar on each side, see
        docs/files.md).
        Along ``scan``: ``scan_beta``, ``scan_case``, ``scan_holds``. The whole ``--json``
        object is ``attrs["boundaries_json"]``.

    Raises
    ------
    ValueError
        A parameter out of range.
    TypeError
        A parameter that is not one number, `scan`, `resolution` or `threads` not a whole
        number.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> b = ra.boundaries(0.5, 0.5, 0.5, beta_min=0.5, beta_max=1.0, scan=4, resolution=32)
    >>> [round(float(x), 3) for x in b.boundary_beta]
    [0.744]
    >>> names = ra.flag_names(b.holds_below)
    >>> names[int(b.holds_below[0])], names[int(b.holds_above[0])]
    ('fails', 'holds')
    """
    numbers = _reals(alpha=alpha, nu=nu, eta=eta, beta_min=beta_min, beta_max=beta_max)
    tol = _real("tol", tol)
    found = json.loads(_core.boundaries(*numbers.values(), _count("scan", scan), tol, _count("resolution", resolution),
                                        _optional_count("threads", threads)))
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
                        alpha=numbers["alpha"], nu=numbers["nu"], eta=numbers["eta"],
                        beta_range=np.asarray(found["beta_range"], dtype=float), tolerance=tol,
                        resolution=int(resolution), boundaries_json=json.dumps(found))
    return xr.Dataset(data_vars, attrs=attrs)
