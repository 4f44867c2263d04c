//! Resonance curves of the paper's type (c) body (α = 0.5, β = 3, ν = η = 0.5): the N = 0
//! curve runs beside the unstable branch σ_u and turns round the cusp; N = 1, 2, 3 lie ever
//! closer to σ_u; every traced point gives N = p/q when solved again as a cell; the fold κ_max
//! of the N = 0 curve agrees with a brute-force scan.

use rubber_atlas::cell::{solve_cell, solve_level, CellOptions};
use rubber_atlas::resonance::{fold, trace_curves, Curve, ResonanceOptions};
use rubber_atlas::torus::{CriticalKind, EffectivePotential};
use rubber_atlas::EllipsoidBody;

fn body() -> EllipsoidBody {
    EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap()
}

fn options(target: f64) -> ResonanceOptions {
    ResonanceOptions {
        target,
        kappa: (0.01, 2.0),
        energy: (0.5, 5.0),
        grid: 48,
        cell: CellOptions {
            tol: 1e-10,
            drift: false,
            ..CellOptions::default()
        },
        max_points: 20_000,
        max_point_error: 1e-6,
    }
}

/// The level of the maximum of V (the separatrix through σ_u) at κ, if there is one.
fn separatrix(body: &EllipsoidBody, kappa: f64) -> Option<f64> {
    EffectivePotential::new(body, kappa)
        .critical_points()
        .iter()
        .find(|p| p.kind == CriticalKind::Maximum)
        .map(|p| p.value)
}

const KAPPA_CUSP: f64 = 1.080220568083;

#[test]
fn the_n0_curve_runs_beside_sigma_u_and_turns_round_the_cusp() {
    let body = body();
    let curves = trace_curves(&body, &options(0.0)).unwrap();
    assert_eq!(curves.len(), 1, "{curves:?}");
    let curve = &curves[0];
    // Beside σ_u, all the way from small κ to the cusp: one branch just above its
    // separatrix (the component holding both wells), the other, after the turn round the
    // cusp, just below it (the σ_sπ well).
    // Below, the curve ends where N's estimate (growing like 1/|ε − ε_s|) reaches
    // max_point_error, 2.4e-10 below the separatrix.
    let (mut above, mut below, mut closest_below) = (0, 0, f64::INFINITY);
    for p in &curve.points {
        if p.kappa < KAPPA_CUSP - 0.02 {
            let gap = p.energy - separatrix(&body, p.kappa).unwrap();
            assert!(gap.abs() < 0.1, "κ = {}: {gap}", p.kappa);
            if gap > 0.0 {
                above += 1;
            } else {
                below += 1;
                closest_below = closest_below.min(-gap);
            }
        }
    }
    assert!(above > 10 && below > 5, "{above} above, {below} below");
    assert!(closest_below < 1e-9, "{closest_below}");
    // Round the cusp: beyond κ_c, and back on both sides of the saddle.
    let kappa_top = curve.points.iter().map(|p| p.kappa).fold(0.0, f64::max);
    assert!(kappa_top > KAPPA_CUSP + 0.02, "{kappa_top}");
    // One end at the window's edge κ → 0; the other runs into the separatrix (N → ±∞ there,
    // and N = 0 is met ever closer to it until double precision can no longer tell).
    let (first, last) = (curve.points[0], curve.points[curve.points.len() - 1]);
    let ends = [first, last];
    assert!(ends.iter().any(|p| p.kappa < 0.05), "{ends:?}");
    assert!(
        ends.iter().all(
            |p| p.kappa < 0.05 || (p.energy - separatrix(&body, p.kappa).unwrap()).abs() < 1e-8
        ),
        "{ends:?}"
    );
}

/// ε − ε_s at the point nearest κ among the curve points on one side of σ_u's separatrix:
/// `above` (the component holds both wells) or below on the σ_s0 side (θ_max at the saddle).
fn distance_at(body: &EllipsoidBody, curves: &[Curve], kappa: f64, above: bool) -> f64 {
    let p = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .filter(|p| {
            let level = separatrix(body, p.kappa).unwrap_or(f64::NAN);
            if above {
                p.energy > level && p.theta_max - p.theta_min > 1.5
            } else {
                p.energy < level && p.theta_max < 1.4
            }
        })
        .min_by(|a, b| (a.kappa - kappa).abs().total_cmp(&(b.kappa - kappa).abs()))
        .expect("a point on that side");
    assert!(
        (p.kappa - kappa).abs() < 0.02,
        "no point near κ = {kappa}: {p:?}"
    );
    p.energy - separatrix(body, p.kappa).unwrap()
}

#[test]
fn integer_curves_lie_ever_closer_to_sigma_u_and_are_on_resonance() {
    let body = body();
    let (mut above, mut below) = (Vec::new(), Vec::new());
    for n in [1.0, 2.0, 3.0] {
        let options = options(n);
        let curves = trace_curves(&body, &options).unwrap();
        assert!(!curves.is_empty(), "no N = {n} curve");
        above.push(distance_at(&body, &curves, 1.06, true));
        if n < 3.0 {
            // Below the separatrix, on the σ_s0 side, N = 3 exists only within 0.01 of the
            // cusp, past the end of N = 1 (which meets the fixed-point curve σ_s0 first).
            below.push(-distance_at(&body, &curves, 1.05, false));
        }
        // Every point, solved again as a cell, has N = n within the tolerance.
        for c in &curves {
            for p in c.points.iter().step_by(5) {
                let cell = solve_cell(&body, p.kappa, p.energy, &options.cell).unwrap();
                let got = &cell.components[p.component];
                assert!(
                    (got.rotation_number - n).abs() <= options.cell.tol.max(got.error_estimate),
                    "N = {} at {p:?}",
                    got.rotation_number
                );
            }
        }
    }
    eprintln!(
        "distances from the separatrix: above (κ = 1.06) {above:?}, below (κ = 1.05) {below:?}"
    );
    // Above the separatrix N = 1, 2, 3 lie ever closer to it; below it, N = 1 and 2.
    assert!(
        above[0] > above[1] && above[1] > above[2] && above[2] > 0.0,
        "above {above:?}"
    );
    assert!(below[0] > below[1] && below[1] > 0.0, "below {below:?}");
}

#[test]
fn the_fold_agrees_with_a_brute_force_scan() {
    let body = body();
    let f = fold(&body, &options(0.0)).unwrap().expect("a fold");
    eprintln!("fold {f:?}");
    assert!(f.kappa_error < 1e-6, "{f:?}");
    assert!(f.rotation_number.abs() < 1e-9);
    // The same fold from another seed grid and a tighter tolerance: within 1e-6.
    let mut other = options(0.0);
    other.grid = 40;
    other.cell.tol = 1e-12;
    let g = fold(&body, &other).unwrap().expect("a fold");
    assert!((f.kappa_max - g.kappa_max).abs() < 1e-6, "{f:?} {g:?}");

    // Brute force: rows of κ across the fold, each scanned along ε for a change of sign of N
    // of the component around the σ_sπ well; the largest such row brackets κ_max.
    let cell = CellOptions {
        tol: 1e-10,
        drift: false,
        ..CellOptions::default()
    };
    let (dk, de) = (2e-5, 2.5e-5);
    let mut last_with_root = f64::NAN;
    for i in 0..100 {
        let kappa = f.kappa_max - 1e-3 + dk * i as f64;
        let potential = EffectivePotential::new(&body, kappa);
        let mut previous: Option<f64> = None;
        let mut crossed = false;
        for j in 0..=1600 {
            let energy = f.energy - 0.02 + de * j as f64;
            let Ok(c) = solve_level(&potential, energy, &cell) else {
                continue;
            };
            // The component holding θ = f.well.
            let Some(comp) = c
                .components
                .iter()
                .find(|x| x.theta_min <= f.well && f.well <= x.theta_max)
            else {
                previous = None;
                continue;
            };
            let n = comp.rotation_number;
            if let Some(p) = previous {
                crossed |= (p > 0.0) != (n > 0.0);
            }
            previous = Some(n);
        }
        if crossed {
            last_with_root = kappa;
        }
    }
    assert!(
        last_with_root <= f.kappa_max && f.kappa_max - last_with_root < 2.0 * dk,
        "brute force {last_with_root}, fold {}",
        f.kappa_max
    );
}
