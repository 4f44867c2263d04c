"""Draws the work-precision plot of the cell solver from docs/work-precision.csv (written by
`cargo bench --bench work_precision`): for each class of cells, time per cell against the
largest error in N over the class, one line per method, a point per requested tolerance
(filled: the true error against 40-digit values; open: the solver's own estimate).

    .venv/bin/python scripts/plot_work_precision.py [CSV] [PNG]
"""

from __future__ import annotations

import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CLASSES = [
    ("regular", "regular librations"),
    ("separatrix", "1e-3 and 1e-6 from a separatrix"),
    ("separatrix_close", "1e-9 and 1e-12 from a separatrix"),
    ("small_kappa", "small κ (1e-2 … 1e-6)"),
]
STYLE = {"quadrature": ("C0", "o"), "ode": ("C3", "s")}
FLOOR = 1e-17  # errors that are exactly 0 are drawn here


def read(path: Path):
    table = defaultdict(list)
    with path.open() as f:
        for row in csv.DictReader(f):
            table[(row["class"], row["method"])].append(
                {
                    "tol": float(row["tol"]),
                    "seconds": float(row["seconds_per_cell"]),
                    "error": max(float(row["max_abs_error_n"]), FLOOR),
                    "estimate": max(float(row["max_error_estimate_n"]), FLOOR),
                }
            )
    return table


def plot(csv_path: Path, png_path: Path) -> None:
    table = read(csv_path)
    fig, axes = plt.subplots(1, len(CLASSES), figsize=(19, 4.6), sharey=True)
    for ax, (key, title) in zip(axes, CLASSES):
        for method, (colour, marker) in STYLE.items():
            rows = sorted(table.get((key, method), []), key=lambda r: -r["tol"])
            if not rows:
                continue
            micro = [1e6 * r["seconds"] for r in rows]
            ax.plot([r["error"] for r in rows], micro, marker=marker, color=colour, label=f"{method}: true error")
            ax.plot(
                [r["estimate"] for r in rows],
                micro,
                marker=marker,
                color=colour,
                markerfacecolor="none",
                linestyle=":",
                label=f"{method}: own estimate",
            )
            for r, t in zip(rows, micro):
                ax.annotate(f"{r['tol']:.0e}", (r["error"], t), fontsize=6, alpha=0.7, xytext=(3, 2), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xlabel("largest |error in N| over the class")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("time per cell [µs] (one core)")
    axes[0].legend(fontsize=7)
    fig.suptitle("rubber-atlas cell solver: work against precision (labels: requested tolerance)")
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


def main(argv: list[str]) -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("csv", nargs="?", default=ROOT / "docs" / "work-precision.csv", type=Path,
                        help="the bench's table [default: docs/work-precision.csv]")
    parser.add_argument("png", nargs="?", default=ROOT / "docs" / "work-precision.png", type=Path,
                        help="the figure to write [default: docs/work-precision.png]")
    args = parser.parse_args(argv[1:])
    plot(args.csv, args.png)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main(sys.argv)
