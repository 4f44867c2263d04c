"""The `.rubber` accessor of xarray Datasets (atlases and `cells` results): the common steps
of a session, one call each."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import xarray as xr

from . import _api


def resonances(lo: float, hi: float, max_q: int = 7) -> list[float]:
    """The fractions p/q with q ≤ max_q in [lo, hi], sorted."""
    found = {
        Fraction(p, q)
        for q in range(1, max_q + 1)
        for p in range(int(np.floor(lo * q)), int(np.ceil(hi * q)) + 1)
    }
    return sorted(float(f) for f in found if lo <= f <= hi)


@xr.register_dataset_accessor("rubber")
class RubberAccessor:
    """`ds.rubber.components(...)`, `ds.rubber.flags(name)`, `ds.rubber.plot_slice(...)`."""

    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    def components(self, alpha: float | None = None, beta: float | None = None, **cell) -> list[dict]:
        """The components of one cell as dicts (see `rubber_atlas.components`)."""
        return _api.components(self._ds, alpha, beta, **cell)

    def flags(self, name: str) -> dict[int, str]:
        """{value: meaning} of the flag variable `name` (`status`, `motion`, `bounded`, …)."""
        return _api.flag_names(self._ds[name])

    def plot_slice(self, alpha_index: int = 0, beta_index: int = 0, max_q: int = 7):
        """A matplotlib Figure of one (α, β) slice of an atlas: the rotation number N of each
        component over the plane with the resonance curves N = p/q (q ≤ max_q) as white
        contours, and log10 of the drift radius R of component 0 (R blows up on the integer
        resonances, where the path runs away). Raises ValueError when the atlas has neither
        a finite rotation_number nor drift_radius (the scene left them out)."""
        import matplotlib.pyplot as plt

        ds = self._ds
        if not {"alpha", "beta"} <= set(ds.dims) or "cell_status" not in ds:
            raise ValueError("plot_slice draws an atlas (dimensions alpha and beta, as open_atlas gives it); "
                             f"this dataset has dimensions {list(ds.dims)}")
        cut = ds.isel(alpha=alpha_index, beta=beta_index)
        plane = [d for d in cut.cell_status.dims]
        if len(plane) != 2:
            raise ValueError(f"plot_slice needs an atlas with two plane dimensions; this one has {plane}")
        x, y = (cut[d].values for d in plane)
        slots = []
        if "rotation_number" in ds:
            slots = [s for s in range(ds.sizes["component"])
                     if np.isfinite(cut.rotation_number.isel(component=s)).any()]
        panels = len(slots) + ("drift_radius" in ds)
        if panels == 0:
            raise ValueError("no finite rotation_number and no drift_radius to draw "
                             "(the scene's [outputs] fields left them out)")
        fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.4), squeeze=False)
        for ax, slot in zip(axes[0], slots):
            n = cut.rotation_number.isel(component=slot).transpose(*plane).values.T
            finite = n[np.isfinite(n)]
            lo, hi = np.percentile(finite, [1, 99])
            mesh = ax.pcolormesh(x, y, n, shading="auto", cmap="viridis", vmin=lo, vmax=hi)
            levels = resonances(lo, hi, max_q)
            if levels:
                ax.contour(x, y, n, levels=levels, colors="white", linewidths=0.5)
            fig.colorbar(mesh, ax=ax, label="rotation number N")
            ax.set_title(f"N, component {slot} (white: N = p/q, q ≤ {max_q})")
        if "drift_radius" in ds:
            ax = axes[0][-1]
            with np.errstate(divide="ignore", invalid="ignore"):
                r = np.log10(cut.drift_radius.isel(component=0).transpose(*plane).values.T)
            mesh = ax.pcolormesh(x, y, np.where(np.isfinite(r), r, np.nan), shading="auto",
                                 cmap="magma", vmin=-2, vmax=2)
            fig.colorbar(mesh, ax=ax, label="log10 R")
            ax.set_title("drift radius R, component 0")
        for ax in axes[0]:
            ax.set_xlabel(plane[0])
            ax.set_ylabel(plane[1])
        fig.suptitle(f"{ds.attrs.get('scene_name', '')}: α = {float(cut.alpha):g}, β = {float(cut.beta):g}")
        fig.tight_layout()
        return fig
