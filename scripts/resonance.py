"""Resonance curves N = p/q from an atlas: contour the rotation number of every component slot
on every (κ, ε) slice, optionally refine each curve with `rubber-atlas resonance` (points
solved to the solver's tolerance instead of interpolated on the grid), and save them.

    .venv/bin/python scripts/resonance.py atlas/out/demo.h5 --pq 0 --out curves.csv
    .venv/bin/python scripts/resonance.py atlas/out/demo.h5 --qmax 3 --refine --out curves.h5

Output columns (CSV, or one HDF5 dataset each): alpha, beta, p, q, target, component, curve,
point, kappa, energy, source ("atlas" or "refined"). N jumps at a separatrix (it diverges
there): contour pieces across such a jump are dropped.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from rubber_atlas import open_atlas

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
# Largest change of N across one grid cell that still counts as continuous.
JUMP = 0.5


@dataclass
class Curve:
    alpha: float
    beta: float
    target: Fraction
    component: int
    kappa: np.ndarray
    energy: np.ndarray
    source: str = "atlas"
    extra: dict = field(default_factory=dict)


def targets(pq: str | None, qmax: int | None, lo: float, hi: float) -> list[Fraction]:
    """The rotation numbers asked for: one P/Q, or every p/q with q ≤ qmax in [lo, hi]."""
    if pq is not None:
        return [Fraction(pq)]
    found = {Fraction(p, q) for q in range(1, qmax + 1) for p in range(int(np.floor(lo * q)), int(np.ceil(hi * q)) + 1)}
    return sorted(f for f in found if lo <= f <= hi)


def contour_lines(kappa: np.ndarray, energy: np.ndarray, n: np.ndarray, level: float) -> list[np.ndarray]:
    """Lines N = level of the field n[κ, ε] (NaN where the component does not exist), split
    where the field jumps by more than JUMP across a grid cell (a separatrix)."""
    import contourpy

    z = np.ma.masked_invalid(n.T)  # rows: energy, columns: kappa
    gen = contourpy.contour_generator(kappa, energy, z, line_type="Separate")
    out = []
    dk, de = np.diff(kappa).mean(), np.diff(energy).mean()
    for line in gen.lines(level):
        keep = np.ones(len(line), bool)
        for i, (k, e) in enumerate(line):
            a = min(max(int((k - kappa[0]) / dk), 0), len(kappa) - 2)
            b = min(max(int((e - energy[0]) / de), 0), len(energy) - 2)
            corners = n[a : a + 2, b : b + 2]
            keep[i] = np.all(np.isfinite(corners)) and np.ptp(corners) < JUMP
        # Split at dropped vertices.
        start = None
        for i in range(len(line) + 1):
            if i < len(line) and keep[i]:
                start = i if start is None else start
            elif start is not None:
                if i - start >= 2:
                    out.append(line[start:i])
                start = None
    return out


def extract(path: str | Path, wanted: list[Fraction] | None = None, qmax: int = 3) -> list[Curve]:
    """Curves N = p/q on every (α, β) slice and component slot of the atlas at `path` (κ > 0:
    at κ = 0, N = 0 identically). A slot holds the components in increasing θ_min, so one
    torus family can change slot where another component appears: a curve may come in
    pieces, which `refine` joins."""
    ds = open_atlas(path)
    kappa, energy = ds.kappa.values, ds.energy.values
    curves = []
    for ia, alpha in enumerate(ds.alpha.values):
        for ib, beta in enumerate(ds.beta.values):
            n_all = ds.rotation_number.isel(alpha=ia, beta=ib).values  # (kappa, energy, component)
            finite = n_all[np.isfinite(n_all)]
            if finite.size == 0:
                continue
            levels = wanted if wanted is not None else targets(None, qmax, float(finite.min()), float(finite.max()))
            for slot in range(n_all.shape[-1]):
                n = n_all[..., slot].copy()
                n[kappa == 0.0, :] = np.nan  # N = 0 identically at κ = 0: no curve there
                if np.isfinite(n).sum() < 4:
                    continue
                for level in levels:
                    for line in contour_lines(kappa, energy, n, float(level)):
                        curves.append(Curve(float(alpha), float(beta), level, slot, line[:, 0], line[:, 1]))
    ds.close()
    return curves


def refine(curves: list[Curve], nu: float, eta: float, window: tuple[float, float, float, float] | None = None,
           tol: float = 1e-10, grid: int = 24) -> list[Curve]:
    """The same resonances traced by `rubber-atlas resonance`, for each body and p/q of
    `curves`: points on N = p/q to the solver's tolerance. The window (κ_min, κ_max, ε_min,
    ε_max) is the atlas's (κ > 0), or by default the curves' bounding box with a margin."""
    out = []
    groups: dict[tuple, list[Curve]] = {}
    for c in curves:
        groups.setdefault((c.alpha, c.beta, c.target), []).append(c)
    for (alpha, beta, target), group in groups.items():
        if window is None:
            k = np.concatenate([c.kappa for c in group])
            e = np.concatenate([c.energy for c in group])
            pad_k, pad_e = 0.25 * (np.ptp(k) + 0.1), 0.25 * (np.ptp(e) + 0.1)
            box = (max(k.min() - pad_k, 1e-3), k.max() + pad_k, e.min() - pad_e, e.max() + pad_e)
        else:
            box = (max(window[0], 1e-3), window[1], window[2], window[3])
        args = [
            BIN, "resonance", "--alpha", repr(float(alpha)), "--beta", repr(float(beta)), "--nu", repr(float(nu)),
            "--eta", repr(float(eta)), "--rotation-number", f"{target.numerator}/{target.denominator}",
            "--kappa-min", repr(float(box[0])), "--kappa-max", repr(float(box[1])),
            "--energy-min", repr(float(box[2])), "--energy-max", repr(float(box[3])),
            "--grid", str(grid), "--tol", repr(float(tol)), "--json",
        ]
        result = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
        for traced in result["curves"]:
            pts = traced["points"]
            out.append(Curve(alpha, beta, target, int(pts[0]["component"]),
                             np.array([p["kappa"] for p in pts]), np.array([p["energy"] for p in pts]),
                             source="refined", extra={"rotation_number": np.array([p["rotation_number"] for p in pts]),
                                                      "error_estimate": np.array([p["error_estimate"] for p in pts]),
                                                      "component": np.array([p["component"] for p in pts])}))
    return out


def atlas_window(path: str | Path) -> tuple[float, float, float, float]:
    """The (κ_min, κ_max, ε_min, ε_max) of an atlas, with κ_min > 0."""
    ds = open_atlas(path)
    k, e = ds.kappa.values, ds.energy.values
    ds.close()
    positive = k[k > 0]
    return float(positive.min()), float(k.max()), float(e.min()), float(e.max())


COLUMNS = ["alpha", "beta", "p", "q", "target", "component", "curve", "point", "kappa", "energy", "source"]


def rows(curves: list[Curve]):
    for i, c in enumerate(curves):
        # The component index of each point (it can change along a traced curve where
        # another component appears below it), else the contoured slot.
        slots = c.extra.get("component", np.full(len(c.kappa), c.component))
        for j, (k, e) in enumerate(zip(c.kappa, c.energy)):
            yield [c.alpha, c.beta, c.target.numerator, c.target.denominator, float(c.target), int(slots[j]), i, j,
                   float(k), float(e), c.source]


def save(curves: list[Curve], out: str | Path) -> None:
    """CSV or HDF5 (by extension), one row per point."""
    out = Path(out)
    data = list(rows(curves))
    if out.suffix == ".csv":
        with out.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(COLUMNS)
            w.writerows(data)
        return
    import h5py

    with h5py.File(out, "w") as f:
        for i, name in enumerate(COLUMNS):
            values = [r[i] for r in data]
            if name == "source":
                f.create_dataset(name, data=np.array(values, dtype="S8"))
            else:
                f.create_dataset(name, data=np.array(values, dtype=float if name in ("alpha", "beta", "target", "kappa", "energy") else int))
        f.attrs["columns"] = ",".join(COLUMNS)


def load(path: str | Path) -> dict[str, np.ndarray]:
    """The saved columns as arrays."""
    path = Path(path)
    if path.suffix == ".csv":
        with path.open() as f:
            r = list(csv.DictReader(f))
        return {k: np.array([row[k] for row in r], dtype=object if k == "source" else float) for k in COLUMNS}
    import h5py

    with h5py.File(path) as f:
        return {k: f[k][()] for k in COLUMNS}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("atlas")
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--pq", help="one rotation number P/Q, e.g. 0, 1, -1/7")
    group.add_argument("--qmax", type=int, help="every p/q with q <= QMAX in the atlas's range of N")
    parser.add_argument("--refine", action="store_true", help="trace the curves with `rubber-atlas resonance`")
    parser.add_argument("--out", required=True, help="CSV or HDF5 file")
    args = parser.parse_args()
    wanted = targets(args.pq, None, 0, 0) if args.pq is not None else None
    curves = extract(args.atlas, wanted, qmax=args.qmax or 1)
    if args.refine:
        ds = open_atlas(args.atlas)
        nu, eta, tol = float(ds.attrs["nu"]), float(ds.attrs["eta"]), float(ds.attrs["tolerance"])
        ds.close()
        curves = refine(curves, nu, eta, window=atlas_window(args.atlas), tol=max(tol, 1e-12))
    save(curves, args.out)
    print(f"wrote {len(curves)} curves ({sum(len(c.kappa) for c in curves)} points) to {args.out}")


if __name__ == "__main__":
    main()
