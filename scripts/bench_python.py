"""Benchmark of the Python package against the program: rubber_atlas.cells on the standard
slice (atlas/standard-slice.toml: 256 x 256 cells, all outputs, tol 1e-10) against
`rubber-atlas run` of the same scene, on the same threads, run alternately; prints the
cells per second of each (best of --repeat) and their ratio.

    .venv/bin/python scripts/bench_python.py --threads 2 --repeat 5

The run's time is the whole command (start-up, computing, writing the compressed file); the
package's is the call, from numpy inputs to the xarray Dataset. Both compute every cell.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np
import xarray as xr

import rubber_atlas as ra

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
SCENE = ROOT / "atlas" / "standard-slice.toml"


def axis(spec) -> np.ndarray:
    if isinstance(spec, list):
        return np.array(spec, dtype=float)
    return np.linspace(spec["start"], spec["stop"], spec["num"])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("--threads", type=int, default=2, help="threads of both (default 2)")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each, alternately (default 5)")
    args = parser.parse_args(argv)
    scene = tomllib.loads(SCENE.read_text())
    body, axes = scene["body"], scene["axes"]
    kappa, energy = axis(axes["kappa"]), axis(axes["energy"])
    alpha, beta = float(axis(axes["alpha"])[0]), float(axis(axes["beta"])[0])
    cells = kappa.size * energy.size
    k = xr.DataArray(kappa, dims="kappa", coords={"kappa": kappa})
    e = xr.DataArray(energy, dims="energy", coords={"energy": energy})
    times = {"rubber-atlas run": [], "rubber_atlas.cells": []}
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "slice.h5"
        for _ in range(args.repeat):
            start = time.perf_counter()
            subprocess.run([BIN, "run", str(SCENE), "--out", str(out), "--force", "--quiet", "--threads",
                            str(args.threads)], check=True)
            times["rubber-atlas run"].append(time.perf_counter() - start)
            start = time.perf_counter()
            ds = ra.cells(alpha, beta, body["nu"], body["eta"], k, e, tol=scene["solver"]["tolerance"],
                          threads=args.threads)
            times["rubber_atlas.cells"].append(time.perf_counter() - start)
        # The same numbers, as a check that both did the same work.
        with ra.open_atlas(out) as atlas:
            same = np.array_equal(atlas.rotation_number.isel(alpha=0, beta=0).values.view(np.uint8),
                                  ds.rotation_number.values.view(np.uint8))
    rates = {name: cells / min(t) for name, t in times.items()}
    print(f"standard slice: {cells} cells, {args.threads} thread(s), best of {args.repeat}, alternately")
    for name, rate in rates.items():
        print(f"  {name:20s} {rate:10.0f} cells/s  (times: {', '.join(f'{t:.3f}' for t in times[name])} s)")
    ratio = rates["rubber_atlas.cells"] / rates["rubber-atlas run"]
    print(f"  ratio cells/run: {ratio:.2f}; rotation_number identical bit for bit: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
