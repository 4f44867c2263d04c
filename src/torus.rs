//! One level set (κ, ε) of the reduced system: its connected components (each an invariant
//! torus of the full system), their turning points, and the integrals over one θ-period:
//! the period T and the precession Δψ per period, hence ω_θ = 2π/T, ω_ψ = Δψ/T and the
//! rotation number N = −Δψ/2π (paper §5, `fourier`, `dpsi`; SPEC §2).
//!
//! The period integrals use θ = c + h sin u over a full turn of u (SPEC §2.3): the
//! inverse-square-root singularity at the turning points disappears, the integrand is smooth
//! and periodic, and the trapezoid rule converges exponentially. Nodes are doubled until two
//! successive sums agree to the requested tolerance; their difference is the error estimate.

use crate::body::{Body, Shape};
use crate::error::{AtlasError, Result};
use crate::reduced::ReducedSystem;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// How the θ-motion on a component looks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// θ oscillates between two turning points.
    Libration,
    /// ε equals a local minimum of V: θ stays at the fixed point (a permanent rotation).
    FixedPoint,
    /// κ = 0 and ε above the top of U: the body rolls over the top along a meridian.
    Rotation,
}

/// A connected component {θ : V(θ) ≤ ε} of the allowed set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// Lower turning point (for κ = 0 it may be negative: θ is continued on the circle).
    pub theta_min: f64,
    /// Upper turning point.
    pub theta_max: f64,
    /// Libration, fixed point or rotation.
    pub kind: MotionKind,
}

/// Critical points of V(θ) = κ²/(2 sin²θ) + U(θ) in (0, π) for κ ≠ 0, found as the roots of
/// the pole-free function sin³θ V′(θ) = −κ² cosθ + sin³θ U′(θ), sorted.
pub fn critical_points<S: Shape>(system: &ReducedSystem<'_, S>) -> Vec<f64> {
    let k2 = system.kappa * system.kappa;
    let g = |t: f64| {
        let (s, c) = t.sin_cos();
        -k2 * c + s * s * s * system.body.shape.potential_prime(t)
    };
    roots_by_scan(g, 0.0, PI, 2048)
        .into_iter()
        .filter(|&t| t > 0.0 && t < PI)
        .collect()
}

/// Critical points of U on the circle [0, 2π): θ = 0, π, and the roots of U′ inside.
pub fn potential_critical_points_on_circle<S: Shape>(body: &Body<S>) -> Vec<f64> {
    let inner: Vec<f64> = roots_by_scan(|t| body.shape.potential_prime(t), 0.0, PI, 2048)
        .into_iter()
        .filter(|&t| t > 1e-12 && t < PI - 1e-12)
        .collect();
    let mut pts = vec![0.0, PI];
    for &t in &inner {
        pts.push(t);
        pts.push(TAU - t);
    }
    pts.sort_by(f64::total_cmp);
    pts
}

/// All roots of a continuous `f` on [a, b] where it changes sign between `n` scan cells, each
/// refined by bisection to the last bit; exact zeros at scan nodes are kept.
pub fn roots_by_scan(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> Vec<f64> {
    let mut roots = Vec::new();
    let x = |i: usize| a + (b - a) * i as f64 / n as f64;
    let mut f_prev = f(a);
    if f_prev == 0.0 {
        roots.push(a);
    }
    for i in 1..=n {
        let (lo, hi) = (x(i - 1), x(i));
        let f_hi = f(hi);
        if f_hi == 0.0 {
            roots.push(hi);
        } else if f_prev != 0.0 && (f_prev < 0.0) != (f_hi < 0.0) {
            roots.push(bisect(&f, lo, hi, f_prev < 0.0));
        }
        f_prev = f_hi;
    }
    roots
}

/// Bisection to the last representable bit on [lo, hi], where `f(lo) < 0` iff `lo_negative`.
pub fn bisect(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, lo_negative: bool) -> f64 {
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm < 0.0) == lo_negative {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

/// The components of {V ≤ ε}, sorted by θ_min. For κ ≠ 0 they lie in (0, π); for κ = 0 the
/// motion lives on the circle and a component may straddle θ = 0 (then θ_min < 0) or be the
/// whole circle (rolling over the top, [`MotionKind::Rotation`]).
pub fn components<S: Shape>(body: &Body<S>, kappa: f64, energy: f64) -> Result<Vec<Component>> {
    let system = ReducedSystem::new(body, kappa);
    let v = |t: f64| system.effective_potential(t);
    let (nodes, values) = if kappa != 0.0 {
        let mut nodes = vec![0.0];
        nodes.extend(critical_points(&system));
        nodes.push(PI);
        let values: Vec<f64> = nodes
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                if i == 0 || i == nodes.len() - 1 {
                    f64::INFINITY
                } else {
                    v(t)
                }
            })
            .collect();
        (nodes, values)
    } else {
        // Start the circle at the global maximum of U.
        let crit = potential_critical_points_on_circle(body);
        let (i_max, &t_max) = crit
            .iter()
            .enumerate()
            .max_by(|a, b| v(*a.1).total_cmp(&v(*b.1)))
            .expect("θ = 0 and π are always critical");
        if energy > v(t_max) {
            return Ok(vec![Component {
                theta_min: t_max - PI,
                theta_max: t_max + PI,
                kind: MotionKind::Rotation,
            }]);
        }
        let mut nodes: Vec<f64> = crit[i_max..].to_vec();
        nodes.extend(crit[..i_max].iter().map(|t| t + TAU));
        nodes.push(t_max + TAU);
        // Keep the lifted angles near [−π, π] so that components around the top straddle 0.
        let shift = if t_max > PI - 1e-9 { -TAU } else { 0.0 };
        let nodes: Vec<f64> = nodes.iter().map(|t| t + shift).collect();
        let values = nodes.iter().map(|&t| v(t)).collect();
        (nodes, values)
    };

    let minimum = values.iter().copied().fold(f64::INFINITY, f64::min);
    if energy < minimum {
        return Err(AtlasError::NoMotion { energy, minimum });
    }
    let inside = |i: usize| values[i] <= energy;
    let mut comps = Vec::new();
    let mut start: Option<f64> = if inside(0) { Some(nodes[0]) } else { None };
    for i in 0..nodes.len() - 1 {
        if inside(i) == inside(i + 1) {
            continue;
        }
        // V is monotone between consecutive critical points: one crossing, found by bisection
        // on V − ε with the sign known at the ends (V = +∞ at the poles for κ ≠ 0).
        let f = |t: f64| v(t) - energy;
        let crossing = bisect(&f, nodes[i], nodes[i + 1], inside(i));
        if inside(i) {
            let lo = start.take().unwrap_or(nodes[i]);
            comps.push((lo, crossing));
        } else {
            start = Some(crossing);
        }
    }
    Ok(comps
        .into_iter()
        .map(|(lo, hi)| Component {
            theta_min: lo,
            theta_max: hi,
            kind: if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1.0) {
                MotionKind::FixedPoint
            } else {
                MotionKind::Libration
            },
        })
        .collect())
}

/// Integrals over one θ-period of a component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodIntegrals {
    /// T = 2 ∫ √(B / (2(ε − V))) dθ over [θ_min, θ_max] (for a rotation: ∫ over the circle).
    pub period: f64,
    /// Δψ = ∫ ψ̇ dt over one period.
    pub psi_advance: f64,
    /// Estimated absolute error of T.
    pub period_error: f64,
    /// Estimated absolute error of Δψ.
    pub psi_advance_error: f64,
    /// Trapezoid nodes used on the last level.
    pub nodes: usize,
    /// Whether both integrals reached the tolerance.
    pub converged: bool,
}

impl PeriodIntegrals {
    /// ω_θ = 2π / T.
    pub fn omega_theta(&self) -> f64 {
        TAU / self.period
    }
    /// ω_ψ = Δψ / T, the mean precession rate.
    pub fn omega_psi(&self) -> f64 {
        self.psi_advance / self.period
    }
    /// N = −ω_ψ / ω_θ = −Δψ / 2π.
    pub fn rotation_number(&self) -> f64 {
        -self.psi_advance / TAU
    }
}

/// T and Δψ of a component by the trapezoid rule in u (θ = c + h sin u for a libration, θ
/// itself for a rotation), doubling the nodes until successive values of T (relative) and of
/// N = −Δψ/2π (absolute) agree within `tol`.
pub fn period_integrals<S: Shape>(
    body: &Body<S>,
    kappa: f64,
    energy: f64,
    component: &Component,
    tol: f64,
) -> Result<PeriodIntegrals> {
    let system = ReducedSystem::new(body, kappa);
    let with_psi = kappa != 0.0;
    // dt/du and ψ̇ dt/du at one node; the turning points (u = ±π/2) take their limits
    // h |cos u| / √(2(ε − V)) → √(h / |V′(θ_turn)|).
    let (c, h) = (
        0.5 * (component.theta_min + component.theta_max),
        0.5 * (component.theta_max - component.theta_min),
    );
    let libration = component.kind == MotionKind::Libration;
    if component.kind == MotionKind::FixedPoint {
        return Err(AtlasError::NotPeriodic {
            reason: "the component is a fixed point",
        });
    }
    let eval = |u: f64| -> Result<(f64, f64)> {
        let (theta, jac) = if libration {
            let (su, cu) = u.sin_cos();
            (c + h * su, h * cu.abs())
        } else {
            (component.theta_min + u, 1.0)
        };
        let b = body.reduced_inertia(theta);
        let gap = energy - system.effective_potential(theta);
        let dt = if libration && (u - FRAC_PI_2).abs() < 1e-15 {
            (b * h / system.effective_potential_prime(component.theta_max).abs()).sqrt()
        } else if libration && (u + FRAC_PI_2).abs() < 1e-15 {
            (b * h / system.effective_potential_prime(component.theta_min).abs()).sqrt()
        } else if gap > 0.0 {
            jac * (b / (2.0 * gap)).sqrt()
        } else {
            return Err(AtlasError::NotPeriodic {
                reason: "a quadrature node fell outside the allowed set (ε ≤ V)",
            });
        };
        let psi = if with_psi {
            system.psi_rate(theta)
        } else {
            0.0
        };
        Ok((dt, psi * dt))
    };
    let u0 = if libration { -FRAC_PI_2 } else { 0.0 };
    let mut n = 8usize;
    let mut sum_t = 0.0;
    let mut sum_psi = 0.0;
    for j in 0..n {
        let (a, b) = eval(u0 + TAU * j as f64 / n as f64)?;
        sum_t += a;
        sum_psi += b;
    }
    let mut t_prev = sum_t * TAU / n as f64;
    let mut psi_prev = sum_psi * TAU / n as f64;
    const MAX_NODES: usize = 1 << 20;
    loop {
        // Doubling: the new nodes are the midpoints of the old ones.
        for j in 0..n {
            let (a, b) = eval(u0 + TAU * (j as f64 + 0.5) / n as f64)?;
            sum_t += a;
            sum_psi += b;
        }
        n *= 2;
        let t = sum_t * TAU / n as f64;
        let psi = sum_psi * TAU / n as f64;
        let (dt, dpsi) = ((t - t_prev).abs(), (psi - psi_prev).abs());
        let converged = dt <= tol * t && dpsi / TAU <= tol;
        if converged || n >= MAX_NODES {
            return Ok(PeriodIntegrals {
                period: t,
                psi_advance: psi,
                period_error: dt,
                psi_advance_error: dpsi,
                nodes: n,
                converged,
            });
        }
        t_prev = t;
        psi_prev = psi;
    }
}
