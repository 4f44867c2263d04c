"""Draws an atlas (`rubber-atlas run`) slice: for the first (α, β) of the file, the rotation
number N of each torus family over the plane of the scene with the resonance curves N = p/q
(|q| ≤ 7) as contours, and the drift radius R (the largest over the tori of each cell): the
path on the plane circles with radius R, which blows up on the integer resonances N ∈ ℤ
(unbounded paths).

    .venv/bin/python scripts/plot_atlas.py atlas/out/demo.h5 --out atlas/out/demo.png
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rubber_atlas import open_atlas  # noqa: E402


def plot(path: str | Path, out: str | Path, alpha_index: int = 0, beta_index: int = 0) -> None:
    """Draws slice (alpha_index, beta_index) of the atlas at `path` to `out` (the package's
    `ds.rubber.plot_slice`)."""
    with open_atlas(path) as ds:
        try:
            fig = ds.rubber.plot_slice(alpha_index, beta_index)
        except ValueError as e:
            raise SystemExit(f"plot_atlas.py: {path}: {e}")
        fig.savefig(out, dpi=110)
        plt.close(fig)


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
