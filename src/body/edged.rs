//! Bodies of revolution whose meridian is made of circular arcs and sharp edges (docs/bodies.md):
//! the thin disk, the truncated ball and the wheel (a ball cut by two parallel planes). The
//! reduction of paper §2 (`oned`) holds for them as for the ellipsoid; only U(θ) changes. On
//! each smooth part of the surface the contact point is either a fixed circle of the body (an
//! edge, radius of curvature of the meridian 0) or on the sphere (radius 1), and there
//! U = p |sinθ| + q cosθ + r, so U + U″ = r. Where the contact passes from one part to the
//! other (θ_c = arccos h) U and U′ are continuous and U″ jumps: a kink, at which the cell
//! solver splits its integrals.

use super::{check_range, Angle, Profile, Shape};
use crate::error::Result;
use nalgebra::Vector3;

/// The kinds of body beyond the ellipsoid: the edged bodies of this module, and a body of the
/// user's own profile ([`super::profile`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgedKind {
    /// A thin disk of rim radius 1, rolling on its rim: U = sinθ + α cosθ.
    Disk,
    /// A ball of radius 1 cut by the plane z = −h (the face down at θ = 0): on the edge of the
    /// cut for θ < θ_c, on the sphere beyond.
    TruncatedBall,
    /// A ball of radius 1 cut by z = ±h: on the lower edge for θ < θ_c, the sphere between,
    /// the upper edge for θ > π − θ_c.
    Wheel,
    /// A body of revolution given by a table of its meridian's points (docs/bodies.md).
    Profile(&'static Profile),
}

impl EdgedKind {
    /// Every kind, in the order of [`EdgedKind::name`]'s list.
    pub const ALL: [EdgedKind; 3] = [Self::Disk, Self::TruncatedBall, Self::Wheel];

    /// The name used on the command line, in scenes and in files.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Disk => "disk",
            Self::TruncatedBall => "truncated_ball",
            Self::Wheel => "wheel",
            Self::Profile(_) => "profile",
        }
    }

    /// The kind of that name (a profile needs its table: not by name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// One smooth part of the surface: there U = p |sinθ| + q cosθ + r and the contact point,
/// seen from the centre of mass, is r = −r γ − p (γ1, γ2, 0)/|sinθ| − q e3.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Part {
    p: f64,
    q: f64,
    r: f64,
}

impl Part {
    /// U. On the sphere (p = 0, r = 1) 1 + q cosθ cancels at the pole the centre of mass
    /// leans away from as |α| = |q| → 1 (U = 1 − |α| there): it is formed as
    /// sin²θ/(1 + |cosθ|) + (1 − |q|)|cosθ| (1 − |cosθ| without cancellation; 1 − |q| exact
    /// for |q| ≥ ½), as the ellipsoid's U is, so that U keeps its relative precision and V's
    /// rounding stays a few ulps of |U|.
    #[inline]
    fn height(&self, a: Angle) -> f64 {
        if self.p == 0.0 && self.q * a.cos < 0.0 && self.q.abs() > 0.5 {
            let lift = a.sin * a.sin / (1.0 + a.cos.abs());
            return lift + (1.0 - self.q.abs()) * a.cos.abs();
        }
        self.p * a.sin.abs() + self.q * a.cos + self.r
    }

    /// U′ = p sgn(sinθ) cosθ − q sinθ.
    #[inline]
    fn slope(&self, a: Angle) -> f64 {
        self.p * a.sin.signum() * a.cos - self.q * a.sin
    }

    /// U′/sinθ = p cosθ/|sinθ| − q.
    #[inline]
    fn slope_over_sin(&self, a: Angle) -> f64 {
        self.p * a.cos / a.sin.abs() - self.q
    }

    /// U″ = −p |sinθ| − q cosθ.
    #[inline]
    fn curvature(&self, a: Angle) -> f64 {
        -self.p * a.sin.abs() - self.q * a.cos
    }
}

/// A body of revolution made of a ball's sphere and flat cuts (or a disk's rim), with its
/// centre of mass at α e3 from the ball's (or the disk's) centre; unit of length the ball's
/// (the rim's) radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgedShape {
    /// Which body.
    pub kind: EdgedKind,
    /// α: the centre of mass at α e3 from the centre of the ball (the disk).
    pub alpha: f64,
    /// h: the cut plane z = −h (and z = +h for the wheel); 0 for the disk.
    pub cut: f64,
    /// ρ = √(1 − h²), the radius of the edge circle (1 for the disk).
    rho: f64,
    /// θ_c and π − θ_c, the kinks in (0, π) (`kink_count` of them are used).
    kinks: [f64; 2],
    kink_count: usize,
}

impl EdgedShape {
    /// A thin disk of rim radius 1, its centre of mass at α along the axis from its centre,
    /// |α| ≤ 100 (a homogeneous disk has α = 0, ν = 2, η = 4). The bound keeps the well by
    /// the pole θ = π (θ = 0 for α < 0), at sinθ ≈ (κ²/|α|)^¼, within the scan for the
    /// critical points of V (checked on |α| ≤ 100).
    pub fn disk(alpha: f64) -> Result<Self> {
        check_range(
            "alpha",
            alpha,
            Some((-100.0, true)),
            Some((100.0, true)),
            "must satisfy -100 <= alpha <= 100 for the disk (the centre of mass within 100 rim \
             radii of the disk)",
        )?;
        Ok(Self {
            kind: EdgedKind::Disk,
            alpha,
            cut: 0.0,
            rho: 1.0,
            kinks: [0.0; 2],
            kink_count: 0,
        })
    }

    /// A ball of radius 1 cut by the plane z = −h, −1 < h < 1, its centre of mass at α e3
    /// from the ball's centre, −1 < α < 1.
    pub fn truncated_ball(alpha: f64, cut: f64) -> Result<Self> {
        Self::cut_ball(EdgedKind::TruncatedBall, alpha, cut, -1.0)
    }

    /// A ball of radius 1 cut by the planes z = ±h, 0 < h < 1, its centre of mass at α e3
    /// from the ball's centre, −1 < α < 1.
    pub fn wheel(alpha: f64, cut: f64) -> Result<Self> {
        Self::cut_ball(EdgedKind::Wheel, alpha, cut, 0.0)
    }

    /// The body of `kind` with centre-of-mass offset α and cut h (ignored for the disk).
    pub fn of(kind: EdgedKind, alpha: f64, cut: f64) -> Result<Self> {
        match kind {
            EdgedKind::Disk => Self::disk(alpha),
            EdgedKind::TruncatedBall => Self::truncated_ball(alpha, cut),
            EdgedKind::Wheel => Self::wheel(alpha, cut),
            EdgedKind::Profile(_) => Err(crate::error::AtlasError::Unsupported {
                what: "profile",
                reason: "a body of a profile is a ProfileShape, not an EdgedShape",
            }),
        }
    }

    fn cut_ball(kind: EdgedKind, alpha: f64, cut: f64, cut_min: f64) -> Result<Self> {
        check_range(
            "alpha",
            alpha,
            Some((-1.0, false)),
            Some((1.0, false)),
            "must satisfy -1 < alpha < 1 (the centre of mass inside the ball)",
        )?;
        let reason = if kind == EdgedKind::Wheel {
            "must satisfy 0 < cut < 1 (the planes z = -cut and z = +cut cut the ball)"
        } else {
            "must satisfy -1 < cut < 1 (the plane z = -cut cuts the ball)"
        };
        check_range(
            "cut",
            cut,
            Some((cut_min, false)),
            Some((1.0, false)),
            reason,
        )?;
        let rho = ((1.0 - cut) * (1.0 + cut)).sqrt();
        // θ_c = arccos h, from atan2 (full precision also near h = ±1).
        let theta_c = rho.atan2(cut);
        let (kinks, kink_count) = match kind {
            EdgedKind::Wheel => ([theta_c, std::f64::consts::PI - theta_c], 2),
            _ => ([theta_c, 0.0], 1),
        };
        Ok(Self {
            kind,
            alpha,
            cut,
            rho,
            kinks,
            kink_count,
        })
    }

    /// The part of the surface in contact at the angle `a` (decided by cosθ against ±h; at a
    /// kink both parts give the same U and U′).
    #[inline]
    fn part(&self, a: Angle) -> Part {
        let (h, rho, alpha) = (self.cut, self.rho, self.alpha);
        let lower_edge = Part {
            p: rho,
            q: h + alpha,
            r: 0.0,
        };
        let sphere = Part {
            p: 0.0,
            q: alpha,
            r: 1.0,
        };
        match self.kind {
            EdgedKind::Disk => Part {
                p: 1.0,
                q: alpha,
                r: 0.0,
            },
            EdgedKind::TruncatedBall if a.cos > h => lower_edge,
            EdgedKind::TruncatedBall => sphere,
            EdgedKind::Wheel if a.cos > h => lower_edge,
            EdgedKind::Wheel if a.cos < -h => Part {
                p: rho,
                q: alpha - h,
                r: 0.0,
            },
            EdgedKind::Wheel => sphere,
            EdgedKind::Profile(_) => unreachable!("an EdgedShape is never a profile"),
        }
    }

    /// Whether the angle `a` lies at a kink (to a few ulps of its cosine ±h) that bounds
    /// `part`: U and U′ of either part agree there (U″ jumps).
    fn bounds(&self, a: Angle, part: Part) -> bool {
        self.parts_beside_kink(a)
            .is_some_and(|parts| parts.contains(&part))
    }

    /// The two parts that meet at the kink the angle `a` lies at (to a few ulps of its
    /// cosine, h or the wheel's −h), the one at smaller θ (larger cosθ) first.
    fn parts_beside_kink(&self, a: Angle) -> Option<[Part; 2]> {
        const NEAR: f64 = 8.0 * f64::EPSILON;
        const STEP: f64 = 1e-6;
        let c = [self.cut, -self.cut][..self.kink_count]
            .iter()
            .copied()
            .find(|&c| (a.cos - c).abs() <= NEAR)?;
        Some([self.part_at_cos(c + STEP), self.part_at_cos(c - STEP)])
    }

    /// The part in contact when the axis is tilted so that γ3 = cosθ = `cos`.
    #[inline]
    fn part_at_cos(&self, cos: f64) -> Part {
        self.part(Angle {
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
            cos,
        })
    }

    /// The edges' (p, q) of U = p sinθ + q cosθ: the disk's rim, the cut balls' edges.
    fn edges(&self) -> Vec<(f64, f64)> {
        let (h, rho, alpha) = (self.cut, self.rho, self.alpha);
        match self.kind {
            EdgedKind::Disk => vec![(1.0, alpha)],
            EdgedKind::TruncatedBall => vec![(rho, h + alpha)],
            EdgedKind::Wheel => vec![(rho, h + alpha), (rho, alpha - h)],
            EdgedKind::Profile(_) => vec![],
        }
    }

    /// The radius of the edge circle, ρ = √(1 − h²) (1 for the disk).
    pub fn edge_radius(&self) -> f64 {
        self.rho
    }
}

impl Shape for EdgedShape {
    /// The disk and the wheel with α = 0.
    fn symmetric_about_equator(&self) -> bool {
        self.alpha == 0.0 && self.kind != EdgedKind::TruncatedBall
    }

    fn kinks(&self) -> &[f64] {
        &self.kinks[..self.kink_count]
    }

    /// A part p sin θ + q cos θ (the disk's rim, an edge) vanishes where (cos θ, sin θ) ⊥
    /// (q, p): at θ = atan2(|q|, −p sgn q) in (0, π), for q ≠ 0, where that part is the one
    /// in contact. The sphere's 1 + α cos θ is positive.
    fn potential_zeros(&self) -> Vec<f64> {
        self.edges()
            .into_iter()
            .filter(|&(_, q)| q != 0.0)
            .map(|(p, q)| (p, q, q.abs().atan2(-p * q.signum())))
            .filter(|&(p, q, theta)| self.part(Angle::new(theta)) == Part { p, q, r: 0.0 })
            .map(|(_, _, theta)| theta)
            .collect()
    }

    /// On an edge U′ = p cosθ − q sinθ vanishes at θ = atan2(p, q), where that lies on the
    /// edge; on the sphere (p = 0) only at the poles (or everywhere where α = 0: B is then
    /// constant there).
    fn slope_zeros(&self) -> Vec<f64> {
        self.edges()
            .into_iter()
            .map(|(p, q)| (p, q, p.atan2(q)))
            .filter(|&(p, q, theta)| self.part(Angle::new(theta)) == Part { p, q, r: 0.0 })
            .map(|(_, _, theta)| theta)
            .collect()
    }

    /// The disk lies flat at both poles, the truncated ball on its face at θ = 0, the wheel
    /// on either face.
    fn faces(&self) -> [bool; 2] {
        match self.kind {
            EdgedKind::Disk | EdgedKind::Wheel => [true, true],
            EdgedKind::TruncatedBall => [true, false],
            EdgedKind::Profile(p) => p.faces(),
        }
    }

    /// χ1 = −p/|sinθ| − r, χ2 = −r cosθ − q (from U = −(χ1 sin²θ + χ2 cosθ) and
    /// U′ = sinθ (χ2 − χ1 cosθ)).
    fn chi(&self, theta: f64) -> (f64, f64) {
        let a = Angle::new(theta);
        let part = self.part(a);
        (-part.p / a.sin.abs() - part.r, -part.r * a.cos - part.q)
    }

    /// (χ1′, χ2′) = (p sgn(sinθ) cosθ / sin²θ, r sinθ).
    fn chi_prime(&self, theta: f64) -> (f64, f64) {
        let a = Angle::new(theta);
        let part = self.part(a);
        (
            part.p * a.sin.signum() * a.cos / (a.sin * a.sin),
            part.r * a.sin,
        )
    }

    /// r = −r γ − p (γ1, γ2, 0)/|γ⊥| − q e3 on the part in contact (γ⊥ = (γ1, γ2)).
    fn contact_point(&self, gamma: &Vector3<f64>) -> Vector3<f64> {
        let part = self.part_at_cos(gamma.z);
        let s = gamma.x.hypot(gamma.y);
        Vector3::new(
            -(part.r + part.p / s) * gamma.x,
            -(part.r + part.p / s) * gamma.y,
            -part.r * gamma.z - part.q,
        )
    }

    /// ṙ = −r γ̇ − p (ḣ/s − h (h, ḣ)/s³) with h = (γ1, γ2, 0), s = |h|.
    fn contact_point_rate(&self, gamma: &Vector3<f64>, gamma_dot: &Vector3<f64>) -> Vector3<f64> {
        let part = self.part_at_cos(gamma.z);
        -gamma_dot * part.r - super::horizontal_direction_rate(gamma, gamma_dot) * part.p
    }

    theta_forms!(
        potential => potential_at,
        potential_prime => potential_prime_at,
        potential_second => potential_second_at,
        contact_distance_sq => contact_distance_sq_at,
    );

    /// d|r|²/dθ = 2U′(U + U″) = 2 r U′.
    fn contact_distance_sq_prime(&self, theta: f64) -> f64 {
        let a = Angle::new(theta);
        2.0 * self.part(a).r * self.potential_prime_at(a)
    }

    #[inline]
    fn potential_at(&self, a: Angle) -> f64 {
        self.part(a).height(a)
    }

    #[inline]
    fn potential_prime_at(&self, a: Angle) -> f64 {
        self.part(a).slope(a)
    }

    #[inline]
    fn potential_second_at(&self, a: Angle) -> f64 {
        self.part(a).curvature(a)
    }

    #[inline]
    fn potential_prime_over_sin_at(&self, a: Angle) -> f64 {
        self.part(a).slope_over_sin(a)
    }

    /// |r|² = U² + U′².
    #[inline]
    fn contact_distance_sq_at(&self, a: Angle) -> f64 {
        self.potential_and_contact_distance_sq_at(a).1
    }

    /// U and |r|² = U² + U′² from one lookup of the part in contact (the solver's inner loop).
    #[inline]
    fn potential_and_contact_distance_sq_at(&self, a: Angle) -> (f64, f64) {
        let part = self.part(a);
        let u = part.height(a);
        let up = part.slope(a);
        (u, u * u + up * up)
    }

    /// (U(x) − U(y)) / sin(x − y) on one part, without cancellation: with d = x − y,
    /// (sin x − sin y)/sin d = cos y − sin y sin d/(1 + cos d) and
    /// (cos x − cos y)/sin d = −sin y − cos y sin d/(1 + cos d). An angle at a kink belongs
    /// to both parts it joins. Across a kink, or where sinθ changes sign, U is differenced
    /// directly (the default's rounding scale).
    #[inline]
    fn potential_divided_difference(
        &self,
        x: Angle,
        y: Angle,
        sin_diff: f64,
        cos_diff: f64,
    ) -> (f64, f64) {
        let part = match (self.part(x), self.part(y)) {
            (px, py) if px == py => Some(py),
            // U is continuous at a kink: an angle at one takes the other angle's part, so
            // that a divided difference from a kink (a piece's end) stays free of
            // cancellation.
            (px, _) if self.bounds(y, px) => Some(px),
            (_, py) if self.bounds(x, py) => Some(py),
            _ => None,
        };
        let Some(part) = part.filter(|_| x.sin * y.sin > 0.0 && cos_diff > -0.5) else {
            return super::subtracted_divided_difference(self, x, y, sin_diff);
        };
        let t = sin_diff / (1.0 + cos_diff);
        let sin_dd = y.cos - y.sin * t;
        let cos_dd = -y.sin - y.cos * t;
        let p = part.p * y.sin.signum() * sin_dd;
        let q = part.q * cos_dd;
        (p + q, p.abs() + q.abs())
    }

    fn potential_second_sides_at(&self, a: Angle) -> Option<[f64; 2]> {
        self.parts_beside_kink(a)
            .map(|parts| parts.map(|part| part.curvature(a)))
    }

    /// The edge parts are arcs of sinusoids: no scale below 1 (the kinks are split at).
    fn angular_feature_scale(&self) -> f64 {
        1.0
    }
}
