"""Speed of rubber-atlas's cell solver against what a researcher writes by hand, measured side
by side in one run on the standard slice of docs/accuracy.md (α = 0.5, β = 3, ν = η = 0.5,
κ ∈ [0, 2] × ε ∈ [0.5, 4.5] on 256 × 256 cells):

- rubber-atlas: `cargo bench --bench cell_speed`, with error control at tol 1e-10, 1 and 2
  threads, in cell-components per second: all outputs, and N alone (T, ω_θ, ω_ψ and N
  without the drift integrals: what the NumPy script computes, and what a scene that asks
  for no drift costs);
- NumPy: N alone by the periodic midpoint rule (64 nodes), vectorised over the whole slice
  (scripts/rubber_model.py, `midpoint_rotation_numbers`), one core;
- SciPy: T and N by `scipy.integrate.quad` cell by cell (`scipy_cell`), one core, on a sample
  of the slice's cells.

Prints a table and writes docs/speed.csv. Also compares N from both Python scripts with
rubber-atlas on a few cells, so that the rates are read with the accuracy they buy.

    .venv/bin/python scripts/speed_comparison.py [--scipy-cells 400]
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np

from rubber_model import Body, midpoint_rotation_numbers, scipy_cell

ROOT = Path(__file__).resolve().parents[1]
BODY = Body(0.5, 3.0, 0.5, 0.5)
KAPPAS = np.linspace(0.0, 2.0, 256)
ENERGIES = np.linspace(0.5, 4.5, 256)


def rust_rates() -> dict[tuple[str, int], float]:
    """Cell-components per second (median of 7) of `cargo bench --bench cell_speed`, by output
    set ("all outputs", "N alone") and thread count."""
    out = subprocess.run(
        ["cargo", "bench", "--quiet", "--bench", "cell_speed"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout
    pattern = r"(all outputs|N alone), threads (\d+): .*= (\d+) per second"
    rates = {(m[1], int(m[2])): float(m[3]) for m in re.finditer(pattern, out)}
    if set(rates) != {(o, t) for o in ("all outputs", "N alone") for t in (1, 2)}:
        raise RuntimeError(f"unexpected cell_speed output:\n{out}")
    return rates


def cells_with_motion():
    """The (κ, ε) of the slice with κ > 0 above the lowest minimum of V."""
    theta = np.linspace(1e-3, np.pi - 1e-3, 4000)
    cells = []
    for kappa in KAPPAS[1:]:
        v_min = BODY.potential(theta, kappa).min()
        cells.extend((kappa, e) for e in ENERGIES if e > v_min + 1e-6)
    return cells


def numpy_rate(nodes: int, repeats: int = 3) -> tuple[float, int]:
    """Cells with motion per second of the vectorised midpoint script over the slice (κ > 0;
    the cells below the minimum of V cost the same but are not counted), best of `repeats`."""
    best = float("inf")
    kappas = KAPPAS[1:]
    for _ in range(repeats):
        start = time.perf_counter()
        with np.errstate(all="ignore"):
            n = midpoint_rotation_numbers(BODY, kappas, ENERGIES, nodes=nodes)
        best = min(best, time.perf_counter() - start)
    cells = int(np.count_nonzero(~np.isnan(n)))
    return cells / best, cells


def numpy_errors(sample, nodes: int) -> np.ndarray:
    """|N(NumPy midpoint) − N(rubber-atlas)| on the sampled cells (the lowest well's libration)."""
    with np.errstate(all="ignore"):
        numpy_n = [midpoint_rotation_numbers(BODY, [k], [e], nodes=nodes)[0, 0] for k, e, _ in sample]
    return np.array([abs(a - n) if np.isfinite(a) else np.inf for a, (_, _, n) in zip(numpy_n, sample)])


def scipy_rate(cells, count: int, seed: int = 1) -> tuple[float, int]:
    rng = np.random.default_rng(seed)
    sample = [cells[i] for i in rng.choice(len(cells), size=min(count, len(cells)), replace=False)]
    start = time.perf_counter()
    done = 0
    for kappa, energy in sample:
        try:
            scipy_cell(BODY, kappa, energy)
            done += 1
        except ValueError:
            pass  # brentq found no sign change: a cell the simple script cannot do
    elapsed = time.perf_counter() - start
    return done / elapsed, done


def rubber_atlas_n(kappa: float, energy: float) -> float:
    binary = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
    out = subprocess.run(
        [binary, "cell", "--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5",
         "--kappa", repr(float(kappa)), "--energy", repr(float(energy)), "--json"],
        check=True, capture_output=True, text=True,
    ).stdout
    components = json.loads(out)["components"]
    # The component around the lowest minimum: the one the Python scripts follow.
    return min(components, key=lambda c: BODY.potential(0.5 * (c["theta_min"] + c["theta_max"]), kappa))["rotation_number"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("--scipy-cells", type=int, default=400)
    parser.add_argument("--accuracy-cells", type=int, default=300)
    args = parser.parse_args()

    print("speed: cargo bench --bench cell_speed (rubber-atlas, all outputs, tol 1e-10)")
    rust = rust_rates()
    cells = cells_with_motion()
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    rng = np.random.default_rng(7)
    picked = [cells[i] for i in rng.choice(len(cells), size=args.accuracy_cells, replace=False)]
    print(f"speed: rubber-atlas cell on {len(picked)} sampled cells, as the accuracy reference")
    sample = [(k, e, rubber_atlas_n(k, e)) for k, e in picked]
    numpy_rows = []
    for nodes in (64, 256, 1024):
        print(f"speed: NumPy midpoint rule with {nodes} nodes, N only, vectorised over the slice")
        rate, count = numpy_rate(nodes)
        errors = numpy_errors(sample, nodes)
        numpy_rows.append((nodes, rate, count, errors))
    numpy_cells_per_s, numpy_cells = numpy_rows[0][1], numpy_rows[0][2]
    print(f"speed: scipy.integrate.quad, T and N, {args.scipy_cells} cells of the slice")
    scipy_cells_per_s, scipy_done = scipy_rate(cells, args.scipy_cells)

    scipy_errors = []
    for k, e, n in sample[:100]:
        try:
            scipy_errors.append(abs(scipy_cell(BODY, k, e)[1] - n))
        except ValueError:
            scipy_errors.append(np.inf)
    scipy_errors = np.array(scipy_errors)

    rows = [
        ("rubber-atlas, 1 thread (all outputs, tol 1e-10)", rust["all outputs", 1], 1),
        ("rubber-atlas, 2 threads (all outputs, tol 1e-10)", rust["all outputs", 2], 2),
        ("rubber-atlas, 1 thread (N alone, tol 1e-10)", rust["N alone", 1], 1),
        ("rubber-atlas, 2 threads (N alone, tol 1e-10)", rust["N alone", 2], 2),
        (f"NumPy midpoint, N only, 64 nodes ({numpy_cells} cells)", numpy_cells_per_s, 1),
        (f"scipy.integrate.quad, T and N ({scipy_done} cells)", scipy_cells_per_s, 1),
    ]
    print()
    print(f"{'solver':58} {'cells/s':>12} {'per core':>12}")
    for name, rate, cores in rows:
        print(f"{name:58} {rate:12.0f} {rate / cores:12.0f}")
    print()
    for outputs in ("N alone", "all outputs"):
        for name, other in (("NumPy (64 nodes)", numpy_cells_per_s), ("SciPy", scipy_cells_per_s)):
            print(f"rubber-atlas ({outputs}, 2 threads) / {name}: {rust[outputs, 2] / other:7.1f}   "
                  f"1 thread: {rust[outputs, 1] / other:6.1f}")
    print()
    print(f"accuracy against rubber-atlas (tol 1e-10) on {len(sample)} random cells of the slice:")
    print(f"{'solver':38} {'cells/s':>10} {'median |ΔN|':>12} {'> 1e-10':>8} {'> 1e-6':>8}")

    def line(name, rate, errors):
        share = lambda x: f"{100 * np.mean(errors > x):7.1f}%"  # noqa: E731
        print(f"{name:38} {rate:10.0f} {np.median(errors):12.1e} {share(1e-10)} {share(1e-6)}")

    for nodes, rate, _, errors in numpy_rows:
        line(f"NumPy midpoint, {nodes} nodes", rate, errors)
    line("scipy.integrate.quad (100 cells)", scipy_cells_per_s, scipy_errors)
    out = ROOT / "docs" / "speed.csv"
    with out.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["solver", "cells_per_second", "cores", "median_abs_error_n", "share_error_above_1e-10",
                         "share_error_above_1e-6"])
        for (outputs, threads), rate in sorted(rust.items()):
            writer.writerow([f"rubber-atlas {outputs} {threads} thread(s)", f"{rate:.0f}", threads, "", "", ""])
        for nodes, rate, _, errors in numpy_rows:
            writer.writerow([f"numpy midpoint {nodes} nodes N only", f"{rate:.0f}", 1, f"{np.median(errors):.1e}",
                             f"{np.mean(errors > 1e-10):.3f}", f"{np.mean(errors > 1e-6):.3f}"])
        writer.writerow(["scipy quad T and N", f"{scipy_cells_per_s:.0f}", 1, f"{np.median(scipy_errors):.1e}",
                         f"{np.mean(scipy_errors > 1e-10):.3f}", f"{np.mean(scipy_errors > 1e-6):.3f}"])
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
