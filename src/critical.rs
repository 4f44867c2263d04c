//! The critical set of the integral map for the ellipsoid (paper §4, docs/model.md): the diagram
//! type on the (α, β²) plane, the branches of permanent rotations σ_s0, σ_u, σ_sπ (`s1`) and,
//! for α = 0, the equator σ_π/2 (`s2`), the equilibria σ0, σπ (`s0`) and θ* (`thz`), the cusp
//! of type (c), and ε_min, the energy needed to roll over the top at κ = 0.
//!
//! Several of the paper's printed formulas carry misprints; the corrected forms used here are
//! those of docs/model.md, and the tests check each against a direct numerical search.

use crate::body::{Angle, AnyBody, Body, EllipsoidBody, Shape};
use crate::error::{AtlasError, Result};
use crate::reduced::ReducedSystem;
use crate::torus::bisect;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI};

/// The five types of bifurcation diagram of paper Fig. `ab` (docs/model.md), plus the degenerate
/// and boundary cases.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiagramType {
    /// β² < 1 − α (α > 0).
    A,
    /// 1 − α < β² < 1 + α (α > 0).
    B,
    /// β² > 1 + α (α > 0): the fixed-point curve has a cusp.
    C,
    /// α = 0, β < 1.
    D,
    /// α = 0, β > 1.
    E,
    /// α = 0, β = 1: a homogeneous ball, U ≡ 1, every attitude an equilibrium.
    Sphere,
    /// β² = 1 − α exactly.
    BoundaryAB,
    /// β² = 1 + α exactly.
    BoundaryBC,
}

impl DiagramType {
    /// The type of an ellipsoid with α ≥ 0.
    pub fn of(alpha: f64, beta: f64) -> Self {
        let b2 = beta * beta;
        if alpha == 0.0 {
            return if beta < 1.0 {
                Self::D
            } else if beta > 1.0 {
                Self::E
            } else {
                Self::Sphere
            };
        }
        if b2 < 1.0 - alpha {
            Self::A
        } else if b2 == 1.0 - alpha {
            Self::BoundaryAB
        } else if b2 < 1.0 + alpha {
            Self::B
        } else if b2 == 1.0 + alpha {
            Self::BoundaryBC
        } else {
            Self::C
        }
    }

    /// The paper's letter or a word for the degenerate cases.
    pub fn label(&self) -> &'static str {
        match self {
            Self::A => "a",
            Self::B => "b",
            Self::C => "c",
            Self::D => "d",
            Self::E => "e",
            Self::Sphere => "sphere",
            Self::BoundaryAB => "a|b",
            Self::BoundaryBC => "b|c",
        }
    }
}

/// A permanent rotation: a fixed point θ = θ0, p = 0 of `eqsys`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FixedPoint {
    /// θ0, the constant inclination of the axis.
    pub theta0: f64,
    /// κ ≥ 0 on the curve (the mirror branch −κ has the same ε and stability).
    pub kappa: f64,
    /// ε on the curve.
    pub energy: f64,
    /// Linear stability: V″(θ0) > 0 (G0′ < 0, a centre).
    pub stable: bool,
    /// Radius of the circle of the centre of mass, ρ_c = Z tanθ0 + α sinθ0 (∞ on σ_π/2).
    pub rho_c: f64,
    /// Radius of the circle of the contact point, ρ_p = β² tanθ0 / Z.
    pub rho_p: f64,
    /// The rotation number of the small oscillations about it, N = −ψ̇(θ0)/ω0 (the bottom of
    /// the well, [`crate::limits::linearised_rotation_number`]); None where unstable.
    pub rotation_number: Option<f64>,
}

/// A run of fixed points with one stability along one branch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Branch {
    /// `sigma_s0` (stable, θ0 < π/2), `sigma_spi` (stable, θ0 > π/2), `sigma_u` (unstable),
    /// `sigma_pi2` (α = 0: the equator θ0 = π/2, any κ).
    pub name: &'static str,
    /// Stability of every point of the run.
    pub stable: bool,
    /// [min, max] of θ0 over the run.
    pub theta0_range: [f64; 2],
    /// [min, max] of κ over the run.
    pub kappa_range: [f64; 2],
    /// [min, max] of ε over the run.
    pub energy_range: [f64; 2],
    /// [min, max] of the linearised rotation number over a stable run (the bottom of the
    /// (κ, ε) plane); None on an unstable one.
    pub rotation_number_range: Option<[f64; 2]>,
    /// Points ordered by θ0 (by κ on σ_π/2); written by `--out`, not in the JSON summary.
    #[serde(skip)]
    pub points: Vec<FixedPoint>,
}

/// An equilibrium κ = 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Equilibrium {
    /// `sigma_0` (resting on the vertex θ = 0), `sigma_pi` (θ = π), `theta_star` (inclined);
    /// for edged bodies also `face_0`, `face_pi`, `inclined` and `neutral_arc`.
    pub name: &'static str,
    /// Inclination θ of the axis.
    pub theta: f64,
    /// ε = U(θ).
    pub energy: f64,
    /// Linear stability, U″(θ) > 0.
    pub stable: bool,
    /// No branch of permanent rotations ends at this point of the (κ, ε) plane.
    pub isolated: bool,
    /// The far end of a `neutral_arc`: U′ vanishes on all of [θ, θ_end] (a ball whose centre
    /// of mass is its centre, rolling on its sphere), every inclination there an equilibrium.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta_end: Option<f64>,
}

/// The cusp of type (c): the saddle-node where σ_s0 and σ_u meet (V′ = V″ = 0, `eq2`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Cusp {
    pub theta: f64,
    pub kappa: f64,
    pub energy: f64,
}

/// The critical set of one body.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalSet {
    /// The body's shape when it is not the ellipsoid (docs/bodies.md).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<&'static str>,
    pub alpha: f64,
    /// β of the ellipsoid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// The cut h of a cut ball.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut: Option<f64>,
    pub nu: f64,
    pub eta: f64,
    /// The ellipsoid's diagram type (a)–(e) (paper Fig. `ab`); None for another body.
    pub diagram_type: Option<DiagramType>,
    /// The kinks of U (an edged body), where U″ jumps: marked on the curves.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub kinks: Vec<f64>,
    /// Every cusp of an edged body (whose curve may have several; `cusp` is the last).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cusps: Vec<Cusp>,
    /// Where a branch changes stability at a kink (V″ jumps through 0 there; no cusp).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stability_changes_at_kinks: Vec<Cusp>,
    /// Inclination of the inclined equilibrium θ*, where it exists (α ≠ 0).
    pub theta_star: Option<f64>,
    /// ε_min: the top of U on the circle; at κ = 0 a body with ε > ε_min rolls over the top.
    pub energy_min: f64,
    /// κ_c = √((β² − 1)/β) for α = 0, β > 1: σ_π/2 is stable for |κ| > κ_c.
    pub kappa_c_equator: Option<f64>,
    pub equilibria: Vec<Equilibrium>,
    pub cusp: Option<Cusp>,
    /// The sampled fixed-point curves, κ ≥ 0, truncated at `kappa_max`.
    pub branches: Vec<Branch>,
    /// The truncation of the sampled curves.
    pub kappa_max: f64,
}

/// κ² on the fixed-point curve (`s1`): κ² = sin⁴θ0 ((β² − 1)/Z − α / cosθ0).
pub fn fixed_point_kappa_sq(body: &EllipsoidBody, theta0: f64) -> f64 {
    let (a, b) = (body.shape.alpha, body.shape.beta);
    let s2 = theta0.sin().powi(2);
    // (sin²θ0 times the bracket first: at β = 1e80 the bracket is 1e160 and sin⁴θ0 alone
    // underflows below θ0 = 1e-77, where κ² is still 1e-150.)
    s2 * (s2 * ((b * b - 1.0) / body.shape.centre_height(theta0) - a / theta0.cos()))
}

/// ε on the fixed-point curve (`s1`):
/// ε = (3Z² − 1)/(2Z) + α (3cos²θ0 − 1)/(2cosθ0). (The paper's closed form; its two terms
/// cancel near θ0 = π/2 on a needle, where [`fixed_point`] takes V(θ0) instead.)
pub fn fixed_point_energy(body: &EllipsoidBody, theta0: f64) -> f64 {
    let z = body.shape.centre_height(theta0);
    let c = theta0.cos();
    (3.0 * z * z - 1.0) / (2.0 * z) + body.shape.alpha * (3.0 * c * c - 1.0) / (2.0 * c)
}

/// The permanent rotation at θ0 (θ0 ≠ π/2, κ² ≥ 0 there), at ε = V(θ0) for its κ: the
/// value of [`fixed_point_energy`] in a form without cancellation (a sum of two positive
/// terms), so that a cell at the point's (κ, ε) finds ε at its minimum of V to V's rounding.
/// (The closed form's terms, ±50 at α = 0.2, β = 0.01 beside θ0 = π/2, left ε 100 ulps below
/// that minimum, and the cell found no motion there: adversary pass 41.)
pub fn fixed_point(body: &EllipsoidBody, theta0: f64) -> FixedPoint {
    let kappa = fixed_point_kappa_sq(body, theta0).max(0.0).sqrt();
    let sys = ReducedSystem::new(body, kappa);
    let z = body.shape.centre_height(theta0);
    let (s, c) = theta0.sin_cos();
    let b2 = body.shape.beta * body.shape.beta;
    FixedPoint {
        theta0,
        kappa,
        energy: sys.effective_potential(theta0),
        stable: sys.effective_potential_second(theta0) > 0.0,
        rho_c: z * s / c + body.shape.alpha * s,
        rho_p: b2 * s / (c * z),
        rotation_number: crate::limits::linearised_rotation_number(body, theta0, kappa),
    }
}

/// θ* of the inclined equilibrium (corrected `thz`): cos²θ* = α²β² / ((β² − 1)(β² − 1 + α²))
/// with the sign of cosθ* that of β² − 1, where that is ≤ 1 (types (a) and (c)).
pub fn inclined_equilibrium(alpha: f64, beta: f64) -> Option<f64> {
    let b2m1 = beta * beta - 1.0;
    let den = b2m1 * (b2m1 + alpha * alpha);
    if alpha == 0.0 || den <= 0.0 {
        return None;
    }
    let cos2 = alpha * alpha * beta * beta / den;
    if cos2 > 1.0 {
        return None;
    }
    Some(cos2.sqrt().copysign(b2m1).acos())
}

/// ε_min = max of U on the circle: 1 + α if β² < 1 + α, else U(θ*) = β √((β² − 1 + α²)/(β² − 1))
/// (docs/model.md; the paper prints (1 + α² − β²)/(1 − β²) under the root).
pub fn energy_min(alpha: f64, beta: f64) -> f64 {
    let b2 = beta * beta;
    if b2 <= 1.0 + alpha.abs() {
        1.0 + alpha.abs()
    } else {
        beta * ((b2 - 1.0 + alpha * alpha) / (b2 - 1.0)).sqrt()
    }
}

impl CriticalSet {
    /// The critical set of an ellipsoid body, its curves sampled with `samples` points per
    /// half (θ0 < π/2, θ0 > π/2) and truncated at κ ≤ `kappa_max`. For α < 0 it is the mirror
    /// image of the body with −α (θ → π − θ; [`DiagramType`] is that of |α|).
    pub fn of(body: &EllipsoidBody, samples: usize, kappa_max: f64) -> Result<Self> {
        Self::of_until(body, samples, kappa_max, &|| false)
    }

    /// [`CriticalSet::of`], given up with [`AtlasError::Stopped`] when `stop` says so (asked
    /// every 65,536 samples; Ctrl-C in Python).
    pub fn of_until(
        body: &EllipsoidBody,
        samples: usize,
        kappa_max: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<Self> {
        let stopped = |i: usize| asked_to_stop(i, stop);
        let (alpha, beta) = (body.shape.alpha, body.shape.beta);
        if alpha < 0.0 {
            let image = EllipsoidBody::ellipsoid(-alpha, beta, body.nu, body.eta)?;
            let mut set = Self::of_until(&image, samples, kappa_max, stop)?.mirrored();
            // θ → π − θ rounds θ0 by up to an ulp; by π/2, where κ² ∝ 1/cosθ0, that put κ
            // off the curve at the rounded θ0 (by 1e-3 at α = −1e-12): there each point is
            // evaluated again on this body, at its own θ0.
            for branch in set.branches.iter_mut().filter(|b| b.name != "sigma_pi2") {
                let points = std::mem::take(&mut branch.points)
                    .into_iter()
                    .map(|p| match p.theta0.cos().abs() < 1e-3 {
                        true => FixedPoint {
                            stable: p.stable,
                            ..fixed_point(body, p.theta0)
                        },
                        false => p,
                    })
                    .filter(|p| p.kappa <= kappa_max)
                    .collect();
                *branch = make_branch(points, branch.name);
            }
            set.branches.retain(|b| !b.points.is_empty());
            return Ok(set);
        }
        check_kappa_max(kappa_max)?;
        crate::error::check_samples(samples)?;
        let samples = samples.max(16);
        let diagram_type = DiagramType::of(alpha, beta);
        let theta_star = inclined_equilibrium(alpha, beta);
        let u = |t: f64| body.shape.potential(t);
        let upp = |t: f64| body.shape.potential_second(t);

        // U and U″ at the poles themselves (sin π as a double, 1.2e-16, times β² gave
        // U(π) = 1.2e84 at β = 1e100).
        let (north, south) = (Angle::new(0.0), Angle::from_pi(0.0));
        let at_pole = |a: Angle| {
            let curvature = body.shape.potential_second_at(a);
            (body.shape.potential_at(a), curvature > 0.0, curvature < 0.0)
        };
        let [(u0, stable0, isolated0), (upi, stable_pi, isolated_pi)] =
            [at_pole(north), at_pole(south)];
        let mut equilibria = vec![
            Equilibrium {
                name: "sigma_0",
                theta: 0.0,
                energy: u0,
                stable: stable0,
                isolated: isolated0,
                theta_end: None,
            },
            Equilibrium {
                name: "sigma_pi",
                theta: PI,
                energy: upi,
                stable: stable_pi,
                isolated: isolated_pi,
                theta_end: None,
            },
        ];
        if let Some(ts) = theta_star {
            equilibria.push(Equilibrium {
                name: "theta_star",
                theta: ts,
                energy: u(ts),
                stable: upp(ts) > 0.0,
                // The branch σ_u (type c) or σ_sπ (type a) ends at κ = 0 on θ*.
                isolated: false,
                theta_end: None,
            });
        }

        let curve = Curve {
            body,
            kappa_sq: &|t| fixed_point_kappa_sq(body, t),
            point: &|t| fixed_point(body, t),
            pole_ends: &|pole| body.shape.potential_second(pole) > 0.0,
            extra: theta_star.into_iter().collect(),
        };
        let (mut branches, cusps) = sample_branches(&curve, samples, kappa_max, &stopped)?;
        let cusp = cusps.last().copied();
        let at = crate::body::Angle::EQUATOR;
        let equator = alpha == 0.0
            || equator_held(
                body.shape.potential_prime_at(at),
                body.shape.potential_second_at(at),
            );
        let kappa_c_equator = (equator && beta > 1.0).then(|| ((beta * beta - 1.0) / beta).sqrt());
        if equator {
            // σ_π/2: ε = κ²/2 + β (`s2`), stable where V″(π/2) = κ² − (β² − 1)/β > 0.
            branches.extend(equator_branches(
                beta,
                -(beta * beta - 1.0) / beta,
                kappa_c_equator,
                samples,
                kappa_max,
                &stopped,
            )?);
        }

        Ok(Self {
            shape: None,
            alpha,
            beta: Some(beta),
            cut: None,
            nu: body.nu,
            eta: body.eta,
            diagram_type: Some(diagram_type),
            kinks: Vec::new(),
            cusps: Vec::new(),
            stability_changes_at_kinks: Vec::new(),
            theta_star,
            energy_min: energy_min(alpha, beta),
            kappa_c_equator,
            equilibria,
            cusp,
            branches,
            kappa_max,
        })
    }
}

/// How one body's curve of permanent rotations is evaluated: the ellipsoid's closed forms
/// (`s1`) or any body's ([`general_fixed_point`]).
struct Curve<'f, S: Shape> {
    /// The body (its V″ decides the stability, and locates a change of it).
    body: &'f Body<S>,
    /// κ² at θ0 (< 0: no permanent rotation there).
    kappa_sq: &'f dyn Fn(f64) -> f64,
    /// The permanent rotation at θ0.
    point: &'f dyn Fn(f64) -> FixedPoint,
    /// Whether a branch may end at this pole (V″ > 0 there).
    pole_ends: &'f dyn Fn(f64) -> bool,
    /// Angles sampled besides the grid, on the curve (θ*, the kinks of U where κ² ≥ 0).
    extra: Vec<f64>,
}

/// The branches of `curve` over the halves θ0 < π/2 and θ0 > π/2, each sampled at `samples`
/// points, truncated at κ ≤ `kappa_max`, and cut into runs of one stability; every change of
/// stability inside a half is located (a cusp, or a kink of U where V″ jumps), in order.
/// `stopped(i)` is asked at every sample.
fn sample_branches<S: Shape>(
    curve: &Curve<'_, S>,
    samples: usize,
    kappa_max: f64,
    stopped: &dyn Fn(usize) -> Result<()>,
) -> Result<(Vec<Branch>, Vec<Cusp>)> {
    let mut branches = Vec::new();
    let mut cusps = Vec::new();
    let halves = [(0.0, FRAC_PI_2, "sigma_s0"), (FRAC_PI_2, PI, "sigma_spi")];
    for (lo, hi, stable_name) in halves {
        let mut pts: Vec<FixedPoint> = Vec::with_capacity(samples + 1);
        // Interior samples; a pole is added only where a branch ends at it (U″ > 0 there,
        // i.e. κ² ≥ 0 on its neighbourhood), never as a lone point.
        // The probes of the curve run from one end of the half to the other: its pole (κ² = 0:
        // a branch that ends there climbs from it, where a tiny κ_max lies below the first
        // sample; where the curve nears it from κ² < 0 there is no climb), the samples, and
        // the last double on this half's side of π/2, where κ → ∞ unless U′(π/2) = 0. The
        // ends only bracket a climb ([`climb_to_kappa_max`]); a sample is a point itself.
        let pole = if lo == 0.0 { 0.0 } else { PI };
        let equator = if lo == 0.0 {
            FRAC_PI_2
        } else {
            FRAC_PI_2.next_up()
        };
        let (first, last) = if lo == 0.0 {
            (pole, equator)
        } else {
            (equator, pole)
        };
        // The extra angles are probes too: a branch climbs steeply from an inclined
        // equilibrium (κ = 0) as well as towards π/2.
        // (An extra angle is on the curve, κ² ≥ 0: an equilibrium's κ² = 0 may round below.)
        let mut probes: Vec<(f64, bool)> = (1..samples)
            .map(|i| (lo + (hi - lo) * i as f64 / samples as f64, false))
            .chain(
                curve
                    .extra
                    .iter()
                    .filter(|&&t| t > lo && t < hi)
                    .map(|&t| (t, true)),
            )
            .collect();
        // A body whose shape turns on a scale w far below the grid's step (an oblate
        // ellipsoid's 1/β at the poles, a prolate one's β at the equator) has its curve's
        // features there: at β = 1e10, N at the bottom peaks at 1.7e9 at θ0 = 1.4e-10, which
        // the grid (and its climbs, evenly in κ) stepped over, reporting 3.8e4 as the top of
        // the range. Probes are added eight a decade from each end of the half in towards
        // the grid, from a thousandth of w up.
        let step = (hi - lo) / samples as f64;
        let finest = 1e-3 * curve.body.shape.angular_feature_scale().min(1.0);
        if finest < step {
            let decades = (step / finest).log10();
            let per_decade = 8.0;
            let count = (decades * per_decade).ceil() as usize;
            for j in 1..=count {
                let d = step * 10f64.powf(-(j as f64) / per_decade);
                // (Not where κ² underflows: κ = 0 off an equilibrium is no permanent
                // rotation, and its N would be 0 where the branch tends to ±1/2.)
                for t in [lo + d, hi - d] {
                    if t > lo && t < hi && (curve.kappa_sq)(t) >= f64::MIN_POSITIVE {
                        probes.push((t, false));
                    }
                }
            }
        }
        probes.sort_by(|a, b| a.0.total_cmp(&b.0));
        probes.dedup_by(|a, b| a.0 == b.0);
        probes.push((last, false));
        let mut previous = (first, (curve.kappa_sq)(first));
        for (i, &(t, on_curve)) in probes.iter().enumerate() {
            stopped(i + 1)?;
            let k2 = (curve.kappa_sq)(t);
            let k2 = if on_curve { k2.max(0.0) } else { k2 };
            pts.extend(climb_to_kappa_max(
                curve,
                previous,
                (t, k2),
                kappa_max,
                samples,
            ));
            previous = (t, k2);
            if i + 1 == probes.len() || k2 < 0.0 {
                continue;
            }
            let p = (curve.point)(t);
            if p.kappa <= kappa_max {
                pts.push(p);
            }
        }
        if (curve.pole_ends)(pole) && !pts.is_empty() {
            pts.push((curve.point)(pole));
        }
        pts.sort_by(|a, b| a.theta0.total_cmp(&b.theta0));
        pts.dedup_by(|a, b| a.theta0 == b.theta0);
        pts.extend(peaks_of_rotation_number(curve, &pts, kappa_max));
        pts.sort_by(|a, b| a.theta0.total_cmp(&b.theta0));
        pts.dedup_by(|a, b| a.theta0 == b.theta0);
        // Runs of equal stability; a flip inside a half is the cusp (V″ = 0 on the curve).
        let mut run: Vec<FixedPoint> = Vec::new();
        for p in pts {
            if let Some(last) = run.last().copied() {
                let contiguous = (p.theta0 - last.theta0) <= 1.5 * (hi - lo) / samples as f64;
                if last.stable != p.stable || !contiguous {
                    if last.stable != p.stable && contiguous {
                        let mut c = locate_cusp(curve, last.theta0, p.theta0, last.stable);
                        // The samples run up in θ0: the stable side is below if `last` is.
                        let stable_side = if last.stable { -1.0 } else { 1.0 };
                        // A change at a kink is on the kink itself (a sample of its own).
                        let kink = curve.body.shape.kinks().iter().copied();
                        if let Some(k) = kink.clone().find(|&k| at_kink(&[k], c.theta)) {
                            let at = (curve.point)(k);
                            c = Cusp {
                                theta: k,
                                kappa: at.kappa,
                                energy: at.energy,
                            };
                        }
                        cusps.push(c);
                        let at = shared_point(curve, c.theta, stable_side);
                        if run.last().is_some_and(|q| q.theta0 == c.theta) {
                            run.pop();
                        }
                        let mut at_end = at;
                        at_end.stable = last.stable;
                        run.push(at_end);
                        branches.push(make_branch(std::mem::take(&mut run), stable_name));
                        let mut at_start = at;
                        at_start.stable = p.stable;
                        run.push(at_start);
                        if p.theta0 == c.theta {
                            continue;
                        }
                    } else {
                        branches.push(make_branch(std::mem::take(&mut run), stable_name));
                    }
                }
            }
            run.push(p);
        }
        if !run.is_empty() {
            branches.push(make_branch(run, stable_name));
        }
    }
    Ok((branches, cusps))
}

/// The largest and the smallest N at the bottom among the sampled points `pts` (sorted by
/// θ0), where either is a peak between two stable neighbours, located to about 1e-10 of θ0
/// between them by golden-section steps on the curve: the branch's range of N is then its
/// own, not its samples' (at β = 1e10 the samples' top, eight a decade, was 4e-4 below the
/// peak's 1.6924e9).
fn peaks_of_rotation_number<S: Shape>(
    curve: &Curve<'_, S>,
    pts: &[FixedPoint],
    kappa_max: f64,
) -> Vec<FixedPoint> {
    let n_of = |p: &FixedPoint| p.rotation_number.filter(|n| n.is_finite());
    let mut found = Vec::new();
    for sign in [1.0, -1.0] {
        let best = (1..pts.len().saturating_sub(1))
            .filter(|&i| pts[i - 1..=i + 1].iter().all(|p| n_of(p).is_some()))
            .max_by(|&i, &j| {
                let (a, b) = (sign * n_of(&pts[i]).unwrap(), sign * n_of(&pts[j]).unwrap());
                a.total_cmp(&b)
            });
        let Some(i) = best else { continue };
        let height = |p: &FixedPoint| sign * n_of(p).unwrap_or(f64::NEG_INFINITY);
        if height(&pts[i]) < height(&pts[i - 1]) || height(&pts[i]) < height(&pts[i + 1]) {
            continue;
        }
        // Golden-section search on (θ_{i−1}, θ_{i+1}) for the largest sign·N.
        let (a, b) = (pts[i - 1].theta0, pts[i + 1].theta0);
        let xtol = 1e-10 * b.abs().max(f64::MIN_POSITIVE);
        let (t, _) = crate::limits::golden_max(|t| height(&(curve.point)(t)), a, b, xtol);
        let top = (curve.point)(t);
        if top.stable && top.kappa <= kappa_max && height(&top) > height(&pts[i]) {
            found.push(top);
        }
    }
    found
}

/// The points of a branch between two probes of the curve, (θ, κ²) each, where κ climbs
/// steeply between them or crosses κ_max: by θ0 = π/2 on a body not symmetric about its
/// equator κ → ∞ (at α = 10⁻⁶, β = 1 the grid's last sample has κ = 0.036, and at α = 10⁻¹⁵
/// the last double before π/2 has κ = 2.5). Points at most 4 κ_max/`samples` apart in κ, from
/// the lower probe's κ up to the crossing κ = κ_max or short of the upper probe, so that the
/// branch is drawn up to κ_max or as far as doubles reach. None where either probe has no
/// permanent rotation (κ² < 0) or both lie beyond κ_max.
fn climb_to_kappa_max<S: Shape>(
    curve: &Curve<'_, S>,
    a: (f64, f64),
    b: (f64, f64),
    kappa_max: f64,
    samples: usize,
) -> Vec<FixedPoint> {
    let ((t_in, k2_in), (t_out, k2_out)) = if a.1 <= b.1 { (a, b) } else { (b, a) };
    let step = 4.0 * kappa_max / samples as f64;
    let (k_in, k_out) = (k2_in.sqrt(), k2_out.sqrt());
    if !(k2_in >= 0.0 && k_in <= kappa_max && k_out - k_in > step.min(kappa_max - k_in)) {
        return Vec::new();
    }
    let crosses = k_out > kappa_max;
    let k_top = k_out.min(kappa_max);
    let steps = ((k_top - k_in) / step).ceil().clamp(1.0, samples as f64) as usize;
    let (lo, hi) = (t_in.min(t_out), t_in.max(t_out));
    // Up to the crossing, or short of the upper probe (a sample already, or the end at π/2).
    let last = if crosses { steps } else { steps - 1 };
    (1..=last)
        .map(|j| {
            let k = k_in + (k_top - k_in) * j as f64 / steps as f64;
            let k2 = if crosses && j == steps {
                kappa_max * kappa_max
            } else {
                k * k
            };
            let f = |t: f64| (curve.kappa_sq)(t) - k2;
            let t = bisect(&f, lo, hi, f(lo) < 0.0);
            // The bisection ends on either side of the root: the crossing is taken inside.
            match (curve.point)(t) {
                p if p.kappa > kappa_max && t_in < t_out => (curve.point)(t.next_down()),
                p if p.kappa > kappa_max => (curve.point)(t.next_up()),
                p => p,
            }
        })
        .filter(|p| p.kappa <= kappa_max && p.kappa > k_in)
        .collect()
}

/// σ_π/2 of a body symmetric about its equator: θ0 = π/2 at every κ (`s2`), ε = κ²/2 + U(π/2)
/// with U(π/2) = `height`, stable where V″(π/2) = κ² + U″(π/2) > 0 (U″(π/2) = `curvature`),
/// i.e. beyond κ_c = `kappa_c` where U″(π/2) < 0; sampled at `samples` + 1 values of κ.
fn equator_branches(
    height: f64,
    curvature: f64,
    kappa_c: Option<f64>,
    samples: usize,
    kappa_max: f64,
    stopped: &dyn Fn(usize) -> Result<()>,
) -> Result<Vec<Branch>> {
    let mut branches = Vec::new();
    let mut run: Vec<FixedPoint> = Vec::new();
    // The stability at κ; where V″(π/2) vanishes at κ = 0 because U″(π/2) does (the sphere,
    // U ≡ 1), the branch's: stable for every κ > 0 (it was labelled unstable whole).
    let stable_at = |kappa: f64| {
        let v2 = kappa * kappa + curvature;
        v2 > 0.0 || (v2 == 0.0 && curvature == 0.0)
    };
    let push_point = |kappa: f64, run: &mut Vec<FixedPoint>, force: Option<bool>| {
        let stable = force.unwrap_or(stable_at(kappa));
        run.push(FixedPoint {
            theta0: FRAC_PI_2,
            kappa,
            energy: 0.5 * kappa * kappa + height,
            stable,
            rho_c: f64::INFINITY,
            rho_p: f64::INFINITY,
            // ψ̇ = 0 on the equator: the librations about it do not precess. At κ_c, where
            // one segment ends and the next begins, both rows carry the stable side's 0.
            rotation_number: (stable || force.is_some()).then_some(0.0),
        });
    };
    for i in 0..=samples {
        stopped(i)?;
        let kappa = kappa_max * i as f64 / samples as f64;
        let stable = stable_at(kappa);
        let last_stable = run.last().map(|p| p.stable);
        if let (Some(kc), Some(last_stable)) = (kappa_c, last_stable) {
            if last_stable != stable {
                push_point(kc, &mut run, Some(last_stable));
                branches.push(make_branch(std::mem::take(&mut run), "sigma_pi2"));
                push_point(kc, &mut run, Some(stable));
            }
        }
        push_point(kappa, &mut run, None);
    }
    branches.push(make_branch(run, "sigma_pi2"));
    Ok(branches)
}

/// The name of a branch or an equilibrium seen in the mirror θ → π − θ.
fn mirror_name(name: &'static str) -> &'static str {
    match name {
        "sigma_s0" => "sigma_spi",
        "sigma_spi" => "sigma_s0",
        "sigma_0" => "sigma_pi",
        "sigma_pi" => "sigma_0",
        other => other,
    }
}

impl FixedPoint {
    /// The same permanent rotation of the mirror body (−α): θ0 → π − θ0; the circles and
    /// the precession turn the other way, so ρ_c, ρ_p and N change sign.
    fn mirrored(self) -> Self {
        FixedPoint {
            theta0: PI - self.theta0,
            rho_c: -self.rho_c,
            rho_p: -self.rho_p,
            rotation_number: self.rotation_number.map(|n| -n),
            ..self
        }
    }
}

impl CriticalSet {
    /// The critical set of the mirror body (α → −α), whose V at θ is this body's at π − θ
    /// (docs/model.md): every angle θ → π − θ, the names of the two halves exchanged, and
    /// ρ_c, ρ_p and N of the opposite sign. Branches and equilibria keep their order by θ.
    fn mirrored(self) -> Self {
        let flip = |[lo, hi]: [f64; 2]| [PI - hi, PI - lo];
        let mut branches: Vec<Branch> = self
            .branches
            .into_iter()
            .rev()
            .map(|b| Branch {
                name: mirror_name(b.name),
                theta0_range: flip(b.theta0_range),
                rotation_number_range: b.rotation_number_range.map(|[lo, hi]| [-hi, -lo]),
                points: b
                    .points
                    .into_iter()
                    .rev()
                    .map(FixedPoint::mirrored)
                    .collect(),
                ..b
            })
            .collect();
        branches.sort_by(|a, b| a.theta0_range[0].total_cmp(&b.theta0_range[0]));
        let mut equilibria: Vec<Equilibrium> = self
            .equilibria
            .into_iter()
            .map(|e| Equilibrium {
                name: mirror_name(e.name),
                theta: PI - e.theta_end.unwrap_or(e.theta),
                theta_end: e.theta_end.map(|_| PI - e.theta),
                ..e
            })
            .collect();
        equilibria.sort_by_key(|e| match e.name {
            "sigma_0" => 0,
            "sigma_pi" => 1,
            _ => 2,
        });
        CriticalSet {
            alpha: -self.alpha,
            theta_star: self.theta_star.map(|t| PI - t),
            cusp: self.cusp.map(|c| Cusp {
                theta: PI - c.theta,
                ..c
            }),
            equilibria,
            branches,
            ..self
        }
    }
}

fn make_branch(points: Vec<FixedPoint>, stable_name: &'static str) -> Branch {
    let stable = points.first().is_some_and(|p| p.stable);
    let name = if stable_name == "sigma_pi2" {
        "sigma_pi2"
    } else if stable {
        stable_name
    } else {
        "sigma_u"
    };
    let range = |f: fn(&FixedPoint) -> f64| {
        points
            .iter()
            .map(f)
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
                [lo.min(x), hi.max(x)]
            })
    };
    let rotation_number_range = stable.then(|| {
        points
            .iter()
            .filter_map(|p| p.rotation_number)
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
                [lo.min(x), hi.max(x)]
            })
    });
    Branch {
        name,
        stable,
        theta0_range: range(|p| p.theta0),
        kappa_range: range(|p| p.kappa),
        energy_range: range(|p| p.energy),
        rotation_number_range,
        points,
    }
}

/// The permanent rotation at a change of stability θ0, the point two segments share, with
/// the stable side's limit of N (the stable samples lie below θ0 if `stable_side` is −1,
/// above if +1). At a kink θk
/// V″ jumps through 0 and N is the stable piece's, taken 1e-9 into it (N varies by about
/// 1e-9 of itself there); at a cusp V″ → 0, so ω_θ → 0 while ψ̇ = −κ cosθ0/(J sin²θ0)
/// (`dpsi`) stays finite: N → ±∞ with the sign of cosθ0 (0 at κ = 0, where ψ stays put).
fn shared_point<S: Shape>(curve: &Curve<'_, S>, theta: f64, stable_side: f64) -> FixedPoint {
    let mut at = (curve.point)(theta);
    let kinks = curve.body.shape.kinks();
    at.rotation_number = Some(match kinks.iter().find(|k| (*k - theta).abs() <= 1e-9) {
        Some(&kink) => {
            let inside = kink + 1e-9 * stable_side;
            (curve.point)(inside).rotation_number.unwrap_or(f64::NAN)
        }
        None if at.kappa == 0.0 => 0.0,
        None => f64::INFINITY.copysign(theta.cos()),
    });
    at
}

/// Whether the equator stands for the permanent rotations by it at every κ, from U′(π/2) =
/// `slope` and U″(π/2) = `curvature`. V′(π/2) = U′(π/2) for every κ (the κ term's slope
/// vanishes there), so it is one exactly where U′(π/2) = 0: a body symmetric about its
/// equator, or a ball centred on its sphere's centre (α = 0) whose sphere holds π/2. Where
/// U′(π/2) is not 0 but tiny, the permanent rotation lies |U′(π/2)|/|V″(π/2)| from π/2, and
/// its (κ, ε) is the equator's, ε = κ²/2 + U(π/2), to O(U′(π/2)). Where that distance is
/// below 2²⁰ half-ulps of π/2 (5.8e-11) at every κ but in a window round κ_c of relative
/// width 1e-3 (|α| ≲ 3e-13 for the ellipsoid of β = 3, 1.2e-13 for the disk), the sampled
/// curve has too few doubles θ0 to climb on: at α = 1e-15, β = 3 its σ_sπ stopped at
/// κ = 2.30 of 3, at 1e-18 at κ_c, and the disk at α = 1e-300 had no branch for κ in (1, 3].
/// The equator branch stands for them there.
fn equator_held(slope: f64, curvature: f64) -> bool {
    slope == 0.0 || slope.abs() <= 1e-3 * EQUATOR_BAND * 1.1e-16 * curvature.abs()
}

/// Half-ulps of π/2 within which a permanent rotation is drawn as the equator's
/// ([`equator_held`]).
const EQUATOR_BAND: f64 = (1u64 << 20) as f64;

/// Whether a change of stability at θ0 is one at a kink of U (V″ jumping through 0, not a
/// cusp): θ0 bisected to within 1e-9 of it.
fn at_kink(kinks: &[f64], theta: f64) -> bool {
    kinks.iter().any(|k| (k - theta).abs() <= 1e-9)
}

/// The zero of V″(θ0) along the fixed-point curve between two samples of opposite stability.
fn locate_cusp<S: Shape>(curve: &Curve<'_, S>, lo: f64, hi: f64, lo_stable: bool) -> Cusp {
    let f = |t: f64| {
        let k2 = (curve.kappa_sq)(t).max(0.0);
        ReducedSystem::new(curve.body, k2.sqrt()).effective_potential_second(t)
    };
    // V″ > 0 on the stable side.
    let theta = bisect(&f, lo, hi, !lo_stable);
    let p = (curve.point)(theta);
    Cusp {
        theta,
        kappa: p.kappa,
        energy: p.energy,
    }
}

/// κ² on the curve of permanent rotations of any body (V′(θ0) = 0, the general form of
/// `s1`): κ² = sin³θ0 U′(θ0) / cosθ0 (0 at a pole).
pub fn general_kappa_sq<S: Shape>(body: &Body<S>, theta0: f64) -> f64 {
    let (s, c) = theta0.sin_cos();
    if s == 0.0 {
        return 0.0;
    }
    s * s * s * body.shape.potential_prime(theta0) / c
}

/// The permanent rotation of any body at θ0: κ from [`general_kappa_sq`],
/// ε = κ²/(2 sin²θ0) + U = sinθ0 U′/(2 cosθ0) + U, stable where V″(θ0) > 0; the centre of
/// mass runs on a circle of radius ρ_c = U tanθ0 and the contact point on one of radius
/// ρ_p = ρ_c + U′ (the contact point is U′ from the centre of mass horizontally).
pub fn general_fixed_point<S: Shape>(body: &Body<S>, theta0: f64) -> FixedPoint {
    let kappa = general_kappa_sq(body, theta0).max(0.0).sqrt();
    let sys = ReducedSystem::new(body, kappa);
    let (s, c) = theta0.sin_cos();
    let u = body.shape.potential(theta0);
    let up = body.shape.potential_prime(theta0);
    let energy = if s == 0.0 { u } else { s * up / (2.0 * c) + u };
    let rho_c = u * s / c;
    FixedPoint {
        theta0,
        kappa,
        energy,
        stable: sys.effective_potential_second(theta0) > 0.0,
        rho_c,
        rho_p: rho_c + up,
        rotation_number: crate::limits::linearised_rotation_number(body, theta0, kappa),
    }
}

/// The equilibria (κ = 0) of an edged body: both poles, where the body stands on a vertex of
/// the sphere (`sigma_0`, `sigma_pi`) or lies on a face (`face_0`, `face_pi`: a corner of U,
/// stable where U rises from it), and the inclined ones (`inclined`), the roots of U′ inside,
/// found by a scan of 4096 cells and bisection. Where U′ vanishes on a whole arc (α = 0 on a
/// ball's sphere), every inclination there is a neutral equilibrium: one `neutral_arc`.
fn edged_equilibria<S: Shape>(body: &Body<S>) -> Vec<Equilibrium> {
    let shape = &body.shape;
    let faces = shape.faces();
    let mut out = Vec::new();
    for (pole, face, name, face_name, inward) in [
        (0.0, faces[0], "sigma_0", "face_0", 1.0),
        (PI, faces[1], "sigma_pi", "face_pi", -1.0),
    ] {
        // sin = 0 exactly at the pole (PI's sine is 1.2e-16).
        let exact = crate::body::Angle {
            sin: 0.0,
            cos: inward,
        };
        let energy = shape.potential_at(exact);
        if face {
            // U′ just inside the pole: U rises from a stable face.
            let slope = inward * shape.potential_prime(pole + inward * 1e-9);
            out.push(Equilibrium {
                name: face_name,
                theta: pole,
                energy,
                stable: slope > 0.0,
                isolated: slope <= 0.0,
                theta_end: None,
            });
        } else {
            let upp = shape.potential_second_at(exact);
            out.push(Equilibrium {
                name,
                theta: pole,
                energy,
                stable: upp > 0.0,
                isolated: upp < 0.0,
                theta_end: None,
            });
        }
    }
    let slope = |t: f64| shape.potential_prime(t);
    // The pieces of U between the poles and the kinks: where U′ vanishes all over one (α = 0
    // on a ball's sphere), every inclination there is a neutral equilibrium, one arc from
    // kink to kink (or pole), however short the piece.
    let mut ends = vec![0.0];
    ends.extend(shape.kinks().iter().copied());
    ends.push(PI);
    ends.sort_by(f64::total_cmp);
    let arcs: Vec<(f64, f64)> = ends
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|&(lo, hi)| {
            hi > lo
                && [0.25, 0.5, 0.75]
                    .iter()
                    .all(|f| slope(lo + f * (hi - lo)) == 0.0)
        })
        .collect();
    for &(lo, hi) in &arcs {
        out.push(Equilibrium {
            name: "neutral_arc",
            theta: lo,
            energy: shape.potential(lo),
            stable: false,
            isolated: false,
            theta_end: Some(hi),
        });
    }
    let on_arc = |t: f64| arcs.iter().any(|&(lo, hi)| (lo..=hi).contains(&t));
    let cells = 4096;
    let at = |i: usize| PI * i as f64 / cells as f64;
    for i in 1..cells - 1 {
        let (lo, hi) = (at(i), at(i + 1));
        if on_arc(lo) || on_arc(hi) {
            continue;
        }
        let (a, b) = (slope(lo), slope(hi));
        if a == 0.0 || a * b < 0.0 {
            let theta = if a == 0.0 {
                lo
            } else {
                bisect(&slope, lo, hi, a < 0.0)
            };
            out.push(Equilibrium {
                name: "inclined",
                theta,
                energy: shape.potential(theta),
                // U′ from − to +: a minimum.
                stable: a < 0.0 || (a == 0.0 && b > 0.0),
                // A branch of permanent rotations ends at κ = 0 on every inclined one.
                isolated: false,
                theta_end: None,
            });
        }
    }
    out.sort_by(|a, b| a.theta.total_cmp(&b.theta));
    out
}

impl CriticalSet {
    /// The critical set of any body: [`CriticalSet::of_until`] for the ellipsoid; for every
    /// other (docs/bodies.md) its curve of permanent rotations ([`general_fixed_point`])
    /// sampled as the ellipsoid's is, with the kinks of U sampled and listed, a change of
    /// stability located (at a kink too, where V″ jumps), the equator σ_π/2 of a symmetric
    /// body, and its equilibria ([`edged_equilibria`]). No branch ends at a face. ε_min is the
    /// top of U on [0, π]. The output names the shape and its parameters α and cut (if any).
    pub fn of_any(
        body: &AnyBody,
        samples: usize,
        kappa_max: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<Self> {
        let parameters = body.shape_parameters();
        let parameter = |name| parameters.iter().find(|p| p.0 == name).map(|p| p.1);
        let named = (
            body.shape_name(),
            parameter("alpha").expect("every shape has alpha"),
            parameter("cut"),
        );
        match body {
            AnyBody::Ellipsoid(b) => Self::of_until(b, samples, kappa_max, stop),
            AnyBody::Edged(b) => Self::of_shape(b, named, samples, kappa_max, stop),
            AnyBody::Profile(b) => Self::of_shape(b, named, samples, kappa_max, stop),
        }
    }

    /// [`CriticalSet::of_any`] of an edged body.
    pub fn of_edged(
        body: &Body<crate::body::EdgedShape>,
        samples: usize,
        kappa_max: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<Self> {
        Self::of_any(&AnyBody::Edged(*body), samples, kappa_max, stop)
    }

    /// [`CriticalSet::of_any`] for a shape other than the ellipsoid, named (shape, α, cut) in
    /// the output.
    fn of_shape<S: Shape>(
        body: &Body<S>,
        (name, alpha, cut): (&'static str, f64, Option<f64>),
        samples: usize,
        kappa_max: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<Self> {
        let stopped = |i: usize| asked_to_stop(i, stop);
        check_kappa_max(kappa_max)?;
        crate::error::check_samples(samples)?;
        let samples = samples.max(16);
        let faces = body.shape.faces();
        let kinks = body.shape.kinks().to_vec();
        let equilibria = edged_equilibria(body);
        // Beside the kinks, the inclined equilibria: the branch that rises from one (κ = 0)
        // is steep there, and the grid's nearest sample may lie far up it.
        let inclined = equilibria
            .iter()
            .filter(|e| e.name == "inclined")
            .map(|e| e.theta);
        let curve = Curve {
            body,
            kappa_sq: &|t| general_kappa_sq(body, t),
            point: &|t| general_fixed_point(body, t),
            pole_ends: &|pole| {
                let face = if pole == 0.0 { faces[0] } else { faces[1] };
                !face && body.shape.potential_second(pole) > 0.0
            },
            extra: kinks
                .iter()
                .copied()
                .filter(|&t| {
                    general_kappa_sq(body, t) >= 0.0
                        && general_fixed_point(body, t).kappa <= kappa_max
                })
                .chain(inclined)
                .collect(),
        };
        let (mut branches, changes) = sample_branches(&curve, samples, kappa_max, &stopped)?;
        // A change of stability at a kink is V″ jumping through 0, not a cusp.
        let cusps: Vec<Cusp> = changes
            .iter()
            .filter(|c| !at_kink(&kinks, c.theta))
            .copied()
            .collect();
        let kink_changes: Vec<Cusp> = changes
            .iter()
            .filter(|c| at_kink(&kinks, c.theta))
            .copied()
            .collect();
        let mut kappa_c_equator = None;
        let a = crate::body::Angle::EQUATOR;
        // At a kink, the side where U bends down the more decides the stability.
        let curvature = if at_kink(&kinks, FRAC_PI_2) {
            let step = 1e-9;
            body.shape
                .potential_second(FRAC_PI_2 - step)
                .min(body.shape.potential_second(FRAC_PI_2 + step))
        } else {
            body.shape.potential_second_at(a)
        };
        let slope = body.shape.potential_prime_at(a);
        if body.shape.symmetric_about_equator() || equator_held(slope, curvature) {
            kappa_c_equator = (curvature < 0.0).then(|| (-curvature).sqrt());
            branches.extend(equator_branches(
                body.shape.potential_at(a),
                curvature,
                kappa_c_equator,
                samples,
                kappa_max,
                &stopped,
            )?);
        }
        let energy_min = equilibria
            .iter()
            .map(|e| e.energy)
            .fold(f64::NEG_INFINITY, f64::max);
        Ok(Self {
            shape: Some(name),
            alpha,
            beta: None,
            cut,
            nu: body.nu,
            eta: body.eta,
            diagram_type: None,
            kinks,
            stability_changes_at_kinks: kink_changes,
            cusp: cusps.last().copied(),
            cusps,
            theta_star: None,
            energy_min,
            kappa_c_equator,
            equilibria,
            branches,
            kappa_max,
        })
    }
}

/// Err(Stopped) at every 65,536th sample `i` if `stop` says so.
fn asked_to_stop(i: usize, stop: &dyn Fn() -> bool) -> Result<()> {
    if i.is_multiple_of(65_536) && stop() {
        Err(AtlasError::Stopped)
    } else {
        Ok(())
    }
}

/// The smallest κ_max. By a pole κ² = sin³θ0 U′/cos θ0, and θ0 by θ = π is known to an ulp
/// of π, 4.4e-16: no branch there is drawn below κ ≈ 4e-32 by a smooth pole (κ ≈ x² √U″, x
/// from the pole) or 1e-24 by a face (κ ≈ x^{3/2} √|U′|); and by θ = 0 κ² underflows below
/// κ ≈ 1e-154. With a lower cut the stable branches vanished.
pub const MIN_KAPPA_MAX: f64 = 1e-20;

/// κ_max must be a finite number in [[`MIN_KAPPA_MAX`], κ's largest value].
fn check_kappa_max(kappa_max: f64) -> Result<()> {
    crate::error::check_range(
        "kappa-max",
        kappa_max,
        Some((MIN_KAPPA_MAX, true)),
        Some((crate::error::MAX_KAPPA, true)),
        "must be at most 1e150 (kappa's largest) and at least 1e-20 (below it the branches \
         by the poles are not resolved in doubles)",
    )
    .map(|_| ())
}
