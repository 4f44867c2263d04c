//! The corrected formulas of docs/model.md and the analytic derivatives, each against a direct
//! numerical search or finite differences, over many random bodies (proptest, failing cases kept in
//! `tests/critical.proptest-regressions` and replayed first).

use proptest::prelude::*;
use rubber_atlas::body::{Ellipsoid, Shape};
use rubber_atlas::critical::{
    energy_min, fixed_point, inclined_equilibrium, CriticalSet, DiagramType,
};
use rubber_atlas::reduced::ReducedSystem;
use rubber_atlas::EllipsoidBody;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Central difference of f at x with step h (error O(h²) + O(ε/h)).
fn diff(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (f(x + h) - f(x - h)) / (2.0 * h)
}

/// Maximum of f on [a, b]: a dense scan, then golden-section search around the best node.
fn maximise(f: impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let n = 4000;
    let x = |i: usize| a + (b - a) * i as f64 / n as f64;
    let best = (0..=n)
        .max_by(|&i, &j| f(x(i)).total_cmp(&f(x(j))))
        .unwrap();
    let (mut lo, mut hi) = (x(best.saturating_sub(1)), x((best + 1).min(n)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(m1) < f(m2) {
            lo = m1;
        } else {
            hi = m2;
        }
    }
    let t = 0.5 * (lo + hi);
    (t, f(t))
}

/// Interior extrema of U on (0, π), found from U's values alone (no derivative formula):
/// sign changes of the centred difference, refined by bisection on it.
fn interior_extrema_of_u(shape: &Ellipsoid) -> Vec<f64> {
    let du = |t: f64| diff(|s| shape.potential(s), t, 1e-6);
    let n = 4000;
    let mut out = Vec::new();
    for i in 1..n - 1 {
        let (a, b) = (PI * i as f64 / n as f64, PI * (i + 1) as f64 / n as f64);
        if du(a) * du(b) < 0.0 {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if du(m) * du(lo) > 0.0 {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            out.push(0.5 * (lo + hi));
        }
    }
    out
}

/// Bodies away from the region boundaries (the classification there is a matter of one ulp).
fn body_strategy() -> impl Strategy<Value = (f64, f64, f64, f64)> {
    (0.02f64..0.95, 0.15f64..4.0, 0.1f64..2.0, 0.1f64..5.0).prop_filter(
        "off the boundaries",
        |(a, b, _, _)| {
            let b2 = b * b;
            (b2 - (1.0 - a)).abs() > 0.02 && (b2 - (1.0 + a)).abs() > 0.02 && (b - 1.0).abs() > 0.01
        },
    )
}

/// The linearisation of `eqsys` at (θ0, p = 0) by finite differences of θ̈(θ, p):
/// the Jacobian is [[0, 1], [∂θ̈/∂θ, ∂θ̈/∂p]], a centre iff its eigenvalues are imaginary.
fn is_centre_numerically(body: &EllipsoidBody, kappa: f64, theta0: f64) -> bool {
    let sys = ReducedSystem::new(body, kappa);
    let a_theta = diff(|t| sys.theta_acceleration(t, 0.0), theta0, 1e-6);
    let a_p = diff(|p| sys.theta_acceleration(theta0, p), 0.0, 1e-6);
    let jac = nalgebra::Matrix2::new(0.0, 1.0, a_theta, a_p);
    let ev = jac.complex_eigenvalues();
    ev.iter().all(|z| z.re.abs() < 1e-6 && z.im.abs() > 1e-6)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 96,
        // Failing cases are kept here and replayed first on the next run.
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::Direct("tests/critical.proptest-regressions"),
        )),
        ..ProptestConfig::default()
    })]

    #[test]
    fn analytic_derivatives_match_finite_differences(
        (alpha, beta, nu, eta) in body_strategy(), theta in 0.05f64..3.09, kappa in -2.0f64..2.0
    ) {
        let b = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let s = &b.shape;
        let h = 1e-5;
        let tol = |x: f64| 1e-7 * x.abs().max(1.0);
        let zp = diff(|t| s.centre_height(t), theta, h);
        prop_assert!((s.centre_height_prime(theta) - zp).abs() < tol(zp));
        let up = diff(|t| s.potential(t), theta, h);
        prop_assert!((s.potential_prime(theta) - up).abs() < tol(up), "U' {} vs {}", s.potential_prime(theta), up);
        let upp = diff(|t| s.potential_prime(t), theta, h);
        prop_assert!((s.potential_second(theta) - upp).abs() < tol(upp), "U'' {} vs {}", s.potential_second(theta), upp);
        let bp = diff(|t| b.reduced_inertia(t), theta, h);
        prop_assert!((b.reduced_inertia_prime(theta) - bp).abs() < tol(bp), "B' {} vs {}", b.reduced_inertia_prime(theta), bp);
        let sys = ReducedSystem::new(&b, kappa);
        let vp = diff(|t| sys.effective_potential(t), theta, h);
        prop_assert!((sys.effective_potential_prime(theta) - vp).abs() < tol(vp));
        let vpp = diff(|t| sys.effective_potential_prime(t), theta, h);
        prop_assert!((sys.effective_potential_second(theta) - vpp).abs() < 1e-6 * vpp.abs().max(1.0));
    }

    #[test]
    fn closed_forms_agree_with_the_vector_contact_point(
        (alpha, beta, nu, eta) in body_strategy(), theta in 0.0f64..PI, phi in 0.0f64..TAU
    ) {
        // B = 1/η + |r|² (the corrected B of docs/model.md) and U = −(r, γ) from r(γ) of paper `r`.
        let b = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let gamma = nalgebra::Vector3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos());
        let r = b.shape.contact_point(&gamma);
        prop_assert!((b.reduced_inertia(theta) - (1.0 / eta + r.norm_squared())).abs() < 1e-13 * b.reduced_inertia(theta));
        prop_assert!((b.shape.potential(theta) + r.dot(&gamma)).abs() < 1e-14 * 4.0);
        // r is the point of the surface whose normal is −γ: on the ellipsoid, normal ∥ 𝐁⁻¹(r + α e3).
        let q = r + nalgebra::Vector3::new(0.0, 0.0, alpha);
        prop_assert!(((q.x / beta).powi(2) + (q.y / beta).powi(2) + q.z * q.z - 1.0).abs() < 1e-13);
        let n = nalgebra::Vector3::new(q.x / (beta * beta), q.y / (beta * beta), q.z).normalize();
        prop_assert!((n + gamma).norm() < 1e-12);
        // The generic χ-formulas of the trait agree with the ellipsoid's closed forms.
        let (c1, c2) = b.shape.chi(theta);
        let (s, c) = theta.sin_cos();
        prop_assert!((-(c1 * s * s + c2 * c) - b.shape.potential(theta)).abs() < 1e-13);
        prop_assert!((s * (c2 - c1 * c) - b.shape.potential_prime(theta)).abs() < 1e-13);
        prop_assert!((c1 * c1 * s * s + c2 * c2 - b.shape.contact_distance_sq(theta)).abs() < 1e-12);
    }

    #[test]
    fn contact_point_rate_matches_finite_difference(
        (alpha, beta, _nu, _eta) in body_strategy(), theta in 0.01f64..3.13, phi in 0.0f64..TAU,
        w in prop::array::uniform3(-2.0f64..2.0)
    ) {
        let shape = Ellipsoid::new(alpha, beta).unwrap();
        let gamma = nalgebra::Vector3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos());
        let omega = nalgebra::Vector3::from(w);
        let gdot = gamma.cross(&omega);
        let h = 1e-6;
        let fd = (shape.contact_point(&(gamma + gdot * h)) - shape.contact_point(&(gamma - gdot * h))) / (2.0 * h);
        prop_assert!((shape.contact_point_rate(&gamma, &gdot) - fd).norm() < 1e-7 * fd.norm().max(1.0));
    }

    #[test]
    fn inclined_equilibrium_and_energy_min_match_direct_search(
        (alpha, beta, nu, eta) in body_strategy()
    ) {
        let b = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let extrema = interior_extrema_of_u(&b.shape);
        match inclined_equilibrium(alpha, beta) {
            Some(ts) => {
                prop_assert_eq!(extrema.len(), 1, "theta* = {} but extrema {:?}", ts, extrema);
                prop_assert!((ts - extrema[0]).abs() < 1e-7, "theta* {} vs search {}", ts, extrema[0]);
            }
            None => prop_assert!(extrema.is_empty(), "no theta* but U has extrema at {:?}", extrema),
        }
        let (_, u_max) = maximise(|t| b.shape.potential(t), 0.0, PI);
        prop_assert!((energy_min(alpha, beta) - u_max).abs() < 1e-10, "eps_min {} vs max U {}", energy_min(alpha, beta), u_max);
    }

    #[test]
    fn diagram_regions_and_isolated_equilibria_match_the_sign_of_kappa_squared(
        (alpha, beta, nu, eta) in body_strategy()
    ) {
        // From U's values only: κ²(θ0) = sin³θ0 U′(θ0) / cosθ0 with U′ by finite differences.
        let b = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let k2 = |t: f64| t.sin().powi(3) * diff(|s| b.shape.potential(s), t, 1e-6) / t.cos();
        let upper_half_has_rotations = (1..400).any(|i| k2(FRAC_PI_2 * i as f64 / 400.0) > 0.0);
        let ty = DiagramType::of(alpha, beta);
        prop_assert_eq!(upper_half_has_rotations, ty == DiagramType::C, "type {:?}", ty);
        let set = CriticalSet::of(&b, 400, 3.0).unwrap();
        let near_0 = k2(0.05) > 0.0;
        let near_pi = k2(PI - 0.05) > 0.0;
        prop_assert_eq!(set.equilibria[0].isolated, !near_0);
        prop_assert_eq!(set.equilibria[1].isolated, !near_pi);
        // Paper: σ0 isolated iff β² < 1 + α, σπ iff β² < 1 − α.
        prop_assert_eq!(set.equilibria[0].isolated, beta * beta < 1.0 + alpha);
        prop_assert_eq!(set.equilibria[1].isolated, beta * beta < 1.0 - alpha);
    }

    #[test]
    fn sampled_fixed_point_curves_are_fixed_points_with_the_right_stability(
        (alpha, beta, nu, eta) in body_strategy()
    ) {
        let b = EllipsoidBody::ellipsoid(alpha, beta, nu, eta).unwrap();
        let set = CriticalSet::of(&b, 300, 3.0).unwrap();
        for br in &set.branches {
            for p in br.points.iter().step_by(17) {
                if p.theta0 < 1e-3 || p.theta0 > PI - 1e-3 || p.kappa < 1e-3 {
                    continue; // equilibria at the poles and θ*: checked elsewhere
                }
                let sys = ReducedSystem::new(&b, p.kappa);
                // V′(θ0) = 0 from values of V, and ε = V(θ0).
                let vp = diff(|t| sys.effective_potential(t), p.theta0, 1e-6);
                prop_assert!(vp.abs() < 1e-6 * (1.0 + p.kappa * p.kappa / p.theta0.sin().powi(3)), "V'({}) = {}", p.theta0, vp);
                prop_assert!((sys.effective_potential(p.theta0) - p.energy).abs() < 1e-11 * p.energy.abs().max(1.0));
                // Stability from the eigenvalues of the finite-difference linearisation,
                // away from the cusp where V″ crosses zero.
                if sys.effective_potential_second(p.theta0).abs() > 1e-3 {
                    prop_assert_eq!(p.stable, is_centre_numerically(&b, p.kappa, p.theta0), "theta0 = {}", p.theta0);
                }
            }
        }
        // Type (c): the cusp is where κ along the left half peaks (a direct maximisation).
        if set.diagram_type == Some(DiagramType::C) {
            let cusp = set.cusp.expect("type (c) has a cusp");
            let ts = set.theta_star.unwrap();
            let (t_peak, k2_peak) = maximise(|t| t.sin().powi(3) * diff(|s| b.shape.potential(s), t, 1e-6) / t.cos(), 1e-3, ts);
            prop_assert!((cusp.theta - t_peak).abs() < 1e-4, "cusp {} vs peak {}", cusp.theta, t_peak);
            prop_assert!((cusp.kappa - k2_peak.sqrt()).abs() < 1e-8, "kappa_c {} vs {}", cusp.kappa, k2_peak.sqrt());
        } else {
            prop_assert!(set.cusp.is_none());
        }
    }

    #[test]
    fn equator_stability_for_alpha_zero_matches_the_linearisation(
        beta in 0.2f64..4.0, kappa in 0.0f64..3.0, nu in 0.1f64..2.0, eta in 0.1f64..5.0
    ) {
        // docs/model.md: V″(π/2) = κ² − (β² − 1)/β; stable iff |κ| > κ_c (β > 1), always (β < 1).
        // The paper's `a0usl` has the inequality reversed.
        prop_assume!((beta - 1.0).abs() > 0.01);
        let b = EllipsoidBody::ellipsoid(0.0, beta, nu, eta).unwrap();
        let v2 = kappa * kappa - (beta * beta - 1.0) / beta;
        prop_assume!(v2.abs() > 1e-3);
        let sys = ReducedSystem::new(&b, kappa);
        prop_assert!((sys.effective_potential_second(FRAC_PI_2) - v2).abs() < 1e-12);
        prop_assert_eq!(v2 > 0.0, is_centre_numerically(&b, kappa, FRAC_PI_2));
        let set = CriticalSet::of(&b, 200, 3.0).unwrap();
        let eq = set.branches.iter().filter(|br| br.name == "sigma_pi2");
        let on = eq.flat_map(|br| br.points.iter()).find(|p| (p.kappa - kappa).abs() < 0.02 && (p.kappa * p.kappa - (beta * beta - 1.0) / beta).abs() > 0.1);
        if let Some(p) = on {
            prop_assert_eq!(p.stable, p.kappa * p.kappa > (beta * beta - 1.0) / beta);
        }
    }
}

#[test]
fn paper_type_c_values_and_misprints() {
    // α = 0.5, β = 3 (docs/model.md): θ* = 1.38509 (the paper's root gives 1.37912), ε_min =
    // 3.04651 (the paper's gives 2.95275).
    let ts = inclined_equilibrium(0.5, 3.0).unwrap();
    assert!((ts - 1.38509).abs() < 5e-6, "theta* = {ts}");
    let printed = (0.5f64 * 3.0 / ((1.0f64 - 9.0) * (1.0 + 0.25 - 9.0)).sqrt()).acos();
    assert!((printed - 1.37912).abs() < 5e-6 && (printed - ts).abs() > 5e-3);
    assert!((energy_min(0.5, 3.0) - 3.04651).abs() < 5e-6);
    let b = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    // The fixed-point curve ends at σ0 (θ0 = 0) and at θ* (κ = 0).
    assert_eq!(fixed_point(&b, 0.0).energy, 1.5);
    assert!(fixed_point(&b, ts).kappa < 1e-6);
    assert_eq!(DiagramType::of(0.5, 3.0), DiagramType::C);
    // β² = 1.2 with α = 0.5 lies between 1 − α and 1 + α: type (b) (the paper's list says
    // 1 − α for the (c) boundary).
    assert_eq!(DiagramType::of(0.5, 1.2f64.sqrt()), DiagramType::B);
    assert_eq!(DiagramType::of(0.5, 0.5), DiagramType::A);
    assert_eq!(DiagramType::of(0.0, 0.5), DiagramType::D);
    assert_eq!(DiagramType::of(0.0, 1.5), DiagramType::E);
}

/// α < 0 is the mirror image of −α: every point of the mirrored diagram is, evaluated directly
/// on the body with α < 0 (the formulas of `s1` and `s0` hold for either sign), a permanent
/// rotation or an equilibrium of that body, with its stability, circles and N; the cusp is a
/// double zero of V′ there.
#[test]
fn a_negative_alpha_diagram_is_the_mirror_image_and_holds_on_its_own_body() {
    for (alpha, beta) in [(-0.4, 3.0), (-0.5, 0.5), (-0.2, 1.05), (-0.9, 20.0)] {
        let body = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
        let image = EllipsoidBody::ellipsoid(-alpha, beta, 0.5, 0.5).unwrap();
        let set = CriticalSet::of(&body, 400, 3.0).unwrap();
        let image_set = CriticalSet::of(&image, 400, 3.0).unwrap();
        assert_eq!(set.alpha, alpha);
        assert_eq!(set.diagram_type, image_set.diagram_type);
        assert_eq!(set.branches.len(), image_set.branches.len());
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()));
        for branch in &set.branches {
            let half_ok = match branch.name {
                "sigma_s0" => branch.theta0_range[1] <= FRAC_PI_2,
                "sigma_spi" => branch.theta0_range[0] >= FRAC_PI_2,
                _ => true,
            };
            assert!(half_ok, "α = {alpha}, β = {beta}: {branch:?}");
            for p in &branch.points {
                let direct = fixed_point(&body, p.theta0);
                assert!(
                    close(p.kappa, direct.kappa)
                        && close(p.energy, direct.energy)
                        && close(p.rho_c, direct.rho_c)
                        && close(p.rho_p, direct.rho_p)
                        && p.stable == branch.stable,
                    "α = {alpha}, β = {beta}: {p:?} vs {direct:?}"
                );
                if let (Some(n), Some(m)) = (p.rotation_number, direct.rotation_number) {
                    assert!(close(n, m), "α = {alpha}, β = {beta}: N {n} vs {m}");
                }
                // Stability from the linearised equations, as for α > 0.
                if p.kappa > 1e-3 && (p.theta0 - FRAC_PI_2).abs() > 1e-3 {
                    let v2 =
                        ReducedSystem::new(&body, p.kappa).effective_potential_second(p.theta0);
                    if v2.abs() > 1e-6 {
                        assert_eq!(p.stable, v2 > 0.0, "α = {alpha}, β = {beta}: {p:?}");
                    }
                }
            }
        }
        for e in &set.equilibria {
            assert!(close(e.energy, body.shape.potential(e.theta)), "{e:?}");
            let expected_theta = match e.name {
                "sigma_0" => 0.0,
                "sigma_pi" => PI,
                _ => e.theta,
            };
            assert_eq!(e.theta, expected_theta, "{e:?}");
            assert!(body.shape.potential_prime(e.theta).abs() < 1e-12, "{e:?}");
        }
        if let Some(c) = set.cusp {
            let sys = ReducedSystem::new(&body, c.kappa);
            assert!(sys.effective_potential_prime(c.theta).abs() < 1e-9, "{c:?}");
            assert!(
                sys.effective_potential_second(c.theta).abs() < 1e-6,
                "{c:?}"
            );
        }
    }
}

/// The homogeneous ball (α = 0, β = 1: U ≡ 1) has V″(π/2) = κ² > 0: its equator branch is
/// stable at every κ > 0 (it was labelled unstable, as V″ vanishes at κ = 0 alone).
#[test]
fn the_spheres_equator_is_stable_at_every_kappa() {
    let b = EllipsoidBody::ellipsoid(0.0, 1.0, 0.5, 0.5).unwrap();
    let set = CriticalSet::of(&b, 200, 3.0).unwrap();
    let equator: Vec<_> = set
        .branches
        .iter()
        .filter(|branch| branch.name == "sigma_pi2")
        .collect();
    assert_eq!(equator.len(), 1, "{equator:?}");
    assert!(equator[0].stable);
    assert!(equator[0].points.iter().all(|p| p.stable));
}

/// Where a curve changes stability (κ_c on the equator of α = 0, β = 3; the cusp of
/// α = 0.5, β = 3) one segment ends and the next begins on the same point: the two rows
/// differ in their stability alone, the rotation number included.
#[test]
fn a_change_of_stability_is_one_point_shared_by_two_segments() {
    for (alpha, beta) in [(0.0, 3.0), (0.5, 3.0), (-0.5, 3.0)] {
        let b = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
        let set = CriticalSet::of(&b, 500, 3.0).unwrap();
        let points: Vec<_> = set.branches.iter().flat_map(|br| &br.points).collect();
        let mut shared = 0;
        for (i, p) in points.iter().enumerate() {
            for q in &points[i + 1..] {
                if p.theta0 == q.theta0 && p.kappa == q.kappa {
                    shared += 1;
                    assert_ne!(p.stable, q.stable, "{alpha} {beta}: {p:?} {q:?}");
                    assert_eq!(p.energy, q.energy);
                    assert_eq!(
                        p.rotation_number.map(f64::to_bits),
                        q.rotation_number.map(f64::to_bits),
                        "{alpha} {beta}: {p:?} {q:?}"
                    );
                }
            }
        }
        assert_eq!(shared, 1, "{alpha} {beta}");
    }
}

/// Near the sphere (β = 1, |α| tiny) κ climbs from 0.036 to ∞ within 8e-4 of θ0 = π/2, inside
/// one step of the θ0 grid: the branch by π/2 still reaches κ_max, each of its points on the
/// curve (V′ = 0) and none beyond κ_max.
#[test]
fn the_branch_by_the_equator_reaches_kappa_max_near_the_sphere() {
    let highest = |set: &CriticalSet| {
        set.branches
            .iter()
            .flat_map(|branch| &branch.points)
            .map(|p| p.kappa)
            .fold(0.0, f64::max)
    };
    for alpha in [1e-6, -1e-6, 1e-3, -1e-12] {
        let b = EllipsoidBody::ellipsoid(alpha, 1.0, 0.5, 0.5).unwrap();
        let set = CriticalSet::of(&b, 2000, 3.0).unwrap();
        let top = highest(&set);
        // (By π/2 one ulp of θ0 moves κ by 1e-9 of itself; by 1e-3 at |α| = 1e-12.)
        let reach = if alpha.abs() < 1e-9 { 1e-2 } else { 1e-8 };
        assert!(top <= 3.0 && top > 3.0 * (1.0 - reach), "{alpha}: {top}");
        let off_the_poles = |p: &&rubber_atlas::critical::FixedPoint| p.theta0.sin() > 1e-12;
        for p in set
            .branches
            .iter()
            .flat_map(|branch| &branch.points)
            .filter(off_the_poles)
        {
            let sys = ReducedSystem::new(&b, p.kappa);
            let slope = sys.effective_potential_prime(p.theta0);
            let scale = 1.0 + p.kappa * p.kappa / p.theta0.sin().powi(3).max(1e-300);
            assert!(slope.abs() < 1e-9 * scale, "{alpha} {p:?}: V′ = {slope}");
        }
        // Before: the grid's sample nearest π/2 ended the branch at κ = 0.036 (α = 1e-6).
        let near_equator = set
            .branches
            .iter()
            .flat_map(|branch| &branch.points)
            .filter(|p| p.kappa > 1.0)
            .count();
        assert!(near_equator >= 100, "{alpha}: {near_equator}");
    }
    // Where the last double before π/2 is below κ_max the branch goes that far (it stopped
    // at 0.036 with κ_max = 1e5; at α = 1e-15 and κ_max = 3 at 1.1e-6).
    for (alpha, kappa_max, reach) in [(1e-6, 1e5, 5e4), (1e-15, 3.0, 1.5)] {
        let b = EllipsoidBody::ellipsoid(alpha, 1.0, 0.5, 0.5).unwrap();
        let top = highest(&CriticalSet::of(&b, 2000, kappa_max).unwrap());
        assert!(
            top <= kappa_max && top > reach,
            "{alpha} {kappa_max}: {top}"
        );
    }
}

/// With a κ_max below the first sample's κ, the branches that start at κ = 0 at a pole still
/// climb from it to κ_max (σ_s0 and σ_spi were missing at κ_max = 1e-6, the disk had none).
#[test]
fn a_tiny_kappa_max_keeps_the_branches_from_the_poles() {
    use rubber_atlas::body::{Body, EdgedShape};
    let b = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    let set = CriticalSet::of(&b, 2000, 1e-6).unwrap();
    let disk = Body::new(EdgedShape::disk(0.3).unwrap(), 0.5, 0.5).unwrap();
    let disk_set = CriticalSet::of_edged(&disk, 2000, 1e-6, &|| false).unwrap();
    for set in [&set, &disk_set] {
        for name in ["sigma_s0", "sigma_spi"] {
            let branch = set.branches.iter().find(|b| b.name == name).unwrap();
            assert!(branch.points.len() > 10, "{name}: {branch:?}");
            let top = branch.points.iter().map(|p| p.kappa).fold(0.0, f64::max);
            assert!(top <= 1e-6 && top > 0.999e-6, "{name}: {top}");
        }
    }
}

/// The smallest cut, κ_max = 1e-20: each stable branch that ends at a pole is still drawn,
/// and no point lies beyond the cut (one σ_u point at κ = 2e-8 stood at θ* above κ_max =
/// 1e-300). Below it the branches by the poles are not resolved in doubles (θ0 by π is
/// known to 4.4e-16, so κ ≥ 4e-32 there): the cut is refused.
#[test]
fn the_smallest_kappa_max_keeps_every_branch_by_a_pole() {
    use rubber_atlas::body::{Body, EdgedShape};
    let tiny = rubber_atlas::critical::MIN_KAPPA_MAX;
    let check = |set: &CriticalSet, what: &str, names: &[&str]| {
        for name in names {
            assert!(
                set.branches.iter().any(|b| b.name == *name && b.stable),
                "{what}: no {name} in {:?}",
                set.branches
            );
        }
        for p in set.branches.iter().flat_map(|b| &b.points) {
            assert!(p.kappa <= tiny, "{what}: {p:?}");
        }
    };
    let b = EllipsoidBody::ellipsoid(0.5, 3.0, 0.5, 0.5).unwrap();
    check(
        &CriticalSet::of(&b, 400, tiny).unwrap(),
        "ellipsoid",
        &["sigma_s0", "sigma_spi"],
    );
    assert!(CriticalSet::of(&b, 400, tiny * 0.1).is_err());
    for (shape, names) in [
        (
            EdgedShape::disk(0.3).unwrap(),
            &["sigma_s0", "sigma_spi"][..],
        ),
        (
            EdgedShape::wheel(0.25, 0.7).unwrap(),
            &["sigma_s0", "sigma_spi"][..],
        ),
        (
            EdgedShape::truncated_ball(0.2, 0.4).unwrap(),
            &["sigma_s0", "sigma_spi"][..],
        ),
    ] {
        let body = Body::new(shape, 0.5, 0.5).unwrap();
        let set = CriticalSet::of_edged(&body, 400, tiny, &|| false).unwrap();
        check(&set, &format!("{shape:?}"), names);
        assert!(CriticalSet::of_edged(&body, 400, tiny * 0.1, &|| false).is_err());
    }
}

/// A far oblate body's N at the bottom peaks within 1/β of a pole, far inside the grid's
/// first step: the range of `sigma_s0` reaches that peak (at β = 1e10 the grid and its climbs
/// had stopped at 3.8e4; at β = 1e80, B = 1/η + β⁴ sin²θ/Z² + … overflowed in β⁴ and N was
/// +inf). References: N = −ψ̇/ω0 along the curve of permanent rotations, maximised by
/// golden-section search in mpmath at 50 and 120 digits (α = ν = η = 0.5).
#[test]
fn the_peak_of_n_at_the_bottom_by_a_far_oblate_pole_is_in_its_range() {
    for (beta, peak) in [(1e10, 1693385652.57088), (1e80, 1.69338565257088e79)] {
        let body = EllipsoidBody::ellipsoid(0.5, beta, 0.5, 0.5).unwrap();
        let set = CriticalSet::of(&body, 2000, 3.0).unwrap();
        let branch = set.branches.iter().find(|b| b.name == "sigma_s0").unwrap();
        let [low, high] = branch.rotation_number_range.unwrap();
        assert_eq!(low, 0.5, "beta {beta}");
        assert!(
            ((high - peak) / peak).abs() < 1e-9,
            "beta {beta}: {high} against {peak}"
        );
    }
}

/// Every permanent rotation on `diagram`'s stable branches is a component of the cell at its
/// (κ, ε): a fixed point with the diagram's N within its estimate. (V at a point of the
/// branches, as the diagram computes it, lay 1–4 ulps below the minimum the cell finds: the
/// cell gave `no_motion` at 609 of the paper's body's 3,374 points, and listed no fixed point
/// at 416 more, in a higher well: adversary pass 40. On a needle, α = 0.2, β = 0.01, the
/// paper's closed form of ε there lay 100 ulps below: 13 of 40 points gave `no_motion`,
/// adversary pass 41.) Each point where V″ leaves no doubt that it is a minimum (not the tip
/// of a cusp, where the minimum meets a maximum), on the paper's body, the needle, a flat
/// body and a mirror image.
#[test]
fn every_stable_point_of_the_diagram_is_a_fixed_point_of_its_cell() {
    for (alpha, beta, resolution, least) in [
        (0.5, 3.0, 2000, 2500),
        (0.2, 0.01, 1000, 200),
        (0.9, 20.0, 500, 200),
        (-0.4, 5.0, 500, 200),
    ] {
        stable_points_are_fixed_points(alpha, beta, resolution, least);
    }
}

/// [`every_stable_point_of_the_diagram_is_a_fixed_point_of_its_cell`] for one body, with the
/// diagram at `resolution` and at least `least` points checked.
fn stable_points_are_fixed_points(alpha: f64, beta: f64, resolution: usize, least: usize) {
    use rubber_atlas::cell::{solve_level, CellOptions};
    use rubber_atlas::torus::{EffectivePotential, MotionKind};
    let body = EllipsoidBody::ellipsoid(alpha, beta, 0.5, 0.5).unwrap();
    let set = CriticalSet::of(&body, resolution, 3.0).unwrap();
    let (mut checked, mut missed) = (0, Vec::new());
    for branch in set.branches.iter().filter(|b| b.stable) {
        for p in branch.points.iter().filter(|p| p.kappa > 0.0) {
            let sys = ReducedSystem::new(&body, p.kappa);
            if sys.effective_potential_second(p.theta0) < 1e-6 {
                continue;
            }
            checked += 1;
            let row = EffectivePotential::new(&body, p.kappa);
            let cell = solve_level(&row, p.energy, &CellOptions::default()).unwrap();
            let found = cell.components.iter().find(|c| {
                c.motion == MotionKind::FixedPoint && (c.theta_min - p.theta0).abs() < 1e-6
            });
            match (found, p.rotation_number) {
                (Some(c), Some(n)) => assert!(
                    (c.rotation_number - n).abs() <= c.errors.rotation_number + 1e-12 * n.abs(),
                    "{p:?}: N = {} ± {}",
                    c.rotation_number,
                    c.errors.rotation_number
                ),
                _ => missed.push((p.kappa, p.energy, cell.status)),
            }
        }
    }
    assert!(checked > least, "α {alpha}, β {beta}: {checked} points");
    assert!(
        missed.is_empty(),
        "α {alpha}, β {beta}: {} of {checked}: {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
}
