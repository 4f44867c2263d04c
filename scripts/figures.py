"""The paper's figures, drawn from this program's own output (every number comes from the
package `rubber_atlas`, the same Rust code as the commands, or an atlas `rubber-atlas run`
wrote):

- ab:    regions of the diagram types (a)–(e) on the (α, β²) plane (`diagram` over a grid);
- wvth:  where permanent rotations exist, ω0² ≥ 0, on the (β², θ) plane for fixed α (the θ0
         ranges of the fixed-point branches of `diagram`);
- bif:   bifurcation diagrams of types (a)–(e): the region of possible motion shaded by the
         number of tori (`n_components` of the paper-a … paper-e atlases), stable branches
         solid and unstable dotted (`diagram --out`);
- phase: phase portraits (θ, θ̇) for chosen κ, one per type (Figs. bifa–bife): one θ-period of
         `trajectory` on each component of several energy levels;
- res:   resonance curves N = p/q over the type (c) diagram (`resonance`), and the centre of
         mass and contact point at N = 0, κ = 0.5 (`trajectory`);
- xy:    the trajectories of Fig. xy: N = −1/7 (κ = 0.8) and quasi-periodic (κ = 1, θ(0) = 2.1);
- bodies: N over (κ, ε) of the disk, the truncated ball, the wheel and a profile (docs/bodies.md), with
         their resonance curves N = 0, ±1/4, ±1/7 (`cells` and `resonance` with `shape=`).

    .venv/bin/python scripts/figures.py all --out docs/figures
    .venv/bin/python scripts/figures.py bif --out docs/figures
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

import rubber_atlas as ra  # noqa: E402
from rubber_atlas import open_atlas  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))
NU = ETA = 0.5
# The paper's bodies of Figs. bifa, bifb, php (type c), bifd, bife.
BODIES = {"a": (0.5, 0.5), "b": (0.5, 1.1), "c": (0.5, 3.0), "d": (0.0, 0.5), "e": (0.0, 1.5)}


def columns(table) -> dict[str, np.ndarray]:
    """The columns of a table (a Dataset of the package) as numpy arrays."""
    return {name: v.values for name, v in table.variables.items()}


def run(*args: str) -> str:
    return subprocess.run([BIN, *map(str, args)], check=True, capture_output=True, text=True).stdout


def diagram_json(alpha: float, beta: float) -> dict:
    """The critical set's summary (`rubber-atlas diagram --json`)."""
    return json.loads(ra.diagram(alpha, beta, NU, ETA).attrs["critical_set_json"])


def diagram_curves(alpha: float, beta: float, kappa_max: float = 3.0):
    """The sampled fixed-point branches: list of (kappa, energy, stable) arrays per segment."""
    cols = columns(ra.diagram(alpha, beta, NU, ETA, kappa_max=kappa_max))
    out = []
    for seg in np.unique(cols["segment"]):
        m = cols["segment"] == seg
        out.append((cols["kappa"][m], cols["energy"][m], bool(cols["stable"][m][0])))
    return out


def draw_branches(ax, alpha: float, beta: float, kappa_max: float = 3.0) -> None:
    for k, e, stable in diagram_curves(alpha, beta, kappa_max):
        ax.plot(k, e, "k-" if stable else "k:", lw=1.2 if stable else 1.0)


def fig_ab(out: Path, n: int = 24) -> Path:
    """Fig. ab: the diagram type of `diagram` on a grid of (α, β²)."""
    colours = {"a": "tab:blue", "b": "tab:orange", "c": "tab:green", "d": "tab:red", "e": "tab:purple"}
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    alphas = np.linspace(0.0, 0.95, n)
    beta2 = np.linspace(0.05, 3.0, n)
    seen = set()
    for a in alphas:
        for b2 in beta2:
            kind = diagram_json(float(a), float(np.sqrt(b2)))["diagram_type"]
            ax.scatter(a, b2, c=colours[kind], s=14, label=None if kind in seen else f"type ({kind})")
            seen.add(kind)
    x = np.linspace(0, 1, 50)
    ax.plot(x, 1 + x, "k-", lw=0.8)
    ax.plot(x, 1 - x, "k--", lw=0.8)
    ax.set_xlabel("α")
    ax.set_ylabel("β²")
    ax.set_title("diagram types (Fig. ab); lines β² = 1 ± α")
    ax.legend(fontsize=8, loc="upper left")
    return save(fig, out / "ab.png")


def fig_wvth(out: Path, alpha: float = 0.5, n: int = 60) -> Path:
    """Fig. wvth: θ0 where permanent rotations exist (ω0² ≥ 0) against β², for fixed α."""
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for b2 in np.linspace(0.05, 4.0, n):
        d = diagram_json(alpha, float(np.sqrt(b2)))
        for branch in d["branches"]:
            lo, hi = branch["theta0_range"]
            ax.plot([b2, b2], [lo, hi], color="tab:blue", lw=3, solid_capstyle="butt")
    ax.axvline(1 - alpha, color="k", ls="--", lw=0.8)
    ax.axvline(1 + alpha, color="k", ls="-", lw=0.8)
    ax.set_xlabel("β²")
    ax.set_ylabel("θ0")
    ax.set_title(f"ω0² ≥ 0: permanent rotations exist (α = {alpha})")
    return save(fig, out / "wvth.png")


def scene_text(kind: str, n: int) -> str:
    alpha, beta = BODIES[kind]
    return f"""name = "paper-{kind}"
[body]
nu = {NU}
eta = {ETA}
[axes]
alpha = [{alpha}]
beta = [{beta}]
kappa = {{ start = 0.0, stop = 2.0, num = {n} }}
energy = {{ start = 0.3, stop = 4.5, num = {n} }}
[solver]
tolerance = 1e-8
[outputs]
fields = ["rotation_number", "status"]
"""


def atlas_for(kind: str, folder: Path, n: int) -> Path:
    """A (κ, ε) atlas of the paper's type-`kind` body, made with `rubber-atlas run`."""
    scene = folder / f"paper-{kind}.toml"
    scene.write_text(scene_text(kind, n))
    path = folder / f"paper-{kind}.h5"
    run("run", scene, "--out", path, "--force", "--quiet")
    return path


def fig_bif(out: Path, n: int = 201) -> Path:
    """Fig. bif: types (a)–(e), the region of motion shaded by the number of tori."""
    fig, axes = plt.subplots(1, 5, figsize=(21, 4.2), sharey=True, layout="constrained")
    with tempfile.TemporaryDirectory() as d:
        for ax, kind in zip(axes, BODIES):
            ds = open_atlas(atlas_for(kind, Path(d), n))
            count = ds.n_components.isel(alpha=0, beta=0).values.T.astype(float)
            count[count == 0] = np.nan
            mesh = ax.pcolormesh(ds.kappa.values, ds.energy.values, count, shading="auto", cmap="Blues", vmin=0, vmax=3)
            ds.close()
            draw_branches(ax, *BODIES[kind], kappa_max=2.0)
            alpha, beta = BODIES[kind]
            ax.set_title(f"({kind}) α = {alpha}, β = {beta}")
            ax.set_xlabel("κ")
            ax.set_xlim(0, 2)
            ax.set_ylim(0.3, 4.5)
    axes[0].set_ylabel("ε")
    fig.colorbar(mesh, ax=axes, label="number of tori", ticks=[1, 2, 3], shrink=0.8)
    return save(fig, out / "bif.png")


def phase_portrait(ax, alpha: float, beta: float, kappa: float, levels: int = 9) -> None:
    """(θ, θ̇) over one θ-period on every component of `levels` energies."""
    info = diagram_json(alpha, beta)
    eps_lo = min(e["energy"] for e in info["equilibria"]) if kappa == 0 else None
    if eps_lo is None:
        # The lowest energy with motion at this κ: the bottom of V, from a cell scan.
        energies = np.linspace(0.3, 6.0, 200)
        scan = ra.cells(alpha, beta, NU, ETA, kappa, energies, tol=1e-6, fields=["status"])
        eps_lo = float(energies[np.argmax(scan.n_components.values > 0)])
    for e in np.linspace(eps_lo + 0.02, eps_lo + 2.5, levels):
        cell = ra.cells(alpha, beta, NU, ETA, kappa, e, tol=1e-6, fields=["motion"])
        for i, c in enumerate(ra.components(cell)):
            if c["motion"] == "fixed_point":
                continue
            cols = columns(ra.trajectory(alpha, beta, NU, ETA, kappa, float(e), component=i, periods=1,
                                         samples=300))
            theta = np.mod(cols["theta"], 2 * np.pi) if kappa == 0 else cols["theta"]
            ax.plot(theta, cols["theta_dot"], ".", ms=0.8, color=plt.cm.viridis((e - eps_lo) / 2.6))
    ax.set_xlabel("θ")
    ax.set_ylabel("θ̇")
    ax.set_title(f"α = {alpha}, β = {beta}, κ = {kappa}")


def fig_phase(out: Path, levels: int = 9) -> Path:
    """Figs. bifa–bife: phase portraits at κ = 0 and κ = 0.5 for each type."""
    fig, axes = plt.subplots(2, 5, figsize=(21, 7.5))
    for col, kind in enumerate(BODIES):
        for row, kappa in enumerate((0.0, 0.5)):
            phase_portrait(axes[row][col], *BODIES[kind], kappa, levels)
    return save(fig, out / "phase.png")


def fig_res(out: Path, targets=("0", "1", "-1/2", "-1/7", "-2/3"), grid: int = 32) -> Path:
    """Fig. res: resonance curves over the type (c) diagram; the centre of mass and the contact
    point on the N = 0 curve at κ = 0.5."""
    alpha, beta = BODIES["c"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    draw_branches(right, alpha, beta, kappa_max=1.6)
    n0 = None
    for i, t in enumerate(targets):
        curves = ra.resonance(alpha, beta, NU, ETA, t, kappa_max=1.6, energy_max=4.5, grid=grid)
        for j in np.unique(curves.curve.values):
            c = curves.where(curves.curve == j, drop=True)
            right.plot(c.kappa, c.energy, color=f"C{i}", lw=1.2, label=f"N = {t}" if j == 0 else None)
            if t == "0" and n0 is None:
                p = int(np.argmin(np.abs(c.kappa.values - 0.5)))
                n0 = {"kappa": float(c.kappa[p]), "energy": float(c.energy[p]), "component": int(c.component[p])}
    right.set_xlabel("κ")
    right.set_ylabel("ε")
    right.set_xlim(0, 1.6)
    right.set_ylim(1.5, 4.5)
    right.legend(fontsize=8)
    right.set_title("resonance curves over diagram (c)")
    if n0 is not None:
        cols = columns(ra.trajectory(alpha, beta, NU, ETA, n0["kappa"], n0["energy"], component=n0["component"],
                                     periods=12, samples=3000))
        left.plot(cols["x_c"], cols["y_c"], "-", color="darkred", lw=1, label="centre of mass")
        left.plot(cols["x_p"], cols["y_p"], ":", color="darkblue", lw=1, label="contact point")
        left.set_aspect("equal")
        left.legend(fontsize=8)
        left.set_title(f"N = 0 at κ = {n0['kappa']:.3f}, ε = {n0['energy']:.5f}: drifts away")
    return save(fig, out / "res.png")


def fig_xy(out: Path) -> Path:
    """Fig. xy: (a) N = −1/7, κ = 0.8, θ(0) = 0.4670288; (b) quasi-periodic, κ = 1, θ(0) = 2.1."""
    alpha, beta = BODIES["c"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.5))
    cases = [(0.8, 0.4670288, 7, "(a) N = −1/7, κ = 0.8"), (1.0, 2.1, 40, "(b) quasi-periodic, κ = 1")]
    for ax, (kappa, theta0, periods, title) in zip(axes, cases):
        cols = columns(ra.trajectory(alpha, beta, NU, ETA, kappa, theta0=theta0, periods=periods,
                                     samples=200 * periods))
        ax.plot(cols["x_c"], cols["y_c"], "-", color="darkred", lw=0.8, label="centre of mass")
        ax.plot(cols["x_p"], cols["y_p"], ":", color="darkblue", lw=0.8, label="contact point")
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.legend(fontsize=8)
    return save(fig, out / "xy.png")


# The egg with a sharp rim of atlas/egg.toml: (ρ, z[, edge]) from the bottom pole.
EGG = [[0, -1], [0.45, -0.92], [0.8, -0.62], [0.98, -0.2], [0.97, 0.25], [0.8, 0.62, 1], [0.4, 0.8], [0, 0.86]]

# The bodies of docs/bodies.md: (title, shape, α, cut, ν, η, κ window, ε window, keywords).
EDGED = [
    ("disk, α = 0.3 (ν = 2, η = 4)", "disk", 0.3, None, 2.0, 4.0, (0.02, 1.5), (0.35, 2.5), {}),
    ("truncated ball, α = 0.2, h = 0.4 (ν = 0.7, η = 1.3)", "truncated_ball", 0.2, 0.4, 0.7, 1.3,
     (0.02, 1.5), (0.65, 3.0), {}),
    ("wheel, α = 0.25, h = 0.7 (ν = 0.7, η = 1.3)", "wheel", 0.25, 0.7, 0.7, 1.3, (0.02, 1.5), (0.7, 3.0), {}),
    ("profile: the egg of atlas/egg.toml, α = −0.1 (ν = 0.8, η = 1.7)", "profile", -0.1, None, 0.8, 1.7,
     (0.02, 1.5), (0.9, 3.0), {"profile": EGG}),
]


def fig_bodies(out: Path, n: int = 121, targets=("0", "1/4", "-1/4", "1/7", "-1/7"), grid: int = 32) -> Path:
    """N of the torus of lowest θ_min over (κ, ε) for each body beyond the ellipsoid, with the resonance
    curves N = p/q traced by continuation (each point on N = p/q within its estimate)."""
    fig, axes = plt.subplots(2, 2, figsize=(12, 10), layout="constrained")
    for ax, (title, shape, alpha, cut, nu, eta, (k0, k1), (e0, e1), extra) in zip(axes.flat, EDGED):
        kappa, energy = np.linspace(k0, k1, n), np.linspace(e0, e1, n)
        cells = ra.cells(alpha, None, nu, eta, kappa=xr.DataArray(kappa, dims="kappa"),
                         energy=xr.DataArray(energy, dims="energy"), shape=shape, cut=cut,
                         fields=["rotation_number"], layout="theta_min", progress=False, **extra)
        n_low = cells.rotation_number.isel(component=0).transpose("energy", "kappa")
        cmap = plt.get_cmap("RdBu_r").with_extremes(bad="0.8")
        mesh = ax.pcolormesh(kappa, energy, n_low, cmap=cmap, vmin=-1.0, vmax=1.0, shading="nearest")
        for i, t in enumerate(targets):
            curves = ra.resonance(alpha, None, nu, eta, t, shape=shape, cut=cut, kappa_min=k0, kappa_max=k1,
                                  energy_max=e1, grid=grid, **extra)
            for j in np.unique(curves.curve.values):
                c = curves.where(curves.curve == j, drop=True)
                ax.plot(c.kappa, c.energy, color=f"C{i + 1}", lw=1.2, label=f"N = {t}" if j == 0 else None)
        ax.set_xlim(k0, k1)
        ax.set_ylim(e0, e1)
        ax.set_xlabel("κ")
        ax.set_ylabel("ε")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=7, loc="upper left")
    fig.colorbar(mesh, ax=axes, label="N of the torus of lowest θ_min (grey: no motion)")
    return save(fig, out / "bodies.png")


def save(fig, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


FIGURES = {"ab": fig_ab, "wvth": fig_wvth, "bif": fig_bif, "phase": fig_phase, "res": fig_res, "xy": fig_xy,
           "bodies": fig_bodies}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("figure", choices=[*FIGURES, "all"])
    parser.add_argument("--out", required=True, help="folder for the PNG files")
    args = parser.parse_args()
    out = Path(args.out)
    for name in FIGURES if args.figure == "all" else [args.figure]:
        print(f"figures: {name} -> {FIGURES[name](out)}")


if __name__ == "__main__":
    main()
