"""The paper's boundedness hypothesis (SPEC §4) tested over an (α, β) atlas.

The hypothesis: trajectories are bounded (1) for β² < 1 + α, except κ = 0 with ε > ε_min;
(2) for β² > 1 + α, α > 0, when κ > κ_max, where κ_max is the fold of the N = 0 curve
(N = 0, ∂N/∂ε = 0). A path is unbounded exactly where a component's rotation number N is an
integer (the drift radius R = |Δζ|/(2|sin πN|) is infinite there), so for every body of the
atlas this script:
- finds the integer resonances at κ > 0: sign changes of N − k between neighbouring cells of
  one continuous component field (not across a separatrix, where N jumps);
- computes κ_max with `rubber-atlas resonance --rotation-number 0 --fold` (case 2);
- gives the verdict: `holds`, `fails` (an integer resonance where the hypothesis says
  bounded), or `not covered` (α = 0, β > 1: diagram type (e));
- for a failure, the evidence: the cell, its N and drift radius, the point of the resonance
  traced exactly, and a `rubber-atlas trajectory` there whose centre of mass drifts away.

    .venv/bin/python scripts/hypothesis.py atlas/hypothesis.h5 --out atlas/out/hypothesis
writes hypothesis.csv, hypothesis.h5 (verdict per (α, β)) and hypothesis.png (the map).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from atlas_io import open_atlas

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
JUMP = 0.5  # a larger change of N between neighbouring cells is a separatrix, not a crossing
VERDICTS = ["holds", "fails", "not covered"]


@dataclass
class Verdict:
    alpha: float
    beta: float
    diagram_type: str
    case: int  # 1: β² < 1 + α; 2: β² > 1 + α, α > 0; 0: not covered
    integer_resonance: bool
    resonance_kappa: float  # the largest κ of an integer crossing found (NaN if none)
    kappa_max: float  # the fold of the N = 0 curve (NaN if none or not computed)
    verdict: str
    evidence_kappa: float = float("nan")
    evidence_energy: float = float("nan")
    evidence_n: float = float("nan")
    evidence_drift_radius: float = float("nan")
    evidence_integer: float = float("nan")
    evidence_component: int = -1


def run(*args: str) -> str:
    return subprocess.run([BIN, *args], check=True, capture_output=True, text=True).stdout


def diagram_type(alpha: float, beta: float, nu: float, eta: float) -> str:
    out = json.loads(run("diagram", "--alpha", repr(alpha), "--beta", repr(beta), "--nu", repr(nu), "--eta", repr(eta),
                         "--json"))
    return out["diagram_type"]


def integer_crossings(kappa: np.ndarray, energy: np.ndarray, n: np.ndarray, drift_radius: np.ndarray,
                      bounded: np.ndarray | None = None):
    """(κ, ε, N, R, k, slot) of the cells next to a crossing of an integer k by N (κ > 0), over
    every component slot, neighbours along κ and along ε; and of the cells the solver marked
    unbounded (N an integer within its error estimate), if `bounded` is given."""
    found = []
    for slot in range(n.shape[-1]):
        z, r = n[..., slot], drift_radius[..., slot]
        for axis in (0, 1):
            lo, hi = (z[:-1, :], z[1:, :]) if axis == 0 else (z[:, :-1], z[:, 1:])
            ok = np.isfinite(lo) & np.isfinite(hi) & (np.abs(hi - lo) < JUMP)
            with np.errstate(invalid="ignore"):
                cross = ok & (np.floor(lo) != np.floor(hi))
            for i, j in np.argwhere(cross):
                ii, jj = (i + 1, j) if axis == 0 else (i, j + 1)
                if kappa[i] <= 0 or kappa[ii] <= 0:
                    continue
                k = float(max(np.floor(lo[i, j]), np.floor(hi[i, j])))
                # The cell of the pair nearer the integer.
                pick = (i, j) if abs(z[i, j] - k) < abs(z[ii, jj] - k) else (ii, jj)
                found.append((float(kappa[pick[0]]), float(energy[pick[1]]), float(z[pick]), float(r[pick]), k, slot))
        if bounded is not None:
            for i, j in np.argwhere(bounded[..., slot] == 0):
                if kappa[i] > 0:
                    found.append((float(kappa[i]), float(energy[j]), float(z[i, j]), float(r[i, j]),
                                  float(np.round(z[i, j])), slot))
    return found


def fold(alpha, beta, nu, eta, window) -> float:
    out = json.loads(run("resonance", "--alpha", repr(alpha), "--beta", repr(beta), "--nu", repr(nu), "--eta", repr(eta),
                         "--rotation-number", "0", "--fold", "--kappa-min", repr(window[0]), "--kappa-max",
                         repr(window[1]), "--energy-min", repr(window[2]), "--energy-max", repr(window[3]),
                         "--grid", "32"))
    return float("nan") if out["kappa_max"] is None else float(out["kappa_max"])


def judge(path: str | Path) -> list[Verdict]:
    ds = open_atlas(path)
    nu, eta = float(ds.attrs["nu"]), float(ds.attrs["eta"])
    kappa, energy = ds.kappa.values, ds.energy.values
    positive = kappa[kappa > 0]
    window = (float(positive.min()), float(kappa.max()), float(energy.min()), float(energy.max()))
    dk = float(np.diff(kappa).max()) if len(kappa) > 1 else 0.0
    verdicts = []
    for ia, alpha in enumerate(ds.alpha.values):
        for ib, beta in enumerate(ds.beta.values):
            alpha, beta = float(alpha), float(beta)
            n = ds.rotation_number.isel(alpha=ia, beta=ib).values
            r = ds.drift_radius.isel(alpha=ia, beta=ib).values if "drift_radius" in ds else np.full_like(n, np.nan)
            b = ds.bounded.isel(alpha=ia, beta=ib).values if "bounded" in ds else None
            crossings = integer_crossings(kappa, energy, n, r, b)
            kind = diagram_type(alpha, beta, nu, eta)
            if beta**2 < 1 + alpha:
                case = 1
            elif alpha > 0:
                case = 2
            else:
                case = 0
            k_max = fold(alpha, beta, nu, eta, window) if case == 2 else float("nan")
            top = max(crossings, key=lambda c: c[0]) if crossings else None
            v = Verdict(alpha, beta, kind, case, bool(crossings), top[0] if top else float("nan"), k_max, "holds")
            if case == 0:
                v.verdict = "not covered"
            elif case == 1:
                bad = crossings
            else:
                # Beyond the fold, with a grid cell's margin (the crossing is between cells).
                limit = k_max if np.isfinite(k_max) else 0.0
                bad = [c for c in crossings if c[0] > limit + dk]
            if case and bad:
                worst = max(bad, key=lambda c: c[0])
                v.verdict = "fails"
                (v.evidence_kappa, v.evidence_energy, v.evidence_n, v.evidence_drift_radius, v.evidence_integer,
                 v.evidence_component) = worst
            verdicts.append(v)
    ds.close()
    return verdicts


def confirm(v: Verdict, nu: float, eta: float, periods=(10, 40)) -> dict:
    """A failure checked with the program: the resonance traced exactly near the evidence cell
    (`resonance`), then the centre of mass over `periods` θ-periods there (`trajectory`): on
    an integer resonance its distance from the start grows in proportion to the periods."""
    if abs(v.evidence_n - v.evidence_integer) < 1e-9:
        # The cell itself is on the resonance (N = k to the solver's tolerance).
        p = {"kappa": v.evidence_kappa, "energy": v.evidence_energy, "component": v.evidence_component,
             "rotation_number": v.evidence_n}
    else:
        pad_k, pad_e = 0.05, 0.05
        traced = json.loads(run("resonance", "--alpha", repr(v.alpha), "--beta", repr(v.beta), "--nu", repr(nu),
                                "--eta", repr(eta), "--rotation-number", repr(v.evidence_integer), "--kappa-min",
                                repr(max(v.evidence_kappa - pad_k, 1e-3)), "--kappa-max",
                                repr(v.evidence_kappa + pad_k), "--energy-min", repr(v.evidence_energy - pad_e),
                                "--energy-max", repr(v.evidence_energy + pad_e), "--grid", "16", "--json"))
        points = [p for c in traced["curves"] for p in c["points"]]
        if not points:
            return {"confirmed": False, "reason": "no resonance point traced near the cell"}
        p = min(points, key=lambda p: (p["kappa"] - v.evidence_kappa) ** 2 + (p["energy"] - v.evidence_energy) ** 2)
    import h5py

    distances = []
    with tempfile.TemporaryDirectory() as d:
        for k in periods:
            out = Path(d) / f"t{k}.h5"
            run("trajectory", "--alpha", repr(v.alpha), "--beta", repr(v.beta), "--nu", repr(nu), "--eta", repr(eta),
                "--kappa", repr(p["kappa"]), "--energy", repr(p["energy"]), "--component", str(p["component"]),
                "--periods", str(k), "--samples", str(20 * k), "--out", str(out))
            with h5py.File(out) as f:
                x, y = f["x_c"][()], f["y_c"][()]
            distances.append(float(np.hypot(x[-1] - x[0], y[-1] - y[0])))
    ratio = distances[1] / distances[0] if distances[0] > 0 else float("nan")
    return {"confirmed": bool(abs(ratio - periods[1] / periods[0]) < 0.5), "kappa": p["kappa"], "energy": p["energy"],
            "rotation_number": p["rotation_number"], "periods": list(periods), "distances": distances}


def save(verdicts: list[Verdict], out: Path, nu: float, eta: float) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    rows = [asdict(v) for v in verdicts]
    with open(out.with_suffix(".csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import h5py

    alphas = sorted({v.alpha for v in verdicts})
    betas = sorted({v.beta for v in verdicts})
    shape = (len(alphas), len(betas))
    with h5py.File(out.with_suffix(".h5"), "w") as f:
        f.attrs["nu"], f.attrs["eta"] = nu, eta
        f.attrs["verdict_meanings"] = " ".join(v.replace(" ", "_") for v in VERDICTS)
        f.create_dataset("alpha", data=alphas)
        f.create_dataset("beta", data=betas)
        grids = {name: np.full(shape, np.nan) for name in ("kappa_max", "resonance_kappa", "case", "verdict")}
        for v in verdicts:
            i, j = alphas.index(v.alpha), betas.index(v.beta)
            grids["kappa_max"][i, j] = v.kappa_max
            grids["resonance_kappa"][i, j] = v.resonance_kappa
            grids["case"][i, j] = v.case
            grids["verdict"][i, j] = VERDICTS.index(v.verdict)
        for name, data in grids.items():
            f.create_dataset(name, data=data)
    plot(verdicts, out.with_suffix(".png"))


def plot(verdicts: list[Verdict], png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4))
    colours = {"holds": "tab:green", "fails": "tab:red", "not covered": "tab:gray"}
    for name, c in colours.items():
        pts = [(v.alpha, v.beta**2) for v in verdicts if v.verdict == name]
        if pts:
            a, b = zip(*pts)
            ax.scatter(a, b, c=c, s=18, label=f"{name} ({len(pts)})")
    alpha = np.linspace(0, 1, 100)
    for sign, style in ((1, "-"), (-1, "--")):
        ax.plot(alpha, 1 + sign * alpha, "k" + style, lw=0.8, label=f"β² = 1 {'+' if sign > 0 else '−'} α")
    ax.set_xlabel("α")
    ax.set_ylabel("β²")
    ax.set_title("boundedness hypothesis: verdict per body")
    ax.legend(fontsize=8)
    pts = [(v.alpha, v.beta**2, v.kappa_max) for v in verdicts if np.isfinite(v.kappa_max)]
    if pts:
        a, b, k = zip(*pts)
        sc = bx.scatter(a, b, c=k, s=18, cmap="viridis")
        fig.colorbar(sc, ax=bx, label="κ_max (fold of N = 0)")
    bx.plot(alpha, 1 + alpha, "k-", lw=0.8)
    bx.set_xlabel("α")
    bx.set_ylabel("β²")
    bx.set_title("κ_max(α, β) where β² > 1 + α")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("atlas", help="an atlas over (alpha, beta) with rotation_number (e.g. atlas/hypothesis.toml)")
    parser.add_argument("--out", required=True, help="output path without extension (.csv, .h5, .png are written)")
    parser.add_argument("--no-confirm", action="store_true", help="skip the trajectory check of failures")
    args = parser.parse_args()
    ds = open_atlas(args.atlas)
    nu, eta = float(ds.attrs["nu"]), float(ds.attrs["eta"])
    ds.close()
    verdicts = judge(args.atlas)
    out = Path(args.out)
    save(verdicts, out, nu, eta)
    counts = {name: sum(v.verdict == name for v in verdicts) for name in VERDICTS}
    print(f"{len(verdicts)} bodies: " + ", ".join(f"{n} {name}" for name, n in counts.items()))
    for v in verdicts:
        if v.verdict != "fails":
            continue
        line = (f"FAILS at alpha={v.alpha:g} beta={v.beta:g} (type {v.diagram_type}, case {v.case}): N crosses "
                f"{v.evidence_integer:g} at kappa={v.evidence_kappa:.4g}, energy={v.evidence_energy:.4g} "
                f"(cell N={v.evidence_n:.4g}, drift radius {v.evidence_drift_radius:.3g}); kappa_max={v.kappa_max:.6g}")
        if not args.no_confirm:
            c = confirm(v, nu, eta)
            line += f"; trajectory: {json.dumps(c)}"
        print(line)
    print(f"wrote {out.with_suffix('.csv')}, {out.with_suffix('.h5')}, {out.with_suffix('.png')}")


if __name__ == "__main__":
    main()
