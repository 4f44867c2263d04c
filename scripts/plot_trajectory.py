"""Draw a trajectory written by `rubber-atlas trajectory` (paper Figs. `res`, `xy`): the paths
of the centre of mass and of the contact point on the plane, and θ(t). The plane is drawn to
scale unless the path is much longer one way than the other (a drifting path), when each axis
gets its own scale so that the path does not shrink to a line.

Usage: python scripts/plot_trajectory.py TRAJECTORY.(h5|csv) --out FIGURE.png
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rubber_atlas import read_table  # noqa: E402


# Equal scales on both axes only while the path's extents differ by at most this factor: a
# drifting path, long and thin, would otherwise shrink to a flat line.
EQUAL_ASPECT_UP_TO = 4.0


def figure(path: str | Path):
    """The figure of the trajectory file at `path` (a matplotlib Figure)."""
    table = read_table(path)
    cols, attrs = {k: v.values for k, v in table.variables.items()}, table.attrs
    fig, (ax_xy, ax_t) = plt.subplots(1, 2, figsize=(11, 5), gridspec_kw={"width_ratios": [1, 1.2]},
                                      layout="constrained")
    ax_xy.plot(cols["x_p"], cols["y_p"], lw=0.6, color="tab:orange", label="contact point")
    ax_xy.plot(cols["x_c"], cols["y_c"], lw=0.9, color="tab:blue", label="centre of mass")
    ax_xy.plot(cols["x_c"][:1], cols["y_c"][:1], "ko", ms=4, label="start")
    xs = np.concatenate([cols["x_p"], cols["x_c"]])
    ys = np.concatenate([cols["y_p"], cols["y_c"]])
    width, height = float(np.ptp(xs)), float(np.ptp(ys))
    if min(width, height) > 0 and max(width, height) / min(width, height) <= EQUAL_ASPECT_UP_TO:
        ax_xy.set_aspect("equal", adjustable="datalim")
        scale = ""
    else:
        scale = " (axes not to scale)"
    ax_xy.set_xlabel("x / b3")
    ax_xy.set_ylabel("y / b3")
    ax_xy.set_title(f"on the plane{scale}", fontsize=9)
    # Above the axes, outside them: never over the path.
    ax_xy.legend(loc="lower center", bbox_to_anchor=(0.5, 1.06), ncol=3, fontsize=8, frameon=False)
    ax_t.plot(cols["t"], cols["theta"], lw=0.8)
    ax_t.set_xlabel("t / sqrt(b3/g)")
    ax_t.set_ylabel("theta / rad")
    title = ", ".join(
        f"{k} = {float(attrs[k]):.7g}" for k in ("alpha", "beta", "nu", "eta", "kappa", "energy") if k in attrs
    )
    fig.suptitle(f"{attrs.get('model', '')} model: {title}", fontsize=9)
    return fig


def plot(path: str | Path, out: str | Path) -> Path:
    """Draws the trajectory file at `path` to `out`; returns `out`."""
    fig = figure(path)
    out = Path(out)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("trajectory")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    print(f"wrote {plot(args.trajectory, args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
