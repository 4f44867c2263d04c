//! The limits that bound the (κ, ε) plane (docs/hypothesis.md): the high-energy limit N∞(λ) of the
//! rotation number at fixed λ = κ/√ε, the linearised N at the bottom of each well (stable
//! permanent rotations, `s1`), and the known limits at κ → 0 and at a separatrix. The
//! verdict on the boundedness hypothesis ([`crate::verdict`]) closes the plane with them.
//!
//! **High energy.** With λ fixed and ε → ∞, time scaled by √ε, the reduced system (`eqsys`)
//! tends to B θ′²/2 + λ²/(2 sin²θ) = 1, ψ′ = −λ cosθ/(J sin²θ) (`dpsi`): U drops out of the
//! energy, B and J stay. The rotation number of that system is
//! N∞(λ) = (λ/π) ∫ cosθ √B / (J sinθ √(2 sin²θ − λ²)) dθ over sinθ ≥ λ/√2.
//! Because |r|² = U² + U′², one has √B/J − 1 = sin²θ H(cosθ) with
//! H = ((1 − ν)/η + (U′/sinθ)²) / (J (√B + J)), smooth on [−1, 1]; the constant part of √B/J
//! integrates to 0 (θ → π − θ), and x = cosθ = x₀ sin u with x₀ = √(1 − λ²/2) turns the rest
//! into an integral with no singularity at all:
//! N∞(λ) = λ x₀ / (√2 π) ∫_{0}^{π/2} sin u [H(x₀ sin u) − H(−x₀ sin u)] du.
//! Its integrand is even and π-periodic in u, so the trapezoid rule converges geometrically.
//! At λ → 0, N∞/λ → (1/(√2 π)) ∫_0^{π/2} sin u [H(sin u) − H(−sin u)] du (the slope); at
//! λ = √2 the torus shrinks to θ = π/2, where ψ̇ = 0, and N∞ = 0.
//!
//! The limit holds for any body, but H is smooth only for one without kinks or faces: for the
//! edged bodies and profiles N∞ is integrated in pieces between the kinks, with a face's peak
//! next to the turning points taken out exactly ([`edged_high_energy_rotation_number`]), and
//! tends to (√B/J|₀ − √B/J|π)/2 as λ → 0, not 0 ([`high_energy_limit_at_small_lambda`]).

use crate::body::{Angle, Body, Shape};
use crate::error::{check_range, Result};
use crate::quadrature::{IntervalNode, TanhSinhLevel, FINEST_LEVEL};
use crate::torus::{CriticalKind, CriticalPoint, EffectivePotential};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, SQRT_2};

/// A value with a bound on its absolute error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    pub value: f64,
    pub error: f64,
}

/// Whether H is smooth on [−1, 1] for `shape`, so that N∞ is the geometrically converging
/// trapezoid sum above: not for a body with a kink (U″ jumps, H′ with it) or a face (U′/sinθ
/// unbounded at a pole), whose limit is [`edged_high_energy_rotation_number`].
pub fn smooth_high_energy_limit<S: Shape>(shape: &S) -> bool {
    shape.kinks().is_empty() && shape.faces() == [false, false]
}

/// The rotation number tends to these at κ → 0 (docs/hypothesis.md): a libration that passes near the
/// pole θ = 0 only winds ψ by −π per passage (N → +1/2), one near θ = π only by +π
/// (N → −1/2), and one that passes near both (a κ = 0 rotation over the top, ε > ε_min) has
/// the two passages cancel, N = O(κ) → 0. They are the κ → 0 edge of the plane the verdict
/// stops short of (its first line is at κ = 1e-6, where cells are at these limits: no
/// integer but 0 is approached, and 0 only as a limit); tests check them against cells at
/// κ = 1e-7.
pub fn small_kappa_limit(near_zero_pole: bool, near_pi_pole: bool) -> f64 {
    match (near_zero_pole, near_pi_pole) {
        (true, false) => 0.5,
        (false, true) => -0.5,
        _ => 0.0,
    }
}

/// N at the bottom of a well: the linearised ratio at the stable permanent rotation θ0
/// (`s1`), N = −ψ̇(θ0)/ω0 with ψ̇ = −κ cosθ0/(J sin²θ0) (`dpsi`) and ω0² = V″(θ0)/B(θ0).
/// It tends to +1/2 as θ0 → 0 and −1/2 as θ0 → π along a branch that ends at a pole
/// (κ ∝ sin²θ0 there, V″ → 4U″), which is the value returned at a pole itself. `None` where
/// the permanent rotation is not stable (V″ ≤ 0).
pub fn linearised_rotation_number<S: Shape>(
    body: &Body<S>,
    theta0: f64,
    kappa: f64,
) -> Option<f64> {
    if theta0 <= 0.0 {
        return (body.shape.potential_second(0.0) > 0.0).then_some(0.5);
    }
    if theta0 >= PI {
        return (body.shape.potential_second(PI) > 0.0).then_some(-0.5);
    }
    let curvature =
        crate::reduced::ReducedSystem::new(body, kappa).effective_potential_second(theta0);
    small_oscillation_ratio(body, Angle::new(theta0), kappa, curvature)
}

/// −ψ̇/ω0 at a minimum of V at angle `a` with V″ = `curvature` (None unless V″ > 0; 0 at
/// κ = 0, where ψ stays put).
fn small_oscillation_ratio<S: Shape>(
    body: &Body<S>,
    a: Angle,
    kappa: f64,
    curvature: f64,
) -> Option<f64> {
    if curvature.is_nan() || curvature <= 0.0 {
        return None;
    }
    if kappa == 0.0 {
        return Some(0.0);
    }
    let red = body.reduction_at(a);
    let omega = (curvature / red.reduced_inertia).sqrt();
    let psi_rate = -kappa * a.cos / (red.integral_factor * a.sin * a.sin);
    Some(-psi_rate / omega)
}

/// [`linearised_rotation_number`] at a minimum of V found by the cell solver (its θ held
/// to full precision near θ = π).
pub fn bottom_rotation_number<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    minimum: &CriticalPoint,
) -> Option<f64> {
    if minimum.kind != CriticalKind::Minimum {
        return None;
    }
    small_oscillation_ratio(
        potential.body,
        minimum.site.angle(),
        potential.kappa,
        minimum.curvature,
    )
}

/// H = (√B/J − 1) / sin²θ at the angle `a`: ((1 − ν)/η + (U′/sinθ)²) / (J (√B + J)).
#[inline]
fn excess_ratio<S: Shape>(body: &Body<S>, a: Angle) -> (f64, f64) {
    let red = body.reduction_at(a);
    let q = body.shape.potential_prime_over_sin_at(a);
    let num = (1.0 - body.nu) / body.eta + q * q;
    let j = red.integral_factor;
    let h = num / (j * (red.reduced_inertia.sqrt() + j));
    // Its rounding: a few ulps of each factor.
    (h, 16.0 * f64::EPSILON * h.abs())
}

/// The shape's own angular scale below which [`odd_part_integral`] crowds its nodes towards
/// u = 0 and π/2 ([`Crowding`]).
const CROWDED_BELOW: f64 = 0.05;

/// How [`odd_part_integral`] lays its nodes on u ∈ [0, π/2]: u = φ − a sin(4φ)/4 with φ on a
/// uniform grid. H varies on the shape's own angular scale w (β near the equator of a prolate
/// ellipsoid, 1/β near the poles of an oblate one): where the odd part's integrand turns, at
/// u = 0 (cos θ = 0) and u = π/2 (the turning point, by a pole as λ → 0). The map keeps the
/// integrand even about both ends (ψ(−φ) = −ψ(φ), ψ(π − φ) = π − ψ(φ)), so the trapezoid rule
/// stays geometric, and near the ends u ≈ δφ + (8/3)φ³ with δ = 1 − a = w^⅔: a feature of
/// width w is about w^⅓ wide in φ. Below [`CROWDED_BELOW`] only (a = 0 above it: the uniform
/// rule as before); at β = 300 the first level has 64 intervals instead of 4,096.
struct Crowding {
    /// a, in [0, 1).
    a: f64,
    /// The fewest intervals before the convergence test is trusted: 8 over the feature's
    /// width in φ (a coarser rule could agree with itself without seeing it).
    first_intervals: usize,
}

impl Crowding {
    fn of<S: Shape>(body: &Body<S>) -> Self {
        let scale = body.shape.angular_feature_scale().clamp(1e-6, 1.0);
        if scale >= CROWDED_BELOW {
            return Self {
                a: 0.0,
                first_intervals: (8.0 / scale).ceil().max(32.0) as usize,
            };
        }
        Self {
            a: 1.0 - scale.powf(2.0 / 3.0),
            first_intervals: (8.0 / scale.cbrt()).ceil().max(32.0) as usize,
        }
    }
}

/// ∫_0^{π/2} sin u [H(x₀ sin u) − H(−x₀ sin u)] du by the trapezoid rule, doubled from at
/// least [`Crowding`]'s first intervals (its nodes crowded towards both ends for a body with
/// narrow features) until a doubling changes the value by at most `abs_tol`; returns
/// the value and a bound on its error: that last change (for a geometrically converging
/// rule the error of the finer sum is far below it) plus the rounding of the sum.
fn odd_part_integral<S: Shape>(
    body: &Body<S>,
    x0: f64,
    one_minus_x0: f64,
    abs_tol: f64,
) -> Estimate {
    // A body symmetric about its equator has H(x) = H(−x): the odd part vanishes, exactly.
    // (The rule's first level alone, 8/β intervals, took 9 s at α = 0, β = 2e-155.)
    if body.shape.symmetric_about_equator() {
        return Estimate {
            value: 0.0,
            error: 0.0,
        };
    }
    // sinθ at cosθ = ±x₀ sin u from 1 − x = (1 − x₀) + x₀ (1 − sin u), with 1 − x₀ from λ
    // (`one_minus_x0`) and 1 − sin u = 2 sin²((π/2 − u)/2), not from the rounded x₀ and x:
    // next to a pole 1 − x would carry their rounding, u/(1 − x) relative (5e-13 at
    // θ = 0.014), and N∞ varies fast with the turning point there (dN∞/dx₀ ≈ 160 at α 0.64,
    // β 9.45, λ = 0.045, where one ulp of λ, flipping x₀'s last bit, moved N∞ by 1.8e-14
    // against its bound of 2.9e-15, and far out the limit then replaced a right quadrature
    // N by its own).
    const FRAC_PI_2_LOW: f64 = 6.123233995736766e-17;
    let odd_part = |u: f64, one_minus_s: f64| -> (f64, f64) {
        let s = u.sin();
        let x = x0 * s;
        let sin = ((one_minus_x0 + x0 * one_minus_s) * (1.0 + x))
            .max(0.0)
            .sqrt();
        let (hp, ep) = excess_ratio(body, Angle { sin, cos: x });
        let (hm, em) = excess_ratio(body, Angle { sin, cos: -x });
        (s * (hp - hm), s * (hp.abs() + hm.abs() + ep + em))
    };
    let crowding = Crowding::of(body);
    let a = crowding.a;
    // The integrand at the grid point φ = j (π/2)/m (j a whole or half number): with u = φ
    // itself where a = 0, else through [`Crowding`]'s map, taking π/2 − u and du/dφ =
    // (1 − a) + 2a sin²2φ from whichever of φ and π/2 − φ is the smaller.
    let g = |j: f64, m: usize| -> (f64, f64) {
        let phi = j * (FRAC_PI_2 / m as f64);
        if a == 0.0 {
            let half = 0.5 * ((FRAC_PI_2 - phi) + FRAC_PI_2_LOW);
            return odd_part(phi, 2.0 * half.sin() * half.sin());
        }
        let rest = (m as f64 - j) * (FRAC_PI_2 / m as f64) + FRAC_PI_2_LOW * (1.0 - j / m as f64);
        let (u, from_top, sin_2phi) = if phi <= FRAC_PI_4 {
            let shift = 0.25 * a * (4.0 * phi).sin();
            (phi - shift, rest + shift, (2.0 * phi).sin())
        } else {
            let from_top = rest - 0.25 * a * (4.0 * rest).sin();
            (FRAC_PI_2 - from_top, from_top, (2.0 * rest).sin())
        };
        let half = 0.5 * from_top;
        let (v, size) = odd_part(u, 2.0 * half.sin() * half.sin());
        let du = (1.0 - a) + 2.0 * a * sin_2phi * sin_2phi;
        (du * v, du * size)
    };
    const MAX_INTERVALS: usize = 1 << 22;
    let first = crowding.first_intervals;
    let mut m = first.next_power_of_two();
    let h0 = FRAC_PI_2 / m as f64;
    let (end, end_abs) = g(m as f64, m);
    let (mut sum, mut abs) = (0.5 * end, 0.5 * end_abs);
    for k in 1..m {
        let (v, size) = g(k as f64, m);
        sum += v;
        abs += size;
    }
    let mut value = sum * h0;
    let mut last_diff = f64::INFINITY;
    loop {
        let (mut add, mut add_abs) = (0.0, 0.0);
        for k in 0..m {
            let (v, size) = g(2.0 * k as f64 + 1.0, 2 * m);
            add += v;
            add_abs += size;
        }
        sum += add;
        abs += add_abs;
        m *= 2;
        let next = sum * FRAC_PI_2 / m as f64;
        let diff = (next - value).abs();
        let rounding = 8.0 * f64::EPSILON * abs * FRAC_PI_2 / m as f64;
        value = next;
        // Converged; or at the rounding level, where a doubling no longer halves the
        // difference (a geometric rule squares it): stop, and keep that difference as the
        // error bar — it is the noise the sum carries.
        let stalled = diff > 0.5 * last_diff && m >= 8 * first;
        if diff <= abs_tol.max(4.0 * rounding) || stalled || m >= MAX_INTERVALS {
            return Estimate {
                value,
                error: diff.max(if stalled { last_diff } else { 0.0 }) + rounding,
            };
        }
        last_diff = diff;
    }
}

/// P(θ) = √B/J − 1 = ((1 − ν)/η sin²θ + U′²) / (J (√B + J)) at the angle `a` (B − J² =
/// (1 − ν)/η sin²θ + U′², since |r|² = U² + U′²): no cancellation, finite at a face's pole.
fn excess_at<S: Shape>(body: &Body<S>, a: Angle) -> f64 {
    let red = body.reduction_at(a);
    let slope = body.shape.potential_prime_at(a);
    let num = (1.0 - body.nu) / body.eta * a.sin * a.sin + slope * slope;
    let j = red.integral_factor;
    num / (j * (red.reduced_inertia.sqrt() + j))
}

/// lim N∞(λ) as λ → 0 for any body: (P(0) − P(π))/2 with P = √B/J − 1 at the poles. At a
/// smooth pole U′ = 0 and B = J², so P = 0 there: only a face (U′ ≠ 0 at its pole) gives a
/// value; a passage next to a pole turns ψ by −π √B/J there (as at κ → 0), and at high energy
/// each period passes next to both poles. N∞ is discontinuous at λ = 0 itself, where κ = 0:
/// the body rolls over the top, or reaches a face and stops.
pub fn high_energy_limit_at_small_lambda<S: Shape>(body: &Body<S>) -> f64 {
    if body.shape.symmetric_about_equator() {
        return 0.0;
    }
    let bottom = Angle { sin: 0.0, cos: 1.0 };
    let top = Angle {
        sin: 0.0,
        cos: -1.0,
    };
    0.5 * (excess_at(body, bottom) - excess_at(body, top))
}

/// Ū, the scale of U: its largest |U| at the poles and the equator.
pub(crate) fn potential_scale<S: Shape>(shape: &S) -> f64 {
    [0.0, 0.5 * PI, PI]
        .iter()
        .map(|&t| shape.potential(t).abs())
        .fold(0.0, f64::max)
}

/// ∞ where a zero of U lies in the allowed set sinθ ≥ μ and J there, √((cos²θ + ν sin²θ)/η),
/// is within a hundred roundings of U (8 eps of its scale): 1/J then peaks on a width that U's
/// rounding decides, and the integral cannot be trusted (a cut ball with η = 1e60 and a zero
/// of U at the equator gave N∞ = 0.327 ± 0.088 against 0.433); else 0.
fn unresolved_peaks<S: Shape>(body: &Body<S>, mu: f64) -> f64 {
    let shape = &body.shape;
    let rounding = 8.0 * f64::EPSILON * potential_scale(shape).max(1.0);
    let hidden = shape.potential_zeros().into_iter().any(|theta| {
        let (s, c) = theta.sin_cos();
        let j2 = (c * c + body.nu * s * s) / body.eta;
        s >= mu && j2 < (100.0 * rounding).powi(2)
    });
    if hidden {
        f64::INFINITY
    } else {
        0.0
    }
}

/// Fewest and most tanh-sinh levels per piece of [`edged_high_energy_rotation_number`]: a
/// difference is trusted from level 5 (257 nodes) on, when it has also shrunk.
const EDGED_FIRST_LEVEL: u32 = 3;
const EDGED_TRUSTED_LEVEL: u32 = 5;

/// N∞(λ) for a body with kinks or faces, where H is not smooth on [−1, 1]. With μ = λ/√2,
/// x₀ = √(1 − μ²), and c = cos u in the form of [`high_energy_rotation_number`] (so
/// cosθ = x₀√(1 − c²), sinθ = √(μ² + x₀²c²), 0 ≤ c ≤ 1 for θ_min ≤ θ ≤ π/2),
/// N∞ = (μx₀/π) ∫₀¹ Q(c)/(μ² + x₀²c²) dc with Q = P(θ) − P(π − θ) ([`excess_at`]). Near
/// c = 0 a face makes Q/(μ² + x₀²c²) a peak of width μ/x₀ and height 1/μ², which no rule
/// resolves as λ → 0; its exact part is taken out:
/// N∞ = (1/π) [Q(0) arctan(x₀/μ) + μx₀ ∫₀¹ (Q(c) − Q(0))/(μ² + x₀²c²) dc].
/// The rest is bounded by |Q′|/(2μ) and integrated by tanh-sinh on pieces split where a kink
/// or a zero of U (a narrow peak of 1/J) lies, each refined until a level changes it by less
/// than its share of `tol`; the error is that change, the rounding of the sum (16 eps of
/// each term), and the tails beyond the rule's last nodes. λ = 0 gives the limit λ → 0
/// ([`high_energy_limit_at_small_lambda`]).
pub fn edged_high_energy_rotation_number<S: Shape>(
    body: &Body<S>,
    lambda: f64,
    tol: f64,
) -> Estimate {
    if body.shape.symmetric_about_equator() || lambda >= SQRT_2 {
        return Estimate {
            value: 0.0,
            error: 0.0,
        };
    }
    let eps = f64::EPSILON;
    if lambda == 0.0 {
        let value = high_energy_limit_at_small_lambda(body);
        return Estimate {
            value,
            error: 16.0 * eps * value.abs(),
        };
    }
    let mu = lambda / SQRT_2;
    let x0 = turning_cosine(lambda);
    if x0 == 0.0 {
        return Estimate {
            value: 0.0,
            error: 0.0,
        };
    }
    // The angle at c, from c and 1 − c each to full precision.
    let angle = |c: f64, one_minus_c: f64| Angle {
        sin: (mu * mu + x0 * x0 * c * c).sqrt(),
        cos: x0 * (one_minus_c * (1.0 + c)).sqrt(),
    };
    // Q and its rounding scale |P(θ)| + |P(π − θ)| (Q cancels where the body is nearly
    // its own mirror image).
    let odd = |a: Angle| {
        let (p, mirrored) = (
            excess_at(body, a),
            excess_at(body, Angle { cos: -a.cos, ..a }),
        );
        (p - mirrored, p.abs() + mirrored.abs())
    };
    let (q0, q0_scale) = odd(Angle { sin: mu, cos: x0 });
    // The split points: kinks and zeros of U, folded onto θ ≤ π/2, as values of c.
    let shape = &body.shape;
    let mut cuts: Vec<f64> = shape
        .kinks()
        .iter()
        .copied()
        .chain(shape.potential_zeros())
        .filter_map(|theta| {
            let s = theta.sin();
            (s > mu).then(|| ((s - mu) * (s + mu)).sqrt() / x0)
        })
        .filter(|&c| c > 0.0 && c < 1.0)
        .collect();
    cuts.sort_by(f64::total_cmp);
    // A kink and the mirror image of another (a body nearly symmetric about its equator)
    // can fall within ulps of each other: one cut.
    cuts.dedup_by(|b, a| *b - *a <= 4.0 * f64::EPSILON);
    let ends: Vec<f64> = std::iter::once(0.0)
        .chain(cuts)
        .chain(std::iter::once(1.0))
        .collect();
    let pieces = ends.len() - 1;
    let prefactor = mu * x0 / PI;
    let piece_tol = 0.25 * tol / (prefactor * pieces as f64);
    let (mut integral, mut error) = (0.0, 0.0);
    for w in ends.windows(2) {
        let (a, b) = (w[0], w[1]);
        let length = b - a;
        // The term at node j of `level`, and its rounding scale.
        let term = |level: u32, j: usize| -> (f64, f64) {
            let node = IntervalNode::tanh_sinh_tabulated(level, j, length);
            let c = a + node.from_left;
            let (q, q_scale) = odd(angle(c, (1.0 - b) + node.from_right));
            let den = mu * mu + x0 * x0 * c * c;
            (
                node.jacobian * (q - q0) / den,
                node.jacobian * (q_scale + q0_scale) / den,
            )
        };
        let first = TanhSinhLevel::new(EDGED_FIRST_LEVEL);
        let (mut sum, mut scale, mut tail) = (0.0, 0.0, 0.0);
        for j in 0..first.count {
            let (v, r) = term(EDGED_FIRST_LEVEL, j);
            sum += v;
            scale += r;
            // The tails beyond τ = ±TAU_MAX: the outermost terms' integrand times the
            // distance left to each end (the integrand is bounded on the piece).
            if j == 0 || j + 1 == first.count {
                let node = IntervalNode::tanh_sinh_tabulated(EDGED_FIRST_LEVEL, j, length);
                let to_end = if j == 0 {
                    node.from_left
                } else {
                    node.from_right
                };
                tail += (v / node.jacobian).abs() * to_end;
            }
        }
        let mut value = sum * first.step;
        let mut last_diff = f64::INFINITY;
        // A piece that does not settle by the finest level has no error bound: its last
        // difference could be far below the truth (a peak of 1/J narrower than the nodes).
        let mut piece_error = f64::INFINITY;
        let mut step = first.step;
        for level in EDGED_FIRST_LEVEL + 1..=FINEST_LEVEL {
            let grid = TanhSinhLevel::new(level);
            step = grid.step;
            for j in (1..grid.count).step_by(2) {
                let (v, r) = term(level, j);
                sum += v;
                scale += r;
            }
            let next = sum * grid.step;
            let diff = (next - value).abs();
            value = next;
            // Settled: within the piece's share of the tolerance, or down to the rounding of
            // the sum itself (below which a level's change is noise).
            let floor = piece_tol.max(64.0 * eps * scale * grid.step);
            if level >= EDGED_TRUSTED_LEVEL
                && diff <= floor
                && (diff <= last_diff || last_diff <= floor)
            {
                piece_error = diff;
                break;
            }
            last_diff = diff;
        }
        integral += value;
        error += piece_error + tail + 16.0 * eps * scale * step;
    }
    let value = (q0 * (x0 / mu).atan() + mu * x0 * integral) / PI;
    Estimate {
        value,
        error: prefactor * error
            + 16.0 * eps * q0_scale
            + 4.0 * eps * value.abs()
            + unresolved_peaks(body, mu),
    }
}

/// 0 ≤ λ ≤ √2: the high-energy limit has motion only there (κ²/2 ≤ ε).
fn check_lambda(lambda: f64) -> Result<f64> {
    check_range(
        "lambda",
        lambda,
        Some((0.0, true)),
        Some((SQRT_2, true)),
        "must satisfy 0 <= lambda <= sqrt(2) (no motion above: kappa^2/2 <= energy)",
    )
}

/// √2 − SQRT_2: the rounding of √2 as a double.
const SQRT_2_LOW: f64 = -9.667293313452913e-17;

/// 1 − λ/√2 to full relative precision: next to λ = √2, 1 − λ/SQRT_2 would carry the
/// roundings of λ/SQRT_2 and of √2 itself (at λ one ulp below √2 N∞ came out 25 % off);
/// SQRT_2 − λ is exact there (Sterbenz), and √2's low part is added.
fn distance_to_top(lambda: f64) -> f64 {
    ((SQRT_2 - lambda) + SQRT_2_LOW) / SQRT_2
}

/// x₀ = cosθ at the turning points of the high-energy limit, x₀² = 1 − λ²/2 (0 beyond √2).
fn turning_cosine(lambda: f64) -> f64 {
    (distance_to_top(lambda) * (1.0 + lambda / SQRT_2))
        .max(0.0)
        .sqrt()
}

/// 1 − x₀ = (λ²/2)/(1 + x₀) to full relative precision (1 − x₀ from the rounded x₀ would
/// carry its rounding, u/(1 − x₀) relative: 2e-13 at λ = 0.045).
fn one_minus_turning_cosine(lambda: f64, x0: f64) -> f64 {
    0.5 * lambda * lambda / (1.0 + x0)
}

/// The family of the tori at large κ (and of the high-energy limit at λ > 0, where κ = λ√ε
/// → ∞): there the κ²/(2 sin²θ) term makes V a single well round θ = π/2, on the side U
/// descends to (U′(π/2) < 0: θ > π/2, the well of σ_sπ for α > 0), or at π/2 itself for a
/// body symmetric about its equator. The tori above a saddle belong to this family too.
pub fn high_energy_family<S: Shape>(body: &Body<S>) -> crate::family::Family {
    use crate::family::Family;
    let slope = body.shape.potential_prime_at(Angle::EQUATOR);
    if body.shape.symmetric_about_equator() || slope == 0.0 {
        Family::WellEquator
    } else if slope < 0.0 {
        Family::WellPi
    } else {
        Family::Well0
    }
}

/// N∞(λ): the rotation number in the limit ε → ∞ at fixed λ = κ/√ε, for 0 ≤ λ ≤ √2 (the
/// allowed set is sinθ ≥ λ/√2), to the absolute accuracy `tol`.
pub fn high_energy_rotation_number<S: Shape>(
    body: &Body<S>,
    lambda: f64,
    tol: f64,
) -> Result<Estimate> {
    check_lambda(lambda)?;
    if !smooth_high_energy_limit(&body.shape) {
        return Ok(edged_high_energy_rotation_number(body, lambda, tol));
    }
    let x0 = turning_cosine(lambda);
    let factor = lambda * x0 / (SQRT_2 * PI);
    if factor == 0.0 {
        return Ok(Estimate {
            value: 0.0,
            error: 0.0,
        });
    }
    let integral = odd_part_integral(
        body,
        x0,
        one_minus_turning_cosine(lambda, x0),
        0.25 * tol / factor,
    );
    Ok(Estimate {
        value: factor * integral.value,
        error: factor * integral.error + 4.0 * f64::EPSILON * (factor * integral.value).abs(),
    })
}

/// Ñ at λ = √2 is taken at x₀ = this: Ñ(x₀) = Ñ(0) + O(x₀²) = 1e-10 relative, while the
/// odd part H(x₀ s) − H(−x₀ s) keeps 1e-11 of its relative accuracy.
const NORMALIZED_END: f64 = 1e-5;

/// Ñ(λ) = N∞(λ) / (λ x₀²) = ∫ … du / (√2 π x₀), x₀² = 1 − λ²/2: N∞ with its two zeros
/// at the ends divided out. It has the sign of N∞ on (0, √2) and finite, generically
/// non-zero, values at both ends (the slope at λ = 0), so a lobe of N∞ of the other sign
/// appears exactly when min Ñ or max Ñ crosses 0: the quantity that decides it.
pub fn normalized_high_energy_rotation_number<S: Shape>(
    body: &Body<S>,
    lambda: f64,
    tol: f64,
) -> Result<Estimate> {
    check_lambda(lambda)?;
    Ok(high_energy_pair(body, lambda, tol).1)
}

/// lim N∞(λ)/λ as λ → 0: how N tends to 0 at fixed κ as ε → ∞ (N ≈ slope · κ/√ε).
pub fn high_energy_slope<S: Shape>(body: &Body<S>, tol: f64) -> Estimate {
    let factor = 1.0 / (SQRT_2 * PI);
    let integral = odd_part_integral(body, 1.0, 0.0, 0.25 * tol / factor);
    Estimate {
        value: factor * integral.value,
        error: factor * integral.error,
    }
}

/// The high-energy limit of one body: the slope of N∞ at λ → 0 and its extrema over
/// 0 < λ < √2 (docs/hypothesis.md contract `high_energy`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HighEnergyLimit {
    /// lim N∞(λ)/λ as λ → 0.
    pub slope: f64,
    /// min N∞ (0 when N∞ ≥ 0: reached at λ → 0 and λ = √2).
    pub n_min: f64,
    /// Where N∞ is smallest (0 when N∞ ≥ 0, and when N∞ ≡ 0).
    pub lambda_at_min: f64,
    /// max N∞ (0 when N∞ ≤ 0).
    pub n_max: f64,
    /// Where N∞ is largest (0 when N∞ ≤ 0, and when N∞ ≡ 0).
    pub lambda_at_max: f64,
    /// min and max of Ñ = N∞/(λ x₀²) over [0, √2]: N∞ takes both signs (an N = 0
    /// resonance at every large κ) exactly when normalized_min < 0 < normalized_max.
    pub normalized_min: f64,
    pub normalized_max: f64,
    /// Bound on the error of `slope`.
    pub slope_error: f64,
    /// Bound on the error of `n_min` and `n_max` (quadrature and location).
    pub extrema_error: f64,
}

/// Number of λ samples in the scan for the extrema of N∞ before each is refined.
const EXTREMA_SCAN: usize = 96;

/// N∞(λ) and Ñ(λ) from one integral, each to the absolute accuracy `tol`.
pub fn high_energy_pair<S: Shape>(body: &Body<S>, lambda: f64, tol: f64) -> (Estimate, Estimate) {
    // At λ = √2 the limit x₀ → 0, approached as NORMALIZED_END says.
    let exact = turning_cosine(lambda);
    let x0 = exact.max(NORMALIZED_END);
    let one_minus_x0 = if x0 == exact {
        one_minus_turning_cosine(lambda, x0)
    } else {
        1.0 - x0
    };
    let c = SQRT_2 * PI;
    // Ñ = I/(c x₀) and N∞ = λ x₀ I / c = λ x₀² Ñ: I to c x₀ tol/4 serves both.
    let i = odd_part_integral(body, x0, one_minus_x0, 0.25 * c * x0 * tol);
    let tilde = Estimate {
        value: i.value / (c * x0),
        error: i.error / (c * x0),
    };
    let scale = lambda * x0 * x0;
    let n = Estimate {
        value: if lambda >= SQRT_2 {
            0.0
        } else {
            scale * tilde.value
        },
        error: scale * tilde.error + 4.0 * f64::EPSILON * (scale * tilde.value).abs(),
    };
    (n, tilde)
}

impl HighEnergyLimit {
    /// The limit not computed: every value NaN (null in JSON).
    pub fn not_computed() -> Self {
        Self {
            slope: f64::NAN,
            n_min: f64::NAN,
            lambda_at_min: f64::NAN,
            n_max: f64::NAN,
            lambda_at_max: f64::NAN,
            normalized_min: f64::NAN,
            normalized_max: f64::NAN,
            slope_error: f64::NAN,
            extrema_error: f64::NAN,
        }
    }

    /// Slope and extrema of N∞ and Ñ to the accuracy `tol` (values; λ to 1e-7, which moves
    /// an extremum's value by N″·1e-14).
    pub fn of<S: Shape>(body: &Body<S>, tol: f64) -> Result<Self> {
        Self::of_until(body, tol, &|| false)
    }

    /// [`Self::of`], given up when `stop` says so (asked at every value of the limit):
    /// then [`crate::error::AtlasError::Stopped`]. (At ν = 1e-300 the limit alone took a
    /// second, deaf to Ctrl-C; an adversary pass.)
    pub fn of_until<S: Shape>(
        body: &Body<S>,
        tol: f64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Self> {
        if !smooth_high_energy_limit(&body.shape) {
            return Err(crate::error::AtlasError::NotPeriodic {
                reason: "the slope and extrema of the high-energy limit are computed for bodies \
                         smooth up to the poles only",
            });
        }
        check_range(
            "tol",
            tol,
            Some((1e-15, true)),
            Some((0.1, true)),
            "must satisfy 1e-15 <= tol <= 0.1",
        )?;
        let lambdas: Vec<f64> = (0..=EXTREMA_SCAN)
            .map(|i| SQRT_2 * i as f64 / EXTREMA_SCAN as f64)
            .collect();
        let stopped = std::sync::atomic::AtomicBool::new(false);
        // A value asked for after `stop` is NaN: the searches below run out on it at once.
        let pair = |l: f64| {
            if stopped.load(std::sync::atomic::Ordering::Relaxed) || stop() {
                stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                let nan = Estimate {
                    value: f64::NAN,
                    error: f64::NAN,
                };
                return (nan, nan);
            }
            high_energy_pair(body, l, tol)
        };
        let values: Vec<(Estimate, Estimate)> = lambdas.par_iter().map(|&l| pair(l)).collect();
        if stopped.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(crate::error::AtlasError::Stopped);
        }
        let slope = values[0].1;
        let mut extrema_error = values
            .iter()
            .map(|(n, t)| n.error.max(t.error))
            .fold(0.0, f64::max);
        let flat = values.iter().all(|(n, _)| n.value.abs() <= n.error);
        // The extremum of sign·f over the scan, refined by golden section where interior;
        // `pick` selects N∞ (0) or Ñ (1).
        let mut extremum = |sign: f64, pick: usize| -> (f64, f64) {
            let get = |e: &(Estimate, Estimate)| if pick == 0 { e.0 } else { e.1 };
            let i = (0..=EXTREMA_SCAN)
                .max_by(|&a, &b| {
                    (sign * get(&values[a]).value).total_cmp(&(sign * get(&values[b]).value))
                })
                .expect("the scan has points");
            if i == 0 || i == EXTREMA_SCAN {
                return (get(&values[i]).value, lambdas[i]);
            }
            let (l, v) = golden_max(
                |l| sign * get(&pair(l)).value,
                lambdas[i - 1],
                lambdas[i + 1],
                1e-7,
            );
            extrema_error = extrema_error.max(get(&pair(l)).error);
            (sign * v, l)
        };
        let (mut n_max, mut lambda_at_max) = extremum(1.0, 0);
        let (mut n_min, mut lambda_at_min) = extremum(-1.0, 0);
        let (normalized_max, _) = extremum(1.0, 1);
        let (normalized_min, _) = extremum(-1.0, 1);
        if stopped.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(crate::error::AtlasError::Stopped);
        }
        if flat {
            (n_max, n_min, lambda_at_max, lambda_at_min) = (0.0, 0.0, 0.0, 0.0);
        }
        // N∞ = 0 at both ends: without an interior value of a sign, that extremum is the
        // limit 0 at λ → 0.
        if n_max <= 0.0 && !flat {
            (n_max, lambda_at_max) = (0.0, 0.0);
        }
        if n_min >= 0.0 && !flat {
            (n_min, lambda_at_min) = (0.0, 0.0);
        }
        Ok(Self {
            slope: slope.value,
            n_min,
            lambda_at_min,
            n_max,
            lambda_at_max,
            normalized_min,
            normalized_max,
            slope_error: slope.error,
            extrema_error,
        })
    }
}

/// The maximum of a unimodal `f` on [a, b] by golden-section search to |b − a| ≤ `xtol`:
/// (argmax, max).
pub fn golden_max(f: impl Fn(f64) -> f64, a: f64, b: f64, xtol: f64) -> (f64, f64) {
    let (x, v, _) = golden_max_settled(f, a, b, xtol, f64::INFINITY);
    (x, v)
}

/// [`golden_max`], going on past |b − a| ≤ `xtol` while the values on the bracket (its ends
/// and its two inner points) still spread by more than `ftol` (a narrow peak's top is still
/// rising there) and the bracket is wider than 8 ulps: (argmax, max, that spread, infinite
/// where f is −∞ at a point of the bracket or the maximum is at an end of [a, b]). Near a
/// smooth maximum the spread bounds how far the max lies above the value returned (by a
/// factor about 6 for a parabola), and each step cuts it by about 0.618².
pub fn golden_max_settled(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    xtol: f64,
    ftol: f64,
) -> (f64, f64, f64) {
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    // f at a and b, once they are former inner points (a maximum at an end of the window,
    // never an inner point, has an infinite spread).
    let (mut fa, mut fb) = (f64::NAN, f64::NAN);
    let spread = |fa: f64, fb: f64, fc: f64, fd: f64| {
        let v = [fa, fb, fc, fd];
        if v.iter().any(|x| x.is_nan()) {
            f64::INFINITY
        } else {
            v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
                - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
        }
    };
    let floor = 8.0 * f64::EPSILON * a.abs().max(b.abs());
    // (A spread that is not finite, an end where f failed, does not shrink: no going on.)
    let settling = |s: f64| s.is_finite() && s > ftol;
    while (b - a).abs() > xtol || settling(spread(fa, fb, fc, fd)) && (b - a).abs() > floor {
        if fc > fd {
            (b, fb) = (d, fd);
            (d, fd) = (c, fc);
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            (a, fa) = (c, fc);
            (c, fc) = (d, fd);
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    let spread = spread(fa, fb, fc, fd);
    if fc > fd {
        (c, fc, spread)
    } else {
        (d, fd, spread)
    }
}
