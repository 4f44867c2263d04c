//! One cell (α, β, ν, η, κ, ε) of the atlas (docs/model.md): for every component of the allowed
//! set, ω_θ, ω_ψ, the rotation number N, the drift |Δζ| and radius R, whether the motion
//! stays bounded, a status and error estimates — by quadrature ([`crate::torus`]) or, as an
//! independent check, by integrating one period of the reduced system ([`crate::period_ode`]).

use crate::body::{Angle, Body, Shape};
use crate::dd::DoubleDouble;
use crate::error::{AtlasError, Result};
use crate::family::Family;
use crate::limits::Estimate;
use crate::period_ode;
use crate::torus::{
    Component, CriticalKind, CriticalPoint, EffectivePotential, MotionKind, PeriodIntegrals,
    SaddleTerms, Site,
};
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

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

    /// Checks the options against the body: the ODE method's error estimate (the difference
    /// of two runs) assumes a smooth right-hand side, which a kink of U (an edged body) breaks
    /// (measured: 8× below the true error at tol 1e-6 on a truncated ball), so it is refused
    /// there.
    pub fn check_for<S: Shape>(&self, body: &Body<S>) -> Result<()> {
        if self.method == Method::Ode && !body.shape.kinks().is_empty() {
            return Err(AtlasError::Unsupported {
                what: "method ode",
                reason: "its error estimate needs a smooth body, and this one has edges \
                         where the contact changes part; use the quadrature",
            });
        }
        // A needle or a flat lentil (β or 1/β below 1e-5) is smooth, but U turns on that
        // scale, nearly a kink: at β = 1e-20 its N was 3e7 times beyond its estimate, and
        // at β = 1e-6 still 1.7–8.7 times (an adversary pass; 0.15 at 3e-6).
        if self.method == Method::Ode && body.shape.angular_feature_scale() < 1e-5 {
            return Err(AtlasError::Unsupported {
                what: "method ode",
                reason: "its error estimate needs U smooth on the integrator's steps, and this \
                         body's U turns within less than 1e-5 rad (beta or 1/beta below 1e-5); \
                         use the quadrature",
            });
        }
        Ok(())
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
    /// κ = 0 and the component reaches a pole where the body has a flat face
    /// ([`crate::body::Shape::faces`]): the body lands on the face and the motion ends there;
    /// no periodic values (NaN).
    ReachesFace,
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
    /// Of each part of `drift_vector`: the drift's error plus the turn of the path by ψ's
    /// error (the path's size times the ψ advance's error; far out on ε, where the limit's N
    /// replaced the quadrature's, also times how far the quadrature's advance is off).
    pub drift_vector: f64,
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
    /// The family of tori the component belongs to (by the wells of V it encloses).
    pub family: Family,
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
    // λ = 0 is κ = 0: rolling over the top along a meridian, as at every finite ε above
    // ε_min (N = 0 there); a body with a face reaches it and stops, as at finite ε.
    let over_the_top = lambda == 0.0;
    let onto_a_face = over_the_top && body.shape.faces() != [false, false];
    let n = if onto_a_face {
        crate::limits::Estimate {
            value: f64::NAN,
            error: f64::NAN,
        }
    } else {
        crate::limits::high_energy_rotation_number(body, lambda, options.tol)?
    };
    let theta_min = (lambda / std::f64::consts::SQRT_2).asin();
    let fixed = theta_min == std::f64::consts::FRAC_PI_2;
    let omega_psi = if n.value == 0.0 {
        0.0
    } else if n.value.is_nan() {
        f64::NAN
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
        period: if onto_a_face { f64::NAN } else { 0.0 },
        omega_theta: if onto_a_face { f64::NAN } else { f64::INFINITY },
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
        family: high_energy_families(body, lambda)[0],
        status: if onto_a_face {
            Status::ReachesFace
        } else if n.error <= options.tol {
            Status::HighEnergyLimit
        } else {
            Status::ToleranceNotReached
        },
        error_estimate: n.error,
        errors: ErrorEstimates {
            period: 0.0,
            omega_theta: 0.0,
            omega_psi: 0.0,
            rotation_number: n.error,
            drift: f64::NAN,
            drift_radius: f64::NAN,
            drift_vector: f64::NAN,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    }]))
}

/// The families of the cell at ε = ∞ with λ = κ/√ε fixed (see [`solve_high_energy_limit`]):
/// none beyond λ = √2, rolling over the top at λ = 0 (κ = 0), else the single well of V at
/// κ → ∞ ([`crate::limits::high_energy_family`]).
pub fn high_energy_families<S: Shape>(body: &Body<S>, lambda: f64) -> Vec<Family> {
    if !(0.0..=std::f64::consts::SQRT_2).contains(&lambda) {
        Vec::new()
    } else if lambda == 0.0 {
        vec![Family::OverTheTop]
    } else {
        vec![crate::limits::high_energy_family(body)]
    }
}

/// One cell, found from scratch (for many cells at one (body, κ), build the
/// [`EffectivePotential`] once and call [`solve_level`]).
pub fn solve_cell<S: Shape>(
    body: &Body<S>,
    kappa: f64,
    energy: f64,
    options: &CellOptions,
) -> Result<CellResult> {
    crate::error::check_kappa(kappa)?;
    crate::error::check_energy(energy)?;
    options.validate()?;
    options.check_for(body)?;
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
    // (Before the fixed points: a body at rest on its face is on the face, not at the
    // bottom of a smooth well.)
    if reaches_face(potential, component) {
        return Ok(ComponentResult {
            status: Status::ReachesFace,
            error_estimate: f64::NAN,
            ..unresolved(component)
        });
    }
    if component.kind == MotionKind::FixedPoint {
        let result = fixed_point(potential, component, options);
        // Linearised limits that overflowed or lost every digit (extreme η, β, κ) are no
        // values: say so rather than carry inf or NaN into N and the bounded flag.
        let defined = result.rotation_number.is_finite()
            && result.period.is_finite()
            && result.error_estimate.is_finite();
        return Ok(if defined {
            result
        } else {
            unresolved(component)
        });
    }
    if let Some(saddle) = separatrix(component, energy) {
        return Ok(on_separatrix(potential, component, &saddle, options));
    }
    let mut raw = match integrate(potential, energy, component, options) {
        Ok(raw) => raw,
        // DOP853 can give up in a stiff corner (step size underflow near a pole at large β
        // and η): the component is marked, not the whole cell refused.
        Err(AtlasError::Integration { .. }) if options.method == Method::Ode => {
            return Ok(unresolved(component));
        }
        // Where ε − V rounds to ≤ 0 at a node inside the turning points (κ and ε so large
        // that their difference has no digit left there), the integrals have no value: the
        // component says so (and far out on ε, N is still the high-energy limit's).
        Err(AtlasError::NotPeriodic { .. }) => {
            let limit = far_out(potential, energy, component, options, f64::NAN, 0.0);
            return Ok(unresolved_but(component, limit));
        }
        Err(e) => return Err(e),
    };
    let offset = level_offset_error(potential, energy, component, &mut raw, options);
    raw.period_error += offset.period;
    raw.psi_advance_error += offset.psi_advance;
    if let Some(d) = raw.drift.as_mut() {
        d.error += offset.drift;
    }
    let limit = far_out(
        potential,
        energy,
        component,
        options,
        -raw.psi_advance / TAU,
        raw.psi_advance_error / TAU,
    );
    Ok(finish(component, raw, limit, options))
}

/// The values of the component that holds a start (`component`, at the start's `energy`):
/// those of [`solve_component`], except that a start at rest on an unstable equilibrium is
/// that equilibrium, on its separatrix (T = ∞, `bounded`), even where the level's other
/// motions land on a face (the upright disk at rest) and so have no values; and a start
/// whose level is lost in rounding has no values and no turning points (NaN), status `tolerance_not_reached`
/// ([`crate::trajectory::Start::is_resolved_by`]).
pub fn solve_start<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    start: &crate::trajectory::Start,
    energy: f64,
    component: &Component,
    options: &CellOptions,
) -> Result<ComponentResult> {
    if !start.is_resolved_by(potential, component) {
        // The level set of the doubles is not the start's: no values, and no turning points.
        let mut result = unresolved(component);
        result.theta_min = f64::NAN;
        result.theta_max = f64::NAN;
        return Ok(result);
    }
    match start.rest_on_saddle(potential, component, energy) {
        Some(saddle) if reaches_face(potential, component) => {
            Ok(on_separatrix(potential, component, &saddle, options))
        }
        _ => solve_component(potential, energy, component, options),
    }
}

/// Whether a κ = 0 component reaches a pole at which the body has a flat face: a pole
/// θ = 2πm (face 0) or π + 2πm (face π) of the lifted circle within [θ_min, θ_max].
pub(crate) fn reaches_face<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    component: &Component,
) -> bool {
    let faces = potential.body.shape.faces();
    if potential.kappa != 0.0 || faces == [false, false] {
        return false;
    }
    let (lo, hi) = (component.theta_min(), component.theta_max());
    let first = (lo / PI).ceil() as i64;
    let last = (hi / PI).floor() as i64;
    (first..=last).any(|k| faces[k.rem_euclid(2) as usize])
}

/// ε above this many times Ū² (Ū the scale of U) is "far out": N(κ, ε) is the high-energy
/// limit N∞(κ/√ε) up to O(Ū/ε), far below double precision, while the quadrature's ψ
/// advance, built from two near-π jumps at turning points within λ/√2 of the poles, loses
/// its digits (at κ = 0.8, ε = 1e50: N = 9e-8 ± 7e-8 against the true −5e-26).
const FAR_OUT: f64 = 1e24;

/// Far out on ε ([`FAR_OUT`]), N of a libration is checked against the high-energy limit
/// N∞(λ), λ = |κ|/√ε, an integral computed apart (`limits`, docs/hypothesis.md). Its bound is
/// the limit's quadrature error plus 1e3·Ū·λ/ε for the O(Ū/ε) it leaves out. Returns the
/// limit (signed as κ, with that bound) where it should replace the quadrature's `n` ± `n_error`:
/// where that has no value, lies beyond both bounds from the limit, or misses the tolerance
/// the limit meets.
fn far_out<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    options: &CellOptions,
    n: f64,
    n_error: f64,
) -> Option<Estimate> {
    let kappa = potential.kappa;
    // Ū ≥ 1: ordinary cells leave here before U is evaluated (this runs for every libration).
    if kappa == 0.0
        || component.kind != MotionKind::Libration
        || energy.is_nan()
        || energy < FAR_OUT
    {
        return None;
    }
    let shape = &potential.body.shape;
    let scale = 1.0 + crate::limits::potential_scale(shape);
    if energy < FAR_OUT * scale * scale {
        return None;
    }
    let lambda = kappa.abs() / energy.sqrt();
    let limit = crate::limits::high_energy_rotation_number(potential.body, lambda, options.tol)
        .ok()
        .filter(|l| l.value.is_finite() && l.error.is_finite())?;
    let value = kappa.signum() * limit.value;
    let bound = limit.error + 1e3 * scale * lambda / energy + 2.0 * f64::EPSILON * value.abs();
    let replace = !(n.is_finite() && n_error.is_finite())
        || (n - value).abs() > n_error + bound
        || (n_error > options.tol && bound <= options.tol);
    replace.then_some(Estimate {
        value,
        error: bound,
    })
}

/// T, Δψ and Δζ of a libration or rotation by the chosen method.
fn integrate<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    options: &CellOptions,
) -> Result<PeriodIntegrals> {
    let tol = options.tol;
    match options.method {
        Method::Quadrature => potential.integrate(energy, component, tol, options.drift),
        Method::Ode => period_ode::integrate(potential, energy, component, tol, options.drift),
    }
}

/// Replaces the saddle terms a libration's integrals carry at the a-priori error of the
/// energy ([`PeriodIntegrals::saddle`]) by the same terms at `delta`, its level offset
/// computed sharply (`level_offset_error`): near a saddle that offset is the energy error
/// the log-divergent dT/dε multiplies (the rounding of the gap at the nodes has its own
/// term). Only ever lowers them.
fn sharpen_saddle_terms<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    raw: &mut PeriodIntegrals,
    delta: f64,
) {
    let before = raw.saddle;
    if before.period == 0.0 && before.psi_advance == 0.0 {
        return;
    }
    // Twice the leading term 1/(λ |ε − V_s|) per passage: with the offset computed exactly
    // the leading term alone left no margin (the true error 0.986 of the whole estimate of T
    // at α = 0, β = 2.38, η = 265, κ = 0, 2e-6 below a separatrix; whole-domain seed 12).
    let sharp =
        potential.saddle_conditioning_within(energy, component, raw.period, 2.0, 2.0 * delta);
    let less = |was: f64, now: f64| (was - now).max(0.0);
    let less_t = less(before.period, sharp.period);
    let less_psi = less(before.psi_advance, sharp.psi_advance);
    let less_drift = less(before.drift, sharp.drift);
    raw.period_error -= less_t;
    raw.psi_advance_error -= less_psi;
    if let Some(d) = raw.drift.as_mut() {
        d.error -= less_psi * d.scale + less_drift;
    }
    raw.saddle = SaddleTerms {
        period: before.period - less_t,
        psi_advance: before.psi_advance - less_psi,
        drift: before.drift - less_drift,
    };
}

/// Errors of T, Δψ and |Δζ| caused by an offset of the energy the integrals are taken at.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct EnergyErrors {
    period: f64,
    psi_advance: f64,
    drift: f64,
}

impl EnergyErrors {
    fn plus(self, other: Self) -> Self {
        Self {
            period: self.period + other.period,
            psi_advance: self.psi_advance + other.psi_advance,
            drift: self.drift + other.drift,
        }
    }
}

/// The error of a libration's integrals from the level of its turning points. The integrand
/// near an end e measures ε − V from V(e) (by the divided difference of V), so the integrals
/// are exact for a level that runs from V(e_min) to V(e_max), off ε by s = ε − V(e) at each
/// end: the common part shifts the energy, the difference tilts the level across the
/// libration. Bounds on |s|: a priori, the rounding of ε − V(c) (the turning points are the
/// roots of ε − V(c) − (V(θ) − V(c)) for a critical point c inside, whose constant carries
/// V(c)'s rounding, a few ulps of its L1 size, whatever the gap) plus the rounding of each
/// root to a double; or, where that would weigh in the tolerance and the shape gives U in
/// double-double, s itself at each end computed in double-double at the angle of the end's
/// (sine, cosine) pair, plus the step where the libration's two halves meet (see below).
/// The error is |dX/dε| δε for X = T, Δψ, Δζ: the crude bound
/// |dX/dε| ≤ 2 ‖X‖ / min(ε − V_min, |V′(e)| |e − θ_b|) (T ∝ (ε − V_min)^p with |p| ≤ ½ where
/// the ends rise at least as steeply as on average; saddles are bounded separately, and
/// where the offset is computed sharply their terms are taken at it) is used when it is far
/// below the tolerance; otherwise, and near a pole at small κ, where the turning point is where ε and
/// U nearly cancel and X varies on the scale of κ, the slope is measured by differences at
/// ε ± h, h a thousandth of the scale X varies on (256 δε near a pole). Where the integrator
/// placed the turning points on ε in double-double ([`PeriodIntegrals::level_residual`]) the
/// offset is that residual alone (about 1e-30 of V), common and spread.
fn level_offset_error<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    raw: &mut PeriodIntegrals,
    options: &CellOptions,
) -> EnergyErrors {
    if component.kind != MotionKind::Libration {
        return EnergyErrors::default();
    }
    let Some(bottom) = component.minimum().copied() else {
        return EnergyErrors::default();
    };
    // (The integrals as they come: the closures below read their values and scales.)
    let values = *raw;
    let eps = f64::EPSILON;
    let scale = component
        .interior
        .iter()
        .map(|p| p.scale)
        .fold(0.0, f64::max);
    // V′, ψ̇ and dψ̇/dθ at the two turning points and the bottom, one evaluation each.
    let chart = |site: &crate::torus::Site| site.theta.min(site.from_pi).abs();
    let sites = [component.lower, component.upper, bottom.site];
    let rates: Vec<(f64, (f64, f64, f64))> = sites
        .iter()
        .map(|s| (chart(s), potential.slope_and_psi_rates(s.angle())))
        .collect();
    // A priori: the rounding of ε − V(c) and of each turning point (an ulp of θ in its
    // chart), as the common shift and as the spread of the two ends.
    let root = |i: usize| 2.0 * eps * sites[i].ulp_scale() * rates[i].1 .0.abs();
    let length = potential
        .separation(&component.lower, &component.upper)
        .abs();
    // The body's own representation error δU acts as an error of the level: up to its bound
    // in common, and between the two ends by at most its variation over the libration,
    // δU′ times its length, where (as a profile's) δU is the fitted arcs' error, a sum of
    // sinusoids of θ (centre and radius errors) whose slopes are bounded by their sizes.
    let represented = potential.body.shape.representation_error();
    let represented_spread = represented * length.min(2.0);
    let a_priori = 4.0 * eps * (scale + energy.abs()) + root(0) + root(1);
    // Away from the poles (at an end near a pole ψ̇ peaks in a sliver of time whose share
    // the relative bounds cover): ∫|ψ̇| dt ≤ T max|ψ̇|, and the shift of the orbit by the
    // rounding of each turning point to a double (an ulp in its chart) moves Δψ by
    // δθ ∫ |dψ̇/dθ| dt (large against Δψ itself where ψ̇ changes sign inside, round π/2): a
    // term of the crude bound only. The integrals are those of the level V(e) at each end e
    // as rounded, so a measured slope times δ (ε − V(e) itself, or its a-priori bound, which
    // counts an ulp of e times V′(e)) already holds that shift.
    let far = rates.iter().zip(&sites).filter(|((x, _), _)| *x > 0.1);
    // ‖Δψ‖ in the crude slope: |Δψ| + 2T max|ψ̇| (ends and bottom, away from the poles), or,
    // where the quadrature gives it and it is smaller (ψ̇ changing sign along the orbit),
    // ∫|ψ̇| dt + 2T max|ψ̇| at the ends (each sign of ψ̇ bounded like T, and the ends moving
    // out into larger |ψ̇|: ∫|ψ̇| dt alone was 3.8× short at a needle). Both checked against
    // slopes measured by differences (tests/suite/cell.rs).
    let end_rate = rates[..2]
        .iter()
        .map(|(_, r)| r.1.abs())
        .fold(0.0, f64::max);
    let psi_scale = (values.psi_advance.abs()
        + 2.0 * values.period * far.clone().map(|((_, r), _)| r.1.abs()).fold(0.0, f64::max))
    .min(
        values
            .psi_variation
            .map_or(f64::INFINITY, |v| v + 2.0 * values.period * end_rate),
    );
    // (Turning points placed on ε are not rounded to doubles: no shift.)
    let psi_shift = if values.level_residual.is_some() {
        0.0
    } else {
        2.0 * eps
            * values.period
            * far
                .map(|((_, r), s)| s.ulp_scale() * r.2.abs())
                .fold(0.0, f64::max)
    };
    let drift_scale = values.drift.map_or(0.0, |d| d.scale);
    // The crude bound of the common shift δε and the tilt's: the two ends' offsets differ by
    // at most `spread`, a level tilted across the libration by m ≤ spread / L. The response,
    // dX/dm = −d(X ⟨θ − θ_mid⟩)/dε (⟨⟩ the time average), is at most (L/2)|dX/dε| (in the
    // level term) plus ‖X‖ |d⟨θ⟩/dε|, and the average moves no faster than the faster end,
    // |dθ_end/dε| = 1/|V′|: an error spread ‖X‖ max(1/|V′|) / L. (Against 30-digit quadrature
    // of a tilted cubic well the two terms were 1.03–27× the true dT/dm, tightest next to
    // the saddle, where the level term carries it; the level term below is 4× that.)
    // The crude slope assumes the well rises at least as steeply at its ends as on average
    // from its bottom, |V′(e)| |e − θ_b| ≥ ε − V_min (a convex or steeper well; a ν-shaped
    // one is at p = ½). Where a wall flattens before its end (the needle's U ≈ |cos θ| near
    // a pole: p up to 1.5 measured), the end moves out at 1/|V′(e)| and the dwell there
    // grows with it: the bound takes the end's distance over its slope in place of the
    // depth, 2 ‖X‖ / min(ε − V_min, |V′(e)| |e − θ_b|).
    // And where V is nearly flat at a shoulder inside the libration or beyond an end, before
    // the next critical point (beside a cusp of the diagram), the level responds to ε on the
    // shoulder's scale ([`EffectivePotential::shoulder_gap`]): 1e-10 below the cusp of the
    // paper's body (α = 0.5, β = 3, ν = η = 0.5, κ_c), |V′(e)| |e − θ_b| put the slope
    // 1/(4d) too low (d the end's distance from the inflection) and T was 152 times its
    // estimate off, its turning point's ulp of ε moving it; 1e-8 above κ_c, just above the
    // shoulder's level, 83 times. (A maximum beyond an end is a saddle: its terms hold it.)
    let beyond = |i: usize, pole: f64| component.neighbours[i].map_or(pole, |p| p.site.theta);
    // A pole where U has a maximum (U″ < 0, no face) is at κ = 0 a separatrix's level, and
    // for small κ the wall rounds the top off on the level scale κ √|U″|: beside it X(ε)
    // varies on |ε − U_pole| + κ √|U″| like a shoulder's, however steep V′ is at an end (at
    // κ = 1e-20, ε = U_pole, V′(e) |e − θ_b| was 1.2e-8 and T 500 times its estimate off).
    let shape = &potential.body.shape;
    // (At κ = 0 the top is a critical point, with its saddle terms.)
    let pole_top = sites[..2]
        .iter()
        .filter(|e| potential.kappa != 0.0 && chart(e) < 0.1)
        .filter_map(|e| {
            let index = usize::from(e.theta > e.from_pi);
            let pole = Angle::POLES[index];
            let curvature = shape.potential_second_at(pole);
            (!shape.faces()[index] && curvature < 0.0).then(|| {
                (energy - shape.potential_at(pole)).abs()
                    + potential.kappa.abs() * (-curvature).sqrt()
            })
        })
        .fold(f64::INFINITY, f64::min);
    let shoulder = potential
        .shoulder_gap(energy, beyond(0, 0.0), beyond(1, PI))
        .min(pole_top);
    let reach = [0, 1]
        .iter()
        .map(|&i| rates[i].1 .0.abs() * potential.separation(&sites[i], &bottom.site).abs())
        .fold(shoulder, f64::min);
    let bounds = |delta: f64, spread: f64| {
        // (Less V_min's rounding: a depth within it would shrink the bound.)
        let depth = (energy - bottom.value - 4.0 * eps * bottom.scale).max(delta);
        let steep = depth.min(reach).max(delta);
        let tilt = if length > 0.0 {
            spread / length
                * rates[..2]
                    .iter()
                    .map(|(_, r)| 1.0 / r.0.abs())
                    .fold(0.0, f64::max)
        } else {
            0.0
        };
        let tilted = EnergyErrors {
            period: tilt * values.period,
            psi_advance: tilt * psi_scale,
            drift: tilt * drift_scale,
        };
        let crude = EnergyErrors {
            period: 2.0 * delta / steep * values.period,
            psi_advance: 2.0 * delta / steep * psi_scale + psi_shift,
            drift: 2.0 * delta / steep * drift_scale,
        };
        (crude, tilted, depth)
    };
    // The wall κ²/(2 sin²θ) a small part of V at an end near a pole: ε and U nearly cancel.
    let near_pole = potential.kappa != 0.0
        && sites[..2].iter().any(|e| {
            let a = e.angle();
            let w = potential.kappa / a.sin;
            chart(e) < 0.1 && 0.5 * w * w < 1e-3 * potential.value_scale(a)
        });
    // Sharper, where the shape gives V in double-double: each end's offset s = ε − V(e) at
    // the angle of the (sine, cosine) pair the integrand measures from, and the step where
    // the two ends' halves meet: the rise V(e_max) − V(e_min) the level is tilted by (see
    // `Piece::tilt_rate`) against its double-double value, plus the rise's response to the
    // rounding of the length between the ends (an ulp of each end in its chart).
    // Sharpest, where the integrator placed the turning points on ε in double-double: the
    // offset is their residual alone, common or spread ([`PeriodIntegrals::level_residual`]).
    let sharp = || -> Option<(f64, f64)> {
        if let Some(residual) = values.level_residual {
            return Some((residual + represented, 2.0 * residual + represented_spread));
        }
        let (lower, lower_error) = potential.value_double_double(sites[0].angle())?;
        let (upper, upper_error) = potential.value_double_double(sites[1].angle())?;
        let level = DoubleDouble::from_f64(energy);
        let (s_lower, s_upper) = (level.sub(lower).to_f64(), level.sub(upper).to_f64());
        let rise = upper.sub(lower).to_f64();
        // (The double-double errors, and one ulp of each difference rounded to a double.)
        let rounding = 2.0 * (lower_error + upper_error) + eps * (s_lower.abs() + s_upper.abs());
        let step = (potential.rise(sites[0].angle(), sites[1].angle(), length) - rise).abs()
            + (rise / length).abs() * eps * (sites[0].ulp_scale() + sites[1].ulp_scale())
            + eps * rise.abs()
            + rounding;
        Some((
            s_lower.abs().max(s_upper.abs()) + step + represented,
            (s_lower - s_upper).abs() + step + represented_spread,
        ))
    };
    // The crude bound is kept (away from a pole) where it is far below the tolerance, or
    // where measuring the slope cannot change the status: the values miss the tolerance
    // without it.
    let tol = options.tol;
    let enough =
        |crude: &EnergyErrors, tilted: &EnergyErrors, last: bool, raw: &PeriodIntegrals| {
            let drift_error = raw.drift.map_or(0.0, |d| d.error);
            let terms = [
                (raw.period_error, crude.period, tilted.period, values.period),
                (
                    raw.psi_advance_error,
                    crude.psi_advance,
                    tilted.psi_advance,
                    TAU,
                ),
                (drift_error, crude.drift, tilted.drift, drift_scale),
            ];
            let small = terms.iter().all(|&(_, c, _, x)| c <= 0.05 * tol * x);
            let misses = terms.iter().any(|&(r, _, t, x)| r + t > tol * x);
            !near_pole && (small || (last && misses))
        };
    // The integrator's saddle terms are at the a-priori energy error: the sharp offset is
    // computed where they weigh in too (the ψ term against tol itself: times the path
    // scale it is the drift's).
    let saddle_small = values.saddle.period <= 0.05 * tol * values.period
        && values.saddle.psi_advance <= 0.05 * tol
        && values.saddle.drift <= 0.05 * tol * drift_scale;
    // A kink whose level lies within the level's uncertainty of ε, at or next to the
    // libration: which side of it the turning point lies on is decided by rounding, and X may
    // jump there (a neutral sphere beside an edge, V′ = 2e-11 on both sides: T = 2866 on the
    // sphere's side, 120 on the edge's, the two levels within an ulp; whole-domain seed 26).
    // The error is then the largest change of X between ε and levels beyond the kink's on
    // either side.
    // (The distance of ε from the nearest kink's level also scales the measured slope's step
    // below.)
    let kink_levels = potential
        .body
        .shape
        .kinks()
        .iter()
        .map(|&k| (energy - potential.value(Site::at(k).angle())).abs())
        .fold(f64::INFINITY, f64::min);
    let uncertainty = a_priori + represented;
    let reach_out = 0.1;
    let ambiguous = (kink_levels <= 4.0 * uncertainty)
        .then(|| {
            potential
                .kinks_inside(
                    component.lower.theta - reach_out,
                    component.upper.theta + reach_out,
                )
                .into_iter()
                .map(|k| potential.value(k.angle()))
                .find(|v| (energy - v).abs() <= 4.0 * uncertainty)
        })
        .flatten();
    if let Some(kink_level) = ambiguous {
        let step = 2.0 * ((energy - kink_level).abs() + uncertainty);
        let at = |e: f64| libration_integrals(potential, e, &bottom, options);
        // (Where either side has no libration of this well, the bounds below hold as they
        // would without the kink: its critical level is a separatrix's, whose terms they have.)
        if let (Some(below), Some(above)) = (at(energy - step), at(energy + step)) {
            let sides = [below, above];
            let change = |x: fn(&PeriodIntegrals) -> (f64, f64)| {
                sides.iter().fold(0.0, |worst: f64, side| {
                    let ((value, error), (here, _)) = (x(side), x(&values));
                    worst.max((value - here).abs() + error)
                })
            };
            let drift =
                sides
                    .iter()
                    .fold(0.0, |worst: f64, side| match (side.drift, values.drift) {
                        (Some(d), Some(v)) => worst.max(
                            (d.value[0] - v.value[0]).hypot(d.value[1] - v.value[1]) + d.error,
                        ),
                        (None, None) => worst,
                        _ => f64::INFINITY,
                    });
            return EnergyErrors {
                period: change(|s| (s.period, s.period_error)),
                psi_advance: change(|s| (s.psi_advance, s.psi_advance_error)),
                drift,
            };
        }
    }
    let (mut crude, mut tilted, mut depth) =
        bounds(a_priori + represented, a_priori + represented_spread);
    if values.level_residual.is_none() && enough(&crude, &tilted, false, raw) && saddle_small {
        return crude.plus(tilted);
    }
    let mut delta = a_priori + represented;
    if let Some((common, spread)) = sharp() {
        delta = common;
        (crude, tilted, depth) = bounds(common, spread);
        sharpen_saddle_terms(potential, energy, component, raw, common);
    }
    if enough(&crude, &tilted, true, raw) {
        return crude.plus(tilted);
    }
    // The step stays well inside the family: below a quarter of the depth and of the
    // distance to every saddle at or next to the component.
    let saddles = component
        .saddles()
        .map(|p| (energy - p.value).abs())
        .fold(f64::INFINITY, f64::min);
    // Away from a pole X(ε) is analytic on the scale of the depth, the end's reach and the
    // distance to the nearest saddle or kink level (a turning point crossing a kink): a step
    // of 1e-3 of that scale leaves the slope changed by about that fraction, which the
    // doubled difference below covers, and it lets the integrals at ε ± h be far less
    // accurate than the cell's, their errors entering times δ/h. Near a pole at small κ
    // (X varies on the scale of κ there) and where that scale is below it, the step is
    // 256 times the a-priori bound (never below: the sharp δ may be far below an ulp of ε,
    // where ε ± h would round back to ε). Never beyond a quarter of the shoulder's gap
    // either: X′ grows without bound as ε nears a cusp's level (∝ 1/(V_k − ε) at the cusp),
    // and a difference across it measures a secant far below X′(ε): at the cusp point of the
    // paper's body (gap 1.1e-13, the step 1.9e-12) T was 2.1 times its estimate off.
    let variation = depth.min(reach).min(saddles).min(kink_levels);
    let narrow = 256.0 * a_priori;
    let h = if near_pole {
        narrow
    } else {
        narrow.max(1e-3 * variation)
    }
    .min(0.25 * depth)
    .min(0.25 * saddles)
    .min(0.25 * shoulder);
    if h < 16.0 * a_priori {
        return crude.plus(tilted);
    }
    // The integrals at ε ± h to what keeps their errors' share, errors δ/h, at a hundredth
    // of the tolerance (never looser than 1e-8, never tighter than the cell's).
    let looser = 0.01 * tol * h / delta;
    let options = &CellOptions {
        tol: if looser > tol {
            looser.min(tol.max(1e-8))
        } else {
            tol
        },
        ..*options
    };
    let at = |e: f64| libration_integrals(potential, e, &bottom, options);
    let (Some(up), Some(down)) = (at(energy + h), at(energy - h)) else {
        return crude.plus(tilted);
    };
    // |dX/dε| from the larger one-sided difference, twice over, plus the differences'
    // own errors.
    let slope = |x: f64, x_up: f64, x_down: f64, errors: f64| {
        2.0 * (x_up - x).abs().max((x - x_down).abs()) / h * delta + errors * delta / h
    };
    let drift = match (raw.drift, up.drift, down.drift) {
        (Some(d), Some(u), Some(w)) => {
            let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
            2.0 * dist(u.value, d.value).max(dist(d.value, w.value)) / h * delta
                + (u.error + d.error + w.error) * delta / h
        }
        _ => 0.0,
    };
    EnergyErrors {
        period: slope(
            values.period,
            up.period,
            down.period,
            up.period_error + raw.period_error + down.period_error,
        ),
        psi_advance: slope(
            values.psi_advance,
            up.psi_advance,
            down.psi_advance,
            up.psi_advance_error + raw.psi_advance_error + down.psi_advance_error,
        ),
        drift,
    }
    .plus(tilted)
}

fn finish(
    component: &Component,
    raw: PeriodIntegrals,
    far_out: Option<Estimate>,
    options: &CellOptions,
) -> ComponentResult {
    // Integrals that overflowed or lost every digit (extreme η, ε or κ) are no values: the
    // component says so rather than carry NaN into N, its error and the bounded flag.
    let drift_defined = raw
        .drift
        .is_none_or(|d| d.value.iter().all(|v| v.is_finite()) && !d.error.is_nan());
    let defined = [raw.period, raw.psi_advance].iter().all(|v| v.is_finite())
        && raw.period > 0.0
        && !raw.period_error.is_nan()
        && !raw.psi_advance_error.is_nan();
    if !(defined && drift_defined) {
        return unresolved_but(component, far_out);
    }
    let t = raw.period;
    let omega_theta = TAU / t;
    let rel_t = raw.period_error / t;
    // Far out on ε, N is the high-energy limit's and ω_ψ = −N ω_θ follows.
    let (n, n_err, omega_psi, omega_psi_err) = match far_out {
        Some(limit) => (
            limit.value,
            limit.error,
            -limit.value * omega_theta,
            limit.value.abs() * omega_theta * rel_t + limit.error * omega_theta,
        ),
        None => {
            let omega_psi = raw.psi_advance / t;
            (
                -raw.psi_advance / TAU,
                raw.psi_advance_error / TAU,
                omega_psi,
                omega_psi.abs() * rel_t + raw.psi_advance_error / t,
            )
        }
    };
    // An unbounded error of Δψ (a turn hidden by a face, `torus`) leaves N and ω_ψ unknown.
    let (n, omega_psi) = if n_err.is_finite() {
        (n, omega_psi)
    } else {
        (f64::NAN, f64::NAN)
    };
    // A libration with ψ ≡ 0 (κ = 0) retraces its way out on the way back: Δζ = 0 exactly,
    // whatever the rounding (quadrature) or truncation (ODE method) of its integral.
    let planar = component.kind == MotionKind::Libration
        && raw.psi_advance == 0.0
        && raw.psi_advance_error == 0.0;
    // The ψ that turns every node of the drift integral is known to the ψ advance's error
    // (|Δζ| is changed by a turn only to second order: its error leaves this out). Where the
    // limit's N replaced the quadrature's, that ψ is off by as much as its advance is off from
    // the limit's.
    let turn = far_out.map_or(0.0, |limit| {
        (raw.psi_advance + TAU * limit.value).abs() + TAU * limit.error
    });
    let (drift, drift_error, drift_vector, drift_vector_error) = match raw.drift {
        Some(_) if planar => (0.0, 0.0, [0.0, 0.0], 0.0),
        Some(d) => (
            d.value[0].hypot(d.value[1]),
            d.error,
            d.value,
            d.error + (raw.psi_advance_error + turn) * d.scale,
        ),
        None => (f64::NAN, f64::NAN, [f64::NAN; 2], f64::NAN),
    };
    let (drift_radius, radius_error) = drift_radius(drift, drift_error, n, n_err);
    let bounded = raw.drift.and_then(|d| {
        let drift = Estimate {
            value: drift,
            error: drift_error,
        };
        let rotation = Estimate {
            value: n,
            error: n_err,
        };
        let rounding = if planar {
            0.0
        } else {
            64.0 * f64::EPSILON * d.scale
        };
        boundedness(component.kind, rotation, drift, rounding, options)
    });
    let errors = ErrorEstimates {
        period: raw.period_error,
        omega_theta: omega_theta * rel_t,
        omega_psi: omega_psi_err,
        rotation_number: n_err,
        drift: drift_error,
        drift_radius: radius_error,
        drift_vector: drift_vector_error,
    };
    let drift_ok = planar
        || raw
            .drift
            .is_none_or(|d| d.error <= options.tol * d.scale.max(f64::MIN_POSITIVE));
    // The limit's N does not need the ψ integral to have converged.
    let converged = raw.converged || far_out.is_some();
    let ok = converged && rel_t <= options.tol && n_err <= options.tol && drift_ok;
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
        family: component.family,
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

/// Whether the path on the plane stays bounded (docs/model.md): a rotation (κ = 0, over the
/// top) never; anything else unless N is an integer and Δζ ≠ 0. N counts as an integer
/// within the resonance tolerance, or within its error estimate if that is larger; Δζ counts
/// as 0 when it and its error are below `rounding`. `None` where the numbers cannot tell:
/// N counts as an integer but Δζ is not told from 0, or N is known to no better than ±1/2.
fn boundedness(
    motion: MotionKind,
    rotation_number: Estimate,
    drift: Estimate,
    rounding: f64,
    options: &CellOptions,
) -> Option<bool> {
    if motion == MotionKind::Rotation {
        return Some(false);
    }
    let n = rotation_number.value;
    let off = (n - n.round()).abs();
    if off > options.resonance_tol.max(rotation_number.error) {
        return Some(true);
    }
    if drift.value <= rounding && drift.error <= rounding {
        return Some(true);
    }
    if rotation_number.error >= 0.5 {
        return None;
    }
    (drift.value > drift.error.max(rounding)).then_some(false)
}

/// [`unresolved`], with N from the high-energy limit where [`far_out`] gives it.
fn unresolved_but(component: &Component, far_out: Option<Estimate>) -> ComponentResult {
    let mut result = unresolved(component);
    if let Some(limit) = far_out {
        result.rotation_number = limit.value;
        result.error_estimate = limit.error;
        result.errors.rotation_number = limit.error;
    }
    result
}

/// A component whose integrals could not be computed: no values (NaN), unbounded errors,
/// status `tolerance_not_reached`.
fn unresolved(component: &Component) -> ComponentResult {
    let unknown = ErrorEstimates {
        period: f64::INFINITY,
        omega_theta: f64::INFINITY,
        omega_psi: f64::INFINITY,
        rotation_number: f64::INFINITY,
        drift: f64::INFINITY,
        drift_radius: f64::INFINITY,
        drift_vector: f64::INFINITY,
    };
    ComponentResult {
        theta_min: component.theta_min(),
        theta_max: component.theta_max(),
        period: f64::NAN,
        omega_theta: f64::NAN,
        omega_psi: f64::NAN,
        rotation_number: f64::NAN,
        drift: f64::NAN,
        drift_radius: f64::NAN,
        bounded: None,
        motion: component.kind,
        family: component.family,
        status: Status::ToleranceNotReached,
        error_estimate: f64::INFINITY,
        errors: unknown,
        drift_vector: [f64::NAN; 2],
        work: 0,
    }
}

/// R = |Δζ| / (2 |sin πN|) and a bound on its error over every |Δζ| and N within their
/// errors: ∞ where N's error reaches an integer (a drift there would be a straight line),
/// 0 when both Δζ and its error are 0 (κ = 0 librations).
fn drift_radius(drift: f64, drift_error: f64, n: f64, n_error: f64) -> (f64, f64) {
    if drift.is_nan() || n.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    if drift == 0.0 && drift_error == 0.0 {
        return (0.0, 0.0);
    }
    let s = (PI * n).sin().abs();
    let r = if drift == 0.0 { 0.0 } else { drift / (2.0 * s) };
    // |sin πx| over N ± δN: 0 if that holds an integer, else its smaller end (|sin πx| is
    // concave between integers); at most |sin πN| + π δN. Less the rounding of sin(πN).
    let rounding = 4.0 * f64::EPSILON * (1.0 + PI * n.abs());
    let s_min = if (n - n.round()).abs() <= n_error {
        0.0
    } else {
        let ends = (PI * (n - n_error))
            .sin()
            .abs()
            .min((PI * (n + n_error)).sin().abs());
        (ends - rounding).max(0.0)
    };
    let s_max = (s + PI * n_error + rounding).min(1.0);
    let largest = (drift + drift_error) / (2.0 * s_min);
    let smallest = (drift - drift_error).max(0.0) / (2.0 * s_max);
    let error = (largest - r).max(r - smallest) + 2.0 * f64::EPSILON * r;
    (r, if error.is_nan() { f64::INFINITY } else { error })
}

/// A maximum inside the component or at one of its ends whose computed level is ε itself.
/// A level a few ulps off is integrated like any other: its orbit is real, and the saddle's
/// conditioning (ulp(V_s)/(λ |ε − V_s|) per passage) says how little its values are worth.
pub(crate) fn separatrix(component: &Component, energy: f64) -> Option<CriticalPoint> {
    component.saddles().find(|p| energy == p.value).copied()
}

/// Whether a maximum inside the component or at one of its ends lies within 4 ulps (of its
/// L1 size) of ε: the values are then real but only as good as that distance allows (the
/// saddle's conditioning), too poor to trace a curve by.
pub fn within_rounding_of_separatrix(component: &Component, energy: f64) -> bool {
    component
        .saddles()
        .any(|p| (energy - p.value).abs() <= 4.0 * f64::EPSILON * p.scale)
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
        family: component.family,
        status: Status::Separatrix,
        error_estimate: 0.0,
        errors: ErrorEstimates {
            period: 0.0,
            omega_theta: 0.0,
            omega_psi: 4.0 * f64::EPSILON * omega_psi.abs(),
            rotation_number: 0.0,
            drift: f64::NAN,
            drift_radius: f64::NAN,
            drift_vector: f64::NAN,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    }
}

/// The linearised limits at a fixed point θ0: ω_θ = √(V″/B), ψ̇(θ0), N = −ψ̇/ω_θ; the centre
/// of mass runs round its circle of radius ρ_c = U tanθ0 (docs/model.md), so R = ρ_c and
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
    let b = red.reduced_inertia;
    // On a kink V″ has a corner: each half of the small oscillation swings on its own
    // side, π/ω of each (ω = √(V″/B)).
    let two_sided = |[before, after]: [f64; 2]| PI * ((b / before).sqrt() + (b / after).sqrt());
    let sides = potential.curvature_sides_at(a);
    let (omega_theta, period) = if sides[0] != sides[1] {
        let period = two_sided(sides);
        (TAU / period, period)
    } else {
        let omega_theta = (m.curvature / b).sqrt();
        (omega_theta, TAU / omega_theta)
    };
    // A kink closer than the swing at the rounding of the level (a few times
    // √(2 · 8 ulp / V″)) may be crossed by the motion at ε: its period then lies between
    // this one and the kink's two-sided one.
    let swing = 4.0 * (16.0 * f64::EPSILON * m.scale / m.curvature).sqrt();
    let straddle = potential
        .kinks_inside(m.site.theta - swing, m.site.theta + swing)
        .iter()
        .filter(|k| k.theta != m.site.theta)
        .map(|k| (two_sided(potential.curvature_sides_at(k.angle())) - period).abs())
        .fold(0.0, f64::max);
    // Where U′(π/2) = 0 the fixed point found at the double nearest π/2 (cosine 6e-17) is
    // the equator itself, where ψ̇ = 0: rolling on a straight line (it gave N = −5e-17, a
    // circle of radius 1.6e16 and `bounded`).
    let equator = Angle::EQUATOR;
    let on_equator =
        m.site.theta == FRAC_PI_2 && potential.body.shape.potential_prime_at(equator) == 0.0;
    let psi_rate = potential.psi_rate(if on_equator { equator } else { a });
    let psi_advance = psi_rate * period;
    let n = if psi_rate == 0.0 {
        0.0
    } else {
        -psi_advance / TAU
    };
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
    let mut result = ComponentResult {
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
        family: component.family,
        status: Status::FixedPoint,
        error_estimate: rel * n.abs(),
        errors: ErrorEstimates {
            period: rel * period,
            omega_theta: rel * omega_theta,
            omega_psi: rel * psi_rate.abs(),
            rotation_number: rel * n.abs(),
            drift: rel * drift,
            drift_radius: rel * radius,
            drift_vector: f64::NAN,
        },
        drift_vector: [f64::NAN; 2],
        work: 0,
    };
    if straddle > 0.0 {
        // Twice the difference: the swing that crosses the kink also has the corner's
        // √(ε − V) term on top (the difference alone was met to 1e-5 of it).
        let straddle = 2.0 * straddle;
        let e = &mut result.errors;
        let share = straddle / period;
        e.period += straddle;
        e.omega_theta += share * omega_theta;
        e.rotation_number += share * n.abs();
        if radius.is_finite() {
            e.drift += radius * psi_rate.abs() * straddle;
        }
        result.error_estimate = e.rotation_number;
        if e.rotation_number > options.tol || e.period > options.tol * period {
            result.status = Status::ToleranceNotReached;
        }
    }
    add_site_error(potential, &m, sides[0] != sides[1], options, &mut result);
    add_window_error(potential, &m, options, &mut result);
    result
}

/// The fixed point's values are taken at the double θ_m nearest the minimum, which may lie a
/// few ulps of θ off it (the rounding of the root of V′, at least half an ulp): where V″ or
/// ψ̇ vary on a scale near that (a needle's minimum within β of π/2, where cos θ ≈ β is only
/// known to an ulp of π/2), the values move with it. Bounded by 1.25 times the largest change
/// of T and ψ̇ over θ_m ± δ (measured over a K times longer step and divided by K), δ the
/// larger of an ulp of θ_m and the root's rounding 4 ε |V′|-scale / V″. (Needles at
/// β = 1e-8 … 1e-4 had T up to 1.3e4 times its estimate off, 8e-9 relative, and N 7e4 times;
/// an adversary pass.)
fn add_site_error<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    m: &crate::torus::CriticalPoint,
    kinked: bool,
    options: &CellOptions,
    result: &mut ComponentResult,
) {
    if kinked || m.curvature.is_nan() || m.curvature <= 0.0 {
        return;
    }
    let site = m.site;
    let a = site.angle();
    let chart = site.ulp_scale().abs();
    let delta = (f64::EPSILON * chart.max(f64::MIN_POSITIVE))
        .max(4.0 * f64::EPSILON * potential.slope_scale_at(a) / m.curvature);
    if !delta.is_finite() {
        return;
    }
    let values = |angle: Angle| -> Option<(f64, f64)> {
        let b = potential.body.reduction_at(angle).reduced_inertia;
        let curvature = potential.curvature_at(angle);
        (curvature > 0.0).then(|| (TAU / (curvature / b).sqrt(), potential.psi_rate(angle)))
    };
    // Measured over a step K δ, K up to 1e4 while K δ stays below a hundredth of the body's
    // finest angular scale, and divided by K: the change is linear over it, and V″'s own
    // rounding at the neighbours (relative 3e-10 by a nearly symmetric body's equator, where
    // T is flat to 1e-16) is divided by K too.
    let reach = (1e-2 * potential.body.shape.angular_feature_scale() / delta).clamp(1.0, 1e4);
    let moved = |d: f64| values(site.moved(d).angle());
    let (Some(here), Some(up), Some(down)) =
        (values(a), moved(reach * delta), moved(-reach * delta))
    else {
        return;
    };
    // (A quarter more for the rounding of the change.)
    let change = |f: fn(&(f64, f64)) -> f64| {
        1.25 * (f(&up) - f(&here)).abs().max((f(&down) - f(&here)).abs()) / reach
    };
    let (period_change, rate_change) = (change(|v| v.0), change(|v| v.1));
    let e = &mut result.errors;
    let period = result.period;
    let share = period_change / period;
    e.period += period_change;
    e.omega_theta += share * result.omega_theta;
    e.omega_psi += rate_change;
    // N = −ψ̇ T / 2π.
    let n_change = (rate_change * period + result.omega_psi.abs() * period_change) / TAU;
    e.rotation_number += n_change;
    if result.drift_radius.is_finite() {
        e.drift +=
            result.drift_radius * (rate_change * period + result.omega_psi.abs() * period_change);
    }
    result.error_estimate = e.rotation_number;
    // (Marked where this term alone misses the tolerance, as the kink's straddle is: the
    // a-priori 16 ulps stay under status `fixed_point` at tol 1e-15, as before.)
    if n_change > options.tol || period_change > options.tol * period {
        result.status = Status::ToleranceNotReached;
    }
}

/// The integrals of the libration of the well of `bottom` at `energy` (`None` where there is
/// none, or it cannot be integrated).
fn libration_integrals<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    bottom: &CriticalPoint,
    options: &CellOptions,
) -> Option<PeriodIntegrals> {
    integrate(
        potential,
        energy,
        &libration_around(potential, energy, bottom)?,
        options,
    )
    .ok()
}

/// The libration at `energy` round the minimum `bottom`, if there is one.
fn libration_around<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    bottom: &CriticalPoint,
) -> Option<Component> {
    potential.components(energy).ok()?.into_iter().find(|c| {
        c.kind == MotionKind::Libration
            && c.lower.theta < bottom.site.theta
            && bottom.site.theta < c.upper.theta
    })
}

/// The fixed-point window: ε within a few ulps of V(θ0) is taken as V(θ0), though the true
/// orbit there is a libration up to w = 8 eps ‖V(θ0)‖ above the bottom, whose values differ
/// from the linearised ones by about w dX/dε (large against N where ψ̇ changes sign at θ0,
/// as near θ = π/2). The slope is measured on the libration at e₁ = 2²⁰ w above the bottom
/// (or a quarter of the way to the nearest saddle), and 2 w |X(e₁) − X₀| / e₁ plus the
/// share of X(e₁)'s own error is added to every error estimate.
fn add_window_error<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    bottom: &CriticalPoint,
    options: &CellOptions,
    result: &mut ComponentResult,
) {
    let window = 8.0 * f64::EPSILON * bottom.scale;
    let saddle = potential
        .critical_points()
        .iter()
        .filter(|p| p.kind != CriticalKind::Minimum && p.value > bottom.value)
        .map(|p| p.value - bottom.value)
        .fold(f64::INFINITY, f64::min);
    let rise = (window * (1u64 << 20) as f64).min(0.25 * saddle);
    let neighbour = (rise > window)
        .then(|| {
            let energy = bottom.value + rise;
            let c = libration_around(potential, energy, bottom)?;
            solve_component(potential, energy, &c, options).ok()
        })
        .flatten();
    let Some(far) = neighbour else {
        // No room for a libration: the values hold only to the rounding of the level.
        result.status = Status::ToleranceNotReached;
        return;
    };
    // Off the kinks the values vary linearly with ε − V at the bottom; at a corner of V″
    // (a bottom on a kink) like √(ε − V), the odd terms of V no longer cancelling between
    // the two halves of the swing.
    let [before, after] = potential.curvature_sides_at(bottom.site.angle());
    let share = if before == after {
        window / rise
    } else {
        (window / rise).sqrt()
    };
    let add = |x0: f64, x1: f64, e1: f64| {
        if x0.is_finite() && x1.is_finite() {
            2.0 * share * (x1 - x0).abs() + share * e1
        } else {
            0.0
        }
    };
    // The linear model needs the values to move at one rate over [0, rise]: a flat well
    // with a near-quartic bottom (a near-sphere, β = 1 − 1e-12) has T ∝ (ε − V)^(−1/4) from
    // far below the rise, and the fixed point's T was 62 times its estimate off 8 ulps above
    // V_min (an adversary pass). Checked at rise/64: where the values there have moved by
    // more than a sixteenth of their change at the rise (1/64 if linear), the whole change
    // there bounds what the window can hold (monotone in ε between), and the status says so.
    let near_rise = rise / 64.0;
    if near_rise > 4.0 * window {
        let near = libration_around(potential, bottom.value + near_rise, bottom)
            .and_then(|c| solve_component(potential, bottom.value + near_rise, &c, options).ok());
        // (Beyond the values' errors, the fixed point's own included: rounding is not a
        // bend; a nearly symmetric body's N = −1e-16 ± 1e-15 by its equator was taken for one.)
        let bent =
            |(x0, e0): (f64, f64), (x_near, e_near): (f64, f64), (x_far, e_far): (f64, f64)| {
                x0.is_finite()
                    && x_near.is_finite()
                    && x_far.is_finite()
                    && (x_near - x0).abs() - e_near - e0 > ((x_far - x0).abs() + e_far + e0) / 16.0
            };
        match near {
            Some(near)
                if bent(
                    (result.period, result.errors.period),
                    (near.period, near.errors.period),
                    (far.period, far.errors.period),
                ) || bent(
                    (result.rotation_number, result.errors.rotation_number),
                    (near.rotation_number, near.errors.rotation_number),
                    (far.rotation_number, far.errors.rotation_number),
                ) =>
            {
                // (As `add` below: a value that is not finite, an equator's radius, adds none.)
                let whole = |x0: f64, x1: f64, e1: f64| {
                    if x0.is_finite() && x1.is_finite() {
                        (x1 - x0).abs() + e1
                    } else {
                        0.0
                    }
                };
                add_changes(result, &near, options.drift, whole);
                result.status = Status::ToleranceNotReached;
                return;
            }
            Some(_) => {}
            None => {
                result.status = Status::ToleranceNotReached;
                return;
            }
        }
    }
    add_changes(result, &far, options.drift, add);
}

/// Adds `term(value, other's value, other's error)` to each error of `result` (the drift's
/// where `drift`), and takes N's as the error estimate.
fn add_changes(
    result: &mut ComponentResult,
    other: &ComponentResult,
    drift: bool,
    term: impl Fn(f64, f64, f64) -> f64,
) {
    let (r, o) = (&*result, other);
    let period = term(r.period, o.period, o.errors.period);
    let omega_theta = term(r.omega_theta, o.omega_theta, o.errors.omega_theta);
    let omega_psi = term(r.omega_psi, o.omega_psi, o.errors.omega_psi);
    let rotation_number = term(
        r.rotation_number,
        o.rotation_number,
        o.errors.rotation_number,
    );
    let drifts = drift.then(|| {
        (
            term(r.drift, o.drift, o.errors.drift),
            term(r.drift_radius, o.drift_radius, o.errors.drift_radius),
        )
    });
    let e = &mut result.errors;
    e.period += period;
    e.omega_theta += omega_theta;
    e.omega_psi += omega_psi;
    e.rotation_number += rotation_number;
    if let Some((d, radius)) = drifts {
        e.drift += d;
        e.drift_radius += radius;
    }
    result.error_estimate = e.rotation_number;
}
