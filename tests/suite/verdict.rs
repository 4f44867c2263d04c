//! The verdict on the boundedness hypothesis over the whole (κ, ε) plane (src/verdict.rs),
//! tested on the bodies of issue 11 against independent computations: every counterexample
//! is solved again by the ODE method (one period of the reduced system with DOP853) and
//! followed with the full six-dimensional model, whose centre of mass must run away by n·|Δζ|
//! after n periods; the boundaries must stay put when the sampling resolution doubles.

use rubber_atlas::cell::{solve_cell, CellOptions, Method};
use rubber_atlas::torus::EffectivePotential;
use rubber_atlas::trajectory::Start;
use rubber_atlas::verdict::{boundaries, verdict, BoundaryOptions, Case, Verdict, VerdictOptions};
use rubber_atlas::EllipsoidBody;

fn judge(alpha: f64, beta: f64) -> (EllipsoidBody, Verdict) {
    let body = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
    let v = verdict(&body, &VerdictOptions::default()).unwrap();
    (body, v)
}

/// Every counterexample: on its integer to the tolerance, confirmed by the ODE method, and a
/// full-model path whose centre of mass is n·|Δζ| from its start after n = 5 and 10 periods.
fn check_counterexamples(body: &EllipsoidBody, v: &Verdict) {
    assert!(!v.counterexamples.is_empty(), "{v:#?}");
    for c in &v.counterexamples {
        let ctx = format!("α = {}, β = {}: {c:?}", v.alpha, v.beta);
        assert!(
            (c.rotation_number - c.integer as f64).abs() <= 1e-10,
            "{ctx}"
        );
        assert!(c.drift > 1e3 * c.drift_error, "{ctx}");
        if v.case == Case::Two {
            assert!(c.kappa > v.kappa_max.unwrap(), "{ctx}");
        } else {
            assert!(c.kappa > 0.0, "{ctx}");
        }
        if c.kappa > 100.0 {
            continue; // far out: the ODE check of the nearer one covers the method
        }
        let ode = CellOptions {
            tol: 1e-10,
            method: Method::Ode,
            ..CellOptions::default()
        };
        let r = solve_cell(body, c.kappa, c.energy, &ode).unwrap();
        let comp = r
            .components
            .iter()
            .find(|x| (x.theta_min - c.theta_min).abs() < 1e-6)
            .unwrap_or_else(|| panic!("{ctx}: ODE components {:?}", r.components));
        assert!(
            (comp.rotation_number - c.integer as f64).abs() <= 1e-8 + comp.error_estimate,
            "{ctx}: ODE N = {} ± {}",
            comp.rotation_number,
            comp.error_estimate
        );
        assert!(
            (comp.drift - c.drift).abs() <= 1e-6 * c.drift,
            "{ctx}: ODE drift {}",
            comp.drift
        );
        let start = Start {
            kappa: c.kappa,
            theta0: c.theta_min,
            theta_dot0: 0.0,
        };
        let away = |periods: f64| crate::full_model_distance(body, &start, periods * comp.period);
        for periods in [5.0, 10.0] {
            let d = away(periods);
            assert!(
                (d - periods * c.drift).abs() <= 1e-5 * periods * c.drift,
                "{ctx}: after {periods} periods the full model is {d} away, expected {}",
                periods * c.drift
            );
        }
    }
}

#[test]
fn prolate_case_one_body_fails_with_an_n_zero_resonance() {
    // Issue 11: α = 0.5, β = 0.5, κ = 0.5 has N < 0 at ε = 8 and N > 0 at ε = 10.
    let (body, v) = judge(0.5, 0.5);
    assert_eq!((v.case, v.holds), (Case::One, Some(false)));
    assert!(v.counterexamples.iter().any(|c| c.integer == 0
        && c.kappa > 0.5
        && c.kappa < 2.0
        && c.energy > 8.0
        && c.energy < 10.0));
    // The limit says the same at every large κ: N at the bottom < 0 < N∞.
    assert!(v.high_energy.normalized_max > 0.0 && v.high_energy.slope > 0.0);
    assert!(v.evidence.limit_failure.is_some());
    check_counterexamples(&body, &v);
}

#[test]
fn strongly_oblate_body_fails_beyond_kappa_max() {
    // Issue 11: α = 0.9, β = 20: κ_max = 3.919 and N falls below −1 at high energy.
    let (body, v) = judge(0.9, 20.0);
    assert_eq!((v.case, v.holds), (Case::Two, Some(false)));
    let k = v.kappa_max.unwrap();
    assert!((k - 3.91899).abs() < 1e-4, "{k}");
    assert!(v.high_energy.n_min < -1.76 && v.high_energy.n_min > -1.7612);
    assert!(v.counterexamples.iter().any(|c| c.integer == -1));
    check_counterexamples(&body, &v);
}

#[test]
fn bodies_just_above_the_n_minus_one_boundary_fail() {
    // Adversary pass 32: just above the N = −1 boundary in β the resonance lies in a sliver
    // above κ_max that the grid steps over; only the refined extreme of N passes −1. These
    // held, with N_min = −1.0000044, −1.0000074 and −1.0000815 in their own evidence.
    for (alpha, beta, boundary) in [
        (0.5, 19.7931, 19.7930141),
        (0.9, 11.4228, 11.4227164),
        (0.999999999999, 10.417, 10.41617),
    ] {
        let (body, v) = judge(alpha, beta);
        assert_eq!((v.case, v.holds), (Case::Two, Some(false)), "{v:#?}");
        assert!(v.fail_margin > 0.0, "{v:#?}");
        assert!(v.counterexamples.iter().any(|c| c.integer == -1), "{v:#?}");
        check_counterexamples(&body, &v);
        // Just below the boundary the body holds.
        let below = boundary * (1.0 - 2e-6);
        let (_, v) = judge(alpha, below);
        assert_eq!(
            (v.case, v.holds),
            (Case::Two, Some(true)),
            "β = {below}: {v:#?}"
        );
        assert!(v.fail_margin < 0.0, "β = {below}: {v:#?}");
    }
}

#[test]
fn a_dip_of_n_at_the_bottom_between_kappa_lines_fails() {
    // Adversary pass 33: N at the bottom of the well, N_b(κ), dips below −1 between two
    // κ-lines (to −1.00009 at κ = 0.35 for α = 0.9, β = 1.6773, ν = 1.5, η = 5, where the
    // lines' bottoms had −0.9994 and above); the verdict held with N_min = −0.99997. Its
    // counterexample lies in the sliver between the bottom and N = −1 above it.
    for (alpha, beta) in [(0.9, 1.6773), (0.867, 1.74)] {
        let body = EllipsoidBody::ellipsoid(alpha, beta, 1.5, 5.0).unwrap();
        let v = verdict(&body, &VerdictOptions::default()).unwrap();
        assert_eq!((v.case, v.holds), (Case::Two, Some(false)), "{v:#?}");
        assert!(v.fail_margin > 0.0, "{v:#?}");
        assert!(v.counterexamples.iter().any(|c| c.integer == -1), "{v:#?}");
        check_counterexamples(&body, &v);
        // The bottom itself: some κ between the lines has N_b < −1 (closed form).
        let dip = v
            .counterexamples
            .iter()
            .find(|c| c.integer == -1)
            .unwrap()
            .kappa;
        let potential = EffectivePotential::new(&body, dip);
        let n_b = potential
            .critical_points()
            .iter()
            .filter_map(|c| rubber_atlas::limits::bottom_rotation_number(&potential, c))
            .fold(f64::INFINITY, f64::min);
        assert!(n_b < -1.0, "N_b({dip}) = {n_b}");
    }
    // Below the boundary, β = 1.6771381 at α = 0.9 (where min N_b = −1), the body holds.
    let body = EllipsoidBody::ellipsoid(0.9, 1.6771, 1.5, 5.0).unwrap();
    let v = verdict(&body, &VerdictOptions::default()).unwrap();
    assert_eq!((v.case, v.holds), (Case::Two, Some(true)), "{v:#?}");
}

#[test]
fn bodies_just_above_the_n_zero_boundary_hold() {
    // Adversary pass 33: just above the lower (N = 0) boundary N at small κ and high energy
    // is a limit's value of 1e-11 (N ~ κ/√ε), within tol 1e-10 of 0: the verdict was
    // undecided over 1.3e-3 of β (relative) at α = 0.5 and 3.7e-3 at α = 0.2, while the cells'
    // own estimates were 2e-14. Such samples are solved again to 1e-13.
    for (alpha, beta) in [(0.5, 0.7446), (0.5, 0.745), (0.2, 0.7795), (0.9, 0.6662)] {
        let (_, v) = judge(alpha, beta);
        assert_eq!(
            (v.case, v.holds),
            (Case::One, Some(true)),
            "α = {alpha}, β = {beta}: {v:#?}"
        );
    }
}

#[test]
fn symmetric_prolate_body_fails_everywhere() {
    // α = 0, β < 1 (type (d)): V is symmetric about the equator, N = 0 on every torus.
    let (body, v) = judge(0.0, 0.5);
    assert_eq!((v.case, v.holds), (Case::One, Some(false)));
    assert_eq!((v.high_energy.n_min, v.high_energy.n_max), (0.0, 0.0));
    assert!(v.counterexamples.iter().all(|c| c.integer == 0));
    check_counterexamples(&body, &v);
}

#[test]
fn the_papers_body_holds_and_uncovered_bodies_are_said_so() {
    let (_, v) = judge(0.5, 3.0);
    assert_eq!((v.case, v.holds), (Case::Two, Some(true)));
    assert!((v.kappa_max.unwrap() - 1.1078360352).abs() < 1e-6);
    assert!(v.counterexamples.is_empty() && v.fail_margin < 0.0);
    let (_, v) = judge(0.0, 2.0);
    assert_eq!((v.case, v.holds), (Case::NotCovered, None));
    // A type (b) body holds: N < 0 everywhere, from the bottom to N∞.
    let (_, v) = judge(0.5, 1.1);
    assert_eq!((v.case, v.holds), (Case::One, Some(true)));
    assert!(v.evidence.rotation_number_range[1] <= 0.0);
}

/// κ_max of a case-2 body and its error bar, by the verdict at `tol`.
fn kappa_max_at(body: &EllipsoidBody, tol: f64) -> (f64, f64) {
    let options = VerdictOptions {
        tol,
        ..VerdictOptions::default()
    };
    let v = verdict(body, &options).unwrap();
    (v.kappa_max.unwrap(), v.kappa_max_error.unwrap())
}

/// Nearly symmetric bodies (α = 1e-9), where N ~ 1e-11 near the fold: at `--tol 1e-8` the
/// curve was traced and κ_max polished at 1e-8, below N's resolution, and κ_max came out
/// 2.1115 ± 2.1e-4 (tol 1e-9: 2.1027) against 1.6329617 ± 1.6e-4 at 1e-10 … 1e-13, and
/// 1.10759 against 0.46704 for the second body (adversary pass 36). κ_max is now solved at
/// 1e-10 at the coarsest: at every tolerance it agrees within the bars with the finest, and
/// with the body at α = 1e-7 (κ_max moves by 1e-5 between them).
#[test]
fn kappa_max_of_a_nearly_symmetric_body_does_not_depend_on_a_coarse_tolerance() {
    for (beta, nu, eta) in [(3.0, 0.5, 0.5), (1.115, 2.0, 1000.0)] {
        let body = EllipsoidBody::ellipsoid(1e-9, beta, nu, eta).unwrap();
        let (fine, fine_err) = kappa_max_at(&body, 1e-12);
        let near = EllipsoidBody::ellipsoid(1e-7, beta, nu, eta).unwrap();
        let (k7, k7_err) = kappa_max_at(&near, 1e-10);
        assert!(
            (fine - k7).abs() <= fine_err + k7_err,
            "{fine} against {k7}"
        );
        for tol in [1e-8, 1e-9] {
            let (k, err) = kappa_max_at(&body, tol);
            assert!(
                (k - fine).abs() <= err + fine_err && err < 1e-3 * k,
                "β = {beta}, tol {tol}: {k} ± {err} against {fine} ± {fine_err}"
            );
        }
    }
}

/// Small α, large β: the inside of the N = 0 curve by its fold is a tongue about 1e-3 wide
/// in ε (N > 0 at κ = 5.1779, ε = 41.254: 5.85e-3 here and against 50 digits). The fold was
/// traced right, 5.1789099, but its polish took the maximum of N over ε ± 0.04 by one golden
/// section, which missed the tongue: κ_max was 5.1771500 ± 5.8e-12 at tol 1e-10 and 5.1771400
/// at 1e-13, with unbounded paths above it (adversary pass 28). Now κ_max is the same at
/// every tolerance, within its bar of the fold traced by `resonance` in another window (tol
/// 1e-12: 5.178909869695742 ± 1.5e-13), and N > 0 just below it, as at the second body.
#[test]
fn kappa_max_is_the_top_of_a_narrow_tongue_of_the_n_zero_curve() {
    for (alpha, beta, traced) in [
        (0.075, 27.844069954726358, 5.178909869695742),
        (0.1, 44.47567486554115, 6.5616428709926335),
    ] {
        let body = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
        for tol in [1e-10, 1e-13] {
            let (k, err) = kappa_max_at(&body, tol);
            assert!(
                (k - traced).abs() <= err + 1e-12,
                "α = {alpha}, tol {tol}: {k} ± {err}"
            );
            assert!(err < 1e-9, "{k} ± {err}");
        }
    }
    // Inside the tongue, above the old κ_max: N > 0, its own solver's (ODE) value too.
    let body = EllipsoidBody::ellipsoid(0.075, 27.844069954726358, 0.5, 0.5).unwrap();
    for method in [Method::Quadrature, Method::Ode] {
        let options = CellOptions {
            method,
            ..CellOptions::default()
        };
        let cell = solve_cell(&body, 5.1779, 41.254, &options).unwrap();
        assert!(
            cell.components
                .iter()
                .any(|c| (c.rotation_number - 5.8519e-3).abs() < 1e-6),
            "{method:?}: {cell:?}"
        );
    }
}

/// Nearly flat oblate bodies (α ~ 0.005, β ~ 200): above the cusp the N = 0 curve goes on
/// as a ridge of N > 0 only 1e-5 wide in ε, 4e-4 above the bottom of V, which moves with κ
/// at dV_min/dκ ≈ 14. The polish's windows, fixed in ε, lost the ridge: κ_max came out
/// 13.8795707 ± 1.9e-13 at tol 1e-10 and 13.86122 at 1e-13 for the first body (16.604935 at
/// 1e-12 for the second), with N > 0 above it and the verdict HOLDS (adversary pass 29). The
/// windows now follow the ridge. The values are checked against an independent search (a
/// golden section of N at tol 1e-14 across the root, outside this program's polish: the sign
/// of M changes within an ulp of them), and here against the ODE method on either side.
#[test]
fn kappa_max_follows_a_ridge_that_moves_with_the_bottom_of_the_well() {
    for (alpha, beta, nu, eta, top, height) in [
        (
            0.006092118261623732,
            193.0128578220233,
            1.9,
            10.0,
            13.880007537397688,
            4.2586e-4,
        ),
        (
            0.003991614092636487,
            276.17042089399007,
            0.1,
            0.5,
            16.609234514619118,
            2.1508e-4,
        ),
    ] {
        let body = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        for tol in [1e-10, 1e-13] {
            let (k, err) = kappa_max_at(&body, tol);
            assert!(
                (k - top).abs() <= err + 4e-15 * top && err < 1e-10,
                "α = {alpha}, tol {tol}: {k} ± {err} against {top}"
            );
        }
        // 1e-6 below the top, on the ridge: N ≈ +1e-4 by both methods. 1e-6 above it, the
        // largest N over ±5 % of the ridge's height (steps of 1e-7 of it: N'' ~ 1e8 leaves the
        // scan at most ~1e-7 below the maximum) is ≈ −1e-4, and the ODE agrees at its place.
        let n_at = |kappa: f64, excess: f64, method| {
            let bottom = EffectivePotential::new(&body, kappa)
                .lowest_minimum()
                .unwrap();
            let options = CellOptions {
                method,
                ..CellOptions::default()
            };
            let cell = solve_cell(&body, kappa, bottom + excess, &options).unwrap();
            assert_eq!(cell.components.len(), 1, "{cell:?}");
            cell.components[0].rotation_number
        };
        for method in [Method::Quadrature, Method::Ode] {
            let n = n_at(top - 1e-6, height, method);
            assert!(n > 3e-5, "α = {alpha}, {method:?}: N = {n} below the top");
        }
        let (n, excess) = (0..=200)
            .map(|i| {
                let excess = height * (0.95 + 0.1 * i as f64 / 200.0);
                (n_at(top + 1e-6, excess, Method::Quadrature), excess)
            })
            .fold(
                (f64::NEG_INFINITY, 0.0),
                |b, p| if p.0 > b.0 { p } else { b },
            );
        assert!(n < -3e-5, "α = {alpha}: N = {n} at {excess} above the top");
        let ode = n_at(top + 1e-6, excess, Method::Ode);
        assert!(ode < -3e-5, "α = {alpha}: ODE N = {ode} above the top");
    }
}

/// On the case line β² = 1 + α the cusp is born at κ_c = 0. One ulp above it (β the double
/// after √1.5 at α = 0.5, after √1.9 at α = 0.9) the fold search opened a resonance window
/// from κ = 0, which it refused: the verdict failed with "invalid kappa_min = 0", an input
/// the user never gave (adversary pass of issue 22). Now an answer, here undecided.
#[test]
fn a_body_an_ulp_beside_the_case_line_gets_a_verdict() {
    for (alpha, beta) in [(0.5, 1.2247448713915892), (0.9, 1.3784048752090223)] {
        assert!(beta * beta > 1.0 + alpha);
        let (_, v) = judge(alpha, beta);
        assert_eq!(v.case, Case::Two, "α = {alpha}");
        assert!(
            v.holds.is_none() || v.kappa_max.is_some(),
            "α = {alpha}: {v:?}"
        );
    }
}

#[test]
fn boundaries_stay_put_when_the_resolution_doubles() {
    let at = |resolution: usize| {
        let options = BoundaryOptions {
            beta_min: 0.6,
            beta_max: 0.9,
            scan: 4,
            verdict: VerdictOptions {
                resolution,
                ..VerdictOptions::default()
            },
        };
        let b = boundaries(0.5, 0.5, 0.5, &options).unwrap();
        assert_eq!(b.boundaries.len(), 1, "{b:#?}");
        b.boundaries[0].clone()
    };
    let (coarse, fine) = (at(32), at(64));
    assert!(
        (coarse.beta - fine.beta).abs() <= 1e-5 + coarse.error + fine.error,
        "{coarse:?} vs {fine:?}"
    );
    assert!((fine.beta - 0.744478).abs() < 1e-5, "{fine:?}");
    assert_eq!(
        (fine.holds_below, fine.holds_above),
        (Some(false), Some(true))
    );
}

/// The N = −1 boundaries at α = 0.5 and 0.9 lie where N's smallest value over the region
/// (found on its edge κ = κ_max, case 2) crosses −1. The margin followed the grid there:
/// its root moved by 9e-4 in β from resolution 16 to 64 (α = 0.5) and by 1.3e-3 from 64 to
/// 128 (α = 0.9), with bars of 5e-8 and 4e-4. N's extremes are now refined to convergence, the
/// boundary is the same at every resolution, the bar holds the move from half the resolution,
/// and a resolution below 32 is refused.
#[test]
fn a_boundary_is_the_same_at_every_resolution_and_its_bar_covers_the_move() {
    let at = |alpha: f64, (beta_min, beta_max): (f64, f64), resolution: usize| {
        let options = BoundaryOptions {
            beta_min,
            beta_max,
            scan: 4,
            verdict: VerdictOptions {
                resolution,
                ..VerdictOptions::default()
            },
        };
        boundaries(alpha, 0.5, 0.5, &options).map(|b| {
            assert_eq!(b.boundaries.len(), 1, "{b:#?}");
            b.boundaries[0].clone()
        })
    };
    for resolution in [16, 5000] {
        let refused = at(0.5, (15.0, 25.0), resolution).unwrap_err().to_string();
        assert!(
            refused.contains("resolution") && refused.contains("between 32 and 4096"),
            "{refused}"
        );
    }
    for (alpha, window, expected) in [
        (0.5, (15.0, 25.0), 19.793014),
        (0.9, (10.5, 12.5), 11.422716),
    ] {
        // (128 agrees too, docs/hypothesis.md; left out for the suite's time.)
        let found = [32, 64].map(|r| at(alpha, window, r).unwrap());
        let finest = &found[1];
        assert!(finest.quantity.contains("N reaches -1"), "{finest:?}");
        assert!((finest.beta - expected).abs() < 1e-6, "{finest:?}");
        for b in &found {
            assert!(
                (b.beta - finest.beta).abs() <= 1e-9 * expected,
                "{b:?} vs {finest:?}"
            );
            assert!(b.error >= 1e-12 && b.error < 2e-3, "{b:?}");
        }
    }
}

#[test]
fn the_half_resolution_shortcut_never_changes_a_verdict() {
    // `verdict` searches half the resolution first and stops at a confirmed counterexample.
    for (alpha, beta) in [(0.5, 0.5), (0.5, 3.0), (0.9, 20.0), (0.5, 1.1), (0.0, 0.3)] {
        let body = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
        let full = verdict(&body, &VerdictOptions::default()).unwrap();
        let quick = VerdictOptions {
            coarse_first: true,
            ..VerdictOptions::default()
        };
        let quick = verdict(&body, &quick).unwrap();
        assert_eq!(full.holds, quick.holds, "α = {alpha}, β = {beta}");
        assert_eq!(
            full.counterexamples.is_empty(),
            quick.counterexamples.is_empty()
        );
    }
}

#[test]
fn bad_options_are_refused() {
    let body = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    for (tol, resolution) in [(0.0, 64), (f64::NAN, 64), (1e-10, 2), (1e-10, 1 << 20)] {
        let options = VerdictOptions {
            tol,
            resolution,
            ..VerdictOptions::default()
        };
        assert!(verdict(&body, &options).is_err());
    }
    let mirror = EllipsoidBody::ellipsoid(-0.5, 3.0, 0.5, 0.5).unwrap();
    assert!(verdict(&mirror, &VerdictOptions::default()).is_err());
    let bad = BoundaryOptions {
        beta_min: 2.0,
        beta_max: 1.0,
        ..BoundaryOptions::default()
    };
    assert!(boundaries(0.5, 0.5, 0.5, &bad).is_err());
}

/// Issue 22 (G3): one scan step may hold two changes. At ν = 1.5, η = 5, α = 0.867 the step
/// from just above the case line (undecided there) to β = 1.78 (fails) holds the end of the
/// undecided band and the N = −1 boundary at 1.7399071; the boundary took its labels from the
/// step's ends ("case 2 undecided below") while the bodies just below it hold, and the
/// undecided → holds change was not reported. Every label must be the verdict of the bodies
/// between two neighbouring boundaries, judged here at their geometric midpoints.
#[test]
fn a_scan_step_that_holds_two_changes_reports_both_with_the_labels_of_its_sides() {
    let (alpha, nu, eta) = (0.8666666666666667, 1.5, 5.0);
    let (options, b) = four_step_scan((alpha, nu, eta), (0.9, 2.5));
    let b = &b;
    let summary: Vec<_> = b
        .iter()
        .map(|x| (x.beta, x.holds_below, x.holds_above, x.quantity.as_str()))
        .collect();
    assert_eq!(b.len(), 3, "{summary:#?}");
    let case_line = (1.0 + alpha).sqrt();
    assert!(b[0].quantity.starts_with("case"), "{summary:#?}");
    assert!(
        (b[1].beta / case_line - 1.0) < 1e-4 && b[1].holds_below.is_none(),
        "{summary:#?}"
    );
    assert_eq!(
        (b[1].holds_above, b[2].holds_above),
        (Some(true), Some(false))
    );
    assert!(
        (b[2].beta - 1.7399071).abs() < 2e-7 + b[2].error,
        "{summary:#?}"
    );
    labels_are_the_verdicts_between((alpha, nu, eta), &options, b);
}

/// The boundaries over (β_min, β_max) from a scan of 4 β, at the verdict's defaults.
fn four_step_scan(
    (alpha, nu, eta): (f64, f64, f64),
    (beta_min, beta_max): (f64, f64),
) -> (BoundaryOptions, Vec<rubber_atlas::verdict::Boundary>) {
    let options = BoundaryOptions {
        beta_min,
        beta_max,
        scan: 4,
        verdict: VerdictOptions::default(),
    };
    let found = boundaries(alpha, nu, eta, &options).unwrap();
    (options, found.boundaries)
}

/// Every boundary's labels against the verdicts of the bodies between it and its neighbours
/// (and the range's ends), judged at their geometric midpoints.
fn labels_are_the_verdicts_between(
    (alpha, nu, eta): (f64, f64, f64),
    options: &BoundaryOptions,
    b: &[rubber_atlas::verdict::Boundary],
) {
    let summary: Vec<_> = b
        .iter()
        .map(|x| (x.beta, x.holds_below, x.holds_above, x.quantity.as_str()))
        .collect();
    let judge = |beta: f64| {
        let body = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let v = verdict(&body, &options.verdict).unwrap();
        (v.case, v.holds)
    };
    let mut edges = vec![options.beta_min];
    edges.extend(b.iter().map(|x| x.beta));
    edges.push(options.beta_max);
    for (i, w) in edges.windows(2).enumerate() {
        let between = judge((w[0] * w[1]).sqrt());
        if i > 0 {
            assert_eq!(
                between,
                (b[i - 1].case_above, b[i - 1].holds_above),
                "{summary:#?}"
            );
        }
        if i < b.len() {
            assert_eq!(between, (b[i].case_below, b[i].holds_below), "{summary:#?}");
        }
    }
}

/// Adversary pass 35: at α = 0.1, ν = η = 0.5 an undecided band about 5e-6 wide lies just
/// above the N = 0 boundary (0.7843961 ± 3.2e-6), where N = −6e-14 ± 1e-13 cannot be told
/// from 0 even at tol 1e-13. The sides were judged four bars away, beyond the band: the
/// boundary read "holds above" and the band's end was not listed. Judged just beyond the bar,
/// both changes are reported, each with the verdicts of the bodies beside it.
#[test]
fn a_band_narrower_than_a_few_error_bars_beside_a_boundary_is_reported() {
    let (alpha, nu, eta) = (0.1, 0.5, 0.5);
    let (options, b) = four_step_scan((alpha, nu, eta), (0.7843, 0.7845));
    let b = &b;
    let summary: Vec<_> = b
        .iter()
        .map(|x| (x.beta, x.error, x.holds_below, x.holds_above))
        .collect();
    assert_eq!(b.len(), 2, "{summary:#?}");
    assert_eq!(
        (b[0].holds_below, b[0].holds_above, b[1].holds_above),
        (Some(false), None, Some(true)),
        "{summary:#?}"
    );
    // The band between them is narrower than four of the first boundary's bars.
    assert!(b[1].beta - b[0].beta < 4.0 * b[0].error, "{summary:#?}");
    labels_are_the_verdicts_between((alpha, nu, eta), &options, b);
}

/// The verdict asks whether N equals an integer; `bounded` whether |N − k| is within the
/// resonance tolerance (adversary pass 34 read the two as contradicting each other). A body
/// that holds has a cell flagged unbounded at the default 1e-9 where N → 0 (κ → 0) without
/// reaching it, bounded at 1e-12 (docs/hypothesis.md).
#[test]
fn a_body_that_holds_may_have_cells_within_the_resonance_tolerance() {
    let body = EllipsoidBody::ellipsoid(0.5, 1.2, 0.5, 0.5).unwrap();
    let v = verdict(&body, &VerdictOptions::default()).unwrap();
    assert_eq!((v.case, v.holds), (Case::One, Some(true)));
    let at = |resonance_tol: f64| {
        let options = CellOptions {
            resonance_tol,
            drift: true,
            ..CellOptions::default()
        };
        let cell = solve_cell(&body, 1e-9, 3.0, &options).unwrap();
        assert_eq!(cell.components.len(), 1);
        cell.components[0].clone()
    };
    let (loose, tight) = (at(1e-9), at(1e-12));
    assert!(
        loose.rotation_number < 0.0 && loose.rotation_number.abs() > 100.0 * loose.error_estimate,
        "{loose:?}"
    );
    assert_eq!((loose.bounded, tight.bounded), (Some(false), Some(true)));
}
