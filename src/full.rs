//! The full equations of motion in redundant variables (paper `eqred`), with the kinematic
//! relations (`kin`) that carry the orientation and the position of the centre of mass.
//! This is the independent reference against which the reduced system and its quadratures are
//! tested, and the `--model full` of `rubber-atlas trajectory`.
//!
//! State (14 numbers): ω, γ, the body images α, β of the fixed horizontal axes, and x_c, y_c.

use crate::body::{Body, Shape};
use crate::reduced::ReducedSystem;
use nalgebra::{Matrix3, SVector, Vector3};

/// Length of the full state vector.
pub const FULL_STATE_LEN: usize = 14;

/// The full state: [ω (3), γ (3), α (3), β (3), x_c, y_c].
pub type FullState = SVector<f64, FULL_STATE_LEN>;

/// The four first integrals of `eqred` (paper §2.3 `sec_inv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullIntegrals {
    /// ℰ = ½ (𝐉ω, ω) − (r, γ).
    pub energy: f64,
    /// F0 = (γ, γ) = 1.
    pub geometric: f64,
    /// F1 = (ω, γ) = 0 (no spinning).
    pub no_spin: f64,
    /// F2 = J(γ3) ω3 = κ.
    pub linear: f64,
}

/// The body-frame vectors of a full state.
#[derive(Debug, Clone, Copy)]
pub struct FullParts {
    pub omega: Vector3<f64>,
    pub gamma: Vector3<f64>,
    pub alpha: Vector3<f64>,
    pub beta: Vector3<f64>,
    pub x_c: f64,
    pub y_c: f64,
}

impl FullParts {
    /// Splits a state vector.
    pub fn of(y: &FullState) -> Self {
        Self {
            omega: Vector3::new(y[0], y[1], y[2]),
            gamma: Vector3::new(y[3], y[4], y[5]),
            alpha: Vector3::new(y[6], y[7], y[8]),
            beta: Vector3::new(y[9], y[10], y[11]),
            x_c: y[12],
            y_c: y[13],
        }
    }
}

/// The full system of a body.
#[derive(Debug, Clone, Copy)]
pub struct FullSystem<'a, S: Shape> {
    /// The body.
    pub body: &'a Body<S>,
}

impl<'a, S: Shape> FullSystem<'a, S> {
    /// The full system of `body`.
    pub fn new(body: &'a Body<S>) -> Self {
        Self { body }
    }

    /// 𝐉 = 𝐈 + |r|² 𝐄 − r ⊗ r: the inertia tensor about the contact point.
    pub fn contact_inertia(&self, r: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.body.inertia()) + Matrix3::identity() * r.norm_squared()
            - r * r.transpose()
    }

    /// Right-hand side of `eqred` and `kin`:
    /// 𝐉ω̇ + ω × 𝐉ω + r × (ω × ṙ) + γ × r − μγ = 0, γ̇ = γ × ω, α̇ = α × ω, β̇ = β × ω,
    /// ṙ_c = Qᵀ v with v = −ω × r, and
    /// μ = (ω × 𝐉ω + r × (ω × ṙ) + γ × r, 𝐉⁻¹γ) / (γ, 𝐉⁻¹γ).
    pub fn rate(&self, y: &FullState) -> FullState {
        let s = FullParts::of(y);
        let gamma_dot = s.gamma.cross(&s.omega);
        let r = self.body.shape.contact_point(&s.gamma);
        let r_dot = self.body.shape.contact_point_rate(&s.gamma, &gamma_dot);
        let j = self.contact_inertia(&r);
        let h = s.omega.cross(&(j * s.omega)) + r.cross(&s.omega.cross(&r_dot)) + s.gamma.cross(&r);
        let lu = j.lu();
        // 𝐉 is symmetric positive definite for every body (𝐈 > 0), so the solve cannot fail.
        let j_inv_gamma = lu.solve(&s.gamma).unwrap_or(s.gamma);
        let mu = h.dot(&j_inv_gamma) / s.gamma.dot(&j_inv_gamma);
        let omega_dot = lu.solve(&(s.gamma * mu - h)).unwrap_or(Vector3::zeros());
        let v = -s.omega.cross(&r);
        let mut out = FullState::zeros();
        out.fixed_rows_mut::<3>(0).copy_from(&omega_dot);
        out.fixed_rows_mut::<3>(3).copy_from(&gamma_dot);
        out.fixed_rows_mut::<3>(6)
            .copy_from(&s.alpha.cross(&s.omega));
        out.fixed_rows_mut::<3>(9)
            .copy_from(&s.beta.cross(&s.omega));
        out[12] = v.dot(&s.alpha);
        out[13] = v.dot(&s.beta);
        out
    }

    /// The four integrals at a state.
    pub fn integrals(&self, y: &FullState) -> FullIntegrals {
        let s = FullParts::of(y);
        let r = self.body.shape.contact_point(&s.gamma);
        let j = self.contact_inertia(&r);
        let g3 = s.gamma.z;
        let rg = r.dot(&s.gamma);
        let big_j = ((g3 * g3 + self.body.nu * (1.0 - g3 * g3)) / self.body.eta + rg * rg).sqrt();
        FullIntegrals {
            energy: 0.5 * (j * s.omega).dot(&s.omega) - rg,
            geometric: s.gamma.norm_squared(),
            no_spin: s.omega.dot(&s.gamma),
            linear: big_j * s.omega.z,
        }
    }

    /// The full state of the reduced state (θ, p, φ, ψ) at F2 = κ, with the centre of mass at
    /// (x_c, y_c): γ from `newvars`, ω from `w12`, α and β the first two columns of the
    /// Euler-angle matrix Q of paper §4 (proof of the proposition on permanent rotations).
    #[allow(clippy::too_many_arguments)]
    pub fn state_from_reduced(
        &self,
        kappa: f64,
        theta: f64,
        theta_dot: f64,
        phi: f64,
        psi: f64,
        x_c: f64,
        y_c: f64,
    ) -> FullState {
        let omega = ReducedSystem::new(self.body, kappa).angular_velocity(theta, theta_dot, phi);
        let (st, ct) = theta.sin_cos();
        let (sf, cf) = phi.sin_cos();
        let (sp, cp) = psi.sin_cos();
        let gamma = Vector3::new(st * sf, st * cf, ct);
        let alpha = Vector3::new(cp * cf - ct * sp * sf, -cp * sf - ct * sp * cf, st * sp);
        let beta = Vector3::new(sp * cf + ct * cp * sf, -sp * sf + ct * cp * cf, -st * cp);
        let mut y = FullState::zeros();
        y.fixed_rows_mut::<3>(0).copy_from(&omega);
        y.fixed_rows_mut::<3>(3).copy_from(&gamma);
        y.fixed_rows_mut::<3>(6).copy_from(&alpha);
        y.fixed_rows_mut::<3>(9).copy_from(&beta);
        y[12] = x_c;
        y[13] = y_c;
        y
    }

    /// The Euler angles (θ, φ, ψ) of a state: γ = (sinθ sinφ, sinθ cosφ, cosθ) and the third
    /// row of Q, (α3, β3, γ3) = (sinθ sinψ, −sinθ cosψ, cosθ).
    pub fn euler_angles(y: &FullState) -> (f64, f64, f64) {
        let s = FullParts::of(y);
        let theta = s.gamma.x.hypot(s.gamma.y).atan2(s.gamma.z);
        let phi = s.gamma.x.atan2(s.gamma.y);
        let psi = s.alpha.z.atan2(-s.beta.z);
        (theta, phi, psi)
    }

    /// Position of the contact point on the plane: r_p = r_c + Qᵀ r, i.e.
    /// (x_c + (r, α), y_c + (r, β)) (paper `rp`).
    pub fn contact_position(&self, y: &FullState) -> (f64, f64) {
        let s = FullParts::of(y);
        let r = self.body.shape.contact_point(&s.gamma);
        (s.x_c + r.dot(&s.alpha), s.y_c + r.dot(&s.beta))
    }

    /// Height of the centre of mass, z_c = −(r, γ) (paper `constr_hol`).
    pub fn centre_height(&self, y: &FullState) -> f64 {
        let s = FullParts::of(y);
        -self.body.shape.contact_point(&s.gamma).dot(&s.gamma)
    }
}
