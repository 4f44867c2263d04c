//! The rolling body: its surface of revolution (behind the [`Shape`] trait) and its mass
//! distribution (ν, η). Everything the reduction of paper §2.3 (`oned`) needs comes from here:
//! the potential U(θ), the reduced inertia B(θ) and the function J(θ) of the integral F2.
//!
//! A body of revolution touches the plane at r(γ) = (χ1 γ1, χ1 γ2, χ2) in the body frame
//! (paper §2.2, with the compatibility relation dχ2/dγ3 = χ1 − (1 − γ3²)/γ3 · dχ1/dγ3 of
//! `hier2002`). A new body (a torus, a truncated sphere, a disk with a rounded rim) is one new
//! implementation of [`Shape`]; every derived quantity has a generic default built from χ1, χ2.

use crate::error::{check_range, Result};
use nalgebra::Vector3;

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
        check_range("beta", beta, Some((0.0, false)), None, "must be > 0")?;
        Ok(Self { alpha, beta })
    }

    /// Z(θ) = √(β² sin²θ + cos²θ): height of the geometric centre above the plane.
    #[inline]
    pub fn centre_height(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        (self.beta * self.beta * s * s + c * c).sqrt()
    }

    /// Z′(θ) = (β² − 1) sinθ cosθ / Z.
    #[inline]
    pub fn centre_height_prime(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        (self.beta * self.beta - 1.0) * s * c / self.centre_height(theta)
    }
}

impl Shape for Ellipsoid {
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

    /// U(θ) = Z(θ) + α cosθ.
    #[inline]
    fn potential(&self, theta: f64) -> f64 {
        self.centre_height(theta) + self.alpha * theta.cos()
    }

    /// U′(θ) = −α sinθ + (β² − 1) sinθ cosθ / Z.
    #[inline]
    fn potential_prime(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        -self.alpha * s + (self.beta * self.beta - 1.0) * s * c / self.centre_height(theta)
    }

    /// U″(θ) = −α cosθ + (β² − 1) [cos 2θ / Z − sinθ cosθ Z′ / Z²].
    #[inline]
    fn potential_second(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let z = self.centre_height(theta);
        let zp = (self.beta * self.beta - 1.0) * s * c / z;
        -self.alpha * c
            + (self.beta * self.beta - 1.0) * ((c * c - s * s) / z - s * c * zp / (z * z))
    }

    /// |r|² = (β⁴ sin²θ + (cosθ + αZ)²) / Z² (SPEC §1.2; the paper's `eqsysell` prints
    /// (αZ − cosθ)², a misprint).
    #[inline]
    fn contact_distance_sq(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let z = self.centre_height(theta);
        let b2 = self.beta * self.beta;
        let w = c + self.alpha * z;
        (b2 * b2 * s * s + w * w) / (z * z)
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
        check_range("eta", eta, Some((0.0, false)), None, "must be > 0")?;
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

    /// J(θ) = √((cos²θ + ν sin²θ)/η + U²): the integral F2 = J ω3 (paper §2.3 `sec_inv`,
    /// with (r, γ) = −U).
    #[inline]
    pub fn integral_factor(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let u = self.shape.potential(theta);
        ((c * c + self.nu * s * s) / self.eta + u * u).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoid_rejects_out_of_range_parameters() {
        assert!(Ellipsoid::new(1.0, 2.0).is_err());
        assert!(Ellipsoid::new(0.2, 0.0).is_err());
        assert!(Ellipsoid::new(f64::NAN, 1.0).is_err());
        assert!(Ellipsoid::new(0.2, f64::INFINITY).is_err());
        assert!(Body::new(Ellipsoid::new(0.5, 3.0).unwrap(), 2.5, 1.0).is_err());
        assert!(Body::new(Ellipsoid::new(0.5, 3.0).unwrap(), 0.5, -1.0).is_err());
        assert!(EllipsoidBody::ellipsoid(0.5, 3.0, 2.0, 0.5).is_ok());
    }
}
