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

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rubber_atlas import read_table  # noqa: E402


def figure(path: str | Path):
    """The figure of the trajectory file at `path` (a matplotlib Figure): the package's
    `.rubber.plot_trajectory()` of the file's table."""
    return read_table(path).rubber.plot_trajectory()


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
