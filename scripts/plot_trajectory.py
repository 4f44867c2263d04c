"""Draw a trajectory written by `rubber-atlas trajectory` (paper Figs. `res`, `xy`): the paths
of the centre of mass and of the contact point on the plane, and θ(t).

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


def plot(path: str | Path, out: str | Path) -> Path:
    table = read_table(path)
    cols, attrs = {k: v.values for k, v in table.variables.items()}, table.attrs
    fig, (ax_xy, ax_t) = plt.subplots(1, 2, figsize=(11, 5), gridspec_kw={"width_ratios": [1, 1.2]})
    ax_xy.plot(cols["x_p"], cols["y_p"], lw=0.6, color="tab:orange", label="contact point")
    ax_xy.plot(cols["x_c"], cols["y_c"], lw=0.9, color="tab:blue", label="centre of mass")
    ax_xy.plot(cols["x_c"][:1], cols["y_c"][:1], "ko", ms=4, label="start")
    ax_xy.set_aspect("equal")
    ax_xy.set_xlabel("x / b3")
    ax_xy.set_ylabel("y / b3")
    ax_xy.legend(loc="best", fontsize=8)
    ax_t.plot(cols["t"], cols["theta"], lw=0.8)
    ax_t.set_xlabel("t / sqrt(b3/g)")
    ax_t.set_ylabel("theta / rad")
    title = ", ".join(
        f"{k} = {float(attrs[k]):.7g}" for k in ("alpha", "beta", "nu", "eta", "kappa", "energy") if k in attrs
    )
    fig.suptitle(f"{attrs.get('model', '')} model: {title}", fontsize=9)
    fig.tight_layout()
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
