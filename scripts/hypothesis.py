"""The paper's boundedness hypothesis (docs/hypothesis.md) over the (α, β) plane, from the verdict of
the package `rubber_atlas` (the code of `rubber-atlas verdict`).

The hypothesis: paths are bounded (1) for β² < 1 + α at every κ ≠ 0; (2) for β² > 1 + α, α > 0,
when κ > κ_max (the fold of the N = 0 curve beside σ_u). `rubber-atlas verdict` decides it for
one body over the whole (κ, ε) plane, the limits ε → ∞, κ → 0 and the bottom of each well
included; `verdict --boundaries` gives, for one α, the β at which the verdict changes, each by
root-finding on the fail margin (the quantity that decides it).

This script, for given (ν, η):
- runs `ra.boundaries` (`verdict --boundaries`) at every α of a grid, whose scan gives the verdict of every
  body of an α × β grid (log-spaced β) and the boundary curves β(α);
- repeats the boundaries (on a coarser grid) for other (ν, η), to show how the curves move;
- confirms each failure region with one full-model trajectory (`ra.trajectory(model="full")`)
  started on a counterexample: its centre of mass must run away linearly, n·|Δζ| after n
  periods;
- writes <out>.csv (the map), <out>-boundaries.csv, <out>-evidence.csv, <out>.h5 (all three)
  and <out>.png (the map with the curves).

    .venv/bin/python scripts/hypothesis.py --out docs/hypothesis
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import h5py
import numpy as np

import rubber_atlas as ra

ROOT = Path(__file__).resolve().parents[1]
CATEGORIES = {"holds": 0, "fails": 1, "not covered": 2, "undecided": 3}


def boundaries(alpha: float, nu: float, eta: float, scan: int, beta_min: float, beta_max: float,
               resolution: int) -> dict:
    """`verdict --boundaries` at one α (the package's, on rayon's pool, which the callers in
    several threads share): {alpha, boundaries: [...], scan: [...]}."""
    found = ra.boundaries(alpha, nu, eta, scan=scan, beta_min=beta_min, beta_max=beta_max, resolution=resolution)
    return json.loads(found.attrs["boundaries_json"])


def verdict(alpha: float, beta: float, nu: float, eta: float, resolution: int) -> dict:
    """The verdict of one body, as `rubber-atlas verdict --json` prints it."""
    return json.loads(ra.verdict(alpha, beta, nu, eta, resolution=resolution).verdict_json.item())


def label(holds, case="1") -> str:
    """holds / fails; for a null verdict, `not covered` where the hypothesis says nothing
    (α = 0, β ≥ 1), else `undecided` (the verdict's reason says why)."""
    if holds is None:
        return "not covered" if case == "not_covered" else "undecided"
    return "holds" if holds else "fails"


def sweep(alphas, nu, eta, scan, beta_min, beta_max, resolution, jobs):
    """`verdict --boundaries` at every α, `jobs` at a time, in α order."""
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(lambda a: boundaries(a, nu, eta, scan, beta_min, beta_max, resolution), alphas))


def map_rows(results) -> list[dict]:
    """One row per body of the scans: the map."""
    rows = []
    for r in results:
        for p in r["scan"]:
            h = p["high_energy"]
            rows.append(dict(alpha=r["alpha"], beta=p["beta"], case=p["case"], verdict=label(p["holds"], p["case"]),
                             kappa_max=np.nan if p["kappa_max"] is None else p["kappa_max"],
                             counterexamples=p["counterexamples"], slope=h["slope"], n_min=h["n_min"],
                             n_max=h["n_max"]))
    return rows


def boundary_rows(results, nu, eta) -> list[dict]:
    rows = []
    for r in results:
        for b in r["boundaries"]:
            rows.append(dict(nu=nu, eta=eta, alpha=r["alpha"], beta=b["beta"], error=b["error"],
                             quantity=b["quantity"],
                             below=f"case {b['case_below']} {label(b['holds_below'], b['case_below'])}",
                             above=f"case {b['case_above']} {label(b['holds_above'], b['case_above'])}"))
    return rows


def curve_kind(row: dict) -> str | None:
    """Boundaries of one mechanism and one side of failure join into one curve β(α) (whether
    the sampled plane or the high-energy limit decided it at that α, and whether a hair-thin
    undecided band lies beside it there); the edges of those bands (found by bisection on the
    verdict) are not curves of their own."""
    if row["quantity"].startswith("case"):
        return "case line beta^2 = 1 + alpha"
    below, above = row["below"], row["above"]
    if row["quantity"] == "verdict" and ("undecided" in below or "undecided" in above):
        return None
    mechanism = row["quantity"].replace("fail_margin: ", "").split(" (sampled")[0].split(" (high-energy")[0]
    side = "fails above" if "fails" in above else "fails below" if "fails" in below else f"{below} | {above}"
    return f"case {below.split()[1]}, {side}: {mechanism}"


def curves_of(brows: list[dict]) -> dict[tuple, dict[str, list]]:
    """{(ν, η): {kind: [(α, β), ...]}}."""
    out: dict[tuple, dict[str, list]] = {}
    for b in brows:
        kind = curve_kind(b)
        if kind is not None:
            out.setdefault((float(b["nu"]), float(b["eta"])), {}).setdefault(kind, []).append(
                (float(b["alpha"]), float(b["beta"])))
    return out


def regions(rows: list[dict]) -> list[list[dict]]:
    """Connected sets of failing bodies on the α × β grid (4-neighbours, one case each)."""
    alphas = sorted({r["alpha"] for r in rows})
    betas = {a: sorted(r["beta"] for r in rows if r["alpha"] == a) for a in alphas}
    at = {(r["alpha"], r["beta"]): r for r in rows}
    index = {(a, b): (i, j) for i, a in enumerate(alphas) for j, b in enumerate(betas[a])}
    cell = {v: k for k, v in index.items()}
    seen, out = set(), []
    for key, r in at.items():
        if r["verdict"] != "fails" or key in seen:
            continue
        stack, region = [key], []
        seen.add(key)
        while stack:
            k = stack.pop()
            region.append(at[k])
            i, j = index[k]
            for n in [(i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)]:
                nk = cell.get(n)
                if nk and nk not in seen and at[nk]["verdict"] == "fails" and at[nk]["case"] == r["case"]:
                    seen.add(nk)
                    stack.append(nk)
        out.append(region)
    return out


def confirm(alpha: float, beta: float, nu: float, eta: float, resolution: int, periods=(10, 20)) -> dict:
    """The first counterexample of one body, followed with the full model: the centre of mass
    is n·|Δζ| from its start after n periods on an integer resonance."""
    v = verdict(alpha, beta, nu, eta, resolution)
    if not v["counterexamples"]:
        return dict(alpha=alpha, beta=beta, confirmed=False, reason=v["evidence"].get("limit_failure") or "none")
    c = min(v["counterexamples"], key=lambda c: abs(np.log(c["kappa"])))
    cell = ra.cells(alpha, beta, nu, eta, c["kappa"], c["energy"], method="ode")
    comp = min(ra.components(cell), key=lambda x: abs(x["theta_min"] - c["theta_min"]))
    distances = []
    for n in periods:
        t = ra.trajectory(alpha, beta, nu, eta, c["kappa"], theta0=c["theta_min"], periods=n, samples=4, model="full")
        x, y = t.x_c.values, t.y_c.values
        distances.append(float(np.hypot(x[-1] - x[0], y[-1] - y[0])))
    expected = [n * c["drift"] for n in periods]
    linear = all(abs(d - e) <= 1e-5 * e for d, e in zip(distances, expected))
    return dict(alpha=alpha, beta=beta, case=v["case"], integer=c["integer"], kappa=c["kappa"], energy=c["energy"],
                rotation_number=c["rotation_number"], ode_rotation_number=comp["rotation_number"],
                drift_per_period=c["drift"], periods=list(periods), distance=distances, confirmed=linear)


def write_csv(path: Path, rows: list[dict]) -> None:
    import csv

    with open(path, "w", newline="") as f:
        if not rows:
            return
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def write_h5(path: Path, tables: dict[str, list[dict]], attrs: dict) -> None:
    with h5py.File(path, "w") as f:
        f.attrs.update(attrs)
        for name, rows in tables.items():
            g = f.create_group(name)
            for key in rows[0] if rows else []:
                values = [r[key] for r in rows]
                if isinstance(values[0], str) or isinstance(values[0], list):
                    g.create_dataset(key, data=np.array([str(v) for v in values], dtype=h5py.string_dtype()))
                else:
                    g.create_dataset(key, data=np.array(values, dtype=float))


def plot(rows: list[dict], brows: list[dict], evidence: list[dict], png: Path, nu: float, eta: float) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    # The raster holds the log-spaced scan; the two bodies 1e-9 either side of β² = 1 + α
    # (the dashed line) are left out of it.
    def on_grid(r):
        return abs(float(r["beta"]) / np.sqrt(1.0 + float(r["alpha"])) - 1.0) > 1e-6

    rows = [r for r in rows if on_grid(r)]
    alphas = np.array(sorted({float(r["alpha"]) for r in rows}))
    betas = np.array(sorted({float(r["beta"]) for r in rows if float(r["alpha"]) == alphas[0]}))
    grid = np.full((len(betas), len(alphas)), np.nan)
    for r in rows:
        i = int(np.argmin(np.abs(betas - float(r["beta"]))))
        grid[i, int(np.argmin(np.abs(alphas - float(r["alpha"]))))] = CATEGORIES[r["verdict"]]
    fig, ax = plt.subplots(figsize=(9.5, 6.5))
    colours = ["#bfe3bf", "#f2b8b5", "#dddddd", "#f5e08a"]
    ax.pcolormesh(alphas, betas, grid, cmap=ListedColormap(colours), vmin=-0.5, vmax=3.5, shading="nearest")
    handles = [Patch(color=c, label=k) for k, c in zip(CATEGORIES, colours)]
    all_curves = curves_of(brows)
    styles = {}
    for n, pair in enumerate(sorted(all_curves, key=lambda p: p != (nu, eta))):
        main = pair == (nu, eta)
        colour = "k" if main else f"C{n}"
        for kind, pts in sorted(all_curves[pair].items()):
            a, b = np.array(sorted(pts)).T
            if kind.startswith("case line"):
                if main:
                    line, = ax.plot(a, b, "k--", lw=1)
                    styles.setdefault(r"$\beta^2 = 1 + \alpha$ (case 1 | case 2)", line)
                continue
            # A curve runs through the α with one boundary of this kind; where an α has
            # several (the verdict alternates along β there), they are drawn as points.
            counts = {x: int(np.sum(a == x)) for x in a}
            single = np.array([counts[x] == 1 for x in a])
            line, = ax.plot(np.where(single, a, np.nan), np.where(single, b, np.nan), "-" if main else ":",
                            color=colour, marker="." if main else None, ms=3, lw=1.6 if main else 1.3)
            ax.plot(a[~single], b[~single], ".", color=colour, ms=4)
            name = f"boundary, nu = {pair[0]}, eta = {pair[1]}"
            styles.setdefault(name, line)
            if main:
                mechanism = kind.split(": ")[-1]
                mid = len(a) // 2
                ax.annotate(mechanism, (a[mid], b[mid]), textcoords="offset points", xytext=(0, 6), fontsize=7,
                            ha="center")
    for e in evidence:
        if str(e.get("confirmed")) == "True":
            star, = ax.plot(float(e["alpha"]), float(e["beta"]), "k*", ms=10)
            styles.setdefault("full-model trajectory on a counterexample", star)
    ax.set_yscale("log")
    ax.set_xlabel(r"$\alpha$")
    ax.set_ylabel(r"$\beta$")
    ax.set_title(f"The boundedness hypothesis over the whole ($\\kappa$, $\\varepsilon$) plane, "
                 f"$\\nu$ = {nu}, $\\eta$ = {eta}", fontsize=10)
    ax.legend(handles=handles + list(styles.values()), labels=[h.get_label() for h in handles] + list(styles),
              fontsize=7, loc="lower right", framealpha=0.9)
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)


def read_csv(path: Path) -> list[dict]:
    import csv

    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main() -> None:
    parser = argparse.ArgumentParser(
        description="The boundedness hypothesis over the (alpha, beta) plane from `rubber-atlas verdict`: the map, "
                    "the boundary curves for several (nu, eta), and trajectory evidence for each failure region.")
    parser.add_argument("--out", required=True, help="output path without extension (.csv, -boundaries.csv, "
                                                     "-evidence.csv, .h5 and .png are written)")
    parser.add_argument("--nu", type=float, default=0.5, help="nu of the map (default 0.5)")
    parser.add_argument("--eta", type=float, default=0.5, help="eta of the map (default 0.5)")
    parser.add_argument("--alphas", type=int, default=40, help="alpha values from 0 to 0.975 (default 40)")
    parser.add_argument("--betas", type=int, default=60, help="log-spaced beta values (default 60)")
    parser.add_argument("--beta-min", type=float, default=0.05, help="smallest beta (default 0.05)")
    parser.add_argument("--beta-max", type=float, default=50.0, help="largest beta (default 50)")
    parser.add_argument("--others", default="0.1,1;1,0.1;1.5,5",
                        help="other (nu, eta) pairs whose boundary curves are drawn, as 'nu,eta;nu,eta' "
                             "(default '0.1,1;1,0.1;1.5,5'; '' for none)")
    parser.add_argument("--other-alphas", type=int, default=10, help="alpha values for the other pairs (default 10)")
    parser.add_argument("--other-betas", type=int, default=24, help="beta scan for the other pairs (default 24)")
    parser.add_argument("--resolution", type=int, default=64,
                        help="sampling of each body's (kappa, energy) plane, as verdict --resolution (default 64; "
                             "a coarser one is faster and may miss a narrow failure)")
    parser.add_argument("--jobs", type=int, default=2, help="verdict processes at a time (default 2)")
    parser.add_argument("--no-confirm", action="store_true", help="skip the trajectory evidence")
    parser.add_argument("--replot", action="store_true",
                        help="only redraw <out>.png from the tables an earlier run wrote")
    args = parser.parse_args()
    out = Path(args.out)
    if args.replot:
        plot(read_csv(out.with_suffix(".csv")), read_csv(out.parent / f"{out.name}-boundaries.csv"),
             read_csv(out.parent / f"{out.name}-evidence.csv"), out.with_suffix(".png"), args.nu, args.eta)
        return

    start = time.time()
    alphas = [float(a) for a in np.linspace(0.0, 0.975, args.alphas)] if args.alphas > 1 else [0.5]
    results = sweep(alphas, args.nu, args.eta, args.betas, args.beta_min, args.beta_max, args.resolution,
                    args.jobs)
    rows = map_rows(results)
    brows = boundary_rows(results, args.nu, args.eta)
    main_seconds = time.time() - start
    for pair in filter(None, args.others.split(";")):
        o_nu, o_eta = (float(x) for x in pair.split(","))
        o_alphas = [float(a) for a in np.linspace(0.0, 0.975, args.other_alphas)]
        o_results = sweep(o_alphas, o_nu, o_eta, args.other_betas, args.beta_min, args.beta_max,
                          args.resolution, args.jobs)
        brows += boundary_rows(o_results, o_nu, o_eta)
    evidence = []
    if not args.no_confirm:
        for region in regions(rows):
            # The body nearest the region's middle (in α, then log β).
            mid_a = np.median([r["alpha"] for r in region])
            mid_b = np.exp(np.median([np.log(r["beta"]) for r in region]))
            body = min(region, key=lambda r: (abs(r["alpha"] - mid_a), abs(np.log(r["beta"] / mid_b))))
            e = confirm(body["alpha"], body["beta"], args.nu, args.eta, args.resolution)
            e["region_bodies"] = len(region)
            evidence.append(e)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_csv(out.with_suffix(".csv"), rows)
    write_csv(out.parent / f"{out.name}-boundaries.csv", brows)
    write_csv(out.parent / f"{out.name}-evidence.csv", evidence)
    attrs = dict(nu=args.nu, eta=args.eta, resolution=args.resolution, program=f"rubber-atlas {ra.__version__} ({ra.git_commit})",
                 command_line=" ".join(sys.argv), seconds_map=main_seconds)
    write_h5(out.with_suffix(".h5"), dict(map=rows, boundaries=brows, evidence=evidence), attrs)
    plot(rows, brows, evidence, out.with_suffix(".png"), args.nu, args.eta)
    counts = {k: sum(r["verdict"] == k for r in rows) for k in CATEGORIES}
    print(f"hypothesis: {len(rows)} bodies ({counts}), {len(brows)} boundaries, "
          f"{sum(e.get('confirmed', False) for e in evidence)}/{len(evidence)} failure regions confirmed by the "
          f"full model; map and curves in {main_seconds:.0f} s, everything in {time.time() - start:.0f} s")
    for e in evidence:
        print("  evidence:", {k: e[k] for k in e if k in ("alpha", "beta", "integer", "kappa", "energy", "distance",
                                                          "confirmed", "region_bodies", "reason")})
    if not all(e.get("confirmed") for e in evidence):
        sys.exit("hypothesis: a failure region was not confirmed by a trajectory")


if __name__ == "__main__":
    main()
