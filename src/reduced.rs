//! The reduced system with one degree of freedom (paper `eqsys`), on the level set F0 = 1,
//! F1 = 0, F2 = κ, and the quadratures that rebuild the rest of the motion from θ(t): the
//! angles φ and ψ (`dfi`, `dpsi`), the angular velocity (`w12`) and the paths of the centre of
//! mass and of the contact point on the plane.

use crate::body::{Body, Shape};
use nalgebra::Vector3;

/// The θ-motion of a body at a fixed value κ of the linear integral F2 = J(θ) ω3.
#[derive(Debug)]
pub struct ReducedSystem<'a, S: Shape> {
    /// The body.
    pub body: &'a Body<S>,
    /// κ, the value of F2 (its sign is the direction of rolling).
    pub kappa: f64,
}

impl<S: Shape> Clone for ReducedSystem<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S: Shape> Copy for ReducedSystem<'_, S> {}

impl<'a, S: Shape> ReducedSystem<'a, S> {
    /// The reduced system of `body` at F2 = `kappa`.
    pub fn new(body: &'a Body<S>, kappa: f64) -> Self {
        Self { body, kappa }
    }

    /// Effective potential V(θ) = κ² / (2 sin²θ) + U(θ).
    #[inline]
    pub fn effective_potential(&self, theta: f64) -> f64 {
        let u = self.body.shape.potential(theta);
        if self.kappa == 0.0 {
            return u; // κ = 0: V = U on the whole circle, poles included
        }
        // (κ/sinθ)², not κ²/sin²θ: both underflow to 0/0 next to a pole at tiny κ.
        let w = self.kappa / theta.sin();
        0.5 * w * w + u
    }

    /// V′(θ) = −κ² cosθ / sin³θ + U′(θ).
    #[inline]
    pub fn effective_potential_prime(&self, theta: f64) -> f64 {
        let up = self.body.shape.potential_prime(theta);
        if self.kappa == 0.0 {
            return up;
        }
        let (s, c) = theta.sin_cos();
        let w = self.kappa / s;
        -w * w * c / s + up
    }

    /// V″(θ) = κ² (sin²θ + 3 cos²θ) / sin⁴θ + U″(θ).
    #[inline]
    pub fn effective_potential_second(&self, theta: f64) -> f64 {
        let upp = self.body.shape.potential_second(theta);
        if self.kappa == 0.0 {
            return upp;
        }
        let (s, c) = theta.sin_cos();
        let w = self.kappa / s;
        w * w * (1.0 + 3.0 * (c / s) * (c / s)) + upp
    }

    /// Energy ε = B(θ) p² / 2 + V(θ) (paper §2.3, below `eqsys`).
    #[inline]
    pub fn energy(&self, theta: f64, theta_dot: f64) -> f64 {
        0.5 * self.body.reduced_inertia(theta) * theta_dot * theta_dot
            + self.effective_potential(theta)
    }

    /// θ̈ = [κ² cosθ / sin³θ − B′(θ) p² / 2 − U′(θ)] / B(θ) (paper `eqsys`).
    #[inline]
    pub fn theta_acceleration(&self, theta: f64, theta_dot: f64) -> f64 {
        let g = -self.effective_potential_prime(theta)
            - 0.5 * self.body.reduced_inertia_prime(theta) * theta_dot * theta_dot;
        g / self.body.reduced_inertia(theta)
    }

    /// ω3 = κ / J(θ).
    #[inline]
    pub fn omega3(&self, theta: f64) -> f64 {
        self.kappa / self.body.integral_factor(theta)
    }

    /// φ̇ = ω3 / sin²θ = κ / (J sin²θ) (paper `dfi`).
    #[inline]
    pub fn phi_rate(&self, theta: f64) -> f64 {
        if self.kappa == 0.0 {
            return 0.0; // the axis passes through the vertical: φ and ψ stay put
        }
        let s = theta.sin();
        self.omega3(theta) / (s * s)
    }

    /// ψ̇ = −κ cosθ / (J sin²θ) (paper `dpsi`).
    #[inline]
    pub fn psi_rate(&self, theta: f64) -> f64 {
        -self.phi_rate(theta) * theta.cos()
    }

    /// The angular velocity in the body frame (paper `w12`):
    /// ω1 = p cosφ − ω3 cotθ sinφ, ω2 = −p sinφ − ω3 cotθ cosφ, ω3 = κ/J.
    pub fn angular_velocity(&self, theta: f64, theta_dot: f64, phi: f64) -> Vector3<f64> {
        let w3 = self.omega3(theta);
        // ω3 cotθ, which is 0 (not 0·∞) when κ = 0 and the axis is vertical.
        let spin = if w3 == 0.0 {
            0.0
        } else {
            w3 * theta.cos() / theta.sin()
        };
        let (sf, cf) = phi.sin_cos();
        Vector3::new(theta_dot * cf - spin * sf, -theta_dot * sf - spin * cf, w3)
    }

    /// Velocity of the centre of mass on the plane, ζ̇ = ẋ_c + i ẏ_c:
    /// ζ̇ = −U(θ) e^{iψ} (κ / (J sinθ) + i p), from ṙ_c = Qᵀ v, v = −ω × r (`kin`, `constr`)
    /// with the Euler-angle matrix Q of paper §4. The paper keeps only the κ-part; docs/model.md
    /// prints the opposite overall sign. This sign is the one the full system gives (tested),
    /// and the one of the paper's own circle x_c = ρ_c sinψ, y_c = −ρ_c cosψ. Returns (ẋ_c, ẏ_c).
    #[inline]
    pub fn centre_velocity(&self, theta: f64, theta_dot: f64, psi: f64) -> (f64, f64) {
        let u = self.body.shape.potential(theta);
        let along = if self.kappa == 0.0 {
            0.0
        } else {
            self.kappa / (self.body.integral_factor(theta) * theta.sin())
        };
        let (sp, cp) = psi.sin_cos();
        // −U e^{iψ} (a + i p) = −U[(a cosψ − p sinψ) + i (a sinψ + p cosψ)]
        (
            -u * (along * cp - theta_dot * sp),
            -u * (along * sp + theta_dot * cp),
        )
    }

    /// Position of the contact point relative to the centre of mass, on the plane:
    /// (x_p − x_c, y_p − y_c) = U′(θ) (sinψ, −cosψ), from r_p = r_c + Qᵀ r (paper `rp`).
    #[inline]
    pub fn contact_offset(&self, theta: f64, psi: f64) -> (f64, f64) {
        let d = self.body.shape.potential_prime(theta);
        let (sp, cp) = psi.sin_cos();
        (d * sp, -d * cp)
    }
}
