"""Writes benches/work_precision_cells.csv: the cells of the work-precision benchmark with their
true T and N from mpmath's tanh-sinh quadrature at 40 digits (scripts/rubber_model.py).

Three classes on the paper's body (α = 0.5, β = 3, ν = η = 0.5):
- regular: librations well inside the allowed region (κ from 0.4 to 1.6);
- separatrix: ε within 1e-3 and 1e-6 of the top of V at κ = 1, below (two components, each
  listed) and above (one component around the saddle); separatrix_close: the same at 1e-9
  and 1e-12, where the rounding of ε − V near the saddle limits any double-precision method;
- small_kappa: κ from 1e-2 down to 1e-6, where a turning point nears the pole θ = 0.

Run it again (`.venv/bin/python scripts/work_precision_truth.py`) after changing the cells.
"""

from __future__ import annotations

import csv
from pathlib import Path

import mpmath

from rubber_model import Body, HighPrecision

ROOT = Path(__file__).resolve().parents[1]
ALPHA, BETA = 0.5, 3.0


def cells():
    body = Body(ALPHA, BETA)
    for kappa, energy in [(0.4, 2.2), (0.7, 2.6), (1.0, 3.0), (1.0, 3.3), (1.3, 3.9), (1.6, 4.4)]:
        yield "regular", kappa, energy, None
    hp = HighPrecision(body, 1.0)
    saddle = [c for c in hp.critical_points() if hp._dv(c + mpmath.mpf("1e-8")) < 0][0]
    top = float(hp._v(saddle))
    for exponent in (3, 6, 9, 12):
        kind = "separatrix" if exponent <= 6 else "separatrix_close"
        below = top - 10.0**-exponent
        yield kind, 1.0, below, float(saddle) - 0.3
        yield kind, 1.0, below, float(saddle) + 0.3
        yield kind, 1.0, top + 10.0**-exponent, float(saddle)
    for kappa in (1e-2, 1e-3, 1e-4, 1e-6):
        yield "small_kappa", kappa, 2.5, 0.3


def main():
    import argparse

    argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " ")).parse_args()
    body = Body(ALPHA, BETA)
    rows = []
    for kind, kappa, energy, near in cells():
        hp = HighPrecision(body, kappa)
        guess = near if near is not None else 1.0
        theta_min, theta_max, period, rotation = hp.integrals(energy, guess)
        centre = 0.5 * (theta_min + theta_max)
        rows.append([kind, ALPHA, BETA, kappa, repr(energy), repr(centre), repr(period), repr(rotation)])
        print(f"{kind:12} kappa {kappa:<8g} energy {energy:.15g}: T {period:.17g} N {rotation:.17g}")
    path = ROOT / "benches" / "work_precision_cells.csv"
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["class", "alpha", "beta", "kappa", "energy", "theta", "period", "rotation_number"])
        writer.writerows(rows)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
