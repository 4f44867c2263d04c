//! One cell (α, β, ν, η, κ, ε) of the atlas (SPEC §2): for every component of the allowed
//! set, ω_θ, ω_ψ, the rotation number N, the drift |Δζ| and radius R, whether the motion
//! stays bounded, a status and error estimates — by quadrature ([`crate::torus`]) or, as an
//! independent check, by integrating one period of the reduced system ([`crate::period_ode`]).

use crate::body::{Body, Shape};
use crate::error::{AtlasError, Result};
use crate::period_ode;
use crate::torus::{
    Component, CriticalKind, CriticalPoint, EffectivePotential, MotionKind, PeriodIntegrals,
};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// How the period integrals are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Tanh-sinh quadrature between the turning points (fast; the default).
    Quadrature,
    /// DOP853 over one θ-period with event location (slow; the independent check).
    Ode,
}

/// What to compute and how accurately.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellOptions {
    /// Requested accuracy: relative for T and ω_θ; absolute for N; for Δζ relative to the
    /// length of the path over the period (|Δζ| itself may be near 0).
    pub tol: f64,
    /// Quadrature or ODE.
    pub method: Method,
    /// Whether to compute Δζ (and with it R and the bounded flag).
    pub drift: bool,
    /// |N − round(N)| below this (or below N's error estimate) counts as a resonance.
    pub resonance_tol: f64,
}

impl Default for CellOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            method: Method::Quadrature,
            drift: true,
            resonance_tol: 1e-9,
        }
    }
}

impl CellOptions {
    /// Checks the options: 1e-15 ≤ tol ≤ 0.1, resonance_tol ≥ 0.
    pub fn validate(&self) -> Result<()> {
        crate::error::check_range(
            "tol",
            self.tol,
            Some((1e-15, true)),
            Some((0.1, true)),
            "must satisfy 1e-15 <= tol <= 0.1",
        )?;
        crate::error::check_range(
            "resonance_tol",
            self.resonance_tol,
            Some((0.0, true)),
            Some((0.5, true)),
            "must satisfy 0 <= resonance_tol <= 0.5",
        )
        .map(|_| ())
    }
}

/// How a computed value is to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every value is within the requested tolerance.
    Ok,
    /// ε is below the minimum of V: no motion (a cell-level status; no components).
    NoMotion,
    /// ε equals a local minimum of V: a permanent rotation; values are the linearised limits.
    FixedPoint,
    /// ε equals a local maximum of V: T = ∞, ω_θ = 0, N = ±∞; drift undefined.
    Separatrix,
    /// The error estimate exceeds the tolerance (too close to a separatrix or a fixed point
    /// for double precision, or the node limit was reached); the values are still the best
    /// available and the error estimate says how good.
    ToleranceNotReached,
    /// ε = ∞ (s = 0 of a compactified plane): θ_min, θ_max and N are the high-energy limit
    /// (N∞(λ), [`crate::limits`]); T = 0 and ω_θ = ∞ there, ω_ψ = −N ω_θ; the drift is not
    /// computed.
    HighEnergyLimit,
}

/// Estimated absolute errors of the values of one component.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorEstimates {
    pub period: f64,
    pub omega_theta: f64,
    pub omega_psi: f64,
    pub rotation_number: f64,
    pub drift: f64,
    pub drift_radius: f64,
}

/// The values of one component (one invariant torus).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentResult {
    /// Lower turning point (for κ = 0 possibly negative: θ continued on the circle).
    pub theta_min: f64,
    /// Upper turning point.
    pub theta_max: f64,
    /// T, the period of θ.
    pub period: f64,
    /// ω_θ = 2π / T.
    pub omega_theta: f64,
    /// ω_ψ = Δψ / T, the mean precession rate.
    pub omega_psi: f64,
    /// N = −ω_ψ / ω_θ = −Δψ / 2π.
    pub rotation_number: f64,
    /// |Δζ|: displacement of the centre of mass over one θ-period from θ_min (NaN if not asked).
    pub drift: f64,
    /// R = |Δζ| / (2 |sin πN|): radius of the circle of the stroboscopic points.
    pub drift_radius: f64,
    /// Whether the path on the plane stays bounded (None if the drift was not computed).
    pub bounded: Option<bool>,
    /// Libration, fixed point or rotation (rolling over the top at κ = 0).
    pub motion: MotionKind,
    /// How to read the values.
    pub status: Status,
    /// Estimated absolute error of the rotation number N (the headline value).
    pub error_estimate: f64,
    /// Estimated absolute errors of every value.
    pub errors: ErrorEstimates,
    /// Δζ as (Δx_c, Δy_c), in the frame where ψ = 0 at θ_min.
    pub drift_vector: [f64; 2],
    /// Integrand evaluations (quadrature) or accepted steps (ODE) spent.
    pub work: usize,
}

/// All components of one cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellResult {
    /// κ.
    pub kappa: f64,
    /// ε.
    pub energy: f64,
    /// `ok` when there is motion, `no_motion` when ε is below the minimum of V.
    pub status: Status,
    /// The components, sorted by θ_min.
    pub components: Vec<ComponentResult>,
}

/// The cell at ε = ∞ with λ = κ/√ε fixed: the torus sinθ ≥ λ/√2 of the limit system
/// B θ′²/2 + λ²/(2 sin²θ) = 1 (`eqsys` without U), with N = N∞(λ) and its error. No motion
/// for λ > √2; a fixed point at θ = π/2 (N = 0) for λ = √2.
pub fn solve_high_energy_limit<S: Shape>(
    body: &Body<S>,
    lambda: f64,
    options: &CellOptions,
) -> Result<CellResult> {
    crate::error::check_range("lambda", lambda, Some((0.0, true)), None, "must be >= 0")?;
    options.validate()?;
    let at_infinity = |components| CellResult {
        kappa: f64::INFINITY,
        energy: f64::INFINITY,
        status: Status::Ok,
        components,
    };
    if lambda > std::f64::consts::SQRT_2 {
        return Ok(CellResult {
            status: Status::NoMotion,
            ..at_infinity(Vec::new())
        });
    }
    let n = crate::limits::high_energy_rotation_number(body, lambda, options.tol)?;
    let theta_min = (lambda / std::f64::consts::SQRT_2).asin();
    // λ = 0 is κ = 0: rolling over the top along a meridian, as at every finite ε above
    // ε_min (N = 0 there).
    let over_the_top = lambda == 0.0;
    let fixed = theta_min == std::f64::consts::FRAC_PI_2;
    let omega_psi = if n.value == 0.0 {
        0.0
    } else {
        -n.value.signum() * f64::INFINITY
    };
    Ok(at_infinity(vec![ComponentResult {
        theta_min,
        theta_max: if over_the_top {
            theta_min + TAU
        } else {
            PI - theta_min
        },
        period: 0.0,
        omega_theta: f64::INFINITY,
        omega_psi,
        rotation_number: n.value,
        drift: f64::NAN,
        drift_radius: f64::NAN,
        bounded: None,
        motion: if over_the_top {
            MotionKind::Rotation
        } else if fixed {
            MotionKind::FixedPoint
        } else {
            MotionKind::Libration
        },
        status: Status::HighEnergyLimit,
        error_estimate: n.error,
        errors: ErrorEstimates {
            period: 0.0,
            omega_theta: 0.0,
            omega_psi: 0.0,
            rotation_number: n.error,
            drift: f64::NAN,
            drift_radius: f64::NAN,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    }]))
}

/// One cell, found from scratch (for many cells at one (body, κ), build the
/// [`EffectivePotential`] once and call [`solve_level`]).
pub fn solve_cell<S: Shape>(
    body: &Body<S>,
    kappa: f64,
    energy: f64,
    options: &CellOptions,
) -> Result<CellResult> {
    crate::error::check_range("kappa", kappa, None, None, "must be finite")?;
    crate::error::check_range("energy", energy, None, None, "must be finite")?;
    options.validate()?;
    solve_level(&EffectivePotential::new(body, kappa), energy, options)
}

/// One cell at the energy `energy`, reusing the critical points of `potential`.
pub fn solve_level<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    options: &CellOptions,
) -> Result<CellResult> {
    let components = match potential.components(energy) {
        Ok(c) => c,
        Err(AtlasError::NoMotion { .. }) => {
            return Ok(CellResult {
                kappa: potential.kappa,
                energy,
                status: Status::NoMotion,
                components: Vec::new(),
            })
        }
        Err(e) => return Err(e),
    };
    let components = components
        .iter()
        .map(|c| solve_component(potential, energy, c, options))
        .collect::<Result<Vec<_>>>()?;
    Ok(CellResult {
        kappa: potential.kappa,
        energy,
        status: Status::Ok,
        components,
    })
}

/// The values of one component.
pub fn solve_component<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    options: &CellOptions,
) -> Result<ComponentResult> {
    if component.kind == MotionKind::FixedPoint {
        return Ok(fixed_point(potential, component, options));
    }
    if let Some(saddle) = separatrix(component, energy) {
        return Ok(on_separatrix(potential, component, &saddle, options));
    }
    let tol = options.tol;
    let raw = match options.method {
        Method::Quadrature => potential.integrate(energy, component, tol, options.drift)?,
        Method::Ode => period_ode::integrate(potential, energy, component, tol, options.drift)?,
    };
    Ok(finish(component, raw, options))
}

fn finish(component: &Component, raw: PeriodIntegrals, options: &CellOptions) -> ComponentResult {
    let t = raw.period;
    let omega_theta = TAU / t;
    let omega_psi = raw.psi_advance / t;
    let n = -raw.psi_advance / TAU;
    let rel_t = raw.period_error / t;
    let n_err = raw.psi_advance_error / TAU;
    let (drift, drift_error, drift_vector) = match raw.drift {
        Some(d) => (d.value[0].hypot(d.value[1]), d.error, d.value),
        None => (f64::NAN, f64::NAN, [f64::NAN; 2]),
    };
    let rotating = component.kind == MotionKind::Rotation;
    let (drift_radius, radius_error) = drift_radius(drift, drift_error, n, n_err);
    let bounded = raw.drift.map(|d| {
        if rotating {
            return false;
        }
        let off = (n - n.round()).abs();
        let resonant = off <= options.resonance_tol.max(n_err);
        let moving = drift > d.error.max(64.0 * f64::EPSILON * d.scale);
        !(resonant && moving)
    });
    let errors = ErrorEstimates {
        period: raw.period_error,
        omega_theta: omega_theta * rel_t,
        omega_psi: omega_psi.abs() * rel_t + raw.psi_advance_error / t,
        rotation_number: n_err,
        drift: drift_error,
        drift_radius: radius_error,
    };
    let drift_ok = raw
        .drift
        .is_none_or(|d| d.error <= options.tol * d.scale.max(f64::MIN_POSITIVE));
    let ok = raw.converged && rel_t <= options.tol && n_err <= options.tol && drift_ok;
    ComponentResult {
        theta_min: component.theta_min(),
        theta_max: component.theta_max(),
        period: t,
        omega_theta,
        omega_psi,
        rotation_number: n,
        drift,
        drift_radius,
        bounded,
        motion: component.kind,
        status: if ok {
            Status::Ok
        } else {
            Status::ToleranceNotReached
        },
        error_estimate: n_err,
        errors,
        drift_vector,
        work: raw.work,
    }
}

/// R = |Δζ| / (2 |sin πN|) and its error; R = 0 when Δζ = 0 exactly (κ = 0 librations).
fn drift_radius(drift: f64, drift_error: f64, n: f64, n_error: f64) -> (f64, f64) {
    if drift.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    if drift == 0.0 {
        return (
            0.0,
            drift_error / (2.0 * (PI * n).sin().abs()).max(f64::MIN_POSITIVE),
        );
    }
    let s = (PI * n).sin().abs();
    let r = drift / (2.0 * s);
    let rel = drift_error / drift + PI * n_error * (PI * n).cos().abs() / s;
    (r, r * rel)
}

/// A maximum inside the component or at one of its ends whose level is ε to rounding.
fn separatrix(component: &Component, energy: f64) -> Option<CriticalPoint> {
    component
        .interior
        .iter()
        .chain(component.neighbours.iter().flatten())
        .find(|p| {
            p.kind != CriticalKind::Minimum
                && (energy - p.value).abs() <= 4.0 * f64::EPSILON * p.value.abs().max(1.0)
        })
        .copied()
}

fn on_separatrix<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    component: &Component,
    saddle: &CriticalPoint,
    options: &CellOptions,
) -> ComponentResult {
    // Time piles up at the saddle: ω_θ → 0, ω_ψ → ψ̇(θ_s), N → ±∞.
    let omega_psi = potential.psi_rate(saddle.site.angle());
    let n = if omega_psi == 0.0 {
        0.0
    } else {
        -omega_psi.signum() * f64::INFINITY
    };
    ComponentResult {
        theta_min: component.theta_min(),
        theta_max: component.theta_max(),
        period: f64::INFINITY,
        omega_theta: 0.0,
        omega_psi,
        rotation_number: n,
        drift: f64::NAN,
        drift_radius: f64::NAN,
        // The motion tends to the unstable permanent rotation (a circle) or equilibrium.
        bounded: options.drift.then_some(true),
        motion: component.kind,
        status: Status::Separatrix,
        error_estimate: 0.0,
        errors: ErrorEstimates {
            period: 0.0,
            omega_theta: 0.0,
            omega_psi: 4.0 * f64::EPSILON * omega_psi.abs(),
            rotation_number: 0.0,
            drift: f64::NAN,
            drift_radius: f64::NAN,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    }
}

/// The linearised limits at a fixed point θ0: ω_θ = √(V″/B), ψ̇(θ0), N = −ψ̇/ω_θ; the centre
/// of mass runs round its circle of radius ρ_c = U tanθ0 (SPEC §1.5), so R = ρ_c and
/// |Δζ| = 2 ρ_c |sin(Δψ/2)|.
fn fixed_point<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    component: &Component,
    options: &CellOptions,
) -> ComponentResult {
    let m = component
        .minimum()
        .copied()
        .expect("a fixed point has its minimum");
    let a = m.site.angle();
    let red = potential.body.reduction_at(a);
    let omega_theta = (m.curvature / red.reduced_inertia).sqrt();
    let psi_rate = potential.psi_rate(a);
    let period = TAU / omega_theta;
    let psi_advance = psi_rate * period;
    let n = -psi_advance / TAU;
    let (drift, radius) = if potential.kappa == 0.0 {
        (0.0, 0.0)
    } else if psi_rate == 0.0 {
        // α = 0 on the equator: straight-line rolling at speed U κ / J.
        (
            red.potential * (potential.kappa / red.integral_factor).abs() * period,
            f64::INFINITY,
        )
    } else {
        let rho = red.potential * (a.sin / a.cos).abs();
        (2.0 * rho * (0.5 * psi_advance).sin().abs(), rho)
    };
    let rel = 16.0 * f64::EPSILON;
    ComponentResult {
        theta_min: component.theta_min(),
        theta_max: component.theta_max(),
        period,
        omega_theta,
        omega_psi: psi_rate,
        rotation_number: n,
        drift: if options.drift { drift } else { f64::NAN },
        drift_radius: if options.drift { radius } else { f64::NAN },
        // A permanent rotation runs round a circle: bounded unless the circle is a line.
        bounded: options.drift.then_some(radius.is_finite()),
        motion: MotionKind::FixedPoint,
        status: Status::FixedPoint,
        error_estimate: rel * n.abs(),
        errors: ErrorEstimates {
            period: rel * period,
            omega_theta: rel * omega_theta,
            omega_psi: rel * psi_rate.abs(),
            rotation_number: rel * n.abs(),
            drift: rel * drift,
            drift_radius: rel * radius,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    }
}
