//! The rolling body: its surface of revolution (behind the [`Shape`] trait) and its mass
//! distribution (ν, η). Everything the reduction of paper §2.3 (`oned`) needs comes from here:
//! the potential U(θ), the reduced inertia B(θ) and the function J(θ) of the integral F2.
//!
//! A body of revolution touches the plane at r(γ) = (χ1 γ1, χ1 γ2, χ2) in the body frame
//! (paper §2.2, with the compatibility relation dχ2/dγ3 = χ1 − (1 − γ3²)/γ3 · dχ1/dγ3 of
//! `hier2002`). A new body (a torus, a truncated sphere, a disk with a rounded rim) is one new
//! implementation of [`Shape`]; every derived quantity has a generic default built from χ1, χ2.

use crate::dd::DoubleDouble;
use crate::error::{check_range, AtlasError, Result, MAX_KAPPA};
use nalgebra::Vector3;

/// `fn name(&self, theta) -> f64 { self.name_at(Angle::new(theta)) }` for each `name =>
/// name_at` pair: a shape whose formulas take the angle's sine and cosine gives its θ forms so.
macro_rules! theta_forms {
    ($($name:ident => $at:ident),* $(,)?) => {
        $(
            #[inline]
            fn $name(&self, theta: f64) -> f64 {
                self.$at(Angle::new(theta))
            }
        )*
    };
}

/// d/dt of γ⊥/|γ⊥|, γ⊥ = (γ1, γ2, 0), when γ moves at γ̇: the rate of the horizontal unit
/// vector towards which an edge's or an arc's contact point lies (0 on the axis).
pub(crate) fn horizontal_direction_rate(
    gamma: &Vector3<f64>,
    gamma_dot: &Vector3<f64>,
) -> Vector3<f64> {
    let h = Vector3::new(gamma.x, gamma.y, 0.0);
    let h_dot = Vector3::new(gamma_dot.x, gamma_dot.y, 0.0);
    let s2 = h.norm_squared();
    if s2 == 0.0 {
        return Vector3::zeros();
    }
    let s = s2.sqrt();
    h_dot / s - h * (h.dot(&h_dot) / (s2 * s))
}

/// (U(x) − U(y)) / sin(x − y) by subtracting U, with its rounding scale
/// (|U(x)| + |U(y)|)/|sin(x − y)| ([`Shape::potential_divided_difference`]'s default, and the
/// fallback of the shapes that override it across a kink).
#[inline]
pub(crate) fn subtracted_divided_difference<S: Shape + ?Sized>(
    shape: &S,
    x: Angle,
    y: Angle,
    sin_diff: f64,
) -> (f64, f64) {
    let (ux, uy) = (shape.potential_at(x), shape.potential_at(y));
    ((ux - uy) / sin_diff, (ux.abs() + uy.abs()) / sin_diff.abs())
}

mod edged;
mod profile;
pub use edged::{EdgedKind, EdgedShape};
pub use profile::{
    parse_table as parse_profile_table, Profile, ProfileArc, ProfileShape, MAX_PROFILE_POINTS,
};

/// An angle θ given by its sine and cosine, both to full relative precision. Near θ = π a
/// double holds θ only to an absolute 4e-16, so callers build the pair from π − θ there
/// (docs/accuracy.md); on the κ = 0 circle θ may be any real number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angle {
    /// sin θ.
    pub sin: f64,
    /// cos θ.
    pub cos: f64,
}

impl Angle {
    /// θ = π/2 exactly (sin 1, cos 0), which no rounded θ gives: cos(FRAC_PI_2) is 6e-17.
    pub const EQUATOR: Angle = Angle { sin: 1.0, cos: 0.0 };
    /// θ = 0 and θ = π exactly (sin π as a double is 1.2e-16).
    pub const POLES: [Angle; 2] = [
        Angle { sin: 0.0, cos: 1.0 },
        Angle {
            sin: 0.0,
            cos: -1.0,
        },
    ];

    /// The angle θ itself.
    #[inline]
    pub fn new(theta: f64) -> Self {
        let (sin, cos) = libm::sincos(theta);
        Self { sin, cos }
    }

    /// The angle π − φ, from its distance φ to the pole θ = π.
    #[inline]
    pub fn from_pi(phi: f64) -> Self {
        let (sin, cos) = libm::sincos(phi);
        Self { sin, cos: -cos }
    }

    /// θ in [0, π] (only for the generic fallbacks; loses precision near the poles).
    #[inline]
    pub fn theta(self) -> f64 {
        self.sin.atan2(self.cos)
    }
}

/// A convex surface of revolution about e3, with the centre of mass on the axis.
///
/// Units: the semi-axis b3 (or any length the shape chooses) is the unit of length. Angles:
/// θ is the angle between e3 and the vertical, so γ3 = cos θ.
pub trait Shape: Send + Sync {
    /// (χ1(θ), χ2(θ)): the contact point r = (χ1 sinθ sinφ, χ1 sinθ cosφ, χ2), seen from the
    /// centre of mass in the body frame (paper §2.2).
    fn chi(&self, theta: f64) -> (f64, f64);

    /// (dχ1/dθ, dχ2/dθ).
    fn chi_prime(&self, theta: f64) -> (f64, f64);

    /// The contact point r(γ) for any vertical unit vector γ in the body frame (paper `r`).
    fn contact_point(&self, gamma: &Vector3<f64>) -> Vector3<f64>;

    /// ṙ = (∂r/∂γ) γ̇: the body-frame rate of the contact point when γ moves at γ̇.
    fn contact_point_rate(&self, gamma: &Vector3<f64>, gamma_dot: &Vector3<f64>) -> Vector3<f64>;

    /// Height of the centre of mass above the plane = potential energy,
    /// U(θ) = −(r, γ) = −(χ1 sin²θ + χ2 cosθ).
    fn potential(&self, theta: f64) -> f64 {
        let (c1, c2) = self.chi(theta);
        let (s, c) = theta.sin_cos();
        -(c1 * s * s + c2 * c)
    }

    /// U′(θ) = sinθ (χ2 − χ1 cosθ) (uses the compatibility relation of χ1, χ2). It is also
    /// the signed horizontal distance from the centre of mass to the contact point.
    fn potential_prime(&self, theta: f64) -> f64 {
        let (c1, c2) = self.chi(theta);
        let (s, c) = theta.sin_cos();
        s * (c2 - c1 * c)
    }

    /// U″(θ) = cosθ (χ2 − χ1 cosθ) + sinθ (χ2′ − χ1′ cosθ + χ1 sinθ).
    fn potential_second(&self, theta: f64) -> f64 {
        let (c1, c2) = self.chi(theta);
        let (d1, d2) = self.chi_prime(theta);
        let (s, c) = theta.sin_cos();
        c * (c2 - c1 * c) + s * (d2 - d1 * c + c1 * s)
    }

    /// |r|² = χ1² sin²θ + χ2².
    fn contact_distance_sq(&self, theta: f64) -> f64 {
        let (c1, c2) = self.chi(theta);
        let s = theta.sin();
        c1 * c1 * s * s + c2 * c2
    }

    /// d|r|²/dθ = 2 (χ1 χ1′ sin²θ + χ1² sinθ cosθ + χ2 χ2′).
    fn contact_distance_sq_prime(&self, theta: f64) -> f64 {
        let (c1, c2) = self.chi(theta);
        let (d1, d2) = self.chi_prime(theta);
        let (s, c) = theta.sin_cos();
        2.0 * (c1 * d1 * s * s + c1 * c1 * s * c + c2 * d2)
    }

    /// U at an angle given by its sine and cosine (the cell solver's form).
    #[inline]
    fn potential_at(&self, a: Angle) -> f64 {
        self.potential(a.theta())
    }

    /// U′ at an angle given by its sine and cosine.
    #[inline]
    fn potential_prime_at(&self, a: Angle) -> f64 {
        self.potential_prime(a.theta())
    }

    /// The size of the terms U′ at an angle is computed from, which its rounding is a few
    /// ulps of (where they cancel, far more than |U′|): by default |U′| itself.
    #[inline]
    fn potential_prime_scale_at(&self, a: Angle) -> f64 {
        self.potential_prime_at(a).abs()
    }

    /// U″ at an angle given by its sine and cosine.
    #[inline]
    fn potential_second_at(&self, a: Angle) -> f64 {
        self.potential_second(a.theta())
    }

    /// |r|² at an angle given by its sine and cosine.
    #[inline]
    fn contact_distance_sq_at(&self, a: Angle) -> f64 {
        self.contact_distance_sq(a.theta())
    }

    /// The divided difference (U(x) − U(y)) / sin(x − y), which tends to U′(y) as x → y.
    /// `sin_diff` = sin(x − y) and `cos_diff` = cos(x − y) come from the caller, who knows
    /// x − y exactly. Shapes override this with a form free of cancellation; this default
    /// subtracts and is only as good as U's rounding allows.
    /// Returns the value and its rounding scale (the sum of the magnitudes of the terms that
    /// were added, so that its absolute rounding error is a few ulps of that scale).
    #[inline]
    fn potential_divided_difference(
        &self,
        x: Angle,
        y: Angle,
        sin_diff: f64,
        cos_diff: f64,
    ) -> (f64, f64) {
        let _ = cos_diff;
        subtracted_divided_difference(self, x, y, sin_diff)
    }

    /// U′(θ) / sinθ = χ2 − χ1 cosθ: the horizontal offset of the contact point per unit
    /// sinθ. It stays finite at the poles, and |r|² = U² + U′² (the contact point seen from
    /// the centre of mass has the vertical part −U and the horizontal part −U′), so
    /// B − J² = sin²θ ((1 − ν)/η + (U′/sinθ)²) without cancellation.
    #[inline]
    fn potential_prime_over_sin_at(&self, a: Angle) -> f64 {
        let (c1, c2) = self.chi(a.theta());
        c2 - c1 * a.cos
    }

    /// Whether the body is its own mirror image in its equatorial plane (U(π − θ) = U(θ)):
    /// then V has a critical point at θ = π/2 for every κ.
    fn symmetric_about_equator(&self) -> bool {
        false
    }

    /// The angles in (0, π), in order, where U″ jumps (the contact passes between a smooth
    /// part of the surface and a sharp edge): integrals over θ are split there, since the
    /// rules' fast convergence needs an integrand analytic on each piece. None for a smooth
    /// body.
    fn kinks(&self) -> &[f64] {
        &[]
    }

    /// U″ on either side of a kink at which the angle `a` lies (to a few ulps of its
    /// cosine): `[before, after]` in increasing θ, the one-sided curvatures of the two parts
    /// that meet there (U and U′ agree, U″ jumps). `None` away from a kink, and for a smooth
    /// body. A critical point of V on a kink is a minimum, a maximum or a shoulder (V
    /// monotone through it) by these signs, not by U″ of whichever part rounding picked.
    fn potential_second_sides_at(&self, a: Angle) -> Option<[f64; 2]> {
        let _ = a;
        None
    }

    /// Whether the body has a flat face that lies on the plane at θ = 0 and at θ = π: a
    /// motion that reaches it ends there (U has a corner at that pole).
    fn faces(&self) -> [bool; 2] {
        [false, false]
    }

    /// The smallest angular scale (in radians) on which U, B and J vary: numerical rules
    /// need steps below it before their convergence tests can be trusted.
    fn angular_feature_scale(&self) -> f64 {
        1.0
    }

    /// The angles in (0, π) about which U, B and J turn on [`Shape::angular_feature_scale`]
    /// where that is below 0.1 (a needle's π/2): the integrals are cut there, where a rule's
    /// nodes crowd ([`crate::torus`]'s pieces). None by default.
    fn feature_angles(&self) -> Vec<f64> {
        Vec::new()
    }

    /// A bound on the error of U as the body is held in doubles, beyond the rounding of its
    /// evaluation: 0 where the shape's parameters are its inputs; a profile's arcs, fitted
    /// through its points, carry the fit's rounding
    /// ([`crate::body::profile::ProfileShape`]). It acts on the cell as an error of the
    /// energy ([`crate::cell`]'s level offset).
    fn representation_error(&self) -> f64 {
        0.0
    }

    /// The θ in (0, π) where U = 0: where the centre of mass lies off the body (the disk with
    /// α ≠ 0, a cut ball with its edge down and h + α < 0, …) it is at the plane's height
    /// there. J² = (cos²θ + ν sin²θ)/η + U² is least there, and the integrands, ∝ 1/J, may
    /// peak sharply ([`crate::torus::EffectivePotential::splits_inside`]). None where U > 0.
    fn potential_zeros(&self) -> Vec<f64> {
        Vec::new()
    }

    /// The θ in (0, π) where U′ = 0 (the poles aside): B = 1/η + U² + U′² is least there and
    /// the integrands, ∝ √B, may dip sharply
    /// ([`crate::torus::EffectivePotential::splits_inside`]). Every shape gives them in
    /// closed form (no default: a shape that left them out would lose that check).
    fn slope_zeros(&self) -> Vec<f64>;

    /// U and |r|² together (shapes override this to share work between the two).
    #[inline]
    fn potential_and_contact_distance_sq_at(&self, a: Angle) -> (f64, f64) {
        (self.potential_at(a), self.contact_distance_sq_at(a))
    }

    /// U at the angle whose sine and cosine are `sin` and `cos`, in double-double, with a
    /// bound on its error (about 1e-30 of U's terms), for shapes that provide it: the cell
    /// solver then knows how far the level of a turning point is from ε far below an ulp of V
    /// (docs/accuracy.md, "The level of the turning points").
    fn potential_double_double(
        &self,
        _sin: DoubleDouble,
        _cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64)> {
        None
    }

    /// [`Shape::potential_double_double`] and |r|² = U² + U′² together, in double-double, for
    /// shapes that provide it (|r|² to about 1e-30 of itself: a sum of squares): the cell
    /// solver's integrands where their rounding in double is what keeps the drift from the
    /// tolerance ([`Body::reduction_double_double`]).
    fn potential_and_contact_distance_sq_double_double(
        &self,
        _sin: DoubleDouble,
        _cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64, DoubleDouble)> {
        None
    }
}

/// An ellipsoid of revolution with semi-axes b1 = β (equatorial) and b3 = 1 (axial), its
/// centre of mass displaced by α along +e3 from the geometric centre (paper §3, `r`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    /// α = a / b3, the displacement of the centre of mass along +e3.
    pub alpha: f64,
    /// β = b1 / b3: β < 1 prolate, β > 1 oblate, β = 1 sphere.
    pub beta: f64,
}

impl Ellipsoid {
    /// A validated ellipsoid: −1 < α < 1 (α < 0 is the mirror image θ → π − θ), β > 0.
    pub fn new(alpha: f64, beta: f64) -> Result<Self> {
        check_range(
            "alpha",
            alpha,
            Some((-1.0, false)),
            Some((1.0, false)),
            "must satisfy -1 < alpha < 1 (the centre of mass inside the body)",
        )?;
        // β² enters U, B and the critical set: beyond 1.3e154 it overflows (a cell at
        // β = 1e200 had "no motion" where it moves). The same bound as κ's.
        check_range(
            "beta",
            beta,
            Some((0.0, false)),
            Some((MAX_KAPPA, true)),
            "must satisfy 0 < beta <= 1e150 (beta^2 must be a double)",
        )?;
        Ok(Self { alpha, beta })
    }

    /// Z(θ) = √(β² sin²θ + cos²θ): height of the geometric centre above the plane.
    #[inline]
    pub fn centre_height(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        (self.beta * self.beta * s * s + c * c).sqrt()
    }

    /// (U, w) = (Z + α cosθ, cosθ + αZ) at an angle, with Z = `z`, to full relative precision
    /// also where they cancel (α cosθ < 0 and |α| → 1: near θ = π for α → 1, near θ = 0 for
    /// α → −1): with L = β² sin²θ / (Z + |cosθ|) = Z − |cosθ| (from Z² − cos²θ = β² sin²θ),
    /// Z + α cosθ = L + (1 − |α|)|cosθ| and cosθ + αZ = sgn α (L − (1 − |α|) Z) (1 − |α| is
    /// exact for |α| ≥ ½).
    #[inline]
    pub fn height_and_offset_at(&self, a: Angle, z: f64) -> (f64, f64) {
        // For |α| ≤ ½, Z + α cosθ ≥ Z/2 (Z ≥ |cosθ|): no cancellation, and a symmetric
        // body (α = 0) keeps U(π − θ) = U(θ) exactly.
        if self.alpha * a.cos >= 0.0 || self.alpha.abs() <= 0.5 {
            return (z + self.alpha * a.cos, a.cos + self.alpha * z);
        }
        let lift = self.lift(a, z);
        let rest = 1.0 - self.alpha.abs();
        (
            lift + rest * a.cos.abs(),
            self.alpha.signum() * (lift - rest * z),
        )
    }

    /// L = Z − |cosθ| = β² sin²θ / (Z + |cosθ|) (from Z² − cos²θ = β² sin²θ), without
    /// cancellation, with Z = `z`: the part of U = L + (1 − |α|)|cosθ| left where Z and
    /// α cosθ cancel.
    #[inline]
    fn lift(&self, a: Angle, z: f64) -> f64 {
        self.beta * self.beta * a.sin * a.sin / (z + a.cos.abs())
    }

    /// Whether Z and α cosθ cancel where U′ and the divided differences of U are formed:
    /// a prolate body (β < 1, so Z ≈ |cosθ| away from θ = π/2) with |α| > ½, on the side
    /// where α cosθ < 0 (beyond π/2 for α > 0, before it for α < 0).
    #[inline]
    fn cancels(&self, a: Angle) -> bool {
        self.beta < 1.0 && self.alpha.abs() > 0.5 && self.alpha * a.cos < 0.0
    }

    /// Z at an angle given by its sine and cosine.
    #[inline]
    pub fn centre_height_at(&self, a: Angle) -> f64 {
        (self.beta * self.beta * a.sin * a.sin + a.cos * a.cos).sqrt()
    }

    /// Z and U = Z + α cosθ in double-double at the angle whose sine and cosine are `sin` and
    /// `cos`, with the bound on U's error ([`Shape::potential_double_double`]).
    #[inline(always)]
    fn height_double_double(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> (DoubleDouble, DoubleDouble, f64) {
        let bs = sin.mul_f64(self.beta);
        let z = bs.mul(bs).add_same_sign(cos.mul(cos)).sqrt();
        let offset = cos.mul_f64(self.alpha);
        let error = crate::dd::RELATIVE_ERROR * (z.hi + offset.hi.abs());
        (z, z.add(offset), error)
    }

    /// β² − 1 as (β − 1)(β + 1): within two ulps of itself (β − 1 is exact by Sterbenz's lemma
    /// for β in [½, 2]), where β·β − 1 loses the digits of β² below an ulp of 1 (near a sphere,
    /// β = 0.9989: 5e-14 of itself, a systematic error of U′ and of T at tight tolerances; a
    /// shallow well of whole-domain seed 77 had T 1.1e-14 off).
    #[inline]
    pub fn beta_squared_less_one(&self) -> f64 {
        (self.beta - 1.0) * (self.beta + 1.0)
    }

    /// Z′(θ) = (β² − 1) sinθ cosθ / Z.
    #[inline]
    pub fn centre_height_prime(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        self.beta_squared_less_one() * s * c / self.centre_height(theta)
    }
}

impl Shape for Ellipsoid {
    /// α = 0: the centre of mass at the geometric centre.
    fn symmetric_about_equator(&self) -> bool {
        self.alpha == 0.0
    }

    /// χ1 = −β²/Z, χ2 = −cosθ/Z − α (paper §3, remark after `r`, in units of b3).
    fn chi(&self, theta: f64) -> (f64, f64) {
        let z = self.centre_height(theta);
        (-self.beta * self.beta / z, -theta.cos() / z - self.alpha)
    }

    fn chi_prime(&self, theta: f64) -> (f64, f64) {
        let z = self.centre_height(theta);
        let zp = self.centre_height_prime(theta);
        let (s, c) = theta.sin_cos();
        (
            self.beta * self.beta * zp / (z * z),
            s / z + c * zp / (z * z),
        )
    }

    /// r = −𝐁γ / √(γ, 𝐁γ) − α e3 with 𝐁 = diag(β², β², 1) (paper `r`).
    fn contact_point(&self, gamma: &Vector3<f64>) -> Vector3<f64> {
        let b2 = self.beta * self.beta;
        let bg = Vector3::new(b2 * gamma.x, b2 * gamma.y, gamma.z);
        let s = gamma.dot(&bg).sqrt();
        Vector3::new(-bg.x / s, -bg.y / s, -bg.z / s - self.alpha)
    }

    /// ṙ = −𝐁γ̇/s + 𝐁γ (γ, 𝐁γ̇)/s³ with s = √(γ, 𝐁γ).
    fn contact_point_rate(&self, gamma: &Vector3<f64>, gamma_dot: &Vector3<f64>) -> Vector3<f64> {
        let b2 = self.beta * self.beta;
        let bg = Vector3::new(b2 * gamma.x, b2 * gamma.y, gamma.z);
        let bgd = Vector3::new(b2 * gamma_dot.x, b2 * gamma_dot.y, gamma_dot.z);
        let s2 = gamma.dot(&bg);
        let s = s2.sqrt();
        -bgd / s + bg * (gamma.dot(&bgd) / (s2 * s))
    }

    /// U′(θ) = −α sinθ + (β² − 1) sinθ cosθ / Z.
    #[inline]
    fn potential_prime(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        -self.alpha * s + self.beta_squared_less_one() * s * c / self.centre_height(theta)
    }

    // U(θ) = Z(θ) + α cosθ; U″(θ) = −α cosθ + (β² − 1) [cos 2θ / Z − sinθ cosθ Z′ / Z²];
    // |r|² = (β⁴ sin²θ + (cosθ + αZ)²) / Z² (docs/model.md; the paper's `eqsysell` prints
    // (αZ − cosθ)², a misprint): from their forms at (sinθ, cosθ) below.
    theta_forms!(
        potential => potential_at,
        potential_second => potential_second_at,
        contact_distance_sq => contact_distance_sq_at,
    );

    #[inline]
    fn potential_at(&self, a: Angle) -> f64 {
        self.height_and_offset_at(a, self.centre_height_at(a)).0
    }

    #[inline]
    fn potential_prime_at(&self, a: Angle) -> f64 {
        a.sin * self.potential_prime_over_sin_at(a)
    }

    /// |sinθ| times the sizes of the two terms of [`Shape::potential_prime_over_sin_at`]: they
    /// cancel where β² − 1 ≈ α at a pole (U″ = β² − 1 − α there), where U′ in double is off
    /// by thousands of ulps of itself (a libration round θ = 0 at α = 0.5, β² − 1 − α = 3e-4:
    /// the limit of the integrand at its turning points, weighted half a step, put T 1.6
    /// times its estimate off at tol 1e-12; an adversary pass).
    #[inline]
    fn potential_prime_scale_at(&self, a: Angle) -> f64 {
        let z = self.centre_height_at(a);
        let terms = if self.cancels(a) {
            (1.0 - self.alpha.abs()) + (self.lift(a, z) + self.beta * self.beta * a.cos.abs()) / z
        } else {
            (self.beta_squared_less_one() * a.cos / z).abs() + self.alpha.abs()
        };
        a.sin.abs() * terms
    }

    /// U″ = −α cosθ + (β² − 1) [(cos²θ − sin²θ) / Z − sinθ cosθ Z′ / Z²]. Where Z and
    /// α cosθ cancel ([`Ellipsoid::cancels`]), U = L + (1 − |α|) c with c = |cosθ| and
    /// L = Z − c, and U″ = L″ − (1 − |α|) c with
    /// L″ = Z″ + c = [c L (Z² + Z c + c²) + β² cos⁴θ + β² (1 − β²) sin⁴θ] / Z³, every term
    /// positive (from Z″ = (β² − 1)(cos²θ − sin²θ + (1 − β²) sin⁴θ) / Z³); the plain form
    /// was 1e-12 off at the bottom of the well at α = 0.999999, β = 0.0068.
    #[inline]
    fn potential_second_at(&self, a: Angle) -> f64 {
        let z = self.centre_height_at(a);
        if self.cancels(a) {
            let b2 = self.beta * self.beta;
            let c = a.cos.abs();
            let lift = self.lift(a, z);
            let (c2, s2) = (c * c, a.sin * a.sin);
            let lift_second = (c * lift * (z * z + z * c + c2) + b2 * c2 * c2
                - b2 * self.beta_squared_less_one() * s2 * s2)
                / (z * z * z);
            return lift_second - (1.0 - self.alpha.abs()) * c;
        }
        let b = self.beta_squared_less_one();
        let zp = b * a.sin * a.cos / z;
        -self.alpha * a.cos
            + b * ((a.cos * a.cos - a.sin * a.sin) / z - a.sin * a.cos * zp / (z * z))
    }

    /// Z varies on the scale β near the equator of a prolate ellipsoid and 1/β near the
    /// poles of an oblate one.
    fn angular_feature_scale(&self) -> f64 {
        self.beta.min(1.0 / self.beta)
    }

    /// A needle's Z = √(β² sin²θ + cos²θ) turns within β of π/2 (its singularities lie at
    /// π/2 ± i artanh β … about ±iβ off the real axis).
    fn feature_angles(&self) -> Vec<f64> {
        if self.beta < 0.1 {
            vec![std::f64::consts::FRAC_PI_2]
        } else {
            Vec::new()
        }
    }

    /// U′ = sinθ ((β² − 1) cosθ / Z − α) = 0 off the poles where (β² − 1) cosθ = α Z:
    /// cos²θ = α²β² / ((β² − 1)(β² − 1 + α²)), cosθ of the sign of α (β² − 1) (π/2 at
    /// α = 0).
    fn slope_zeros(&self) -> Vec<f64> {
        let b = self.beta_squared_less_one();
        if b == 0.0 {
            // (The sphere: U′ = −α sinθ, zero only at the poles, or everywhere at α = 0.)
            return Vec::new();
        }
        let c2 =
            self.alpha * self.alpha * self.beta * self.beta / (b * (b + self.alpha * self.alpha));
        if !(0.0..1.0).contains(&c2) {
            return Vec::new();
        }
        let c = c2.sqrt() * (self.alpha * b).signum();
        vec![c.acos()]
    }

    /// U′/sinθ = (β² − 1) cosθ / Z − α; where its two terms cancel ([`Ellipsoid::cancels`]),
    /// with c = |cosθ| and L = Z − c = β² sin²θ / (Z + c), the same as
    /// sgn α ((1 − |α|) − (L + β² c) / Z), whose terms are all small.
    #[inline]
    fn potential_prime_over_sin_at(&self, a: Angle) -> f64 {
        let z = self.centre_height_at(a);
        let b2 = self.beta * self.beta;
        if self.cancels(a) {
            let lift = self.lift(a, z);
            return self.alpha.signum()
                * ((1.0 - self.alpha.abs()) - (lift + b2 * a.cos.abs()) / z);
        }
        self.beta_squared_less_one() * a.cos / z - self.alpha
    }

    #[inline]
    fn contact_distance_sq_at(&self, a: Angle) -> f64 {
        self.potential_and_contact_distance_sq_at(a).1
    }

    /// (U(x) − U(y)) / sin(x − y) without cancellation, from Z(x)² − Z(y)² = (β² − 1)
    /// sin(x − y) sin(x + y) and cos x − cos y = −sin(x − y) (sin x + sin y) / (1 + cos(x − y)):
    /// (β² − 1) sin(x + y) / (Z(x) + Z(y)) − α (sin x + sin y) / (1 + cos(x − y)).
    ///
    /// Where U cancels at both points ([`Ellipsoid::cancels`]), those two terms are each of
    /// order 1 against a difference of order U, so U = L + (1 − |α|) c is differenced
    /// instead (c = |cosθ|, L = β² sin²θ / D, D = Z + c): with E = (D(x) − D(y)) / sin(x − y)
    /// = (β² − 1) sin(x + y) / (Z(x) + Z(y)) + sgn α (sin x + sin y) / (1 + cos(x − y)),
    /// (L(x) − L(y)) / sin(x − y) = (β² sin(x + y) − L(y) E) / D(x), and
    /// (c(x) − c(y)) / sin(x − y) = sgn α (sin x + sin y) / (1 + cos(x − y)). For β < 1 the
    /// two parts of E, and the two of the numerator, have one sign (issue 12: at α = 0.999999,
    /// β = 0.0068 the plain form put a turning point 240 ulps off).
    #[inline]
    fn potential_divided_difference(
        &self,
        x: Angle,
        y: Angle,
        _sin_diff: f64,
        cos_diff: f64,
    ) -> (f64, f64) {
        let b2 = self.beta * self.beta;
        let sin_sum = x.sin * y.cos + x.cos * y.sin;
        let (zx, zy) = (self.centre_height_at(x), self.centre_height_at(y));
        let shape = self.beta_squared_less_one() * sin_sum / (zx + zy);
        if self.cancels(x) && self.cancels(y) {
            let cdd = self.alpha.signum() * (x.sin + y.sin) / (1.0 + cos_diff);
            let e = shape + cdd;
            let lift_dd = (b2 * sin_sum - self.lift(y, zy) * e) / (zx + x.cos.abs());
            let rest = (1.0 - self.alpha.abs()) * cdd;
            return (lift_dd + rest, lift_dd.abs() + rest.abs());
        }
        let offset = self.alpha * (x.sin + y.sin) / (1.0 + cos_diff);
        (shape - offset, shape.abs() + offset.abs())
    }

    /// U = Z + α cosθ with Z = √(β² sin²θ + cos²θ), to a few units of 2⁻¹⁰⁶ of Z + |α cosθ|
    /// (a relative error of U that grows as the two terms cancel).
    fn potential_double_double(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64)> {
        let (_, u, error) = self.height_double_double(sin, cos);
        Some((u, error))
    }

    /// U as [`Shape::potential_double_double`], and |r|² = U² + U′² with
    /// U′ = sinθ ((β² − 1) cosθ / Z − α) (β² − 1 exact in double-double: β·β is a double's
    /// exact product). None where a term overflows (β beyond about 1e77).
    #[inline(always)]
    fn potential_and_contact_distance_sq_double_double(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64, DoubleDouble)> {
        let (z, u, error) = self.height_double_double(sin, cos);
        let b = DoubleDouble::from_f64(self.beta)
            .mul_f64(self.beta)
            .add_f64(-1.0);
        let slope = sin.mul(b.mul(cos).div(z).add_f64(-self.alpha));
        let r2 = u.mul(u).add_same_sign(slope.mul(slope));
        (r2.hi.is_finite() && r2.lo.is_finite()).then_some((u, error, r2))
    }

    #[inline]
    fn potential_and_contact_distance_sq_at(&self, a: Angle) -> (f64, f64) {
        let z = self.centre_height_at(a);
        let b2 = self.beta * self.beta;
        let (u, w) = self.height_and_offset_at(a, z);
        // |r|² = (β⁴ sin²θ + w²)/Z², each part scaled by 1/Z before squaring: β⁴ overflows
        // beyond β = 1e77, where |r| is still below 1e154 (the diagram's N at the bottom came
        // out +inf there, from B = inf).
        let inv_z = 1.0 / z;
        let (horizontal, vertical) = (b2 * a.sin * inv_z, w * inv_z);
        (u, horizontal * horizontal + vertical * vertical)
    }
}

/// A body: a shape and its mass distribution, in the paper's dimensionless units
/// (unit of length b3, of mass m, of time √(b3/g)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body<S: Shape> {
    /// The surface and the position of the centre of mass.
    pub shape: S,
    /// ν = i3 / i1, axial over equatorial central moment of inertia, 0 < ν ≤ 2.
    pub nu: f64,
    /// η = m b3² / i1 > 0.
    pub eta: f64,
}

/// U, B and J at one angle: everything the reduction takes from the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reduction {
    /// U, the height of the centre of mass.
    pub potential: f64,
    /// B = 1/η + |r|².
    pub reduced_inertia: f64,
    /// J = √((cos²θ + ν sin²θ)/η + U²).
    pub integral_factor: f64,
}

/// [`Reduction`] in double-double ([`Body::reduction_double_double`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReductionDoubleDouble {
    /// U.
    pub potential: DoubleDouble,
    /// A bound on the absolute error of U (its terms may cancel).
    pub potential_error: f64,
    /// η B = 1 + η |r|².
    pub scaled_inertia: DoubleDouble,
    /// η J² = cos²θ + ν sin²θ + η U².
    pub scaled_integral_factor_sq: DoubleDouble,
}

/// The paper's body: an ellipsoid of revolution.
pub type EllipsoidBody = Body<Ellipsoid>;

impl EllipsoidBody {
    /// A validated ellipsoid body from the four dimensionless parameters (α, β, ν, η).
    pub fn ellipsoid(alpha: f64, beta: f64, nu: f64, eta: f64) -> Result<Self> {
        Body::new(Ellipsoid::new(alpha, beta)?, nu, eta)
    }
}

impl<S: Shape> Body<S> {
    /// A body with validated mass parameters: 0 < ν ≤ 2, η > 0.
    pub fn new(shape: S, nu: f64, eta: f64) -> Result<Self> {
        check_range(
            "nu",
            nu,
            Some((0.0, false)),
            Some((2.0, true)),
            "must satisfy 0 < nu <= 2 (i3 <= i1 + i2 = 2 i1)",
        )?;
        // A subnormal ν is zero to every sum it enters, and makes each one slow.
        if nu > 0.0 && nu < f64::MIN_POSITIVE {
            return Err(AtlasError::InvalidParameter {
                name: "nu",
                value: nu,
                reason: "is subnormal: nu must be >= 2.2250738585072014e-308 (the least normal \
                         double)",
            });
        }
        check_range("eta", eta, Some((0.0, false)), None, "must be > 0")?;
        // The inertia 1/η must be a number: below 5.6e-309 it overflows to infinity.
        if !(1.0 / eta).is_finite() {
            return Err(AtlasError::InvalidParameter {
                name: "eta",
                value: eta,
                reason: "is so small that 1/eta overflows: eta must be >= 5.6e-309",
            });
        }
        Ok(Self { shape, nu, eta })
    }

    /// The central inertia tensor, diag(1/η, 1/η, ν/η), in units of m b3².
    pub fn inertia(&self) -> Vector3<f64> {
        Vector3::new(1.0 / self.eta, 1.0 / self.eta, self.nu / self.eta)
    }

    /// B(θ) = 1/η + |r|²: the inertia of the reduced θ-motion (paper `eqsys`).
    #[inline]
    pub fn reduced_inertia(&self, theta: f64) -> f64 {
        1.0 / self.eta + self.shape.contact_distance_sq(theta)
    }

    /// B′(θ) = d|r|²/dθ.
    #[inline]
    pub fn reduced_inertia_prime(&self, theta: f64) -> f64 {
        self.shape.contact_distance_sq_prime(theta)
    }

    /// U, B and J at one angle, sharing the work (the cell solver's inner loop).
    #[inline]
    pub fn reduction_at(&self, a: Angle) -> Reduction {
        let (potential, r2) = self.shape.potential_and_contact_distance_sq_at(a);
        let j2 = (a.cos * a.cos + self.nu * a.sin * a.sin) / self.eta + potential * potential;
        Reduction {
            potential,
            reduced_inertia: 1.0 / self.eta + r2,
            integral_factor: j2.sqrt(),
        }
    }

    /// U (with the bound on its error of [`Shape::potential_double_double`]), η B and η J² in
    /// double-double at the angle whose sine and cosine are `sin` and `cos`, for shapes that
    /// provide |r|² so (the ellipsoid): η B = 1 + η |r|² and η J² = cos²θ + ν sin²θ + η U² to
    /// about 1e-29 of themselves (sums of positive terms), scaled by η so that no quotient is
    /// needed. None for other shapes, or where a term overflows.
    #[inline(always)]
    pub fn reduction_double_double(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> Option<ReductionDoubleDouble> {
        let (potential, potential_error, r2) = self
            .shape
            .potential_and_contact_distance_sq_double_double(sin, cos)?;
        let scaled_inertia = r2.mul_f64(self.eta).add_f64(1.0);
        let axial = sin.mul(sin).mul_f64(self.nu).add_same_sign(cos.mul(cos));
        let scaled_integral_factor_sq =
            axial.add_same_sign(potential.mul(potential).mul_f64(self.eta));
        let finite = |x: DoubleDouble| x.hi.is_finite() && x.lo.is_finite();
        (finite(scaled_inertia)
            && finite(scaled_integral_factor_sq)
            && scaled_integral_factor_sq.hi > 0.0)
            .then_some(ReductionDoubleDouble {
                potential,
                potential_error,
                scaled_inertia,
                scaled_integral_factor_sq,
            })
    }

    /// J(θ) = √((cos²θ + ν sin²θ)/η + U²): the integral F2 = J ω3 (paper §2.3 `sec_inv`,
    /// with (r, γ) = −U).
    #[inline]
    pub fn integral_factor(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let u = self.shape.potential(theta);
        ((c * c + self.nu * s * s) / self.eta + u * u).sqrt()
    }
}

/// A body of any supported shape: what the command line passes around (the solvers are
/// generic over [`Shape`]; [`with_body!`](crate::with_body) calls one with the shape inside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyBody {
    /// The paper's ellipsoid of revolution (α, β).
    Ellipsoid(EllipsoidBody),
    /// A disk, a truncated ball or a wheel (α and the cut h).
    Edged(Body<EdgedShape>),
    /// A body of the user's own profile (α, the height of the centre of mass on the axis).
    Profile(Body<ProfileShape>),
}

impl AnyBody {
    /// The validated body of `kind` (None: the ellipsoid), with centre-of-mass offset α,
    /// `second` = β of the ellipsoid or the cut h of a cut ball (ignored by the disk), and
    /// mass parameters ν, η.
    pub fn new(
        kind: Option<EdgedKind>,
        alpha: f64,
        second: f64,
        nu: f64,
        eta: f64,
    ) -> Result<Self> {
        Ok(match kind {
            None => AnyBody::Ellipsoid(EllipsoidBody::ellipsoid(alpha, second, nu, eta)?),
            Some(EdgedKind::Profile(p)) => {
                AnyBody::Profile(Body::new(ProfileShape::new(p, alpha)?, nu, eta)?)
            }
            Some(kind) => AnyBody::Edged(Body::new(EdgedShape::of(kind, alpha, second)?, nu, eta)?),
        })
    }

    /// The kind of edged body, None for the ellipsoid.
    pub fn kind(&self) -> Option<EdgedKind> {
        match self {
            AnyBody::Ellipsoid(_) => None,
            AnyBody::Edged(b) => Some(b.shape.kind),
            AnyBody::Profile(b) => Some(EdgedKind::Profile(b.shape.profile)),
        }
    }

    /// The shape's name: `ellipsoid`, `disk`, `truncated_ball` or `wheel`.
    pub fn shape_name(&self) -> &'static str {
        shape_name(self.kind())
    }

    /// The shape's parameters by name, as the command line, the JSON and the files name
    /// them: (α, β) of the ellipsoid, α of the disk, (α, cut) of the cut balls.
    pub fn shape_parameters(&self) -> Vec<(&'static str, f64)> {
        let (alpha, second) = match self {
            AnyBody::Ellipsoid(b) => (b.shape.alpha, b.shape.beta),
            AnyBody::Edged(b) => (b.shape.alpha, b.shape.cut),
            AnyBody::Profile(b) => (b.shape.alpha, 0.0),
        };
        std::iter::once(("alpha", alpha))
            .chain(second_parameter(self.kind()).map(|name| (name, second)))
            .collect()
    }
}

/// Every shape's name, the ellipsoid first (scenes, the package and the command line).
pub const SHAPE_NAMES: [&str; 5] = ["ellipsoid", "disk", "truncated_ball", "wheel", "profile"];

/// The shape of that name: Some(None) for the ellipsoid, Some(kind) for an edged body, None
/// for an unknown name.
pub fn shape_kind(name: &str) -> Option<Option<EdgedKind>> {
    if name == "ellipsoid" {
        Some(None)
    } else {
        EdgedKind::from_name(name).map(Some)
    }
}

/// The name of the shape `kind` (None: the ellipsoid).
pub fn shape_name(kind: Option<EdgedKind>) -> &'static str {
    kind.map_or("ellipsoid", |k| k.name())
}

/// The shape's parameter beside α, as files and scenes name it: β of the ellipsoid, the cut of
/// the truncated ball and the wheel; none for the disk.
pub fn second_parameter(kind: Option<EdgedKind>) -> Option<&'static str> {
    match kind {
        None => Some("beta"),
        Some(EdgedKind::Disk) | Some(EdgedKind::Profile(_)) => None,
        Some(_) => Some("cut"),
    }
}

/// `with_body!(any, b => expression)`: the expression with `b` bound to the `&Body<S>` inside
/// an [`AnyBody`] reference, whatever its shape.
#[macro_export]
macro_rules! with_body {
    ($body:expr, $b:ident => $e:expr) => {
        match $body {
            $crate::body::AnyBody::Ellipsoid($b) => $e,
            $crate::body::AnyBody::Edged($b) => $e,
            $crate::body::AnyBody::Profile($b) => $e,
        }
    };
}
