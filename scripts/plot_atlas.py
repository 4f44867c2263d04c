"""Draws an atlas (`rubber-atlas run`) slice: for the first (α, β) of the file, the rotation
number N of each component over the (κ, ε) plane with the resonance curves N = p/q (|q| ≤ 7)
as contours, and the drift radius R of component 0: the path on the plane circles with radius
R, which blows up on the integer resonances N ∈ ℤ (unbounded paths).

    .venv/bin/python scripts/plot_atlas.py atlas/demo.h5 --out atlas/out/demo.png
"""
from __future__ import annotations

import argparse
from fractions import Fraction
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from atlas_io import open_atlas  # noqa: E402


def resonances(lo: float, hi: float, max_q: int = 7) -> list[float]:
    """The fractions p/q with q ≤ max_q in [lo, hi], sorted."""
    found = {Fraction(p, q) for q in range(1, max_q + 1) for p in range(int(np.floor(lo * q)), int(np.ceil(hi * q)) + 1)}
    return sorted(float(f) for f in found if lo <= f <= hi)


def plot(path: str | Path, out: str | Path, alpha_index: int = 0, beta_index: int = 0) -> None:
    ds = open_atlas(path)
    cut = ds.isel(alpha=alpha_index, beta=beta_index)
    kappa, energy = cut.kappa.values, cut.energy.values
    slots = []
    if "rotation_number" in ds:
        slots = [s for s in range(ds.sizes["component"]) if np.isfinite(cut.rotation_number.isel(component=s)).any()]
    panels = len(slots) + ("drift_radius" in ds)
    if panels == 0:
        ds.close()
        raise SystemExit(f"plot_atlas.py: {path} has no finite rotation_number and no drift_radius to draw "
                         "(the scene's [outputs] fields left them out)")
    fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.4), squeeze=False)
    for ax, slot in zip(axes[0], slots):
        n = cut.rotation_number.isel(component=slot).values.T
        finite = n[np.isfinite(n)]
        lo, hi = np.percentile(finite, [1, 99])
        mesh = ax.pcolormesh(kappa, energy, n, shading="auto", cmap="viridis", vmin=lo, vmax=hi)
        levels = resonances(lo, hi)
        if levels:
            ax.contour(kappa, energy, n, levels=levels, colors="white", linewidths=0.5)
        fig.colorbar(mesh, ax=ax, label="rotation number N")
        ax.set_title(f"N, component {slot} (white: N = p/q, q ≤ 7)")
    if "drift_radius" in ds:
        ax = axes[0][-1]
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.log10(cut.drift_radius.isel(component=0).values.T)
        mesh = ax.pcolormesh(kappa, energy, np.where(np.isfinite(r), r, np.nan), shading="auto",
                             cmap="magma", vmin=-2, vmax=2)
        fig.colorbar(mesh, ax=ax, label="log10 R")
        ax.set_title("drift radius R, component 0")
    for ax in axes[0]:
        ax.set_xlabel("κ")
        ax.set_ylabel("ε")
    fig.suptitle(f"{ds.attrs.get('scene_name', '')}: α = {float(cut.alpha):g}, β = {float(cut.beta):g}")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    ds.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("atlas")
    parser.add_argument("--out", required=True)
    parser.add_argument("--alpha-index", type=int, default=0)
    parser.add_argument("--beta-index", type=int, default=0)
    args = parser.parse_args()
    plot(args.atlas, args.out, args.alpha_index, args.beta_index)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
