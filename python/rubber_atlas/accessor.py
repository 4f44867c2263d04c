"""The `.rubber` accessor of xarray Datasets (atlases and `cells` results): the common steps
of a session, one call each."""

from __future__ import annotations

import functools
import math
from fractions import Fraction

import numpy as np
import xarray as xr

from . import _api

# Short axis labels of the planes' dimensions.
_LABELS = {"kappa": "κ", "energy": "ε", "excess_energy": "ε − V_min", "lambda": "λ = κ/√ε",
           "s": "s = 1/√ε", "alpha": "α", "beta": "β", "cut": "h", "nu": "ν", "eta": "η"}
# At most this many resonance contours per panel: fewer denominators beyond.
_MAX_LEVELS = 60
# The largest max_q of plot_slice: beyond it the contours would be lowered to fewer anyway.
_MAX_Q = 100
# A trajectory's plane is drawn with equal scales only while the path's extents differ by at
# most this factor: a drifting path, long and thin, would otherwise shrink to a flat line.
_EQUAL_ASPECT_UP_TO = 4.0


def resonances(lo: float, hi: float, max_q: int = 7) -> list[float]:
    """The rational numbers p/q with q ≤ `max_q` in [lo, hi].

    Parameters
    ----------
    lo, hi : float
        The interval.
    max_q : int, default 7
        The largest denominator, ≥ 1.

    Returns
    -------
    list of float
        The values p/q, sorted, each once.

    Examples
    --------
    >>> from rubber_atlas.accessor import resonances
    >>> [round(x, 4) for x in resonances(-0.5, 0.5, max_q=3)]
    [-0.5, -0.3333, 0.0, 0.3333, 0.5]
    """
    found = {
        Fraction(p, q)
        for q in range(1, max_q + 1)
        for p in range(int(np.floor(lo * q)), int(np.ceil(hi * q)) + 1)
    }
    return sorted(float(f) for f in found if lo <= f <= hi)


def _contour_levels(lo: float, hi: float, max_q: int) -> tuple[int, list[float]]:
    """The largest q ≤ `max_q` whose values p/q in [lo, hi] number at most `_MAX_LEVELS`, with
    those values; where even the integers are more, q = 1 and the first `_MAX_LEVELS` of them.
    The count only grows with q, so q is found by bisection, and a q whose p/q (repeats
    counted, from the ends alone) are too many to list is not listed: N's range reaches 1e12
    beside a separatrix, and `max_q` 1000 took minutes one q at a time (adversary pass 34)."""
    def fits(q: int) -> bool:
        listed = sum(max(0, math.floor(hi * k) - math.ceil(lo * k) + 1) for k in range(1, q + 1))
        return listed <= _MAX_LEVELS or (listed <= 400 * _MAX_LEVELS and len(resonances(lo, hi, q)) <= _MAX_LEVELS)

    if not fits(1):
        first = math.ceil(lo)
        return 1, [float(i) for i in range(first, first + _MAX_LEVELS) if i <= hi]
    good, bad = 1, max_q + 1
    while bad - good > 1:
        mid = (good + bad) // 2
        good, bad = (mid, bad) if fits(mid) else (good, mid)
    return good, resonances(lo, hi, good)


def _family_codes(ds: xr.Dataset) -> dict[str, int]:
    """{name: code} of the torus families the `family` flags of `ds` know."""
    if "family" in ds:
        _api._with_components(ds, "ds.rubber.family (and families)")
    if "family" not in ds:
        # (A dataset of no rubber-atlas at all was told it came from an old version of it:
        # adversary pass of 2026-11-28.)
        if ds.attrs.get("program") != "rubber-atlas" and "cell_status" not in ds:
            raise ValueError("this dataset is not an atlas of rubber-atlas (no `family` variable, no "
                             "`cell_status`, no attribute program = 'rubber-atlas'): open one with "
                             "rubber_atlas.open_atlas, or compute one with rubber_atlas.cells")
        raise ValueError("this dataset has no `family` variable: it was written by a version of rubber-atlas "
                         "from before the families of tori (its components are numbered by increasing "
                         "theta_min); compute it again (`rubber-atlas run`, or rubber_atlas.cells)")
    return {name: code for code, name in _api.flag_names(ds["family"]).items() if name != "no_value"}


def _reads(method):
    """The method reading a damaged file says so, naming the file (see `_api._reading`)."""

    @functools.wraps(method)
    def reading(self, *args, **kwargs):
        with _api._reading(self._ds):
            return method(self, *args, **kwargs)

    return reading


@xr.register_dataset_accessor("rubber")
class RubberAccessor:
    """The ``.rubber`` accessor of atlases (`open_atlas`) and `cells` results.

    ``ds.rubber.components(...)``, ``ds.rubber.flags(name)``, ``ds.rubber.families()``,
    ``ds.rubber.family(name)``, ``ds.rubber.plot_slice(...)``.

    Examples
    --------
    >>> import rubber_atlas as ra
    >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=[0.8, 1.0], energy=2.5)
    >>> ds.rubber.flags("motion")
    {0: 'libration', 1: 'fixed_point', 2: 'rotation', 255: 'no_value'}
    """

    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    @_reads
    def components(self, alpha: float | None = None, beta: float | None = None, **cell) -> list[dict]:
        """The components of one cell as dicts (see `rubber_atlas.components`).

        Parameters
        ----------
        alpha, beta : float, optional
            The body, as grid values (an atlas).
        **cell : float
            The rest of the cell by the dataset's other dimensions: grid values (``kappa=…,
            energy=…``, ``lambda_=…, s=…``) or indices (``cell=3``).

        Returns
        -------
        list of dict
            One dict per component, sorted by theta_min, one key per per-component
            variable of the dataset (named as in ``rubber-atlas cell --json``; the errors as
            flat ``*_error`` keys); ``status``, ``motion`` and ``family`` as names,
            ``bounded`` as True/False/None.

        Raises
        ------
        KeyError
            The cell is not given by the dataset's dimensions, or is not on the grid (NaN
            and ±inf never are); the exception is a ValueError too.
        TypeError
            A value that is not one number.
        ValueError
            The dataset is not an atlas or a `cells` result, or its file is damaged.

        Examples
        --------
        >>> import rubber_atlas as ra
        >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=[0.8, 0.05], energy=2.5)
        >>> [round(c["rotation_number"], 4) for c in ds.rubber.components(cell=1)]
        [0.5321, -0.5442]
        """
        return _api.components(self._ds, alpha, beta, **cell)

    def flags(self, name: str) -> dict[int, str]:
        """The meanings of the flag variable `name`.

        Parameters
        ----------
        name : str
            A flag variable of the dataset: ``status``, ``motion``, ``bounded``,
            ``family``, ``cell_status``.

        Returns
        -------
        dict of int to str
            {flag value: meaning}.

        Raises
        ------
        KeyError
            No variable `name`.
        ValueError
            `name` is not a flag variable.

        Examples
        --------
        >>> import rubber_atlas as ra
        >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, 2.5)
        >>> ds.rubber.flags("bounded")
        {0: 'unbounded', 1: 'bounded', 255: 'no_value'}
        """
        return _api.flag_names(self._ds[name])

    @_reads
    def families(self) -> list[str]:
        """The names of the torus families present in the dataset.

        Returns
        -------
        list of str
            In order of their codes, e.g. ``['well_0', 'well_pi', 'over_the_top']``: the
            families of the ``component`` coordinate (layout "family"), or those that some
            cell has (layout "theta_min").

        Raises
        ------
        ValueError
            The dataset has no ``family`` variable (an atlas from before families of tori).

        Examples
        --------
        >>> import rubber_atlas as ra
        >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=[0.05, 0.8], energy=2.5)
        >>> ds.rubber.families()
        ['well_0', 'well_pi']
        """
        ds = self._ds
        names = {code: name for name, code in _family_codes(ds).items()}
        if _api._component_layout(ds) == "family":
            codes = [int(c) for c in ds["component"].values if int(c) in names]
        else:
            codes = sorted(int(c) for c in np.unique(np.asarray(ds["family"].values)) if int(c) in names)
        return [names.get(c, f"family_{c}") for c in codes]

    @_reads
    def family(self, name: str) -> xr.Dataset:
        """The per-component variables of one torus family, as fields over the plane.

        The families label a component of {V ≤ ε} by the minima of V it encloses: "well_0"
        (a well whose minimum is at θ < π/2), "well_pi" (at θ > π/2), "well_equator" (α = 0
        with the single minimum at θ = π/2) and "over_the_top" (κ = 0, rolling over the
        top); a torus above a saddle, round both wells, belongs to the family of the well V
        keeps at large κ ("well_pi" for α > 0). A profile with two wells on one side has a
        second torus there, round the shallower well: "well_0_second" or "well_pi_second". A family's rotation number is continuous
        over the plane except across a critical curve, so its resonance curves are contours
        of one field. See docs/model.md.

        Parameters
        ----------
        name : str
            The family's name (a meaning of the ``family`` flags).

        Returns
        -------
        xarray.Dataset
            Every variable of the dataset with a ``component`` dimension (``theta_min``,
            ``rotation_number``, ``drift``, … and their ``_error``, the flags), for that
            family, over the dataset's other dimensions (the plane, and α, β for an atlas),
            with its coordinates; NaN (floats) and 255 (flags) where the cell has no torus
            of the family. ``attrs["family"]`` is `name`.

        Raises
        ------
        ValueError
            The dataset has no ``family`` variable (written before families of tori).
        KeyError
            `name` is not a family, or none of its tori is in the dataset; the message lists
            the families present.

        Examples
        --------
        >>> import numpy as np
        >>> import rubber_atlas as ra
        >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=np.linspace(0.2, 1.0, 5), energy=[2.0, 2.5, 3.0],
        ...               fields=["rotation_number"])
        >>> ds.rubber.families()
        ['well_0', 'well_pi']
        >>> pi = ds.rubber.family("well_pi")
        >>> dict(pi.rotation_number.sizes)
        {'kappa': 5, 'energy': 3}
        >>> pi.rotation_number.sel(energy=2.5).round(4).values.tolist()
        [-0.6646, -0.7721, -0.8171, -0.8152, nan]
        >>> ds.rubber.family("well_0").rotation_number.sel(energy=3.0).round(4).values.tolist()
        [0.601, 0.6633, 0.6857, nan, nan]
        """
        ds = self._ds
        codes = _family_codes(ds)
        present = self.families()
        if name not in codes or name not in present:
            what = "no torus family" if name not in codes else "no torus of the family"
            raise KeyError(f"{what} {name!r} in this dataset: it has {', '.join(present) or 'none'}")
        code = codes[name]
        per_component = [v for v in ds.data_vars if "component" in ds[v].dims]
        if _api._component_layout(ds) == "family":
            out = ds[per_component].sel(component=code, drop=True)
        else:
            # Components in increasing theta_min: the one of this family in each cell. At κ = 0
            # two mirror twins (the body leaning either way) may both be: the one at larger θ
            # is taken, as the family layout keeps it.
            mask = ds["family"] == code
            fields = {}
            for v in per_component:
                var = ds[v]
                fill = _api._fill(var.dtype)
                picked = xr.full_like(var.isel(component=0, drop=True), fill)
                for slot in range(ds.sizes["component"]):
                    picked = xr.where(mask.isel(component=slot, drop=True),
                                      var.isel(component=slot, drop=True), picked)
                fields[v] = picked.astype(var.dtype).assign_attrs(var.attrs)
            out = xr.Dataset(fields, attrs=dict(ds.attrs))
            for c, coord in ds.coords.items():
                if "component" not in coord.dims and c not in out.coords:
                    out = out.assign_coords({c: coord})
        out.attrs = dict(ds.attrs, family=name)
        return out

    @_reads
    def plot_trajectory(self):
        """Draws a trajectory (from `trajectory`, or a file of `rubber-atlas trajectory` read
        with `read_table`): the paths of the centre of mass and of the contact point on the
        plane, and θ(t).

        The plane is drawn to scale unless the path is much longer one way than the other (a
        drifting path, e.g. on an integer resonance), when each axis gets its own scale so that
        the path does not shrink to a line (the title says so).

        Returns
        -------
        matplotlib.figure.Figure
            Two panels: the plane (x, y in units of b3) and θ over t (units of √(b3/g)).

        Raises
        ------
        ValueError
            The dataset is not a trajectory (it lacks t, theta, x_c, y_c, x_p or y_p), or
            has no rows.

        Examples
        --------
        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> import rubber_atlas as ra
        >>> path = ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, theta0=0.4670288, periods=7)
        >>> fig = path.rubber.plot_trajectory()
        >>> [ax.get_title() for ax in fig.axes]
        ['on the plane', 'theta(t)']
        """
        import matplotlib.pyplot as plt

        ds = self._ds
        missing = [k for k in ("t", "theta", "x_c", "y_c", "x_p", "y_p") if k not in ds.variables]
        if missing:
            raise ValueError(f"plot_trajectory draws a trajectory; this dataset lacks {', '.join(missing)}")
        cols = {k: np.asarray(ds[k].values) for k in ("t", "theta", "x_c", "y_c", "x_p", "y_p")}
        if not cols["t"].size:
            raise ValueError("the trajectory is empty (t has no values): nothing to draw")
        fig, (ax_xy, ax_t) = plt.subplots(1, 2, figsize=(11, 5), gridspec_kw={"width_ratios": [1, 1.2]},
                                          layout="constrained")
        ax_xy.plot(cols["x_p"], cols["y_p"], lw=0.6, color="tab:orange", label="contact point")
        ax_xy.plot(cols["x_c"], cols["y_c"], lw=0.9, color="tab:blue", label="centre of mass")
        ax_xy.plot(cols["x_c"][:1], cols["y_c"][:1], "ko", ms=4, label="start")
        xs = np.concatenate([cols["x_p"], cols["x_c"]])
        ys = np.concatenate([cols["y_p"], cols["y_c"]])
        width, height = float(np.ptp(xs)), float(np.ptp(ys))
        if min(width, height) > 0 and max(width, height) / min(width, height) <= _EQUAL_ASPECT_UP_TO:
            ax_xy.set_aspect("equal", adjustable="datalim")
            ax_xy.set_title("on the plane", fontsize=9)
        else:
            ax_xy.set_title("on the plane (axes not to scale)", fontsize=9)
        ax_xy.set_xlabel("x / b3")
        ax_xy.set_ylabel("y / b3")
        # Above the axes, outside them: never over the path.
        ax_xy.legend(loc="lower center", bbox_to_anchor=(0.5, 1.06), ncol=3, fontsize=8, frameon=False)
        ax_t.plot(cols["t"], cols["theta"], lw=0.8)
        ax_t.set_xlabel("t / sqrt(b3/g)")
        ax_t.set_ylabel("theta / rad")
        ax_t.set_title("theta(t)", fontsize=9)
        attrs = ds.attrs
        title = ", ".join(f"{k} = {float(attrs[k]):.7g}"
                          for k in ("alpha", "beta", "cut", "nu", "eta", "kappa", "energy") if k in attrs)
        fig.suptitle(f"{attrs.get('model', '')} model: {title}", fontsize=9)
        return fig

    @_reads
    def plot_slice(self, alpha_index: int = 0, beta_index: int = 0, max_q: int = 7, *, cut_index: int = 0):
        """A matplotlib Figure of the rotation number of each torus family over a plane.

        One panel per family present: its rotation number N over the plane on a diverging
        colour map centred on N = 0, over the whole range of N (nothing is clipped; grey where
        a cell has no torus of the family), with the resonance curves N = p/q as contours
        (integers, where the path may run away, in black; other fractions in dark grey); and
        a last panel with log10 of the drift radius R,
        the largest over the tori of each cell (R blows up on the integer resonances). A
        dataset without the ``family`` variable (from before families of tori) gets one
        panel per component slot instead.

        Parameters
        ----------
        alpha_index, beta_index : int, default 0
            The body of an atlas (indices along ``alpha`` and ``beta``), when the dataset
            has those dimensions; a negative index counts from the end, as in numpy (−1 is
            the last).
        max_q : int, default 7
            The largest denominator q of the contours N = p/q, from 1 to 100; lowered where a
            panel would have more than 60 contours.
        cut_index : int, default 0
            The cut of a truncated ball or wheel atlas (index along ``cut``, negative from
            the end; the disk's atlas has no second dimension).

        Returns
        -------
        matplotlib.figure.Figure
            The figure (one row of panels, each with its colour bar). Axes are the plane's
            dimensions: (κ, ε), (κ, ε − V_min) or (λ, s) for an atlas or a `cells` result
            over such a grid.

        Raises
        ------
        ValueError
            The dataset is not an atlas or a `cells` result over two dimensions (besides
            α and β, or α and the cut); an index beyond ``alpha``, ``beta`` or ``cut`` (a dataset without that
            dimension has index 0 only); `max_q` outside 1 … 100; a slice that is empty or whose axes
            are not finite; nothing to draw: neither rotation_number nor drift_radius (the
            fields left them out), or no finite value of them (the message counts the
            cells by ``cell_status``, e.g. "12 no_motion"); a damaged file.
        TypeError
            An index or `max_q` that is not a whole number.

        Examples
        --------
        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> import numpy as np
        >>> import rubber_atlas as ra
        >>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=np.linspace(0.05, 2.0, 12),
        ...               energy=np.linspace(0.5, 4.5, 10))
        >>> fig = ds.rubber.plot_slice()
        >>> [ax.get_title() for ax in fig.axes if ax.get_title()]
        ['well_0: N', 'well_pi: N', 'log10 R (largest)']
        """
        import matplotlib.colors
        import matplotlib.pyplot as plt

        ds = self._ds
        _api._cells_dataset(ds, "plot_slice")
        max_q = _api._count("max_q", max_q)
        if not 1 <= max_q <= _MAX_Q:
            raise ValueError(f"invalid max_q = {max_q}: must be between 1 and {_MAX_Q}")
        cut = ds
        for name, index in (("alpha", alpha_index), ("beta", beta_index), ("cut", cut_index)):
            index = _api._count(f"{name}_index", index)
            if name not in ds.cell_status.dims:
                if index not in (0, -1):
                    hint = (" (a truncated ball's or wheel's atlas has its cuts along cut: cut_index=)"
                            if name == "beta" and "cut" in ds.cell_status.dims else "")
                    raise ValueError(f"invalid {name}_index = {index}: the dataset has no dimension {name} "
                                     f"(its dimensions are {list(ds.cell_status.dims)}): leave {name}_index at 0"
                                     f"{hint}")
                continue
            size = ds.sizes[name]
            if not -size <= index < size:
                raise ValueError(f"invalid {name}_index = {index}: the dataset has {size} value{'s' * (size != 1)} "
                                 f"of {name} (index 0 … {size - 1}, or {-size} … -1 from the end)")
            if name in ds.cell_status.dims:
                cut = cut.isel({name: index})
        plane = list(cut.cell_status.dims)
        if len(plane) != 2:
            raise ValueError("plot_slice draws an atlas slice or a cells result over a plane of two dimensions "
                             f"(e.g. kappa and energy); this dataset has dimensions {list(ds.cell_status.dims)}. "
                             "For a grid give cells kappa and energy as DataArrays along 'kappa' and 'energy' "
                             "(or numpy vectors of different lengths): vectors of one length are paired cell "
                             "by cell")
        empty = [d for d in plane if cut.sizes[d] == 0]
        if empty:
            raise ValueError(f"the slice is empty: {' and '.join(empty)} {'has' if len(empty) == 1 else 'have'} "
                             "no values")
        x, y = (cut[d].values if d in cut.coords else np.arange(cut.sizes[d]) for d in plane)
        for d, axis in zip(plane, (x, y)):
            if axis.dtype.kind not in "iuf" or not np.isfinite(axis).all():
                raise ValueError(f"the axis {d} has values that are not finite numbers: plot_slice draws over "
                                 "finite axes")
        # An axis given out of order (cells over an unsorted κ) drew a wrong mesh with only
        # matplotlib's warning (an adversary pass): the slice is drawn in the axes' order.
        unsorted = [d for d, axis in zip(plane, (x, y)) if d in cut.coords and (np.diff(axis) < 0).any()]
        if unsorted:
            cut = cut.sortby(unsorted)
            x, y = (cut[d].values if d in cut.coords else np.arange(cut.sizes[d]) for d in plane)
        panels = []  # (title, N over the plane)
        if "rotation_number" in cut:
            if "family" in cut:
                accessor = cut.rubber
                # Rolling over the top (kappa = 0) has N = 0 by definition: no panel.
                for name in accessor.families():
                    n = accessor.family(name).rotation_number
                    if name != "over_the_top" and np.isfinite(n).any():
                        panels.append((f"{name}: N", n))
            else:
                for slot in range(cut.sizes["component"]):
                    n = cut.rotation_number.isel(component=slot)
                    if np.isfinite(n).any():
                        panels.append((f"component {slot}: N", n))
        drift = "drift_radius" in cut and bool(np.isfinite(cut.drift_radius).any())
        if not panels and not drift:
            if "rotation_number" not in cut and "drift_radius" not in cut:
                raise ValueError("this dataset has neither rotation_number nor drift_radius to draw (the scene's "
                                 "[outputs] fields, or cells' fields=, left them out)")
            names = _api.flag_names(cut.cell_status)
            codes, counts = np.unique(np.asarray(cut.cell_status.values), return_counts=True)
            shown = ", ".join(f"{n} {names.get(int(c), c)}" for c, n in zip(codes, counts))
            raise ValueError("nothing to draw: no torus of this slice has a finite rotation_number (rolling over "
                             f"the top, N = 0, has no panel) or drift_radius; its cells: {shown}")
        count = len(panels) + drift
        fig, axes = plt.subplots(1, count, figsize=(4.6 * count, 4.0), squeeze=False, layout="constrained")
        denominators = []
        for ax, (title, n) in zip(axes[0], panels):
            values = n.transpose(*plane).values.T
            finite = values[np.isfinite(values)]
            # Centred on 0, each side over its own range (N is often mostly of one sign: a
            # symmetric scale would show the other side as white).
            low = float(finite.min()) if finite.size else -1.0
            high = float(finite.max()) if finite.size else 1.0
            span = max(abs(low), abs(high), 1e-300)
            norm = matplotlib.colors.TwoSlopeNorm(vcenter=0.0, vmin=min(low, -1e-6 * span),
                                                  vmax=max(high, 1e-6 * span))
            # Infinities (on a separatrix) take the end colours: arrows say so.
            extend = {(False, False): "neither", (True, False): "min", (False, True): "max",
                      (True, True): "both"}[(bool(np.isneginf(values).any()), bool(np.isposinf(values).any()))]
            # Grey where the cell has no torus of the family (white is N = 0).
            ax.set_facecolor("0.82")
            mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(values), shading="auto", cmap="RdBu_r", norm=norm)
            fig.colorbar(mesh, ax=ax, label="N", extend=extend)
            lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 0.0)
            q, levels = _contour_levels(lo, hi, max_q)
            integers = [v for v in levels if float(v).is_integer()]
            fractions = [v for v in levels if not float(v).is_integer()]
            contoured = np.ma.masked_invalid(values)
            if len(x) > 1 and len(y) > 1:
                if fractions:
                    ax.contour(x, y, contoured, levels=fractions, colors="0.3", linewidths=0.5,
                               linestyles="solid")
                if integers[:_MAX_LEVELS]:
                    ax.contour(x, y, contoured, levels=integers[:_MAX_LEVELS], colors="black", linewidths=1.1,
                               linestyles="solid")
            ax.set_title(title if q == max_q else f"{title} (q ≤ {q})", fontsize=10)
            denominators.append(q)
        if drift:
            ax = axes[0][-1]
            with np.errstate(divide="ignore", invalid="ignore"):
                r = np.log10(cut.drift_radius.max("component", skipna=True).transpose(*plane).values.T)
            # R spans decades and is infinite on a resonance: the scale covers the 2nd to 98th
            # percentiles of the slice's finite values, the arrows say that more lies beyond.
            finite_r = r[np.isfinite(r)]
            lo_r, hi_r = np.percentile(finite_r, [2, 98]) if finite_r.size else (-2.0, 2.0)
            hi_r = hi_r if hi_r > lo_r else lo_r + 1.0
            mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(r), shading="auto", cmap="magma", vmin=lo_r, vmax=hi_r)
            fig.colorbar(mesh, ax=ax, label="log10 R", extend="both")
            ax.set_title("log10 R (largest)", fontsize=10)
        for ax in axes[0]:
            ax.set_xlabel(_LABELS.get(plane[0], plane[0]))
            ax.set_ylabel(_LABELS.get(plane[1], plane[1]))
        shape = ds.attrs.get("shape", "")
        body = ", ".join([shape] * bool(shape) + [f"{_LABELS[k]} = {float(cut[k]):g}"
                                                  for k in ("alpha", "beta", "cut", "nu", "eta")
                                                  if k in cut.coords and cut[k].ndim == 0])
        name = ds.attrs.get("scene_name", "")
        contours = f"; contours N = p/q, q ≤ {max_q} (integers black)" if denominators else ""
        fig.suptitle(f"{name}: {body}{contours}" if name else f"{body}{contours}", fontsize=10)
        return fig
