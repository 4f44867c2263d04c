//! One level set (κ, ε) of the reduced system, computed by quadrature: the critical points of
//! V (found once per (body, κ) and reused for every ε), the components of {V ≤ ε} (each an
//! invariant torus), their turning points, and the integrals over one θ-period — the period
//! T, the precession Δψ and the drift Δζ of the centre of mass (paper §5, `dpsi`; docs/model.md).
//!
//! A libration is first integrated whole after the cosine substitution (module `cosine`),
//! geometrically convergent unless a saddle or a pole comes close. Otherwise the component is
//! cut at its turning points and at every maximum or tangency inside it, and each piece is
//! integrated in θ by the tanh-sinh rule, whose nodes crowd double-exponentially at the
//! piece's ends, where the 1/√ singularity of a turning point, the near-logarithmic one of a
//! nearby saddle and the narrow ψ̇ peak near a pole at small κ all sit. In both, the gap
//! ε − V(θ) is evaluated from the nearer end with the divided difference of V, so it keeps
//! full relative precision right up to the turning points (docs/accuracy.md).

use crate::body::{Angle, Body, Reduction, Shape};
use crate::dd::{CompensatedSum, DoubleDouble};
use crate::error::{AtlasError, Result};
use crate::family::{self, Family, Side};
use crate::quadrature::{
    chebyshev_antiderivative, spectral_antiderivative, ChebyshevLevel, ChebyshevPiece,
    IntervalNode, TanhSinhLevel, FINEST_LEVEL, TAU_MAX,
};
use rustfft::num_complex::Complex;
use std::cell::OnceCell;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::OnceLock;

mod cosine;

const EPS: f64 = f64::EPSILON;

/// How close to ±π/2 a minimum of V is taken as lying at the equator, its side then decided
/// by the exact sign of U′(π/2) (or, for a body symmetric about its equator, on it). A well
/// this close to π/2 with a saddle between them exists only next to a degenerate body.
const EQUATOR_WINDOW: f64 = 1e-6;

/// The nodes of V round the θ-axis at one ε ([`EffectivePotential::levels`]).
enum Levels {
    /// κ = 0 and ε above the top of U: the whole circle.
    OverTheTop(Vec<Option<CriticalPoint>>),
    /// Otherwise.
    Nodes(Vec<Option<CriticalPoint>>),
}

/// V at a node (+∞ at a pole).
fn node_value(n: &Option<CriticalPoint>) -> f64 {
    n.map_or(f64::INFINITY, |p| p.value)
}

/// Whether `node` is a minimum of V above ε by no more than its rounding (4 eps of the L1
/// size of V's terms there, the window in which [`EffectivePotential::make_component`] takes
/// ε for the minimum's own level): ε there cannot be told from the bottom of that well, and
/// the body rests in its permanent rotation. (V at a point of `diagram`'s stable branches,
/// as it computes it, lay 1–4 ulps below the minimum found here: `cell` gave `no_motion` at
/// 609 of 3,374 of them, and no fixed point at 416 more of a higher well: adversary pass 40.)
fn at_rounding_minimum(node: &Option<CriticalPoint>, energy: f64) -> bool {
    node.is_some_and(|m| {
        m.kind == CriticalKind::Minimum
            && m.value > energy
            && m.value - energy <= 4.0 * EPS * m.scale
    })
}

/// [`node_runs`], and a run of its own for each minimum within rounding above ε
/// ([`at_rounding_minimum`]), in order.
fn runs_at(nodes: &[Option<CriticalPoint>], energy: f64) -> Vec<(usize, usize)> {
    let mut runs = node_runs(nodes, energy);
    runs.extend(
        (0..nodes.len())
            .filter(|&i| at_rounding_minimum(&nodes[i], energy))
            .map(|i| (i, i)),
    );
    runs.sort_unstable();
    runs
}

/// The maximal runs `(first, last)` of consecutive nodes at or below ε: one per component
/// of {V ≤ ε}, in order.
fn node_runs(nodes: &[Option<CriticalPoint>], energy: f64) -> Vec<(usize, usize)> {
    let inside = |i: usize| node_value(&nodes[i]) <= energy;
    let mut runs = Vec::new();
    let mut start = inside(0).then_some(0);
    for i in 0..nodes.len() - 1 {
        if inside(i) == inside(i + 1) {
            continue;
        }
        if inside(i) {
            runs.push((start.take().unwrap_or(i), i));
        } else {
            start = Some(i + 1);
        }
    }
    if let Some(first) = start {
        runs.push((first, nodes.len() - 1));
    }
    runs
}

/// A point of the θ-axis, kept with its distance to the pole θ = π so that sin θ and cos θ
/// have full relative precision near both poles. On the κ = 0 circle θ is the lifted angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// θ (for points near π, π − `from_pi` rounded).
    pub theta: f64,
    /// π − θ, exact for points that were found in this form.
    pub from_pi: f64,
    /// Whether θ is the exact one (made by [`Site::at`]) rather than π − θ.
    theta_exact: bool,
}

impl Site {
    /// The point θ.
    #[inline]
    pub fn at(theta: f64) -> Self {
        Self {
            theta,
            from_pi: PI - theta,
            theta_exact: true,
        }
    }

    /// The point π − φ.
    #[inline]
    pub fn from_pi(phi: f64) -> Self {
        Self {
            theta: PI - phi,
            from_pi: phi,
            theta_exact: false,
        }
    }

    /// The site `d` further on in θ, in the same chart (θ + d, or π − (φ − d)).
    #[inline]
    pub fn moved(&self, d: f64) -> Self {
        if self.theta_exact {
            Self::at(self.theta + d)
        } else {
            Self::from_pi(self.from_pi - d)
        }
    }

    /// The size the site's rounding is relative to: |θ| where θ is held exactly, else
    /// |π − θ| (negative beyond π on the κ = 0 circle).
    #[inline]
    pub fn ulp_scale(&self) -> f64 {
        if self.theta_exact {
            self.theta.abs()
        } else {
            self.from_pi.abs()
        }
    }

    /// sin θ and cos θ, from whichever of θ and π − θ is held exactly (PI − θ is off π − θ
    /// by π − PI = 1.2e-16, a 1e-12 relative error of a libration 1e-4 wide beyond π/2).
    #[inline]
    pub fn angle(&self) -> Angle {
        if self.theta_exact {
            Angle::new(self.theta)
        } else {
            Angle::from_pi(self.from_pi)
        }
    }
}

/// What kind of critical point of V a point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CriticalKind {
    /// A local minimum: a stable permanent rotation (κ ≠ 0) or equilibrium (κ = 0).
    Minimum,
    /// A local maximum: an unstable one; its level is a separatrix.
    Maximum,
    /// A degenerate critical point with V increasing or decreasing through it: a tangency,
    /// or a shoulder on an edged body's kink (one part's maximum meeting the other's
    /// minimum). Its level is a separatrix: the motion there takes forever to reach it.
    Inflection,
}

/// A critical point of V.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalPoint {
    /// Where it is.
    pub site: Site,
    /// V there.
    pub value: f64,
    /// The L1 size of V's terms there ([`EffectivePotential::value_scale`]): V's rounding
    /// is a few ulps of it, and so is every window round this level.
    pub scale: f64,
    /// V″ there.
    pub curvature: f64,
    /// Minimum, maximum or inflection.
    pub kind: CriticalKind,
}

/// How the θ-motion on a component looks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionKind {
    /// θ oscillates between two turning points.
    Libration,
    /// ε equals a local minimum of V: θ stays at the fixed point (a permanent rotation).
    FixedPoint,
    /// κ = 0 and ε above the top of U: the body rolls over the top along a meridian.
    Rotation,
}

/// A connected component {θ : V(θ) ≤ ε} of the allowed set.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Lower turning point (for κ = 0 it may be negative: θ is continued on the circle; for a
    /// rotation it is the top of U where the circle is cut).
    pub lower: Site,
    /// Upper turning point (for a rotation, `lower` + 2π).
    pub upper: Site,
    /// Libration, fixed point or rotation.
    pub kind: MotionKind,
    /// The family of tori it belongs to (by the wells it encloses).
    pub family: Family,
    /// The critical points strictly inside, in order (lifted on the κ = 0 circle).
    pub interior: Vec<CriticalPoint>,
    /// The critical points at or just outside the lower and the upper end (none at a pole).
    pub neighbours: [Option<CriticalPoint>; 2],
}

impl Component {
    /// The permanent rotation at the minimum `m` of V (ε at its level, to rounding), between
    /// the critical points `neighbours`.
    fn resting_at(
        m: CriticalPoint,
        family: Family,
        neighbours: [Option<CriticalPoint>; 2],
    ) -> Self {
        Component {
            lower: m.site,
            upper: m.site,
            kind: MotionKind::FixedPoint,
            family,
            interior: vec![m],
            neighbours,
        }
    }

    /// θ_min.
    pub fn theta_min(&self) -> f64 {
        self.lower.theta
    }

    /// θ_max.
    pub fn theta_max(&self) -> f64 {
        self.upper.theta
    }

    /// The maxima and inflections of V inside the component or at its ends (the saddles its
    /// level may sit on), in order.
    pub fn saddles(&self) -> impl Iterator<Item = &CriticalPoint> {
        self.interior
            .iter()
            .chain(self.neighbours.iter().flatten())
            .filter(|p| p.kind != CriticalKind::Minimum)
    }

    /// The lowest critical point inside (the centre of a libration).
    pub fn minimum(&self) -> Option<&CriticalPoint> {
        self.interior
            .iter()
            .filter(|c| c.kind == CriticalKind::Minimum)
            .min_by(|a, b| a.value.total_cmp(&b.value))
    }

    /// How far `theta` lies outside [θ_min, θ_max] (0 inside).
    pub fn distance_to(&self, theta: f64) -> f64 {
        (self.lower.theta - theta)
            .max(theta - self.upper.theta)
            .max(0.0)
    }
}

/// V(θ) = κ²/(2 sin²θ) + U(θ) at one (body, κ) with its critical points: what every cell of a
/// row of the atlas (fixed α, β, κ; varying ε) shares.
#[derive(Debug, Clone)]
pub struct EffectivePotential<'a, S: Shape> {
    /// The body.
    pub body: &'a Body<S>,
    /// κ.
    pub kappa: f64,
    critical: Vec<CriticalPoint>,
    /// The narrow dips of the integrands' factors, (θ, width): of B = 1/η + U² + U′² at each
    /// zero of U′ in (0, π) where B has a minimum ([`EffectivePotential::dip_width`]), and of
    /// J² near θ = π/2 where ν + η U² is small ([`EffectivePotential::equator_dip`]).
    dips: Vec<(f64, f64)>,
    /// The angles in (0, π) where the integrals are split ([`Self::splits_inside`]), found
    /// once.
    split_angles: Vec<f64>,
    /// 1/η in double-double, for [`precise_sample`].
    inverse_eta: DoubleDouble,
    /// The extrema of sin³θ V′ in (0, π) that are not critical points (κ ≠ 0, a shape
    /// without kinks): where V′ is least on a stretch of V, a shoulder, near-flat beside a
    /// cusp of the diagram ([`Self::shoulder_gap`]). Found by the critical-point scan.
    shoulders: Vec<Site>,
}

/// Number of scan cells for critical points; between scan nodes the pole-free function
/// sin³θ V′ is monotone unless its own derivative changes sign, and those roots are scanned too.
const SCAN_CELLS: usize = 1024;

/// The body's part of the critical-point scan, the same at every κ: the [`SCAN_CELLS`]
/// uniform sites in (0, π) with sinθ, cosθ, U′ and U″ at each, the largest |U′| (at least 1)
/// on every eighth cell's middle and the largest |U″| (at least 1) at the poles. Built once
/// per body and handed to [`EffectivePotential::with_scan`] when V is wanted at many κ (a
/// verdict, a resonance curve, a plane with κ per cell): it is most of the scan's work.
#[derive(Debug, Clone)]
pub struct ScanTable {
    sites: Vec<Site>,
    angles: Vec<Angle>,
    slopes: Vec<f64>,
    seconds: Vec<f64>,
    steepest: f64,
    pole_curvature: f64,
}

impl ScanTable {
    /// The table of a body.
    pub fn new<S: Shape>(body: &Body<S>) -> Self {
        let shape = &body.shape;
        let cell = PI / SCAN_CELLS as f64;
        let half = SCAN_CELLS / 2;
        let sites: Vec<Site> = (1..=half)
            .map(|i| Site::at(cell * i as f64))
            .chain((half + 1..SCAN_CELLS).map(|i| Site::from_pi(cell * (SCAN_CELLS - i) as f64)))
            .collect();
        let angles: Vec<Angle> = sites.iter().map(Site::angle).collect();
        Self {
            slopes: angles
                .iter()
                .map(|&a| shape.potential_prime_at(a))
                .collect(),
            seconds: angles
                .iter()
                .map(|&a| shape.potential_second_at(a))
                .collect(),
            sites,
            angles,
            steepest: (1..=SCAN_CELLS / 8)
                .map(|i| shape.potential_prime_at(Angle::new(8.0 * cell * i as f64 - 0.5 * cell)))
                .map(f64::abs)
                .fold(1.0, f64::max),
            pole_curvature: [Site::at(0.0), Site::from_pi(0.0)]
                .iter()
                .map(|s| shape.potential_second_at(s.angle()).abs())
                .fold(1.0, f64::max),
        }
    }
}

impl<'a, S: Shape> EffectivePotential<'a, S> {
    /// V of `body` at F2 = `kappa`, with its critical points in (0, π) (κ ≠ 0) or on the
    /// circle [0, 2π) (κ = 0).
    pub fn new(body: &'a Body<S>, kappa: f64) -> Self {
        Self::with_scan(body, kappa, &ScanTable::new(body))
    }

    /// [`Self::new`] with the body's part of the critical-point scan made beforehand
    /// (`table` must be the same body's).
    pub fn with_scan(body: &'a Body<S>, kappa: f64, table: &ScanTable) -> Self {
        let mut v = Self {
            body,
            kappa,
            critical: Vec::new(),
            dips: Vec::new(),
            split_angles: Vec::new(),
            inverse_eta: DoubleDouble::from_f64(1.0).div(DoubleDouble::from_f64(body.eta)),
            shoulders: Vec::new(),
        };
        (v.critical, v.shoulders) = v.find_critical_points(table);
        v.dips = body
            .shape
            .slope_zeros()
            .into_iter()
            .map(|zero| (zero, v.dip_width(zero)))
            .chain(v.equator_dip())
            .filter(|(_, width)| width.is_finite())
            .collect();
        v.split_angles = v.find_split_angles();
        v
    }

    /// The width of the dip of B = 1/η + U² + U′² at a zero z of U′ in (0, π): with x = θ − z,
    /// B ≈ 1/η + U² + U″(U″ + U) x², which vanishes at x = ±i √((1/η + U²)/(U″(U″ + U))):
    /// the integrands (∝ √B) are analytic only that far off the real axis. ∞ where
    /// U″(U″ + U) ≤ 0 (a maximum of B; on an edge U + U″ = 0 and B is constant).
    fn dip_width(&self, zero: f64) -> f64 {
        let a = Angle::new(zero);
        let shape = &self.body.shape;
        let u = shape.potential_at(a);
        let second = shape.potential_second_at(a);
        let curvature = second * (second + u);
        if curvature > 0.0 {
            ((1.0 / self.body.eta + u * u) / curvature).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// The dip of η J² = cos²θ + ν sin²θ + η U² about θ = π/2 (for ν < 1 its first two terms
    /// fall to ν there), as (θ_J, width): with x = θ − π/2, η J² ≈ a + b x + c x², whose
    /// complex zeros, where 1/J is singular, lie `width` = √(m/c) off the real axis at
    /// θ_J = π/2 − b/(2c), m = a − b²/(4c) the least value. None where the quadratic has no
    /// minimum or it lies outside (0, π). At ν = 0.018, η = 0.0034 (width 0.15) the Mercator
    /// map's middle steps (0.66 in θ on 64 steps of a libration from pole to pole at
    /// κ = −6e-5, ε = 221) stepped over it, and N was 1.28 times its estimate off at tol
    /// 1e-10 (an adversary pass).
    fn equator_dip(&self) -> Option<(f64, f64)> {
        let body = self.body;
        let a = Angle::EQUATOR;
        let u = body.shape.potential_at(a);
        let u1 = body.shape.potential_prime_at(a);
        let u2 = body.shape.potential_second_at(a);
        let eta = body.eta;
        let constant = body.nu + eta * u * u;
        let linear = 2.0 * eta * u * u1;
        let quadratic = 1.0 - body.nu + eta * (u1 * u1 + u * u2);
        if quadratic <= 0.0 {
            return None;
        }
        let least = constant - linear * linear / (4.0 * quadratic);
        let at = FRAC_PI_2 - linear / (2.0 * quadratic);
        (least > 0.0 && at > 0.0 && at < PI).then(|| (at, (least / quadratic).sqrt()))
    }

    /// The dips of B as the θ-interval [`lower`, `upper`] sees them: for each (on the κ = 0
    /// circle each of its images ±θ + 2πm; for κ ≠ 0 the images outside (0, π) are farther
    /// than the dip itself and change nothing), the point of the interval nearest it and its
    /// width there, hypot(its distance outside the interval, its width). No allocation: this
    /// runs for every libration.
    pub(crate) fn dips_seen(
        &self,
        lower: f64,
        upper: f64,
    ) -> impl Iterator<Item = (f64, f64)> + '_ {
        let turns = ((lower - PI) / TAU).floor() as i64..=((upper + PI) / TAU).ceil() as i64;
        self.dips.iter().flat_map(move |&(zero, width)| {
            turns.clone().flat_map(move |m| {
                let turn = TAU * m as f64;
                [turn + zero, turn - zero].map(|theta| {
                    let nearest = theta.clamp(lower, upper);
                    (nearest, (theta - nearest).abs().hypot(width))
                })
            })
        })
    }

    /// The critical points, sorted by θ.
    pub fn critical_points(&self) -> &[CriticalPoint] {
        &self.critical
    }

    /// The bottom of V: its deepest minimum (None only if V has no minimum, which the
    /// ellipsoid never has).
    pub fn lowest_minimum(&self) -> Option<f64> {
        self.critical
            .iter()
            .filter(|p| p.kind == CriticalKind::Minimum)
            .map(|p| p.value)
            .min_by(f64::total_cmp)
    }

    /// θ of every minimum of V, in increasing θ: the wells, one family of tori each.
    pub fn minimum_sites(&self) -> Vec<f64> {
        self.critical
            .iter()
            .filter(|p| p.kind == CriticalKind::Minimum)
            .map(|p| p.site.theta)
            .collect()
    }

    /// The minimum of V nearest θ = `well` (a well followed from one κ to the next), if V has
    /// one.
    pub fn minimum_nearest(&self, well: f64) -> Option<&CriticalPoint> {
        self.critical
            .iter()
            .filter(|p| p.kind == CriticalKind::Minimum)
            .min_by(|p, q| {
                (p.site.theta - well)
                    .abs()
                    .total_cmp(&(q.site.theta - well).abs())
            })
    }

    /// The levels of the maxima of V and of its shoulders (an edged body's critical point on
    /// a kink with V monotone through it), sorted: the separatrices. Between two of them N of
    /// one component is continuous in ε; it diverges only at a separatrix.
    pub fn separatrix_levels(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self
            .critical
            .iter()
            .filter(|p| p.kind != CriticalKind::Minimum)
            .map(|p| p.value)
            .collect();
        v.sort_by(f64::total_cmp);
        v
    }

    /// V at an angle.
    #[inline]
    pub fn value(&self, a: Angle) -> f64 {
        let u = self.body.shape.potential_at(a);
        if self.kappa == 0.0 {
            u
        } else {
            let w = self.kappa / a.sin;
            0.5 * w * w + u
        }
    }

    /// V in double-double with a bound on its error (about 1e-30 of its terms) at the angle
    /// atan2(sin, cos) of the pair `a` (normalised onto the circle first: the cell solver's
    /// integrands measure V from an end's pair of rounded sine and cosine), where the shape
    /// gives U so ([`Shape::potential_double_double`]).
    pub fn value_double_double(&self, a: Angle) -> Option<(DoubleDouble, f64)> {
        let (sin, cos) = on_circle(a);
        self.value_double_double_on_circle(sin, cos)
    }

    /// [`Self::value_double_double`] at the angle whose sine and cosine are `sin` and `cos`
    /// (a pair on the unit circle to double-double precision).
    fn value_double_double_on_circle(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64)> {
        let (u, error) = self.body.shape.potential_double_double(sin, cos)?;
        if self.kappa == 0.0 {
            return Some((u, error));
        }
        Some(with_wall(
            u,
            error,
            DoubleDouble::from_f64(self.kappa).div(sin),
        ))
    }

    /// V(b) − V(a) between two angles `length` = θ_b − θ_a apart (from
    /// [`EffectivePotential::separation`]), to full relative precision where they are close:
    /// sin(θ_b − θ_a) times the divided difference of V (its plain difference beyond 1.98
    /// apart, where the divided difference would lose to cos(θ_b − θ_a) → −1).
    pub(crate) fn rise(&self, a: Angle, b: Angle, length: f64) -> f64 {
        self.rise_with_error(a, b, length).0
    }

    /// [`Self::rise`] and a bound on its rounding: four ulps of the terms.
    fn rise_with_error(&self, a: Angle, b: Angle, length: f64) -> (f64, f64) {
        let (sl, cl) = length.sin_cos();
        if cl > -0.4 {
            let (d, scale) = divided_difference(self, b, a, sl, cl);
            let rise = sl * d;
            (rise, 4.0 * EPS * (rise.abs() + sl.abs() * scale))
        } else {
            let scales = self.value_scale(a) + self.value_scale(b);
            (self.value(b) - self.value(a), 4.0 * EPS * scales)
        }
    }

    /// The L1 size of V's terms at an angle, κ²/(2 sin²θ) + |U|: V's rounding is a few ulps
    /// of it.
    #[inline]
    pub fn value_scale(&self, a: Angle) -> f64 {
        let u = self.body.shape.potential_at(a).abs();
        if self.kappa == 0.0 {
            u
        } else {
            let w = self.kappa / a.sin;
            0.5 * w * w + u
        }
    }

    /// θ_b − θ_a to one rounding, whatever chart each site is held in: a site held as π − θ
    /// has its θ only rounded (an ulp of π, which against a libration 1e-8 wide round π/2 is
    /// a 2e-8 relative error of its length, and against one 1e-3 wide round π at κ = 0 and
    /// α → 1 was a 3e-14 error of T), so the difference is taken in the chart both sites are
    /// exact in, or across π/2 with π split into two doubles.
    pub fn separation(&self, a: &Site, b: &Site) -> f64 {
        // π = PI + PI_LOW to 2⁻¹⁰⁶.
        const PI_LOW: f64 = 1.2246467991473532e-16;
        match (a.theta_exact, b.theta_exact) {
            (true, true) => b.theta - a.theta,
            (false, false) => a.from_pi - b.from_pi,
            // PI − θ is exact for θ in [π/2, 2π] and the second difference when the sites
            // are close (Sterbenz's lemma); elsewhere one rounding.
            (true, false) => ((PI - a.theta) - b.from_pi) + PI_LOW,
            (false, true) => -(((PI - b.theta) - a.from_pi) + PI_LOW),
        }
    }

    /// V′ at an angle: −κ² cosθ / sin³θ + U′.
    #[inline]
    pub fn slope(&self, a: Angle) -> f64 {
        let up = self.body.shape.potential_prime_at(a);
        if self.kappa == 0.0 {
            up
        } else {
            // (κ/sinθ)² keeps κ² from underflowing at |κ| < 1e-154.
            let w = self.kappa / a.sin;
            let cot = a.cos / a.sin;
            // (Where (κ/sinθ)² alone would underflow, cotθ first: by a pole it is large.)
            let wall = if w.abs() < 1e-150 {
                w * (w * cot)
            } else {
                w * w * cot
            };
            -wall + up
        }
    }

    /// V″ at an angle: (κ/sinθ)² (sin²θ + 3 cos²θ) / sin²θ + U″.
    pub fn curvature_at(&self, a: Angle) -> f64 {
        let upp = self.body.shape.potential_second_at(a);
        if self.kappa == 0.0 {
            return upp;
        }
        let w = self.kappa / a.sin;
        w * w * (1.0 + 3.0 * (a.cos / a.sin) * (a.cos / a.sin)) + upp
    }

    /// V″ on either side of an angle, `[before, after]` in increasing θ: they differ on a
    /// kink of U ([`Shape::potential_second_sides_at`]), and equal V″ elsewhere.
    pub fn curvature_sides_at(&self, a: Angle) -> [f64; 2] {
        let v = self.curvature_at(a);
        let shape = &self.body.shape;
        match shape.potential_second_sides_at(a) {
            Some(sides) => sides.map(|u| v - shape.potential_second_at(a) + u),
            None => [v; 2],
        }
    }

    /// Where to look for critical points of V, in increasing θ over [0, π] (κ = 0: the
    /// uniform cells alone), with g′/sin²θ ([`Self::find_critical_points`]) at each site:
    /// [`SCAN_CELLS`] uniform cells (their body's part from `table`), each pole's end cell
    /// again on a logarithmic scale (8 points a decade) down to 10⁻³ √|κ|, below which V′ < 0
    /// near θ = 0 (> 0 near π) whatever U (the wall κ²/sin³θ beats any U′ there), so that a
    /// small well at a pole is not lost inside the first cell. Sites beyond π/2 are held as
    /// π − θ.
    fn scan_sites(&self, table: &ScanTable, dg: &impl Fn(Angle) -> f64) -> (Vec<Site>, Vec<f64>) {
        let cell = PI / SCAN_CELLS as f64;
        // κ = 0: the poles are critical points themselves, no well hides at them. Else the
        // well nearest a pole sits where κ²/sin³θ meets U′: at sinθ ~ (κ²/U″)^¼ by a smooth
        // pole, but at (κ²/U′)^⅓, much nearer, by a face, where U′ stays finite. U″ at the
        // poles and U′ on the cells may be far above 1: an oblate ellipsoid has U″ = β² − 1
        // − α at its poles and U′ ≈ β beyond 1/β of them, and at β = 1e10, κ = 0.25 its wells
        // at θ ≈ 1e-4 lay inside the first site, 1e-3 √κ (an adversary pass: `no_motion`
        // where the body moves).
        let innermost = if self.kappa == 0.0 {
            cell
        } else {
            let k = self.kappa.abs();
            // (Each bound in powers of κ itself: κ² underflows below 1e-154.)
            let smooth = k.sqrt() / table.pole_curvature.sqrt().sqrt();
            let steep = k.powf(2.0 / 3.0) / table.steepest.cbrt();
            let faces = self.body.shape.faces() != [false, false];
            1e-3 * if faces || table.steepest > 1.0 {
                smooth.min(steep)
            } else {
                smooth
            }
        }
        .max(f64::MIN_POSITIVE);
        let mut logs = Vec::new();
        let mut x = innermost;
        while x < cell {
            logs.push(x);
            x *= 10f64.powf(0.125);
        }
        let mut sites: Vec<Site> = logs.iter().map(|&x| Site::at(x)).collect();
        let mut values: Vec<f64> = sites.iter().map(|s| dg(s.angle())).collect();
        sites.extend(&table.sites);
        values.extend(
            (0..table.sites.len())
                .map(|i| self.dg_over_sin2(table.angles[i], table.slopes[i], table.seconds[i])),
        );
        let far: Vec<Site> = logs.iter().rev().map(|&x| Site::from_pi(x)).collect();
        values.extend(far.iter().map(|s| dg(s.angle())));
        sites.extend(far);
        (sites, values)
    }

    /// The zeros of `f` on a sequence of sites, `values` of `f` there, one per neighbouring
    /// pair with a sign change (bisected) or an exact zero at a site.
    fn sign_changes(&self, f: &impl Fn(Angle) -> f64, sites: &[Site], values: &[f64]) -> Vec<Site> {
        let mut zeros = Vec::new();
        for (i, w) in sites.windows(2).enumerate() {
            let (fa, fb) = (values[i], values[i + 1]);
            if fa == 0.0 {
                zeros.push(w[0]);
            } else if fb != 0.0 && (fa < 0.0) != (fb < 0.0) {
                zeros.push(self.bisect_sites(f, w[0], w[1]));
            }
        }
        if values.last() == Some(&0.0) {
            zeros.push(sites[sites.len() - 1]);
        }
        zeros
    }

    /// A sign change of `f` between two sites, bisected to the last bit in θ on (0, π/2] and
    /// in π − θ on [π/2, π), so that a zero keeps its relative precision at either pole; a
    /// bracket across π/2 is first cut there. (Bisected in the chart of the bracket's right
    /// end, a critical point 4e-4 from θ = 0 was held only to an ulp of π, which put the
    /// turning points beside it 5e-14 off at α → −1.)
    fn bisect_sites(&self, f: &impl Fn(Angle) -> f64, a: Site, b: Site) -> Site {
        let in_theta = |lo: f64, hi: f64| {
            let f_lo = f(Site::at(lo).angle());
            Site::at(bisect(&|x| f(Site::at(x).angle()), lo, hi, f_lo < 0.0))
        };
        let in_phi = |lo: f64, hi: f64| {
            let f_lo = f(Site::from_pi(lo).angle());
            Site::from_pi(bisect(&|x| f(Site::from_pi(x).angle()), lo, hi, f_lo < 0.0))
        };
        if b.theta <= FRAC_PI_2 {
            return in_theta(a.theta, b.theta);
        }
        if a.theta >= FRAC_PI_2 {
            return in_phi(b.from_pi, a.from_pi);
        }
        let middle = f(Site::at(FRAC_PI_2).angle());
        if middle == 0.0 {
            Site::at(FRAC_PI_2)
        } else if (middle < 0.0) != (f(a.angle()) < 0.0) {
            in_theta(a.theta, FRAC_PI_2)
        } else {
            in_phi(b.from_pi, FRAC_PI_2)
        }
    }

    /// ψ̇ = −κ cosθ / (J sin²θ) at an angle (0 for κ = 0).
    pub fn psi_rate(&self, a: Angle) -> f64 {
        if self.kappa == 0.0 {
            return 0.0;
        }
        self.psi_rate_with(a, self.body.reduction_at(a).integral_factor)
    }

    /// [`Self::psi_rate`] with J at the angle known (0 for κ = 0, also at a pole).
    fn psi_rate_with(&self, a: Angle, j: f64) -> f64 {
        if self.kappa == 0.0 {
            return 0.0;
        }
        -self.kappa * a.cos / (j * a.sin * a.sin)
    }

    /// (V′, ψ̇, dψ̇/dθ) at an angle from one evaluation of the body, with
    /// dψ̇/dθ = κ (sin²θ + 2 cos²θ) / (J sin³θ) + κ cosθ J′ / (J² sin²θ) and
    /// J′ = ((ν − 1) sinθ cosθ / η + U U′) / J (ψ̇ and its slope 0 for κ = 0).
    pub fn slope_and_psi_rates(&self, a: Angle) -> (f64, f64, f64) {
        let up = self.body.shape.potential_prime_at(a);
        if self.kappa == 0.0 {
            return (up, 0.0, 0.0);
        }
        let red = self.body.reduction_at(a);
        let j = red.integral_factor;
        let jp = ((self.body.nu - 1.0) * a.sin * a.cos / self.body.eta + red.potential * up) / j;
        let w = self.kappa / a.sin;
        let cot = a.cos / a.sin;
        let slope = -w * w * cot + up;
        let psi = -w * cot / j;
        let psi_slope = w * (1.0 + 2.0 * cot * cot) / j + w * cot * jp / (j * j);
        (slope, psi, psi_slope)
    }

    /// g′/sin²θ = κ²/sinθ + 3 cosθ U′ + sinθ U″ at `a`, from U′ and U″ there (the
    /// derivative of g = sin³θ V′ that brackets the critical points; see
    /// [`Self::find_critical_points`]).
    fn dg_over_sin2(&self, a: Angle, slope: f64, second: f64) -> f64 {
        let w = self.kappa / a.sin;
        w * w * a.sin + 3.0 * a.cos * slope + a.sin * second
    }

    /// The critical points, and the shoulders ([`Self::shoulders`]).
    fn find_critical_points(&self, table: &ScanTable) -> (Vec<CriticalPoint>, Vec<Site>) {
        let shape = &self.body.shape;
        // Roots of g = sin³θ V′ = −κ² cosθ + sin³θ U′ (no pole; U′'s roots in (0, π) for
        // κ = 0), bracketed between the roots of g′ = κ² sinθ + 3 sin²θ cosθ U′ + sin³θ U″
        // so that close pairs (near the cusp, tangencies) are not lost between scan nodes.
        // Both are evaluated divided by a power of sinθ (V′ = g/sin³θ, g′/sin²θ), which
        // keeps their signs and keeps κ² from underflowing.
        // Where the wall's (κ/sinθ)² cotθ underflows (|κ| < 1e-154 away from the poles) and
        // U′ is exactly 0 (a homogeneous sphere), V′ rounds to 0 at every site, and each site
        // was taken for a critical point (3193 of them at κ = 1e-300; a sphere given as a
        // profile then had 11 separatrix components): there the sign of V′ is the wall's,
        // that of −cosθ.
        let g = |a: Angle| match self.slope(a) {
            0.0 if self.kappa != 0.0 && shape.potential_prime_at(a) == 0.0 => {
                -a.cos * f64::MIN_POSITIVE
            }
            slope => slope,
        };
        let dg = |a: Angle| {
            self.dg_over_sin2(a, shape.potential_prime_at(a), shape.potential_second_at(a))
        };
        let (scan, dg_values) = self.scan_sites(table, &dg);
        // A flat U at κ = 0 (the homogeneous sphere) has no isolated critical points: every
        // energy above U is uniform rolling; only θ = 0 and π are kept as reference points.
        let flat = self.kappa == 0.0 && scan.iter().all(|s| g(s.angle()) == 0.0);
        let extrema = self.sign_changes(&dg, &scan, &dg_values);
        let mut cuts = vec![scan[0]];
        cuts.extend(&extrema);
        cuts.push(scan[scan.len() - 1]);
        cuts.dedup();
        let mut roots = if flat {
            Vec::new()
        } else {
            let values: Vec<f64> = cuts.iter().map(|s| g(s.angle())).collect();
            self.sign_changes(&g, &cuts, &values)
        };
        roots.dedup();
        // A critical point on a kink: V′ there may round to either sign on both sides (V
        // rising or falling through a shoulder, whose slope is zero at one point only), so
        // the sign changes can miss it. Any kink where V′ vanishes to rounding is one.
        if !flat {
            for &theta in shape.kinks() {
                let site = Site::at(theta);
                let a = site.angle();
                let w = self.kappa / a.sin;
                let scale = w * w * (a.cos / a.sin).abs()
                    + shape.potential_at(a).abs()
                    + shape.potential_prime_at(a).abs();
                let known = roots.iter().any(|r| (r.theta - theta).abs() <= 1e-12);
                if !known && g(a).abs() <= 8.0 * EPS * scale {
                    let at = roots.partition_point(|r| r.theta < theta);
                    roots.insert(at, site);
                }
            }
        }
        let sites: Vec<Site> = if self.kappa != 0.0 {
            roots
        } else {
            // On the circle [0, 2π): θ = 0 and π always, the roots and their mirror images,
            // θ itself held but for π.
            let mut t: Vec<f64> = roots
                .iter()
                .map(|s| s.theta)
                .filter(|&t| t > 1e-9 && t < PI - 1e-9)
                .collect();
            let mirrored: Vec<f64> = t.iter().rev().map(|x| TAU - x).collect();
            t.insert(0, 0.0);
            t.push(PI);
            t.extend(mirrored);
            // θ = π held as π − θ = 0: exactly the pole, where PI is 1.2e-16 short of it.
            t.into_iter()
                .map(|x| {
                    if x == PI {
                        Site::from_pi(0.0)
                    } else {
                        Site::at(x)
                    }
                })
                .collect()
        };
        let mut shoulders = Vec::with_capacity(sites.len());
        let mut points: Vec<CriticalPoint> = sites
            .into_iter()
            .map(|site| {
                let [before, after] = self.curvature_sides_at(site.angle());
                // On a kink whose one-sided curvatures differ in sign V is monotone through
                // the point (a shoulder: a maximum of one part and a minimum of the other
                // merged); its concave side's curvature sets the slow passage at its level.
                // Otherwise the flatter side's curvature (the slower passage).
                shoulders.push(before * after < 0.0);
                CriticalPoint {
                    site,
                    value: self.value(site.angle()),
                    scale: self.value_scale(site.angle()),
                    curvature: if before <= 0.0 && after <= 0.0 {
                        before.max(after)
                    } else {
                        before.min(after)
                    },
                    kind: CriticalKind::Inflection,
                }
            })
            .collect();
        // Classify by comparing with the neighbours (poles count as +∞ for κ ≠ 0; on the
        // circle the neighbours wrap around).
        let n = points.len();
        let values: Vec<f64> = points.iter().map(|p| p.value).collect();
        for (i, p) in points.iter_mut().enumerate() {
            if shoulders[i] {
                continue;
            }
            let (left, right) = if self.kappa != 0.0 {
                (
                    if i == 0 { f64::INFINITY } else { values[i - 1] },
                    if i + 1 == n {
                        f64::INFINITY
                    } else {
                        values[i + 1]
                    },
                )
            } else {
                (values[(i + n - 1) % n], values[(i + 1) % n])
            };
            p.kind = if p.value < left && p.value < right {
                CriticalKind::Minimum
            } else if p.value > left && p.value > right {
                CriticalKind::Maximum
            } else if p.curvature > 0.0 {
                CriticalKind::Minimum
            } else if p.curvature < 0.0 && (p.value >= left || p.value >= right) {
                CriticalKind::Maximum
            } else {
                CriticalKind::Inflection
            };
        }
        let shoulders = if self.kappa != 0.0 && shape.kinks().is_empty() {
            extrema
                .into_iter()
                .filter(|e| points.iter().all(|p| p.site.theta != e.theta))
                .collect()
        } else {
            Vec::new()
        };
        (points, shoulders)
    }

    /// The least height over which V is nearly flat at a shoulder strictly between `lower`
    /// and `upper` ([`Self::shoulders`]): |ε − V_k| + |s|^{3/2} / √(|V‴|/6) at each, with
    /// s = V′ there. In the model V = V_k + s x + c x³ it is the rise across the shoulder's
    /// flat stretch, |x| ≲ √(|s/c|), plus ε's distance from it: the level responds to ε on that
    /// scale (at s = 0, the cusp, an end a distance d before the inflection has
    /// V_k − ε = c d³ and dT/dε = T_end / (6 c d³)). ∞ where there is none.
    pub(crate) fn shoulder_gap(&self, energy: f64, lower: f64, upper: f64) -> f64 {
        self.shoulders
            .iter()
            .filter(|k| k.theta > lower && k.theta < upper)
            .map(|k| {
                let a = k.angle();
                let slope = self.slope(a).abs();
                let h = 1e-5 * k.theta.min(k.from_pi).min(1.0);
                let third = (self.curvature_at(Site::at(k.theta + h).angle())
                    - self.curvature_at(Site::at(k.theta - h).angle()))
                    / (2.0 * h);
                (energy - self.value(a)).abs() + slope * slope.sqrt() / (third.abs() / 6.0).sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The components of {V ≤ ε}, sorted by θ_min. For κ ≠ 0 they lie in (0, π); for κ = 0
    /// the motion lives on the circle and a component may straddle θ = 0 (then θ_min < 0) or
    /// be the whole circle (rolling over the top, [`MotionKind::Rotation`]).
    pub fn components(&self, energy: f64) -> Result<Vec<Component>> {
        let nodes = match self.levels(energy)? {
            Levels::OverTheTop(nodes) => {
                let (first, last) = (nodes[0].unwrap(), nodes[nodes.len() - 1].unwrap());
                return Ok(vec![Component {
                    lower: first.site,
                    upper: last.site,
                    kind: MotionKind::Rotation,
                    family: Family::OverTheTop,
                    interior: nodes[1..nodes.len() - 1]
                        .iter()
                        .flatten()
                        .copied()
                        .collect(),
                    neighbours: [None, None],
                }]);
            }
            Levels::Nodes(nodes) => nodes,
        };
        let last_node = nodes.len() - 1;
        let runs = runs_at(&nodes, energy);
        let families = self.families_of_runs(&nodes, &runs);
        Ok(runs
            .into_iter()
            .zip(families)
            .map(|((first, last), family)| {
                // A minimum just above ε, within its rounding: the body rests there.
                if let Some(m) = nodes[first].filter(|m| first == last && m.value > energy) {
                    let neighbours = [
                        first.checked_sub(1).and_then(|i| nodes[i]),
                        nodes.get(last + 1).copied().flatten(),
                    ];
                    return Component::resting_at(m, family, neighbours);
                }
                // A run that starts or ends at a node reaches the top of the circle itself
                // (κ = 0, a separatrix); otherwise its ends are crossings of V = ε.
                let lower = if first == 0 {
                    nodes[0].unwrap().site
                } else {
                    self.turning_point(&nodes[first - 1], &nodes[first], energy)
                };
                let upper = if last == last_node {
                    nodes[last].unwrap().site
                } else {
                    self.turning_point(&nodes[last], &nodes[last + 1], energy)
                };
                self.make_component(&nodes, (lower, upper), (first, last), energy, family)
            })
            .collect())
    }

    /// The families of the components of {V ≤ ε}, in θ_min order, without their turning
    /// points: as [`EffectivePotential::components`] labels them, at a fraction of its cost.
    pub fn families(&self, energy: f64) -> Result<Vec<Family>> {
        Ok(match self.levels(energy)? {
            Levels::OverTheTop(_) => vec![Family::OverTheTop],
            Levels::Nodes(nodes) => self.families_of_runs(&nodes, &runs_at(&nodes, energy)),
        })
    }

    /// The families of the components whose interiors hold the nodes of `runs` (index
    /// ranges into `nodes`), in order: each by [`EffectivePotential::family_of_run`], and
    /// two tori on one side told apart by the depths of their wells
    /// ([`family::rank_by_depth`]).
    fn families_of_runs(
        &self,
        nodes: &[Option<CriticalPoint>],
        runs: &[(usize, usize)],
    ) -> Vec<Family> {
        let mut families: Vec<Family> = runs
            .iter()
            .map(|&(first, last)| self.family_of_run(&nodes[first..=last]))
            .collect();
        if families.len() > 1 {
            let depths: Vec<f64> = runs
                .iter()
                .map(|&(first, last)| {
                    nodes[first..=last]
                        .iter()
                        .map(node_value)
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            family::rank_by_depth(&mut families, &depths);
        }
        families
    }

    /// The nodes that cut the θ-axis into pieces where V is monotone: the critical points
    /// between the two poles (κ ≠ 0, `None` at each pole), or around the circle starting
    /// and ending at the highest one (κ = 0, lifted so that components round θ = 0
    /// straddle it). Errors for a non-finite ε and for ε below the bottom of V.
    fn levels(&self, energy: f64) -> Result<Levels> {
        if !energy.is_finite() {
            return Err(AtlasError::InvalidParameter {
                name: "energy",
                value: energy,
                reason: "must be finite",
            });
        }
        let mut nodes: Vec<Option<CriticalPoint>> = Vec::with_capacity(self.critical.len() + 2);
        if self.kappa != 0.0 {
            nodes.push(None);
            nodes.extend(self.critical.iter().copied().map(Some));
            nodes.push(None);
        } else {
            let (top, peak) = self
                .critical
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.value.total_cmp(&b.1.value))
                .expect("θ = 0 and π are always critical on the circle");
            let lift = |p: &CriticalPoint, by: f64| CriticalPoint {
                site: if by == 0.0 {
                    p.site
                } else {
                    Site::at(p.site.theta + by)
                },
                ..*p
            };
            // Keep lifted angles near [−π, π] so that components around θ = 0 straddle it.
            let shift = if peak.site.theta > PI - 1e-9 {
                -TAU
            } else {
                0.0
            };
            nodes.extend(self.critical[top..].iter().map(|p| Some(lift(p, shift))));
            nodes.extend(
                self.critical[..top]
                    .iter()
                    .map(|p| Some(lift(p, shift + TAU))),
            );
            nodes.push(Some(lift(peak, shift + TAU)));
            if energy > peak.value {
                return Ok(Levels::OverTheTop(nodes));
            }
        }
        let minimum = nodes.iter().map(node_value).fold(f64::INFINITY, f64::min);
        if energy < minimum && !nodes.iter().any(|n| at_rounding_minimum(n, energy)) {
            return Err(AtlasError::NoMotion { energy, minimum });
        }
        Ok(Levels::Nodes(nodes))
    }

    /// The family of the component whose interior holds the nodes `run` (all at or below
    /// ε): named by the side of the equator its minima lie on; a component round wells on
    /// both sides (above a saddle) belongs to the family of the well V keeps at large κ
    /// ([`crate::limits::high_energy_family`]). A run without a minimum (a degenerate
    /// tangency) is named by its lowest node.
    fn family_of_run(&self, run: &[Option<CriticalPoint>]) -> Family {
        let outer = crate::limits::high_energy_family(self.body);
        let points = run.iter().flatten();
        let minima = points.clone().filter(|p| p.kind == CriticalKind::Minimum);
        family::of_sides(minima.map(|p| self.side(p)), outer)
            .or_else(|| {
                let lowest = points.min_by(|a, b| a.value.total_cmp(&b.value))?;
                family::of_sides([self.side(lowest)], outer)
            })
            .expect("a run holds at least one node")
    }

    /// Which side of the equator a minimum of V lies on, by its distance from θ = 0 (on the
    /// κ = 0 circle the lifted angle taken to (−π, π]). For κ ≠ 0 the single minimum of a
    /// body symmetric about its equator lies at π/2 exactly (by symmetry, whatever its
    /// rounding). A minimum within [`EQUATOR_WINDOW`] of π/2 may have been rounded across
    /// it (at large κ the well sits within |U′(π/2)|/κ² of π/2, and cos(FRAC_PI_2) = 6e-17
    /// then outweighs U′ in V′): its side is that of the exact sign of V′(π/2) = U′(π/2)
    /// (the κ term vanishes there), beyond π/2 where V descends.
    fn side(&self, p: &CriticalPoint) -> Side {
        let symmetric = self.body.shape.symmetric_about_equator();
        let wrapped = (p.site.theta + PI).rem_euclid(TAU) - PI;
        let from_equator = wrapped.abs() - FRAC_PI_2;
        if self.kappa != 0.0 && symmetric {
            // One well, at π/2; or a mirror pair, one on each side however close; or both
            // (an edged body, a band of sphere between two edges): with an odd number of
            // wells, the middle one is at π/2.
            let minima: Vec<&CriticalPoint> = self
                .critical
                .iter()
                .filter(|c| c.kind == CriticalKind::Minimum)
                .collect();
            let middle = (minima.len() % 2 == 1).then(|| minima[minima.len() / 2]);
            return if middle.is_some_and(|m| m.site.theta == p.site.theta) {
                Side::Equator
            } else if from_equator < 0.0 {
                Side::Upper
            } else {
                Side::Lower
            };
        }
        if from_equator.abs() > EQUATOR_WINDOW {
            return if from_equator < 0.0 {
                Side::Upper
            } else {
                Side::Lower
            };
        }
        // (On the circle U(−θ) = U(θ): the well near −π/2 mirrors the one near π/2.)
        // A slope within U's rounding and the body's representation error is none: a
        // profile's table symmetric about z = α has U′(π/2) = −6e-16 from its fitted arcs,
        // and its equator well was filed as well_pi beside the well of its lower face, two
        // tori of one family (adversary pass of 2026-11-28).
        let shape = &self.body.shape;
        let slope = shape.potential_prime_at(Angle::EQUATOR);
        let flat =
            4.0 * EPS * shape.potential_at(Angle::EQUATOR).abs() + shape.representation_error();
        if symmetric || slope.abs() <= flat {
            Side::Equator
        } else if slope < 0.0 {
            Side::Lower
        } else {
            Side::Upper
        }
    }

    /// The component of `family` between `lower` and `upper`, whose interior holds the nodes
    /// of `run`, first..=last (the nodes equal to an end are not interior).
    fn make_component(
        &self,
        nodes: &[Option<CriticalPoint>],
        (lower, upper): (Site, Site),
        (first, last): (usize, usize),
        energy: f64,
        family: Family,
    ) -> Component {
        let interior: Vec<CriticalPoint> = nodes[first..=last]
            .iter()
            .flatten()
            .filter(|p| p.site.theta > lower.theta && p.site.theta < upper.theta)
            .copied()
            .collect();
        // The critical point at or just beyond each end (a separatrix level touches it).
        let at = |i: usize, site: Site| nodes[i].filter(|p| p.site.theta == site.theta);
        let neighbours = [
            at(first, lower).or_else(|| first.checked_sub(1).and_then(|i| nodes[i])),
            at(last, upper).or_else(|| nodes.get(last + 1).copied().flatten()),
        ];
        // ε at a minimum to rounding: the turning points may have met on the minimum itself.
        let closed: Vec<CriticalPoint> = nodes[first..=last]
            .iter()
            .flatten()
            .filter(|p| p.site.theta >= lower.theta && p.site.theta <= upper.theta)
            .copied()
            .collect();
        let at_minimum = closed.len() == 1
            && closed[0].kind == CriticalKind::Minimum
            && energy - closed[0].value <= 4.0 * EPS * closed[0].scale;
        if at_minimum {
            return Component::resting_at(closed[0], family, neighbours);
        }
        Component {
            lower,
            upper,
            kind: MotionKind::Libration,
            family,
            interior,
            neighbours,
        }
    }

    /// The root of V = ε between two adjacent nodes (V monotone between them; `None` is a
    /// pole), by Newton's method safeguarded with bisection, in θ on (0, π/2] and in π − θ on
    /// [π/2, π) so that turning points near θ = π keep their relative precision.
    fn turning_point(
        &self,
        a: &Option<CriticalPoint>,
        b: &Option<CriticalPoint>,
        energy: f64,
    ) -> Site {
        // A node at the level itself (a shoulder, or a maximum, met exactly) is the end.
        if let Some(p) = [a, b].into_iter().flatten().find(|p| p.value == energy) {
            return p.site;
        }
        let lo = a.map_or(0.0, |p| p.site.theta);
        let hi = b.map_or(PI, |p| p.site.theta);
        // V − ε measured from the critical point inside the level set, as
        // sin(θ − c) D(θ, c) − (ε − V(c)): both turning points of a libration are then roots
        // of one cancellation-free function, so their levels agree far below an ulp of ε
        // (near a flat minimum an ulp of mismatch would shift the orbit visibly).
        let inside = [a, b]
            .into_iter()
            .flatten()
            .find(|p| p.value <= energy)
            .copied();
        let inside_angle = inside.map(|c| c.site.angle());
        // (V − ε, V′) at a site.
        let level = |site: Site| -> (f64, f64) {
            let t = site.angle();
            let slope = self.slope(t);
            if let (Some(c), Some(c_angle)) = (inside, inside_angle) {
                let diff = self.separation(&c.site, &site);
                let (sd, cd) = libm::sincos(diff);
                if cd > -0.4 {
                    let d = divided_difference(self, t, c_angle, sd, cd).0;
                    // Right next to a pole D ∝ κ²/(sin²θ sin θ_c) overflows before V does
                    // (below 7e-155·κ^0.75): there V − ε is taken as it is.
                    if d.is_finite() {
                        return (sd * d - (energy - c.value), slope);
                    }
                }
            }
            (self.value(t) - energy, slope)
        };
        // Newton starts from the quadratic model around the minimum inside,
        // θ = c ± √(2 (ε − V_c) / V″_c), when it has one.
        let offset = inside.filter(|c| c.curvature > 0.0).map(|c| {
            let toward_b = a.is_some_and(|p| p.site.theta == c.site.theta);
            let d = (2.0 * (energy - c.value) / c.curvature).sqrt();
            (c, if toward_b { d } else { -d })
        });
        let start_theta = offset.map(|(c, d)| c.site.theta + d);
        let start_phi = offset.map(|(c, d)| c.site.from_pi - d);
        let f_left = |x: f64| level(Site::at(x));
        // The sign of V − ε at a node is known (a pole is +∞): no evaluation needed there.
        let below = |n: &Option<CriticalPoint>| n.is_some_and(|p| p.value < energy);
        // Beyond π/2 the root is sought in π − θ, for κ = 0 too (where the circle's lifted
        // θ ≤ 2π keeps PI − θ exact): a libration round θ = π at κ = 0 may be as narrow as
        // one at a pole for κ ≠ 0 (1e-3 wide as α → 1), and an ulp of π in each turning
        // point would be a 3e-13 relative uncertainty of its length.
        if hi <= FRAC_PI_2 {
            return Site::at(safe_newton(f_left, lo, hi, below(a), start_theta));
        }
        let f_right = |phi: f64| {
            let (value, slope) = level(Site::from_pi(phi));
            (value, -slope)
        };
        let phi_lo = b.map_or(0.0, |p| p.site.from_pi);
        if lo >= FRAC_PI_2 {
            let phi_hi = a.map_or(PI, |p| p.site.from_pi);
            return Site::from_pi(safe_newton(f_right, phi_lo, phi_hi, below(b), start_phi));
        }
        // The bracket straddles π/2: pick the half with the sign change.
        let mid = f_left(FRAC_PI_2).0;
        let lo_val = a.map_or(f64::INFINITY, |p| p.value) - energy;
        if mid == 0.0 {
            Site::at(FRAC_PI_2)
        } else if (mid < 0.0) != (lo_val < 0.0) {
            Site::at(safe_newton(f_left, lo, FRAC_PI_2, below(a), start_theta))
        } else {
            Site::from_pi(safe_newton(f_right, phi_lo, FRAC_PI_2, below(b), start_phi))
        }
    }

    /// T, Δψ and (if `with_drift`) Δζ of a libration or rotation, refined until the
    /// level-to-level change is within `tol` (relative for T and Δζ, absolute for
    /// N = −Δψ/2π); the error estimates add a bound on the rounding errors of the gap ε − V.
    /// A libration with no kink inside by the cosine substitution (`cosine`); otherwise in
    /// pieces cut at the kinks, saddles and tangencies, each by Clenshaw–Curtis where it is
    /// predicted to converge ([`ChebyshevPiece`]), else (or where it does not) by tanh-sinh.
    pub fn integrate(
        &self,
        energy: f64,
        component: &Component,
        tol: f64,
        with_drift: bool,
    ) -> Result<PeriodIntegrals> {
        self.integrate_by(energy, component, tol, with_drift, Rules::Fastest)
    }

    /// [`Self::integrate`] by the rules `rules` allows (the tanh-sinh rule alone is the
    /// other rules' check).
    #[doc(hidden)]
    pub fn integrate_by(
        &self,
        energy: f64,
        component: &Component,
        tol: f64,
        with_drift: bool,
        rules: Rules,
    ) -> Result<PeriodIntegrals> {
        let fast_rules = rules == Rules::Fastest;
        if component.kind == MotionKind::FixedPoint {
            return Err(AtlasError::NotPeriodic {
                reason: "the component is a fixed point",
            });
        }
        // A libration is tried whole with the cosine substitution first: unless a saddle or
        // a pole comes close to the level, that is several times cheaper.
        // (Not across a kink of U: its rule converges geometrically only on an analytic
        // integrand.)
        // (The evaluations spent on it where it gives up count in the other rules' work.)
        let mut spent = 0;
        if fast_rules
            && component.kind == MotionKind::Libration
            && self
                .splits_inside(component.lower.theta, component.upper.theta)
                .is_empty()
        {
            let mut whole = self.pieces(energy, component, false);
            self.sharpen_gaps(&mut whole, energy, component.kind, tol);
            match cosine::integrate(self, &whole[0], energy, component, tol, with_drift)? {
                Ok(result) => return Ok(result),
                Err(work) => spent = work,
            }
        }
        let mut pieces = self.pieces(energy, component, true);
        self.sharpen_gaps(&mut pieces, energy, component.kind, tol);
        let kinds = if fast_rules {
            self.chebyshev_kinds(component, &pieces, tol)
        } else {
            vec![None; pieces.len()]
        };
        let mut samples: Vec<PieceSamples> = pieces
            .iter()
            .zip(&kinds)
            .map(|(p, kind)| {
                let chebyshev = kind.and_then(|(kind, least, map)| {
                    PieceSamples::chebyshev(self, p, energy, kind, map, START_LEVEL, least)
                });
                match chebyshev {
                    Some(s) => Ok(s),
                    None => PieceSamples::new(self, p, energy, START_LEVEL),
                }
            })
            .collect::<Result<_>>()?;
        let double = if component.kind == MotionKind::Rotation {
            1.0
        } else {
            2.0
        };
        let share = 1.0 / pieces.len() as f64;
        // Near a saddle the conditioning of ε (below) may exceed the tolerance: refining the
        // quadrature much below that bound (a worst case; a tenth of it) would buy nothing.
        let provisional = double * samples.iter().map(|s| s.period(0)).sum::<f64>();
        let residual = level_residual(component, &pieces);
        let floor =
            self.placed_saddle_conditioning(energy, component, provisional, double, residual);
        let (floor_t, floor_psi) = (floor.period, floor.psi_advance);
        let mut converged = true;
        for (piece, sample) in pieces.iter().zip(samples.iter_mut()) {
            // Half of the tolerance for the quadrature, half left for rounding (which the
            // refinement cannot reduce).
            let misses = |sample: &PieceSamples| {
                sample.error(DT)
                    > (0.5 * tol * sample.period(0)).max(0.1 * floor_t * share / double)
                    || double * sample.error(DPSI) / TAU
                        > (0.5 * tol * share).max(0.1 * floor_psi * share / TAU)
            };
            // By a pole the tanh-sinh levels must also show one rate: their sums can converge
            // fast and then stall (a truncated ball at κ = 0.0018, θ_min = 8e-4: d₁ = 2.4e-9
            // after 2.2e-3, the level's error 4.9e-9; N at tol 1e-6 was 1.44× its estimate).
            while sample.level < sample.least_level
                || (sample.rule == Rule::TanhSinh && self.by_a_pole(piece) && !sample.one_rate())
                || misses(sample)
            {
                match sample.rule {
                    Rule::Chebyshev(_) => {
                        if sample.level >= CHEBYSHEV_LAST_LEVEL
                            || !sample.refine(self, piece, energy)?
                        {
                            // Slow (a near-singular end) or a node outside: tanh-sinh takes
                            // over.
                            let spent = sample.evaluations;
                            *sample = PieceSamples::new(self, piece, energy, START_LEVEL)?;
                            sample.evaluations += spent;
                        }
                    }
                    Rule::TanhSinh => {
                        if sample.level >= MAX_LEVEL {
                            // (Levels that never showed one rate keep their estimate, as
                            // before.)
                            converged &= !misses(sample);
                            break;
                        }
                        sample.refine(self, piece, energy)?;
                    }
                }
            }
        }
        // (Once, where the rounding of the nodes in double is what keeps the drift from the
        // tolerance: the tanh-sinh nodes again in double-double, `take_again_precise`.)
        let mut retaken = false;
        loop {
            let sum = |f: &dyn Fn(&PieceSamples) -> f64| {
                samples.iter().map(f).sum::<CompensatedSum>().value()
            };
            let period = double * sum(&|s| s.period(0));
            let psi_advance = double * sum(&|s| s.psi(0));
            let mut period_error = double * sum(&|s| s.error(DT));
            let mut psi_advance_error = double * sum(&|s| s.error(DPSI));
            let (period_quadrature, psi_quadrature) = (period_error, psi_advance_error);
            let period_rounding = double * sum(&|s| s.rounding(|n| n.dt));
            let psi_rounding = double * sum(&|s| s.rounding(|n| n.dpsi));
            let psi_variation = double * sum(&|s| s.size(DPSI));
            let saddle =
                self.placed_saddle_conditioning(energy, component, period, double, residual);
            let (saddle_t, saddle_psi) = (saddle.period, saddle.psi_advance);
            period_error += period_rounding + saddle_t;
            psi_advance_error += psi_rounding + saddle_psi;
            // A turning point nearer its pole than the rule's last node (e^{−π sinh τ_max} of the
            // piece) hides the peak of ψ̇ ~ κ/sin²θ there, which turns ψ by up to ±π/2 as θ
            // passes it by a smooth pole: the sums cannot see it, so its whole size goes into the
            // estimate. By a face (U rising linearly from the pole, B and J² unequal there) the
            // turn has no such bound: at ν = 2, η = 4 a disk's passage turns ψ by 7.0, N = √5/2
            // in the limit κ → 0. There Δψ is unknown.
            let faces = self.body.shape.faces();
            let hidden: Vec<bool> = if self.kappa == 0.0 {
                Vec::new()
            } else {
                pieces
                    .iter()
                    .flat_map(|p| [(p.left, p.length), (p.right, p.length)])
                    .filter(|(end, length)| {
                        end.excess == 0.0
                            && end.site.theta.min(end.site.from_pi) < HIDDEN_PEAK * length
                    })
                    .map(|(end, _)| faces[usize::from(end.site.from_pi < end.site.theta)])
                    .collect()
            };
            if !hidden.is_empty() {
                psi_advance_error += if hidden.iter().any(|&face| face) {
                    f64::INFINITY
                } else {
                    PI * hidden.len() as f64
                };
                converged = false;
            }
            let mut drift = None;
            if with_drift {
                // Rounding in T and Δψ enters the drift through the phases and the weights.
                // (And the tails of Δψ: a sweep by a pole cut short turns the rest of the path.)
                let psi_tail = double * sum(&|s| s.tail(|n| n.dpsi));
                // (And the time spent by a saddle, at the speed there: `saddle.drift`, absolute.)
                let phase =
                    period_rounding / period.max(1e-300) + psi_rounding + saddle_psi + psi_tail;
                // The floor of the phases' rounding with the nodes in double-double (below).
                // (Half the bound of each node, as `PieceSamples::rounding` counts it, and an
                // ulp for its gap.)
                let precise = 0.5 * (PRECISE_NODE_ROUNDING + EPS);
                let floor_psi = precise * psi_variation + saddle_psi;
                let floor_phase = precise + floor_psi + psi_tail;
                // (Whether the shape gives its nodes in double-double is asked only where the
                // rest holds and it matters: this runs for every libration with a drift.)
                let may_retake_here = !retaken
                    && converged
                    && hidden.is_empty()
                    && period_quadrature + precise * period + saddle_t <= tol * period
                    && psi_quadrature + floor_psi <= tol * TAU
                    && samples.iter().all(|sample| sample.rule == Rule::TanhSinh);
                let may_retake = || {
                    may_retake_here && pieces.iter().all(|piece| self.gives_precise_nodes(piece))
                };
                let mut known = Vec::new();
                let mut result = drift_estimate(&samples, psi_advance, double, &mut known);
                for _ in 0..(MAX_LEVEL - START_LEVEL) {
                    // (What the tolerance leaves after the phases' rounding, which is added below,
                    // as for T and Δψ: refined only to the tolerance itself, 25 librations by the
                    // saddle of the standard slice missed 1e-13 by that rounding. Where it leaves
                    // less than a tenth of that rounding, the tolerance itself, as before: the
                    // drift misses it anyway, and refining further only cost work at 1e-14.)
                    // (Where the nodes will be taken again in double-double, what the tolerance
                    // leaves after their floor: by the standard slice's saddle at tol 1e-14 the
                    // drift stopped at a tenth of the phases' rounding in double, above what
                    // the floor left.)
                    let room = tol - phase;
                    let precise_room = tol - floor_phase;
                    let target = if room > 0.1 * phase {
                        room
                    } else if precise_room > 0.1 * floor_phase && may_retake() {
                        precise_room
                    } else {
                        tol.max(0.1 * phase)
                    };
                    if result.error <= target * result.scale
                        || samples.iter().any(|s| s.level >= MAX_LEVEL)
                    {
                        break;
                    }
                    let mut refined = true;
                    for (piece, sample) in pieces.iter().zip(samples.iter_mut()) {
                        if !sample.refine(self, piece, energy)? {
                            refined = false;
                            break;
                        }
                    }
                    if !refined {
                        // A Clenshaw–Curtis node outside the allowed set: the drift keeps the
                        // estimate it has.
                        break;
                    }
                    let psi = double * samples.iter().map(|s| s.psi(0)).sum::<f64>();
                    result = drift_estimate(&samples, psi, double, &mut known);
                }
                // The tolerance missed by the phases' rounding, but met with the integrands in
                // double-double, and T and Δψ with them: the nodes again. (At tol 1e-14, 910
                // librations of the standard slice by a pole, κ < 0.05, missed by their drift
                // alone, all integrated by the tanh-sinh rule, its nodes in double.)
                let room = tol * result.scale - saddle.drift;
                let retake = result.error + phase * result.scale > room
                    && result.error + floor_phase * result.scale <= room
                    && may_retake();
                if retake {
                    for (piece, sample) in pieces.iter().zip(samples.iter_mut()) {
                        sample.take_again_precise(self, piece, energy)?;
                    }
                    retaken = true;
                    continue;
                }
                result.error += phase * result.scale + saddle.drift;
                if !hidden.is_empty() {
                    // The hidden turn rotates the rest of the path: Δζ is unknown to its size.
                    result.error += result.scale;
                }
                drift = Some(result);
            }
            return Ok(PeriodIntegrals {
                period,
                psi_advance,
                period_error,
                psi_advance_error,
                drift,
                psi_variation: Some(psi_variation),
                saddle,
                level_residual: residual,
                work: spent + samples.iter().map(|s| s.evaluations).sum::<usize>(),
                converged,
            });
        }
    }

    /// Whether [`precise_sample`] can take the nodes of `piece` in double-double: an end with a
    /// sharp pair, on a shape that gives the reduction in double-double there.
    fn gives_precise_nodes(&self, piece: &Piece) -> bool {
        [&piece.left, &piece.right]
            .iter()
            .any(|end| self.end_gives_precise_nodes(end))
    }

    /// Whether `end` has a sharp pair at which the shape gives the reduction in double-double
    /// (what [`precise_sample`] measures its nodes from).
    fn end_gives_precise_nodes(&self, end: &PieceEnd) -> bool {
        end.sharp
            .as_ref()
            .is_some_and(|s| self.body.reduction_double_double(s.sin, s.cos).is_some())
    }

    /// The errors of T and Δψ caused by the conditioning of the energy near a saddle (inside
    /// the component, passed `double` times a period, or just beyond an end, passed once):
    /// T grows like −log|ε − V_s| / λ there, so an error δε in the energy (at least the
    /// rounding of V_s, or `energy_error` if larger) moves T by δε / (λ |ε − V_s|) per passage.
    pub(crate) fn saddle_conditioning(
        &self,
        energy: f64,
        component: &Component,
        period: f64,
        double: f64,
        energy_error: f64,
    ) -> SaddleTerms {
        self.saddle_terms(energy, component, period, double, false, |p| {
            energy_error.max(4.0 * EPS * (p.scale + energy.abs()))
        })
    }

    /// [`Self::saddle_conditioning`] of the quadrature's pieces: where their turning points
    /// were placed on ε (`residual`, [`PeriodIntegrals::level_residual`]), at twice it, the
    /// whole offset of their level (the rounding of V at the nodes is in the nodes' bounds);
    /// otherwise at the a-priori error of the energy. (Taken at the a-priori error, the term
    /// set how far the drift was refined, 0.1 of it, and was then replaced by the residual's
    /// in `cell`: 58 librations by the saddle of the standard slice missed tol 1e-13 by their
    /// drift alone.)
    fn placed_saddle_conditioning(
        &self,
        energy: f64,
        component: &Component,
        period: f64,
        double: f64,
        residual: Option<f64>,
    ) -> SaddleTerms {
        match residual {
            Some(residual) => {
                self.saddle_conditioning_within(energy, component, period, double, 2.0 * residual)
            }
            None => self.saddle_conditioning(energy, component, period, double, 0.0),
        }
    }

    /// [`Self::saddle_conditioning`] for an energy known to within `delta` (a libration's
    /// level offset computed sharply: see `cell::level_offset_error`).
    pub(crate) fn saddle_conditioning_within(
        &self,
        energy: f64,
        component: &Component,
        period: f64,
        double: f64,
        delta: f64,
    ) -> SaddleTerms {
        self.saddle_terms(energy, component, period, double, true, |_| delta)
    }

    /// The saddle terms with the energy error `delta` at each saddle; where `sharp` (an
    /// offset computed in double-double, far below an ulp of V), each saddle's distance from
    /// ε is taken in double-double too ([`Self::saddle_distance`]), and a level offset that
    /// may reach across the saddle makes the terms infinite: the integrals are then of a
    /// motion on the separatrix's other side (ε 5e-17 above a saddle whose level rounded
    /// to an ulp above it: two librations of T 2.1e5 ± 4e3 where the truth is one
    /// rotation of T 2.05e5; adversary pass).
    fn saddle_terms(
        &self,
        energy: f64,
        component: &Component,
        period: f64,
        double: f64,
        sharp: bool,
        delta: impl Fn(&CriticalPoint) -> f64,
    ) -> SaddleTerms {
        let mut terms = SaddleTerms::default();
        let gap = |p: &CriticalPoint| (energy - p.value).abs().max(EPS * p.scale);
        let saddles = component
            .interior
            .iter()
            .map(|p| (*p, double))
            .chain(component.neighbours.iter().flatten().map(|p| (*p, 1.0)))
            .filter(|(p, _)| p.kind != CriticalKind::Minimum)
            .map(|(p, passes)| (p, passes, gap(&p), sharp));
        let shoulders = self
            .near_shoulders(energy, component, double)
            .into_iter()
            .map(|(p, passes, gap)| (p, passes, gap, false));
        for (p, passes, gap, sharp) in saddles.chain(shoulders) {
            let a = p.site.angle();
            let red = self.body.reduction_at(a);
            let b = red.reduced_inertia;
            // The distance left once the offset is spent: (ε − V_s) ± δ must keep its sign.
            let gap = if sharp {
                let (distance, error) = self.saddle_distance(energy, &p);
                let room = distance - error - delta(&p);
                if room.is_nan() || room <= 0.0 {
                    return SaddleTerms {
                        period: f64::INFINITY,
                        psi_advance: f64::INFINITY,
                        drift: f64::INFINITY,
                    };
                }
                room
            } else {
                gap
            };
            // dT/dε ≈ 1/(λ |ε − V_s|) per passage; never more than T/|ε − V_s| (a flat or
            // degenerate point, λ = 0, has no logarithm).
            let lambda = (p.curvature.abs() / b).sqrt();
            let sensitivity = (1.0 / lambda).min(period) / gap;
            let dt = passes * delta(&p) * sensitivity;
            terms.period += dt;
            terms.psi_advance += dt * self.psi_rate_with(a, red.integral_factor).abs();
            terms.drift += dt * self.saddle_speed(a, &red);
        }
        terms
    }

    /// |ζ̇| at rest in θ at `a` (a critical point: p = 0), |U| κ / (J sin θ): how fast the
    /// centre of mass moves while the motion lingers by a saddle, which the saddle's time
    /// term ([`Self::saddle_conditioning`]) times this adds to the drift. (Left out, the drift
    /// of librations within 1e-6 of a separatrix was up to 5.7 times its estimate off, at
    /// status `ok` at tol 1e-10: adversary pass of 2026-11-28.)
    fn saddle_speed(&self, a: Angle, red: &Reduction) -> f64 {
        if self.kappa == 0.0 {
            return 0.0;
        }
        (red.potential * self.kappa / (red.integral_factor * a.sin)).abs()
    }

    /// The size of V′'s terms at `a`, which its rounding is a few ulps of: U′'s
    /// ([`Shape::potential_prime_scale_at`]) and the wall's κ² |cos θ| / sin³θ.
    pub(crate) fn slope_scale_at(&self, a: Angle) -> f64 {
        let wall = if self.kappa == 0.0 {
            0.0
        } else {
            let w = self.kappa / a.sin;
            (w * w * a.cos / a.sin).abs()
        };
        self.body.shape.potential_prime_scale_at(a) + wall
    }

    /// |ε − V_s| for the critical point `p` and a bound on its error: V at the point in
    /// double-double where the shape gives it (about 1e-30 of V's terms), plus how far the
    /// extremum may lie beyond V at the rounded site, V′²/(2|V″|) with V′ there bounded by
    /// its value and rounding; else in double, with 4 ulps of V's terms.
    fn saddle_distance(&self, energy: f64, p: &CriticalPoint) -> (f64, f64) {
        let a = p.site.angle();
        let plain = (
            (energy - p.value).abs(),
            4.0 * EPS * (p.scale + energy.abs()),
        );
        let Some((value, error)) = self.value_double_double(a) else {
            return plain;
        };
        let distance = DoubleDouble::from_f64(energy).sub(value).to_f64();
        let slope = self.slope(a).abs() + 4.0 * EPS * self.slope_scale_at(a);
        let beyond = slope * slope / (2.0 * p.curvature.abs());
        let error = error + EPS * distance.abs() + beyond;
        if error.is_finite() {
            (distance.abs(), error)
        } else {
            plain
        }
    }

    /// The kinks inside the component (passed `double` times a period) or between an end and
    /// the critical point beyond it (passed once) where V is nearly a shoulder: concave on
    /// one side (V″ = −a), convex on the other, with a slope s = |V′| so small that the
    /// motion lingers there as at a saddle. Each is returned as a saddle with its passes and
    /// the gap |ε − V_k| + s²/(2a): on the concave side ε − V ≈ δ + s x + a x²/2, whose
    /// time grows like log(1/δ)/λ while δ is above s²/(2a) and stays at its value there
    /// below (dT/dε ≈ 2a/(λ s²)). Kinks that are critical points are counted as such.
    fn near_shoulders(
        &self,
        energy: f64,
        component: &Component,
        double: f64,
    ) -> Vec<(CriticalPoint, f64, f64)> {
        if self.body.shape.kinks().is_empty() {
            return Vec::new();
        }
        let [before, after] = component.neighbours;
        let lower = before.map_or(
            if self.kappa != 0.0 {
                0.0
            } else {
                component.lower.theta
            },
            |p| p.site.theta,
        );
        let upper = after.map_or(
            if self.kappa != 0.0 {
                PI
            } else {
                component.upper.theta
            },
            |p| p.site.theta,
        );
        let critical: Vec<f64> = component
            .interior
            .iter()
            .chain(component.neighbours.iter().flatten())
            .map(|p| p.site.theta)
            .collect();
        self.kinks_inside(lower, upper)
            .into_iter()
            .filter(|k| critical.iter().all(|t| (t - k.theta).abs() > 1e-12))
            .filter_map(|site| {
                let a = site.angle();
                let [c0, c1] = self.curvature_sides_at(a);
                if c0 * c1 >= 0.0 {
                    return None;
                }
                let concave = c0.min(c1).abs();
                let (value, scale) = (self.value(a), self.value_scale(a));
                let slope = self.slope(a);
                let gap = (energy - value).abs().max(EPS * scale) + slope * slope / (2.0 * concave);
                let inside =
                    site.theta > component.lower.theta && site.theta < component.upper.theta;
                let point = CriticalPoint {
                    site,
                    value,
                    scale,
                    curvature: -concave,
                    kind: CriticalKind::Inflection,
                };
                Some((point, if inside { double } else { 1.0 }, gap))
            })
            .collect()
    }

    /// The kinks of U ([`Shape::kinks`]) strictly between `lower` and `upper`, in order. On
    /// the κ = 0 circle θ is lifted and U(−θ) = U(θ), so a kink θ_k recurs at ±θ_k + 2πm.
    pub fn kinks_inside(&self, lower: f64, upper: f64) -> Vec<Site> {
        lifted_inside(self.body.shape.kinks(), lower, upper)
    }

    /// Where the integrals over θ are split, strictly between `lower` and `upper`, in order:
    /// the kinks of U (its pieces are analytic), and the zero θ_U of U
    /// ([`Shape::potential_zeros`]) where the peak of 1/J there is narrow: its width, the
    /// distance of J's complex zeros from the real axis, √((cos²θ_U + ν sin²θ_U)/η)/|U′(θ_U)|,
    /// below [`SHARP_PEAK`]; likewise a zero of U′ ([`Shape::slope_zeros`]) where the dip of
    /// B = 1/η + U² + U′² there ([`Self::dip_width`]) is narrower. A rule's level
    /// differences cannot see a peak far narrower than its steps: a disk with α = −72.7,
    /// η = 217 (width 5e-4) had N off by 4× its estimate.
    pub fn splits_inside(&self, lower: f64, upper: f64) -> Vec<Site> {
        lifted_inside(&self.split_angles, lower, upper)
    }

    /// The angles of [`Self::splits_inside`] in (0, π).
    fn find_split_angles(&self) -> Vec<f64> {
        let mut splits = self.body.shape.kinks().to_vec();
        // A narrow dip of B = 1/η + U² + U′² where U′ crosses 0 ([`Self::dip_width`]): at a
        // large η against a sharp curvature (a prolate ellipsoid at η = 394, 0.005 wide) the
        // rules' level differences stepped over it (T 10× its estimate off at tol 1e-3).
        splits.extend(
            self.dips
                .iter()
                .filter(|(_, width)| *width < SHARP_PEAK)
                .map(|(zero, _)| *zero),
        );
        splits.extend(
            self.body
                .shape
                .potential_zeros()
                .into_iter()
                .filter(|&zero| {
                    let a = Angle::new(zero);
                    let floor = (a.cos * a.cos + self.body.nu * a.sin * a.sin) / self.body.eta;
                    floor.sqrt() < SHARP_PEAK * self.body.shape.potential_prime_at(a).abs()
                }),
        );
        splits
    }
}

/// The width of a peak of 1/J below which the integrals are split at it
/// ([`EffectivePotential::splits_inside`]): the features the rules resolve unsplit are at
/// least the shapes' angular scale 0.1 ([`Shape::angular_feature_scale`]).
const SHARP_PEAK: f64 = 0.1;

/// `angles` and their images ±θ + 2πm strictly between `lower` and `upper`, in order, as
/// sites (on the κ = 0 circle θ is lifted and U(−θ) = U(θ)).
fn lifted_inside(angles: &[f64], lower: f64, upper: f64) -> Vec<Site> {
    if angles.is_empty() {
        return Vec::new();
    }
    let (first, last) = (
        ((lower - PI) / TAU).floor() as i64,
        ((upper + PI) / TAU).ceil() as i64,
    );
    let mut inside: Vec<f64> = (first..=last)
        .flat_map(|m| {
            let turn = TAU * m as f64;
            angles.iter().flat_map(move |&k| [turn + k, turn - k])
        })
        .filter(|&t| t > lower && t < upper)
        .collect();
    inside.sort_by(f64::total_cmp);
    inside.dedup();
    inside.into_iter().map(Site::at).collect()
}

impl<S: Shape> EffectivePotential<'_, S> {
    /// An interior end `plain` of a libration (a critical point below ε, a kink, a needle's
    /// π/2) on the level its turning points are measured against. A turning point's gaps
    /// vanish at the double e itself, so its level is V(e), ε only to the rounding of the
    /// root; the libration's level runs linearly from V(e_min) to V(e_max), and an interior
    /// end k gets the excess level(k) − V(k) = V(b) − V(k) + w (V(b′) − V(b)), b the nearer
    /// turning point, b′ the other, w = |k − b| / L, with V(b) − V(k) = −sin(k − b) D(k, b)
    /// (D the divided difference of V, free of cancellation on the part both lie on) and
    /// `rise` = V(e_max) − V(e_min). Against ε − V(k) in double this is sharper (its rounding,
    /// a few ulps of V, is not small against ε − V(k) when k lies near a turning point: 3e-9
    /// in N at 1e-13 from a kink on a truncated ball) and it keeps the level one straight
    /// line: at ε at an interior end and V(e) at the turning points, the level bent by each
    /// turning point's offset s = ε − V(e) over half the libration, which moves T by about
    /// s/(ε − V_min) of itself whatever s's spread (a needle's small libration cut at its
    /// minimum, β = 0.0013, 4.5e-6 deep: T 1.15e-12 off, 1.9 times its estimate, at tol
    /// 1e-11; an adversary pass), where [`crate::cell`] bounds a straight level's offsets.
    /// `None` where the computed excess is not above twice its rounding (a kink too close to
    /// a turning point to tell on which side it lies, or a maximum just below ε): a kink is
    /// then not cut (the piece's integrand differs from an analytic one only that close to
    /// its end), and a critical point is kept at the level ε.
    fn on_turning_level(
        &self,
        plain: PieceEnd,
        lower: &PieceEnd,
        upper: &PieceEnd,
        length: f64,
        rise: (f64, f64),
    ) -> Option<PieceEnd> {
        let (rise, rise_error) = rise;
        let from_lower = self.separation(&lower.site, &plain.site);
        let from_upper = self.separation(&plain.site, &upper.site);
        // The signed step k − b from the nearer turning point b, and V(b′) − V(b).
        let (turning, step, other) = if from_lower <= from_upper {
            (lower, from_lower, rise)
        } else {
            (upper, -from_upper, -rise)
        };
        let share = step.abs() / length;
        // V(b) − V(k).
        let (climb, drop_error) = self.rise_with_error(turning.angle, plain.angle, step);
        let drop = -climb;
        let tilt = share * other;
        let excess = drop + tilt;
        let error = drop_error + 4.0 * EPS * (excess.abs() + tilt.abs()) + share * rise_error;
        (excess > 2.0 * error).then_some(PieceEnd {
            excess,
            level: turning.level + tilt,
            excess_error: error,
            ..plain
        })
    }

    /// Whether a turning point of the piece lies by a pole (κ ≠ 0, nearer than 1 % of the
    /// piece): ψ̇ ~ κ/sin²θ peaks there over a sliver the first levels of the tanh-sinh rule
    /// may step over alike, their sums converging fast and then stalling.
    fn by_a_pole(&self, piece: &Piece) -> bool {
        self.kappa != 0.0
            && [
                (&piece.left, piece.left.site.theta),
                (&piece.right, piece.right.site.from_pi),
            ]
            .iter()
            .any(|(end, distance)| end.excess == 0.0 && *distance < 0.01 * piece.length)
    }

    /// The Clenshaw–Curtis kind of each piece of a libration across a kink, with the least
    /// level whose differences are trusted (`None`: the tanh-sinh rule): the first piece has
    /// θ_min, the last θ_max as its turning point (a libration with no kink inside, or with a
    /// narrow peak of 1/J, stays with the tanh-sinh rule). Only where the rule is predicted to
    /// converge within [`CHEBYSHEV_PLANNED_INTERVALS`]: its error falls like ρ^{−N},
    /// ρ = |z + √(z² − 1)| for the singularity z of the integrand nearest [−1, 1] in the
    /// rule's variable. Those located: a pole beyond an end (ψ̇ ~ κ/sin²θ); the other zero of
    /// ε − V beyond a turning point (a saddle there), from its local quadratic; the zeros of
    /// ε − V beyond any other end (a kink, or a maximum or tangency the piece is cut at) from
    /// its local quadratic (V′ and the piece's side of V″: ±i√(2(ε − V)/|V″|) at a maximum)
    /// and, should both nearly vanish (a near-shoulder, a flat maximum), from the cubic term,
    /// with |V‴| taken as 6 times V's scale there.
    fn chebyshev_kinds(
        &self,
        component: &Component,
        pieces: &[Piece],
        tol: f64,
    ) -> Vec<Option<(ChebyshevPiece, u32, cosine::Map)>> {
        let n = pieces.len();
        let (lower, upper) = (component.lower.theta, component.upper.theta);
        let kinks = self.kinks_inside(lower, upper);
        if component.kind != MotionKind::Libration
            || n < 2
            || kinks.is_empty()
            || self.splits_inside(lower, upper).len() != kinks.len()
        {
            return vec![None; n];
        }
        // ρ of a point z of the complex plane of the rule's variable on [−1, 1].
        let bernstein = |z: Complex<f64>| {
            let root = (z * z - 1.0).sqrt();
            (z + root).norm().max((z - root).norm())
        };
        // The zeros beyond an end (at outward distance x) of the local model of the gap,
        // e + a x + ½ c x² (a, c its outward slope and curvature), as complex distances
        // (real ones only where positive: behind the end the gap is positive).
        let zeros = |e: f64, a: f64, c: f64| -> Vec<Complex<f64>> {
            if c == 0.0 || !c.is_finite() {
                return if a < 0.0 && e > 0.0 {
                    vec![Complex::new(-e / a, 0.0)]
                } else {
                    Vec::new()
                };
            }
            let disc = a * a - 2.0 * e * c;
            let roots = if disc >= 0.0 {
                let r = disc.sqrt();
                vec![
                    Complex::new((-a + r) / c, 0.0),
                    Complex::new((-a - r) / c, 0.0),
                ]
            } else {
                let r = (-disc).sqrt() / c;
                vec![Complex::new(-a / c, r), Complex::new(-a / c, -r)]
            };
            roots
                .into_iter()
                .filter(|x| x.im != 0.0 || x.re > 0.0)
                .collect()
        };
        // The pole beyond an end (none at κ = 0, where V is smooth through it).
        let pole = |end: &PieceEnd, left: bool| {
            (self.kappa != 0.0).then(|| {
                let distance = if left {
                    end.site.theta
                } else {
                    end.site.from_pi
                };
                Complex::new(distance, 0.0)
            })
        };
        // The gap's outward slope and curvature at an end, on the piece's side of a kink
        // (the sides are ordered by |θ|: mirrored where a lifted angle has sin θ < 0).
        let local = |end: &PieceEnd, left: bool| {
            let sides = self.curvature_sides_at(end.angle);
            let inside = usize::from(left == (end.angle.sin >= 0.0));
            let slope = self.slope(end.angle);
            (if left { slope } else { -slope }, -sides[inside])
        };
        // The cubic term's zeros, at d = (6 e / |V‴|)^{1/3} in the three directions of the
        // cube roots of −1 that face outwards.
        let cubic = |end: &PieceEnd| -> [Complex<f64>; 3] {
            let third = 6.0 * self.value_scale(end.angle);
            let d = (6.0 * end.excess.max(0.0) / third).cbrt();
            let r = Complex::from_polar(d, std::f64::consts::FRAC_PI_3);
            [Complex::new(d, 0.0), r, r.conj()]
        };
        // The points beyond an end that bound ρ, as outward distances in the map's variable:
        // the gap's zeros (of its local model, without the excess at a turning point), the
        // cubic term's (beyond a kink), and the pole (θ) or the edge of the strip |Im s| < π/2
        // (Mercator's s = ln tan(θ/2), which sends the pole to infinity). In s an outward
        // distance x in θ from an end at d from its pole is ln tan(d/2) − ln tan((d − x)/2).
        let beyond = |end: &PieceEnd, left: bool, turning: bool, mercator: bool| {
            let (a, c) = local(end, left);
            let excess = if turning { 0.0 } else { end.excess.max(0.0) };
            let mut points = zeros(excess, a, c);
            if !turning {
                points.extend(cubic(end));
            }
            if !mercator {
                points.extend(pole(end, left));
                return points;
            }
            let d = Complex::new(
                if left {
                    end.site.theta
                } else {
                    end.site.from_pi
                },
                0.0,
            );
            let s = |y: Complex<f64>| (0.5 * y).tan().ln();
            let mut points: Vec<Complex<f64>> =
                points.into_iter().map(|x| s(d) - s(d - x)).collect();
            points.push(s(d) + Complex::new(0.0, FRAC_PI_2));
            points
        };
        let rho = |points: Vec<Complex<f64>>, z: &dyn Fn(Complex<f64>) -> Complex<f64>| {
            points
                .into_iter()
                .map(|x| bernstein(z(x)))
                .fold(f64::INFINITY, f64::min)
        };
        let planned = CHEBYSHEV_PLANNED_INTERVALS as f64;
        pieces
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let plain = cosine::Map::Plain { length: p.length };
                // Mercator's map where an end lies nearer its pole than the piece is long
                // (κ ≠ 0, the piece within (0, π)).
                let near_pole = self.kappa != 0.0
                    && p.left.angle.sin > 0.0
                    && p.right.angle.sin > 0.0
                    && p.left.site.theta.min(p.right.site.from_pi) < p.length;
                let plan = |map: cosine::Map| {
                    let (mercator, length) = match map {
                        cosine::Map::Plain { length } => (false, length),
                        cosine::Map::Mercator { length, .. } => (true, length),
                    };
                    // Beside a turning point the far end is u = 1: x − x_t = L u², so a point
                    // x beyond it is at u = √(1 + x/L), and beyond the turning point itself
                    // at u² = −x/L; between kinks at 1 + 2x/L.
                    let half = |x: Complex<f64>| (1.0 + x / length).sqrt();
                    let whole = |x: Complex<f64>| 1.0 + 2.0 * x / length;
                    let turning = |x: Complex<f64>| (-x / length).sqrt();
                    let (kind, rho) = if k == 0 {
                        let rho = rho(beyond(&p.left, true, true, mercator), &turning)
                            .min(rho(beyond(&p.right, false, false, mercator), &half));
                        (ChebyshevPiece::TurningLeft, rho)
                    } else if k == n - 1 {
                        let rho = rho(beyond(&p.right, false, true, mercator), &turning)
                            .min(rho(beyond(&p.left, true, false, mercator), &half));
                        (ChebyshevPiece::TurningRight, rho)
                    } else {
                        let rho = rho(beyond(&p.left, true, false, mercator), &whole)
                            .min(rho(beyond(&p.right, false, false, mercator), &whole));
                        (ChebyshevPiece::Regular, rho)
                    };
                    // The intervals the prediction needs; before them a level's differences
                    // are not trusted (the coarse levels of a near-singular end may agree by
                    // chance).
                    let needed = -tol.ln() / rho.ln();
                    // (Mercator's levels are trusted to d₁ only, not to the plain map's
                    // geometric rate: a level more for the same error, so it is counted
                    // twice.)
                    let cost = if mercator { 2.0 * needed } else { needed };
                    (needed <= planned).then_some((cost, needed, kind, map))
                };
                // (Mercator's is planned only where the plain map needs more than 64
                // intervals: below, it could save a level at most, and its plan costs complex
                // logarithms and tangents: planned beyond 32, the plans took 14 % of the time
                // of the truncated ball's scene, against 5 % before.)
                let plain = plan(plain);
                let mercator = if near_pole && plain.is_none_or(|(_, needed, ..)| needed > 64.0) {
                    plan(cosine::Map::mercator(p))
                } else {
                    None
                };
                [plain, mercator]
                    .into_iter()
                    .flatten()
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .map(|(_, needed, kind, map)| (kind, needed.max(1.0).log2().ceil() as u32, map))
            })
            .collect()
    }

    /// The pieces of a component: cut at the ends and, if `cut`, at every interior maximum or
    /// tangency and at every kink of U (a libration's interior ends on the straight level of
    /// its turning points, [`EffectivePotential::on_turning_level`]).
    fn pieces(&self, energy: f64, component: &Component, cut: bool) -> Vec<Piece> {
        let end = |site: Site, turning: bool| {
            let angle = site.angle();
            let value = self.value(angle);
            PieceEnd {
                site,
                angle,
                excess: if turning { 0.0 } else { energy - value },
                level: if turning { value } else { energy },
                // ε − V(e) carries the rounding of V(e) and of the subtraction.
                excess_error: if turning {
                    0.0
                } else {
                    4.0 * EPS * (self.value_scale(angle) + energy.abs())
                },
                sharp: None,
                placed: None,
            }
        };
        let turning = component.kind == MotionKind::Libration;
        let lower = end(component.lower, turning);
        let upper = end(component.upper, turning);
        // A libration's interior ends on the straight level of its turning points.
        // (The turning points' span and rise only where there is an interior end: this runs
        // for every libration.)
        let line = std::cell::OnceCell::new();
        let on_level = |site: Site| {
            if !turning {
                return Some(end(site, false));
            }
            let &(span, rise) = line.get_or_init(|| {
                let span = self.separation(&lower.site, &upper.site);
                (span, self.rise_with_error(lower.angle, upper.angle, span))
            });
            self.on_turning_level(end(site, false), &lower, &upper, span, rise)
        };
        let mut ends = vec![lower];
        // Maxima and tangencies are near-singular points. Minima are harmless inside a piece
        // unless U is sharply curved (an angular feature scale below 0.1, e.g. a prolate
        // ellipsoid with β < 0.1 round θ = π/2), where the feature sits at the minimum and
        // the sparse middle nodes of a long piece would step over it.
        let sharp = self.body.shape.angular_feature_scale() < 0.1;
        ends.extend(
            component
                .interior
                .iter()
                .filter(|p| cut && (p.kind != CriticalKind::Minimum || sharp))
                .map(|p| on_level(p.site).unwrap_or_else(|| end(p.site, false))),
        );
        if cut {
            // U″ jumps at a kink: each piece must be analytic for the rule's fast convergence;
            // and a narrow peak of 1/J is put at a piece's end, where the rule's nodes crowd.
            ends.extend(
                self.splits_inside(component.lower.theta, component.upper.theta)
                    .into_iter()
                    .filter_map(on_level),
            );
            // And at a needle's π/2, where Z turns within β (a tenth of that scale clear of
            // the ends and of every critical point, which are cut already): a libration
            // across it that neither turns nor has its minimum there (α → −1, β = 0.0038)
            // had the turn in the middle of a piece, and T was 9.3 times its estimate off at
            // tol 1e-4 (adversary pass of 2026-11-28).
            let shape = &self.body.shape;
            let clear = 0.1 * shape.angular_feature_scale();
            let taken: Vec<f64> = ends.iter().map(|e| e.site.theta).collect();
            ends.extend(
                lifted_inside(
                    &shape.feature_angles(),
                    component.lower.theta + clear,
                    component.upper.theta - clear,
                )
                .into_iter()
                .filter(|site| {
                    taken
                        .iter()
                        .chain(self.critical.iter().map(|p| &p.site.theta))
                        .all(|&t| (t - site.theta).abs() > clear)
                })
                .map(|site| on_level(site).unwrap_or_else(|| end(site, false))),
            );
            ends[1..].sort_by(|a, b| a.site.theta.total_cmp(&b.site.theta));
            ends.dedup_by(|a, b| a.site.theta == b.site.theta);
        }
        ends.push(upper);
        ends.windows(2)
            .map(|w| {
                let (l, r) = (w[0], w[1]);
                let length = self.separation(&l.site, &r.site);
                // The levels V(e) + excess of the two ends differ by rounding (a turning point
                // is only a root to the last bit); the gap is measured from the nearer end, so
                // without a correction it would jump at the middle by that difference, which
                // near a minimum is not small against ε − V.
                let rise = self.rise(l.angle, r.angle, length);
                Piece {
                    left: l,
                    right: r,
                    length,
                    tilt_rate: (rise + r.excess - l.excess) / length,
                }
            })
            .collect()
    }
}

impl<S: Shape> EffectivePotential<'_, S> {
    /// At a tolerance below [`SHARP_GAPS_BELOW`], where the shape gives V in double-double:
    /// the pieces' ends in double-double, so that `sample` can compute a gap whose rounding in
    /// double would weigh in the error (the divided difference of V cancelling) as
    /// level + tilt − V(t) in double-double, to about an ulp of the gap. Each turning point is
    /// placed on the level ε ([`Placed`]) and every other end's excess ε − V(e) is taken in
    /// double-double, so that every end's level is ε and the pieces need no tilt; where a
    /// turning point cannot be placed (V′ too small there for one Newton step to land within
    /// a few ulps of it), the ends keep their double levels V(e) + excess and the tilt.
    fn sharpen_gaps(&self, pieces: &mut [Piece], energy: f64, kind: MotionKind, tol: f64) {
        // (Not across the joints of a profile's arcs: the end at a joint takes its U from
        // either arc, which meet only to their representation, and a turning point within
        // 1e-12 … 1e-8 of V(joint) had T 2.2e-11 off with an estimate of 3.4e-13 at tol 1e-13;
        // an adversary pass.)
        if tol >= SHARP_GAPS_BELOW || !self.body.shape.kinks().is_empty() {
            // (In double too the gaps vanish at the pairs' angles: where that rounding, up to
            // an ulp of the larger of sin θ and cos θ at each end, could weigh in against the
            // tolerance relative to the length, the length is taken between the pairs. Not on
            // a shape with kinks: there it put T 5 times its estimate off beside a kink of the
            // truncated ball and a joint of a profile, for a reason not yet found; it is left
            // as it was, as the sharp gaps are.)
            if kind == MotionKind::Libration && self.body.shape.kinks().is_empty() {
                for piece in pieces.iter_mut() {
                    if 4.0 * EPS > 1e-3 * tol * piece.length {
                        piece.length += pair_span(piece);
                    }
                }
            }
            return;
        }
        let threshold = SHARP_GAP_ROUNDING.max(0.02 * tol);
        let level = DoubleDouble::from_f64(energy);
        let mut ends = Vec::with_capacity(2 * pieces.len());
        for end in pieces.iter().flat_map(|p| [&p.left, &p.right]) {
            let (sin, cos) = on_circle(end.angle);
            let Some((value, error)) = self.value_double_double_on_circle(sin, cos) else {
                return;
            };
            let placed = if end.excess == 0.0 {
                self.place_on_level(end, sin, cos, value, level)
            } else {
                None
            };
            ends.push((sin, cos, value, error, placed));
        }
        // (Not a rotation's: its two outer ends are one critical point, held as two doubles
        // up to an ulp of 2π apart; near a separatrix the integrand peaks there like
        // ε − V_s to the −½, and the sliver between them, hidden under the rounding of the
        // excess in double, was a 7e-10 error of T at ε − V_s = 1e-13 with it in
        // double-double.)
        let all_placed = kind == MotionKind::Libration
            && pieces
                .iter()
                .flat_map(|p| [&p.left, &p.right])
                .zip(&ends)
                .all(|(end, e)| end.excess != 0.0 || e.4.is_some());
        let mut ends = ends.into_iter();
        for piece in pieces.iter_mut() {
            for end in [&mut piece.left, &mut piece.right] {
                let (sin, cos, value, error, placed) = ends.next().unwrap();
                end.sharp = Some(if all_placed {
                    if end.excess == 0.0 {
                        end.placed = placed;
                    } else {
                        // (ε − V(e) in double-double, rounded once.)
                        end.excess = level.sub(value).to_f64();
                        end.excess_error = error + EPS * end.excess.abs();
                    }
                    end.level = energy;
                    SharpEnd {
                        sin,
                        cos,
                        level,
                        error: 0.0,
                        threshold,
                    }
                } else {
                    SharpEnd {
                        sin,
                        cos,
                        level: value.add_f64(end.excess),
                        error,
                        threshold,
                    }
                });
            }
            if all_placed {
                // Both ends on ε: the nodes run from e + shift at either end, e the angle of
                // the end's pair of sine and cosine (which the gaps are measured from), and no
                // tilt. (The pairs' angles are off the sites' by up to an ulp of the sine or
                // cosine: a 2e-14 error of T in a libration 1.7e-3 wide at θ = 2.57, once its
                // level offset no longer hid it; whole-domain seed 12.)
                let shift = |end: &PieceEnd| end.placed.map_or(0.0, |p| p.shift);
                piece.length += pair_span(piece) + shift(&piece.right) - shift(&piece.left);
                piece.tilt_rate = 0.0;
            } else if kind == MotionKind::Libration {
                // (The gaps vanish at the ends' pairs, whatever their levels: a libration
                // 6.9e-10 wide at θ = 6e-6, its turning points too far off ε to be placed,
                // had T 1.8 times its estimate off with the length between the doubles.)
                piece.length += pair_span(piece);
            }
        }
    }

    /// The turning point `end` (its pair on the circle `sin`, `cos` and V there, `value`, in
    /// double-double) moved onto `level` by up to three Newton steps δ = (ε − V)/V′(e), with V
    /// at e + δ in double-double for the next step and the residual; `None` where the shift is
    /// not below 1e-9 of e in its chart (a root finder's stopping tolerance in V, not θ,
    /// leaves a turning point by a flat V up to a few hundred ulps off) or the residual not
    /// below a thousandth of the offset ε − V(e) (a turning point by a flat V, next to a
    /// critical point).
    fn place_on_level(
        &self,
        end: &PieceEnd,
        sin: DoubleDouble,
        cos: DoubleDouble,
        value: DoubleDouble,
        level: DoubleDouble,
    ) -> Option<Placed> {
        let offset = level.sub(value).to_f64();
        let slope = self.slope(end.angle);
        let mut shift = 0.0;
        let mut moved = (sin, cos, value, 0.0);
        let mut residual = offset;
        for _ in 0..3 {
            shift += residual / slope;
            if !shift.is_finite() || shift.abs() > 1e-9 * end.site.ulp_scale() {
                return None;
            }
            let (moved_sin, moved_cos) = turned(sin, cos, shift);
            let (value, error) = self.value_double_double_on_circle(moved_sin, moved_cos)?;
            moved = (moved_sin, moved_cos, value, error);
            residual = level.sub(value).to_f64();
            if residual.abs() <= error {
                break;
            }
        }
        let (moved_sin, moved_cos, moved_value, moved_error) = moved;
        let residual = residual.abs() + moved_error;
        let near = 2.0 * (shift * self.curvature_at(end.angle) / slope).abs();
        (near.is_finite() && (residual <= 1e-3 * offset.abs() || offset == 0.0)).then_some(Placed {
            shift,
            offset,
            residual,
            near,
            sin: moved_sin,
            cos: moved_cos,
            value: moved_value,
            value_error: moved_error,
        })
    }
}

/// The pair (`sin`, `cos`) of an angle turned by a small `step` (|step| ≤ 1e-9), in
/// double-double: sin(e + δ) = sin e cos δ + cos e sin δ, cos(e + δ) = cos e cos δ − sin e sin δ,
/// with cos δ − 1 = −δ²/2 + δ⁴/24 and sin δ = δ − δ³/6 (to 1e-45), scaled onto the circle.
fn turned(sin: DoubleDouble, cos: DoubleDouble, step: f64) -> (DoubleDouble, DoubleDouble) {
    let square = step * step;
    let cos_less_one = -0.5 * square * (1.0 - square / 12.0);
    let sin_step = DoubleDouble::from_f64(step).add_f64(-step * square / 6.0);
    let moved_sin = sin.add(cos.mul(sin_step)).add(sin.mul_f64(cos_less_one));
    let moved_cos = cos.sub(sin.mul(sin_step)).add(cos.mul_f64(cos_less_one));
    DoubleDouble::onto_circle(moved_sin, moved_cos)
}

/// atan2(sin, cos) − θ for the pair (sin, cos) = [`Site::angle`]: the rounding of the pair as
/// an angle, up to about an ulp of sin θ or cos θ, from both in double-double.
fn pair_offset(site: &Site) -> f64 {
    let a = site.angle();
    if site.theta_exact {
        let (sin, cos) = DoubleDouble::sin_cos(site.theta);
        cos.mul_f64(a.sin).sub(sin.mul_f64(a.cos)).to_f64()
    } else {
        // The pair (sin φ, −cos φ) of π − φ: its angle is π less that of (sin φ, cos φ).
        let (sin, cos) = DoubleDouble::sin_cos(site.from_pi);
        -cos.mul_f64(a.sin).add(sin.mul_f64(a.cos)).to_f64()
    }
}

/// The length of `piece` between the angles of its ends' (sine, cosine) pairs, which its gaps
/// vanish at, less that between its ends' sites.
fn pair_span(piece: &Piece) -> f64 {
    pair_offset(&piece.right.site) - pair_offset(&piece.left.site)
}

/// [`PeriodIntegrals::level_residual`] of a libration cut into `pieces`: the largest residual
/// of its turning points where both were placed on ε.
fn level_residual(component: &Component, pieces: &[Piece]) -> Option<f64> {
    if component.kind != MotionKind::Libration {
        return None;
    }
    let ends = [&pieces.first()?.left, &pieces.last()?.right];
    ends.iter()
        .map(|end| end.placed.map(|p| p.residual))
        .try_fold(0.0, |worst: f64, r| r.map(|r| worst.max(r)))
}

/// Δζ over one θ-period from θ_min (ψ = 0 there), on the current levels, and again on the
/// levels below for the error estimate. For a libration the way back is the way out
/// mirrored: at θ on the way back ψ = Δψ − ψ_out(θ) and p dt = −dθ, so
/// Δζ = −∫ U [a t′ (e^{iψ} + e^{i(Δψ−ψ)}) + i (e^{iψ} − e^{i(Δψ−ψ)})] dθ over [θ_min, θ_max]
/// with a = κ/(J sinθ), t′ = dt/dθ (from ζ̇ = −U e^{iψ}(a + i p), see
/// [`crate::reduced::ReducedSystem::centre_velocity`]).
/// `known` keeps the sums already made, by the pieces' levels (a refinement reuses them as its
/// two coarser levels).
fn drift_estimate(
    samples: &[PieceSamples],
    psi_advance: f64,
    double: f64,
    known: &mut KnownDrifts,
) -> DriftEstimate {
    let mut level = |stride_exp: u32| {
        // (The pieces' levels, four bits each: a key for up to 16 pieces, none beyond.)
        let key = (samples.len() <= 16).then(|| {
            samples
                .iter()
                .fold(0u64, |key, s| (key << 4) | u64::from(s.level - stride_exp))
        });
        if let Some((_, value)) = known.iter().find(|(k, _)| key.is_some() && *k == key) {
            return *value;
        }
        let psi = if stride_exp == 0 {
            psi_advance
        } else {
            double * samples.iter().map(|s| s.psi(stride_exp)).sum::<f64>()
        };
        let value = drift_sum(samples, psi, double, 1 << stride_exp);
        known.push((key, value));
        value
    };
    // Clenshaw–Curtis pieces in their geometric regime (T's and Δψ's sums, and the drift's
    // own on a fourth level: one rate, as `cosine::single_rate` asks): the cosine rule's trust.
    let (fine, mid, coarse) = (level(0), level(1), level(2));
    let rate = if samples.iter().all(PieceSamples::geometric) {
        let coarsest = level(3);
        let (d1, d2, d3) = (
            fine.distance(&mid),
            mid.distance(&coarse),
            coarse.distance(&coarsest),
        );
        if d2 == 0.0 || d3 == 0.0 || d1 / d2 >= (d2 / d3).powi(2) / 16.0 {
            Convergence::Geometric
        } else {
            Convergence::Unknown
        }
    } else {
        Convergence::Unknown
    };
    DriftEstimate::from_levels(fine, mid, coarse, rate)
}

/// Drift sums already made, by the pieces' levels.
type KnownDrifts = Vec<(Option<u64>, LevelDrift)>;

/// Δζ on one level of a rule: its value, the L1 size of its integrand (the path scale), and
/// the largest change of the phase its nodes take e^{iψ} at between neighbours (of ψ̃, ψ less
/// its mean rate, in the cosine rule, which integrates e^{iνφ} exactly).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LevelDrift {
    pub(crate) value: [f64; 2],
    pub(crate) scale: f64,
    pub(crate) phase_step: f64,
}

impl LevelDrift {
    /// |Δζ − Δζ′| between two levels.
    fn distance(&self, other: &Self) -> f64 {
        (self.value[0] - other.value[0]).hypot(self.value[1] - other.value[1])
    }
}

/// The largest change between neighbours of `phases` (0 for fewer than two).
pub(crate) fn largest_step(phases: &[f64]) -> f64 {
    phases
        .windows(2)
        .fold(0.0, |worst: f64, w| worst.max((w[1] - w[0]).abs()))
}

/// The largest phase step between neighbouring nodes at which a level is taken to resolve
/// e^{iψ} (four nodes a quarter-turn): where the phase turns faster the sums alias, and three
/// levels can agree on a wrong Δζ. (A libration passing a pole within 1e-4 at κ = −2.5e-4,
/// N = 811, Δψ = −5096 over a period: its drift was `ok` at tol 1e-6 with 65 … 129 cosine
/// nodes, 112 times too small against an estimate of 2.9e-8; adversary pass of 2026-11-28.)
const RESOLVED_PHASE_STEP: f64 = FRAC_PI_2;
const _: () = assert!(MAX_LEVEL < 16 && crate::quadrature::FINEST_CHEBYSHEV_LEVEL < 16);

/// Δζ and the L1 size of its integrand from every `stride`-th node of each piece's samples.
/// A Clenshaw–Curtis piece whose left end is θ_min ([`ChebyshevPiece::TurningLeft`]) takes
/// the way out and the way back apart: continued to u < 0, the way out is the previous
/// period's way back, e^{−iΔψ} times this one's, and the rule's weights of ∫ over [0, 1] at
/// the mirrored nodes (v_{N−j}) carry that factor; elsewhere the two ways join smoothly (at
/// θ_max, or within the piece) and the sum of both is integrated at once.
fn drift_sum(samples: &[PieceSamples], psi_advance: f64, double: f64, stride: usize) -> LevelDrift {
    let stride_exp = stride.trailing_zeros();
    let (sa, ca) = psi_advance.sin_cos();
    let (mut re, mut im, mut scale) = (0.0, 0.0, 0.0);
    let mut psi_offset = 0.0;
    let mut phase_step: f64 = 0.0;
    let mut psi = Vec::new();
    for s in samples {
        s.psi_along(stride_exp, &mut psi);
        phase_step = phase_step.max(largest_step(&psi));
        let weights = s.weights(stride_exp);
        let mirror = (s.rule == Rule::Chebyshev(ChebyshevPiece::TurningLeft))
            .then(|| &ChebyshevLevel::get(s.level - stride_exp).turning_left_mirror);
        for (i, (n, &p)) in s.nodes.iter().step_by(stride).zip(&psi).enumerate() {
            let step = weights.at(i);
            let (sp, cp) = libm::sincos(psi_offset + p);
            // E = e^{iψ}, F = e^{i(Δψ − ψ)} = e^{iΔψ} conj(E).
            let (fr, fi) = (ca * cp + sa * sp, sa * cp - ca * sp);
            let (along, across) = (n.along, n.across);
            if double == 2.0 {
                // −[along (E + F) + i across (E − F)]: the way out −E (along + i across),
                // the way back −F (along − i across).
                let out = [-(along * cp - across * sp), -(along * sp + across * cp)];
                let back = [-(along * fr + across * fi), -(along * fi - across * fr)];
                re += step * (out[0] + back[0]);
                im += step * (out[1] + back[1]);
                if let Some(mirror) = mirror {
                    // + b [(e^{iΔψ} − 1) out + (e^{−iΔψ} − 1) back].
                    let b = mirror[i];
                    let (rc, rs) = (ca - 1.0, sa);
                    re += b * (rc * out[0] - rs * out[1] + rc * back[0] + rs * back[1]);
                    im += b * (rc * out[1] + rs * out[0] + rc * back[1] - rs * back[0]);
                }
            } else {
                // Rotation: one way round, −[along + i across] E.
                re -= step * (along * cp - across * sp);
                im -= step * (along * sp + across * cp);
            }
            scale += step * double * (along.abs() + across.abs());
        }
        psi_offset += psi.last().copied().unwrap_or(0.0);
    }
    LevelDrift {
        value: [re, im],
        scale,
        phase_step,
    }
}

/// Δζ with its error estimate and the scale the tolerance is relative to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftEstimate {
    /// Δζ = (Δx_c, Δy_c) over one θ-period from θ_min, in the frame where ψ = 0 there.
    pub value: [f64; 2],
    /// Estimated absolute error of Δζ.
    pub error: f64,
    /// ∫ |integrand|: the size of the path over one period, the scale of the tolerance.
    pub scale: f64,
}

impl DriftEstimate {
    /// The finest of three successive levels' Δζ, with its error from their differences by
    /// [`cautious_error`]: at `rate` where the coarsest level resolves e^{iψ}
    /// ([`RESOLVED_PHASE_STEP`]), at [`Convergence::Unknown`] where only the two finer ones
    /// do, and the whole path scale (Δζ unknown, the levels to be refined) where the middle
    /// one does not either.
    fn from_levels(
        fine: LevelDrift,
        mid: LevelDrift,
        coarse: LevelDrift,
        rate: Convergence,
    ) -> Self {
        let (d1, d2) = (fine.distance(&mid), mid.distance(&coarse));
        // (A NaN phase step is no resolved one.)
        let resolved = |l: LevelDrift| l.phase_step <= RESOLVED_PHASE_STEP;
        let rate = if resolved(coarse) {
            rate
        } else {
            Convergence::Unknown
        };
        let mut error = cautious_error(d1, d2, rate).max(LEVEL_FLOOR * fine.scale);
        if !resolved(mid) {
            error = error.max(fine.scale);
        }
        Self {
            value: fine.value,
            error,
            scale: fine.scale,
        }
    }
}

/// The errors of T, Δψ and Δζ from the conditioning of the energy near a saddle
/// ([`EffectivePotential::saddle_conditioning`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SaddleTerms {
    /// Of T.
    pub period: f64,
    /// Of Δψ.
    pub psi_advance: f64,
    /// Of Δζ through the time spent by the saddle, beyond the phases' (Δψ's term times the
    /// path scale).
    pub drift: f64,
}

/// Integrals over one θ-period of a component, with their errors, from either method
/// (this module's quadrature or [`crate::period_ode`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodIntegrals {
    /// T = 2 ∫ √(B / (2(ε − V))) dθ over [θ_min, θ_max] (a rotation: ∫ over the circle).
    pub period: f64,
    /// Δψ = ∫ ψ̇ dt over one period.
    pub psi_advance: f64,
    /// Estimated absolute error of T.
    pub period_error: f64,
    /// Estimated absolute error of Δψ.
    pub psi_advance_error: f64,
    /// Δζ, when asked for.
    pub drift: Option<DriftEstimate>,
    /// ∫ |ψ̇| dt over one period (the L1 size of Δψ's integrand), where the method gives it
    /// (the quadratures; not the ODE runs).
    pub psi_variation: Option<f64>,
    /// The parts of `period_error`, `psi_advance_error` and the drift's error that bound the
    /// conditioning near a saddle at the a-priori error of the energy (see
    /// [`EffectivePotential::saddle_conditioning`]; Δψ's part enters the drift's error times
    /// the path scale as well): a libration whose level offset is known more sharply
    /// replaces them.
    pub saddle: SaddleTerms,
    /// Where a libration's turning points were placed on the level ε in double-double
    /// ([`EffectivePotential::integrate`] below tol 1e-11 on a shape that gives V so): a bound
    /// on |ε − V| at them, the whole offset of the level the integrals are those of. `None`:
    /// the ends are doubles, each at its own level V(e) (see `cell::level_offset_error`).
    pub level_residual: Option<f64>,
    /// Integrand evaluations (quadrature) or accepted steps (ODE) spent.
    pub work: usize,
    /// Whether the method reached what its estimates assume (false: the tanh-sinh levels ran
    /// out, or a ψ̇ peak lay beyond its nodes). Whether the estimates meet the tolerance is
    /// the status's to judge, after the level offset's terms (`cell::finish`).
    pub converged: bool,
}

/// A turning point closer to its pole than this fraction of its piece lies beyond the
/// tanh-sinh nodes (the last at e^{−π sinh 4} ≈ 6e-38 of the piece).
const HIDDEN_PEAK: f64 = 1e-30;

/// The finest Clenshaw–Curtis level tried for T and Δψ (N = 256, 129 nodes on a piece with
/// a turning point) before the tanh-sinh rule takes the piece over.
const CHEBYSHEV_LAST_LEVEL: u32 = 8;

/// The Clenshaw–Curtis intervals within which a piece must be predicted to converge for
/// the rule to be tried (see `EffectivePotential::chebyshev_kinds`).
const CHEBYSHEV_PLANNED_INTERVALS: usize = 128;

/// The first level, the coarsest at which the level differences are trusted: its two levels
/// below (steps ½ and ¼ in τ) are then past the first, pre-asymptotic ones.
const START_LEVEL: u32 = 4;
const MAX_LEVEL: u32 = FINEST_LEVEL;

#[derive(Debug, Clone, Copy)]
struct PieceEnd {
    site: Site,
    angle: Angle,
    /// ε − V at the end: 0 at a turning point (by definition of the end), > 0 at a saddle.
    excess: f64,
    /// The level V + `excess` the gap is measured against at the end: V(e) at a turning
    /// point (ε to within the rounding of the root), ε at a saddle. Between the ends the
    /// level runs linearly (see `Piece::tilt_rate`), in both of `sample`'s forms of the gap.
    level: f64,
    /// Bound on the rounding error of `excess` (0 at a turning point, whose level is the
    /// gap's zero by construction; the offset of that level from ε is bounded in
    /// [`crate::cell`]).
    excess_error: f64,
    /// The end in double-double where the gaps are computed sharply
    /// ([`EffectivePotential::sharpen_gaps`]).
    sharp: Option<SharpEnd>,
    /// A turning point placed on the level ε in double-double ([`Placed`]); `None`: the end
    /// is the double `angle` itself, at the level `level`.
    placed: Option<Placed>,
}

/// A turning point e (a double) moved onto the level ε: the true end is e + `shift`, where
/// V = ε to within `residual`, and the gap at t = e + x is ε − V(t) = `offset` − (V(t) − V(e))
/// with `offset` = ε − V(e), both taken from V in double-double. The nodes are then placed
/// from e + `shift`, and the integrals are those of the level ε itself: the rounding of the
/// root to a double (an offset of up to V′ ulp(e)/2 of the level, whose effect through
/// dX/dε near a saddle was the largest term of T's estimate at tol 1e-13) is gone.
/// Measured from e itself, a gap is off its value from e + `shift` by at most `near` of
/// itself: |shift V″/V′| at the end, doubled. `sin`, `cos` are the pair of e + `shift` and
/// `value` V there, in double-double, within `value_error`.
#[derive(Debug, Clone, Copy)]
struct Placed {
    shift: f64,
    offset: f64,
    residual: f64,
    near: f64,
    sin: DoubleDouble,
    cos: DoubleDouble,
    value: DoubleDouble,
    value_error: f64,
}

/// An end's angle, on the unit circle, and its level V + `excess` in double-double, with the
/// bound on that level's error (about 1e-30 of V's terms).
#[derive(Debug, Clone, Copy)]
struct SharpEnd {
    sin: DoubleDouble,
    cos: DoubleDouble,
    level: DoubleDouble,
    error: f64,
    /// The relative rounding of a gap in double above which it is recomputed: the larger of
    /// [`SHARP_GAP_ROUNDING`] and a fiftieth of the tolerance (gaps rounded below that add
    /// at most a hundredth of the tolerance to T and Δψ).
    threshold: f64,
}

/// Tolerances below which the gaps whose rounding in double exceeds [`SHARP_GAP_ROUNDING`] are
/// computed in double-double ([`EffectivePotential::sharpen_gaps`]), on a shape without kinks.
const SHARP_GAPS_BELOW: f64 = 1e-11;

/// The relative rounding bound of a gap in double above which it is recomputed in
/// double-double at tight tolerances: the divided difference of V cancels where the wall's
/// and U's slopes nearly balance (in a narrow well, next to a saddle), 20–300 eps of the gap
/// measured on the standard slice.
const SHARP_GAP_ROUNDING: f64 = 4.0 * EPS;

#[derive(Debug, Clone, Copy)]
struct Piece {
    left: PieceEnd,
    right: PieceEnd,
    length: f64,
    /// m / L with m = (V + excess)(right) − (V + excess)(left): the gap is taken against the
    /// level that runs linearly from one end's to the other's, so it vanishes at both
    /// turning points and is continuous in between.
    tilt_rate: f64,
}

impl Piece {
    /// The piece with its gaps computed in double only.
    fn in_double(&self) -> Self {
        let mut plain = *self;
        plain.left.sharp = None;
        plain.right.sharp = None;
        plain
    }

    /// The end nearer `node`, and the node's signed offset from it (≥ 0 from the left end).
    #[inline]
    fn nearer_end(&self, node: IntervalNode) -> (&PieceEnd, f64) {
        if node.from_left <= node.from_right {
            (&self.left, node.from_left)
        } else {
            (&self.right, -node.from_right)
        }
    }
}

impl SharpEnd {
    /// The (sine, cosine) pair of the angle `offset` beyond the end, whose sine and cosine are
    /// `sin_offset` and `cos_offset`, in double-double, scaled onto the unit circle.
    #[inline(always)]
    fn rotated(&self, sin_offset: f64, cos_offset: f64) -> (DoubleDouble, DoubleDouble) {
        let sin = self
            .sin
            .mul_f64(cos_offset)
            .add(self.cos.mul_f64(sin_offset));
        let cos = self
            .cos
            .mul_f64(cos_offset)
            .sub(self.sin.mul_f64(sin_offset));
        DoubleDouble::onto_circle(sin, cos)
    }
}

/// What one node contributes, already multiplied by dθ/dτ (not by the τ-step).
#[derive(Debug, Clone, Copy, Default)]
struct NodeSample {
    /// dt/dτ = t′ dθ/dτ.
    dt: f64,
    /// ψ̇ dt/dτ.
    dpsi: f64,
    /// U a t′ dθ/dτ with a = κ/(J sinθ).
    along: f64,
    /// U dθ/dτ.
    across: f64,
    /// Bound on the relative rounding error of the gap ε − V at the node.
    rounding: f64,
}

/// Which rules [`EffectivePotential::integrate_by`] may use.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rules {
    /// The cheapest that converges (as [`EffectivePotential::integrate`]).
    Fastest,
    /// The tanh-sinh rule on every piece.
    TanhSinhOnly,
}

/// The rule a piece is integrated by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rule {
    /// Tanh-sinh in τ: any end singularity, level differences trusted only to d₁.
    TanhSinh,
    /// Clenshaw–Curtis ([`ChebyshevPiece`]): an analytic piece whose only end singularity is
    /// a turning point's inverse square root, at a fraction of the tanh-sinh nodes.
    Chebyshev(ChebyshevPiece),
}

/// The samples of one piece on its current level of its rule (the level below is every
/// other node).
struct PieceSamples {
    rule: Rule,
    /// How a Clenshaw–Curtis piece's variable covers the piece: θ itself, or Mercator's
    /// s = ln tan(θ/2) by a pole (the tanh-sinh rule's: θ).
    map: cosine::Map,
    level: u32,
    /// The least level whose differences are trusted.
    least_level: u32,
    nodes: Vec<NodeSample>,
    evaluations: usize,
    /// Whether the tanh-sinh nodes are taken with their integrands in double-double
    /// ([`precise_sample`]; see [`Self::take_again_precise`]).
    precise: bool,
    /// The sums of dt and of dψ on this level and the three below (`period`, `psi`), and
    /// their L1 sizes on this level, made once per level: the refinement's tests and the
    /// results ask for them many times.
    sums: OnceCell<SampleSums>,
}

impl PieceSamples {
    fn new<S: Shape>(
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        energy: f64,
        level: u32,
    ) -> Result<Self> {
        let lv = TanhSinhLevel::new(level);
        let nodes = (0..lv.count)
            .map(|j| {
                sample(
                    v,
                    piece,
                    energy,
                    IntervalNode::tanh_sinh_tabulated(level, j, piece.length),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            rule: Rule::TanhSinh,
            map: cosine::Map::Plain {
                length: piece.length,
            },
            level,
            least_level: 0,
            evaluations: nodes.len(),
            nodes,
            precise: false,
            sums: OnceCell::new(),
        })
    }

    /// The Clenshaw–Curtis samples of `kind` on `level` (trusted from `least_level`), or
    /// `None` where a node is not inside the allowed set or the turning point is too flat
    /// for its limit.
    fn chebyshev<S: Shape>(
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        energy: f64,
        kind: ChebyshevPiece,
        map: cosine::Map,
        level: u32,
        least_level: u32,
    ) -> Option<Self> {
        let nodes = (0..kind.count(level))
            .map(|i| chebyshev_sample(v, piece, energy, kind, &map, level, i))
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            rule: Rule::Chebyshev(kind),
            map,
            level,
            least_level,
            evaluations: nodes.len(),
            nodes,
            precise: false,
            sums: OnceCell::new(),
        })
    }

    /// The quadrature weights of the level 2^`stride_exp` times coarser, whose nodes are
    /// every 2^`stride_exp`-th of this level's (indexed by that level's nodes).
    #[inline]
    fn weights(&self, stride_exp: u32) -> Weights {
        match self.rule {
            Rule::TanhSinh => {
                Weights::Uniform(TanhSinhLevel::new(self.level).step * (1u32 << stride_exp) as f64)
            }
            Rule::Chebyshev(kind) => {
                Weights::Table(&ChebyshevLevel::get(self.level - stride_exp).piece[kind as usize])
            }
        }
    }

    /// The sum of `f` over every 2^`stride_exp`-th node (0: this level; 1: the level below),
    /// times that level's weights.
    fn sum(&self, stride_exp: u32, f: impl Fn(&NodeSample) -> f64) -> f64 {
        let stride = 1usize << stride_exp;
        let nodes = self.nodes.iter().step_by(stride);
        match self.weights(stride_exp) {
            Weights::Uniform(step) => step * nodes.map(f).sum::<CompensatedSum>().value(),
            Weights::Table(w) => nodes
                .zip(w)
                .map(|(n, w)| w * f(n))
                .sum::<CompensatedSum>()
                .value(),
        }
    }

    /// The sums of dt (`part` 0) or dψ (1) on this level and the three below (a level the
    /// rule does not have: NaN, never asked for).
    fn level_sums(&self, part: usize) -> [f64; 4] {
        self.sample_sums().by_level[part]
    }

    /// Σ |dt| (`part` 0) or Σ |dψ| (1) times the weights on this level: the L1 sizes.
    fn size(&self, part: usize) -> f64 {
        self.sample_sums().size[part]
    }

    /// In one pass over the nodes, the ten sums side by side (each [`Self::sum`]'s terms in
    /// its order: the same values, where ten passes made ten chains of dependent additions).
    fn sample_sums(&self) -> &SampleSums {
        self.sums.get_or_init(|| {
            let weights: [Option<Weights>; 4] = std::array::from_fn(|k| {
                let k = k as u32;
                let exists = match self.rule {
                    Rule::TanhSinh => k < 3 || self.level >= 4,
                    Rule::Chebyshev(_) => self.level > k,
                };
                exists.then(|| self.weights(k))
            });
            let mut by_level = [[CompensatedSum::default(); 4]; 2];
            let mut size = [CompensatedSum::default(); 2];
            for (i, n) in self.nodes.iter().enumerate() {
                for (k, w) in weights.iter().enumerate() {
                    if i % (1 << k) != 0 {
                        continue;
                    }
                    // (A uniform level's step multiplies its sum, a table's weights each term.)
                    let weight = match w {
                        Some(Weights::Uniform(_)) => None,
                        Some(Weights::Table(table)) => match table.get(i >> k) {
                            Some(&w) => Some(w),
                            None => continue,
                        },
                        None => continue,
                    };
                    let term = |x: f64| weight.map_or(x, |w| w * x);
                    by_level[DT][k].add(term(n.dt));
                    by_level[DPSI][k].add(term(n.dpsi));
                    if k == 0 {
                        size[DT].add(term(n.dt.abs()));
                        size[DPSI].add(term(n.dpsi.abs()));
                    }
                }
            }
            let value = |k: usize, sum: CompensatedSum| match weights[k] {
                Some(Weights::Uniform(step)) => step * sum.value(),
                Some(Weights::Table(_)) => sum.value(),
                None => f64::NAN,
            };
            SampleSums {
                by_level: [DT, DPSI]
                    .map(|part| std::array::from_fn(|k| value(k, by_level[part][k]))),
                size: [DT, DPSI].map(|part| value(0, size[part])),
            }
        })
    }

    fn period(&self, stride_exp: u32) -> f64 {
        self.level_sums(0)[stride_exp as usize]
    }

    fn psi(&self, stride_exp: u32) -> f64 {
        self.level_sums(1)[stride_exp as usize]
    }

    /// Error of the sum of `f`: see [`level_error`]; for tanh-sinh plus the tails beyond
    /// |τ| = TAU_MAX ([`Self::tail`]), for Clenshaw–Curtis with the geometric rate trusted
    /// where a fourth level shows one rate ([`cosine::single_rate`]) and the last difference
    /// is below [`GEOMETRIC_FROM`] of the integrand's L1 size. On the first levels of a
    /// piece that ends next to a maximum the differences can fall faster than the errors: a
    /// truncated ball's libration (α = 0.999999, tol 0.1) had T-sums 61.5, 50.9, 52.27,
    /// 52.282 on 16 … 128 intervals, one rate by the test, and an error of 3.4e-3 where
    /// d₁ max(√r, 1/10) put 1.3e-3 (an adversary pass); d₁ itself bounds it.
    fn error(&self, part: usize) -> f64 {
        let [s0, s1, s2, s3] = self.level_sums(part);
        let sums = [s0, s1, s2];
        match self.rule {
            Rule::TanhSinh => {
                level_error(sums, Convergence::Unknown) + self.tail(PART_VALUES[part])
            }
            Rule::Chebyshev(_) if matches!(self.map, cosine::Map::Mercator { .. }) => {
                // Mercator's levels as the cosine rule's: d₁ where they are trusted, else the
                // integrand's whole L1 size (refined on, or to the tanh-sinh rule). (Sums on
                // their floor are trusted whatever the rate: the last difference may be 0.)
                if self.level >= 4
                    && (at_level_floor(sums, Convergence::Unknown)
                        || (cosine::single_rate(s3, sums) && cosine::mercator_falling(s3, sums)))
                {
                    level_error(sums, Convergence::Unknown)
                } else {
                    self.size(part)
                }
            }
            Rule::Chebyshev(_) => {
                let settled = (s0 - s1).abs() <= GEOMETRIC_FROM * self.size(part);
                let rate = if self.level >= 4 && cosine::single_rate(s3, sums) && settled {
                    Convergence::Geometric
                } else {
                    Convergence::Unknown
                };
                level_error(sums, rate)
            }
        }
    }

    /// Bound on the integral of `f` beyond the tanh-sinh rule's last nodes, |τ| > TAU_MAX
    /// (0 for Clenshaw–Curtis, which covers its piece). Refining does not shrink it. Near an
    /// end x ≈ L e^{−π sinh τ} and dx/dτ ≈ π cosh τ x; an integrand at most like x^{−1/2}
    /// there (a turning point; bounded at the other ends) makes ln g, g = f dx/dτ, fall at
    /// a rate of at least (π/2) cosh τ − 1, so the tail is at most
    /// g(τ_max)/((π/2) cosh τ_max − 1), 1/41.9 of the last node's g (the leading terms of x
    /// and f there are off by less than 1e-3 of them: the last node lies within 6e-38 L of
    /// the end, a turning point at least 1e-30 L from its pole); a quarter more is taken.
    /// Where a turning point lies by a pole (κ ≠ 0), Δψ's tail
    /// is a share ~√(x_last/θ_end) of the sweep round it: 1e-10 of N at κ = 1e-18, where
    /// the step times g (1/1024 of g at level 10) had put N's error at 2.7e-11 (adversary
    /// pass of issue 22, helper 11).
    fn tail(&self, f: impl Fn(&NodeSample) -> f64) -> f64 {
        match self.rule {
            Rule::TanhSinh => {
                let decay = FRAC_PI_2 * TAU_MAX.cosh() - 1.0;
                1.25 * (f(&self.nodes[0]).abs() + f(self.nodes.last().unwrap()).abs()) / decay
            }
            Rule::Chebyshev(_) => 0.0,
        }
    }

    /// Whether T's and Δψ's sums on the last four levels show one rate
    /// ([`cosine::single_rate`]: each ratio of differences at least a sixteenth of the square
    /// of the one before, as under E(n) = C ρⁿ and under the tanh-sinh rule's
    /// E(h) = C e^{−c/h}). A last ratio far below that has the error the earlier levels saw
    /// die out, and what is left (a feature the coarse levels stepped over) is not seen.
    fn one_rate(&self) -> bool {
        self.level >= 4
            && (0..2).all(|part| {
                let [s0, s1, s2, s3] = self.level_sums(part);
                cosine::single_rate(s3, [s0, s1, s2])
            })
    }

    /// Whether the levels are a Clenshaw–Curtis rule's in one geometric regime.
    fn geometric(&self) -> bool {
        matches!(self.rule, Rule::Chebyshev(_))
            && matches!(self.map, cosine::Map::Plain { .. })
            && self.one_rate()
    }

    /// Σ ½ (relative gap error) |f| weight: the gap enters t′ as (ε − V)^{−1/2}.
    fn rounding(&self, f: impl Fn(&NodeSample) -> f64) -> f64 {
        let node_rounding = self.map.node_rounding();
        self.sum(0, |n| 0.5 * (n.rounding + node_rounding) * f(n).abs())
    }

    /// Take a tanh-sinh piece's nodes again with their integrands in double-double
    /// ([`precise_sample`], each checked against the node in double it replaces), and its
    /// refinements likewise. (A Clenshaw–Curtis piece keeps its nodes.)
    fn take_again_precise<S: Shape>(
        &mut self,
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        energy: f64,
    ) -> Result<()> {
        if self.rule != Rule::TanhSinh || self.precise {
            return Ok(());
        }
        for (j, n) in self.nodes.iter_mut().enumerate() {
            let node = IntervalNode::tanh_sinh_tabulated(self.level, j, piece.length);
            *n = precise_sample(v, piece, piece, energy, node, Some(*n))?;
        }
        self.evaluations += self.nodes.len();
        self.precise = true;
        self.sums = OnceCell::new();
        Ok(())
    }

    /// Halve the step: keep the old nodes (now the even ones) and add the odd ones. `false`
    /// (the samples unchanged) where a Clenshaw–Curtis node is not in the allowed set.
    fn refine<S: Shape>(
        &mut self,
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        energy: f64,
    ) -> Result<bool> {
        self.sums = OnceCell::new();
        self.level += 1;
        let (level, precise) = (self.level, self.precise);
        match self.rule {
            Rule::TanhSinh => interleave(&mut self.nodes, |j| {
                let node = IntervalNode::tanh_sinh_tabulated(level, j, piece.length);
                if precise {
                    precise_sample(v, piece, piece, energy, node, None)
                } else {
                    sample(v, piece, energy, node)
                }
            })?,
            Rule::Chebyshev(kind) => {
                // The new (odd) nodes first: where one is not in the allowed set the samples
                // stay as they were.
                let map = self.map;
                let odd = (1..self.nodes.len())
                    .map(|j| chebyshev_sample(v, piece, energy, kind, &map, level, 2 * j - 1))
                    .collect::<Option<Vec<_>>>();
                let Some(odd) = odd else {
                    self.level -= 1;
                    return Ok(false);
                };
                let mut odd = odd.into_iter();
                interleave(&mut self.nodes, |_| Ok(odd.next().expect("one a gap")))?;
            }
        }
        self.evaluations += self.nodes.len() / 2;
        Ok(true)
    }

    /// ψ from the piece's left end at every `stride`-th node (the cumulative integral of
    /// ψ̇ dt on that level), into `out`.
    fn psi_along(&self, stride_exp: u32, out: &mut Vec<f64>) {
        let stride = 1usize << stride_exp;
        let rates = self.nodes.iter().step_by(stride).map(|n| n.dpsi);
        out.clear();
        match self.rule {
            Rule::TanhSinh => {
                let rates: Vec<f64> = rates.collect();
                let step = TanhSinhLevel::new(self.level).step * stride as f64;
                out.extend(spectral_antiderivative(&rates, step));
            }
            Rule::Chebyshev(kind) => {
                let level = self.level - stride_exp;
                match chebyshev_psi_matrix(kind, level) {
                    // (The matrix's row i against the rates: the same linear map as the
                    // transforms, without their set-up, which dominated the drift's cost on
                    // the few nodes of most pieces.)
                    //
                    // Column by column: each ψ_i still sums its terms in the order of the rates
                    // (bit for bit the row's dot product), but the nodes' sums run side by
                    // side, where one row's sum was a chain of dependent additions (half the
                    // drift's time on a truncated ball).
                    Some(matrix) => {
                        let count = kind.count(level);
                        out.resize(count, -0.0);
                        for (column, rate) in matrix.chunks_exact(count).zip(rates) {
                            for (psi, m) in out.iter_mut().zip(column) {
                                *psi += m * rate;
                            }
                        }
                    }
                    None => chebyshev_psi_along(kind, level, rates, out),
                }
            }
        }
    }
}

/// ψ from a Clenshaw–Curtis piece's left end at each node of `level` (the antiderivative of the
/// interpolating polynomial of the `rates`, node by node), into `out`, by
/// [`chebyshev_antiderivative`].
fn chebyshev_psi_along(
    kind: ChebyshevPiece,
    level: u32,
    rates: impl Iterator<Item = f64>,
    out: &mut Vec<f64>,
) {
    let n = 1usize << level;
    // The rates at x_j = cos(jπ/N), j = 0 … N (a half piece's continued evenly).
    let mut values = vec![0.0; n + 1];
    for (i, rate) in rates.enumerate() {
        let j = kind.chebyshev_index(level, i);
        values[j] = rate;
        if kind != ChebyshevPiece::Regular {
            values[n - j] = rate;
        }
    }
    let mut q = vec![0.0; n + 1];
    chebyshev_antiderivative(&values, &mut q);
    let count = kind.count(level);
    out.extend((0..count).map(|i| {
        let j = kind.chebyshev_index(level, i);
        match kind {
            // ∫ from x = −1 (j = N).
            ChebyshevPiece::Regular => q[j],
            // ∫ from u = 0 (j = N/2) up to u_j.
            ChebyshevPiece::TurningLeft => q[j] - q[n / 2],
            // ∫ from u = 1 (j = 0) down to u_j.
            ChebyshevPiece::TurningRight => q[0] - q[j],
        }
    }));
}

/// The levels up to which [`chebyshev_psi_along`] is applied as a matrix (at most 129 nodes a
/// piece: 17,000 entries).
const PSI_MATRIX_LEVELS: u32 = 7;

/// [`chebyshev_psi_along`] of `kind` on `level` as a column-major count × count matrix (its
/// columns, stored one after another, the images of the unit vectors), built once; `None`
/// above [`PSI_MATRIX_LEVELS`].
fn chebyshev_psi_matrix(kind: ChebyshevPiece, level: u32) -> Option<&'static [f64]> {
    const LEVELS: usize = PSI_MATRIX_LEVELS as usize + 1;
    static MATRICES: [[OnceLock<Vec<f64>>; LEVELS]; 3] =
        [const { [const { OnceLock::new() }; LEVELS] }; 3];
    let cell = MATRICES[kind as usize].get(level as usize)?;
    Some(cell.get_or_init(|| {
        let count = kind.count(level);
        let mut matrix = vec![0.0; count * count];
        let mut column = Vec::with_capacity(count);
        for j in 0..count {
            column.clear();
            chebyshev_psi_along(
                kind,
                level,
                (0..count).map(|i| f64::from(i == j)),
                &mut column,
            );
            matrix[j * count..(j + 1) * count].copy_from_slice(&column);
        }
        matrix
    }))
}

/// The share of a Clenshaw–Curtis piece's L1 size below which its last level difference is
/// in the asymptotic regime where the geometric rate is trusted ([`PieceSamples::error`]):
/// every tolerance below 1e-8 gets there before its estimate passes.
const GEOMETRIC_FROM: f64 = 1e-6;

/// What [`PieceSamples::sample_sums`] keeps for a level, by part (dt, dψ).
struct SampleSums {
    /// The sums on the level and the three below.
    by_level: [[f64; 4]; 2],
    /// The L1 sizes on the level.
    size: [f64; 2],
}

/// The parts of [`PieceSamples::level_sums`]: dt and dψ.
const DT: usize = 0;
const DPSI: usize = 1;
const PART_VALUES: [fn(&NodeSample) -> f64; 2] = [|n| n.dt, |n| n.dpsi];

/// A level's quadrature weights.
enum Weights {
    Uniform(f64),
    Table(&'static [f64]),
}

impl Weights {
    #[inline]
    fn at(&self, i: usize) -> f64 {
        match self {
            Weights::Uniform(step) => *step,
            Weights::Table(w) => w[i],
        }
    }
}

/// The integrands at node `i` of a Clenshaw–Curtis piece; at the turning point their limit
/// (see `cosine::end_sample`: θ − θ_e = L u², so ℓ = 4L).
fn chebyshev_sample<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    energy: f64,
    kind: ChebyshevPiece,
    map: &cosine::Map,
    level: u32,
    i: usize,
) -> Option<NodeSample> {
    if kind.turning_node(level) == Some(i) {
        let left = kind == ChebyshevPiece::TurningLeft;
        return cosine::end_sample_with_length(v, piece, 4.0 * map.end_length(piece, left), left);
    }
    let node = match map {
        cosine::Map::Plain { .. } => {
            IntervalNode::chebyshev_tabulated(kind, level, i, piece.length)
        }
        cosine::Map::Mercator { .. } => {
            map.place(IntervalNode::chebyshev_tabulated(kind, level, i, 1.0))
        }
    };
    sample(v, piece, energy, node).ok()
}

/// The nodes of the next finer level of a nested rule, in place: the old ones become the
/// even nodes and `new(j)` gives each odd node j (on an error the nodes are left half-made).
fn interleave(
    nodes: &mut Vec<NodeSample>,
    mut new: impl FnMut(usize) -> Result<NodeSample>,
) -> Result<()> {
    let old = nodes.len();
    nodes.resize(2 * old - 1, NodeSample::default());
    for j in (1..old).rev() {
        nodes[2 * j] = nodes[j];
    }
    for j in 1..old {
        nodes[2 * j - 1] = new(2 * j - 1)?;
    }
    Ok(())
}

/// The error of the finest of three successive sums of a nested rule (finest first), from
/// the level differences d₁ = |I₀ − I₁| and d₂ = |I₁ − I₂| by [`cautious_error`].
/// Never below [`LEVEL_FLOOR`] of the finest sum.
fn level_error(sums: [f64; 3], rate: Convergence) -> f64 {
    let (d1, d2) = ((sums[0] - sums[1]).abs(), (sums[1] - sums[2]).abs());
    cautious_error(d1, d2, rate).max(LEVEL_FLOOR * sums[0].abs())
}

/// The least error a level difference is trusted to show, relative to the sum: below it
/// the differences are the integrand's rounding (bounded apart), not the rule's truncation.
const LEVEL_FLOOR: f64 = 8.0 * EPS;

/// Whether [`level_error`] of `sums` is its floor: refining cannot lower it further.
fn at_level_floor(sums: [f64; 3], rate: Convergence) -> bool {
    let (d1, d2) = ((sums[0] - sums[1]).abs(), (sums[1] - sums[2]).abs());
    cautious_error(d1, d2, rate) <= LEVEL_FLOOR * sums[0].abs()
}

/// What a rule's level differences may be trusted to say about the next level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Convergence {
    /// One geometric rate once past the first levels: the trapezoid rule in the plain cosine
    /// map, whose integrand's nearest singularities (the poles, the shape's, complex turning
    /// points) set a single strip. Over the whole domain against 50-digit values (issue 12:
    /// 131 + 311 + 311 cells) its sums never fell short of d₁ max(√r, 1/10).
    Geometric,
    /// Possibly several rates: the tanh-sinh rule (its first levels near a separatrix are
    /// pre-asymptotic: d₁²/d₂ was 7× short at tol 1e-6) and the Mercator map, which spreads a
    /// pole over a long s-range (E₀/d₁ = 0.54 after r = 5e-7, κ = −2.5e-5 at high energy).
    Unknown,
}

/// The error of the finest of three successive sums of a nested rule from the level
/// differences d₁ ≈ E₁ and d₂ ≈ E₂ of the two coarser ones, r = d₁/d₂. Under E(n) = C ρⁿ,
/// E₀ = d₁ r², but the first levels may not be in the asymptotic regime (seen on random
/// cells: r = 9e-4 followed by E₀/E₁ = 2e-3 for T, r = 2e-5 followed by 1e-2 for the
/// drift), so a [`Convergence::Geometric`] rule gets d₁ max(√r, 1/10) — never more than one
/// digit beyond the last difference — and d₁ itself until r ≤ 0.01. Any other rule gets d₁,
/// which bounds E₀ whenever the levels improve. Used for T, Δψ and Δζ by either rule.
fn cautious_error(d1: f64, d2: f64, rate: Convergence) -> f64 {
    if rate == Convergence::Geometric && d2 > 0.0 && d1 <= 0.01 * d2 {
        d1 * (d1 / d2).sqrt().max(0.1)
    } else {
        d1
    }
}

/// The integrands at one tanh-sinh node of a piece.
#[inline]
fn sample<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    energy: f64,
    node: IntervalNode,
) -> Result<NodeSample> {
    // Measure from the nearer end: offset x ≥ 0 and the end's angle (a placed end lies
    // `shift` beyond its double, and its gap is measured from V there, `offset` below ε).
    let (end, signed) = piece.nearer_end(node);
    // (Nodes nearer a placed end than its shift, in the tanh-sinh rule's tails, are measured
    // from the double: there ε − V(e) and the shift times D would cancel to their rounding,
    // and D at e is D at e + shift to within `Placed::near`.)
    // The gaps are those of the level V(e + shift), within `residual` of ε (bounded as a
    // level offset in `cell::level_offset_error`): the shifted form measures from ε itself,
    // off by that residual, which against a gap beyond the shift is below 1e-13 of it.
    let (signed, offset, near, residual) = match end.placed {
        Some(placed) if signed.abs() > placed.shift.abs() => {
            (signed + placed.shift, placed.offset, 0.0, placed.residual)
        }
        Some(placed) => (signed, 0.0, placed.near, 0.0),
        None => (signed, 0.0, 0.0, 0.0),
    };
    let (sx, cx) = libm::sincos(signed);
    let e = end.angle;
    let a = Angle {
        sin: e.sin * cx + e.cos * sx,
        cos: e.cos * cx - e.sin * sx,
    };
    let red = v.body.reduction_at(a);
    let v_t = if v.kappa == 0.0 {
        red.potential
    } else {
        let w = v.kappa / a.sin;
        0.5 * w * w + red.potential
    };
    let (gap, abs_err) = if 16.0 * (energy - v_t) > energy.abs() + v_t.abs() || cx <= -0.4 {
        // Far from the ends and from saddles the plain difference loses at most 4 bits. It
        // is taken against the same tilted level as the form below: against ε itself the
        // gap would jump where the forms meet by the ends' offsets from ε (a 4e-13 relative
        // jump, a 3e-14 error of T, in a libration 1e-3 wide round θ = π at κ = 0).
        let level = end.level + piece.tilt_rate * signed;
        (level - v_t, 4.0 * EPS * (level.abs() + v_t.abs()))
    } else {
        // ε − V(t) = excess − sin(t − e) D(t, e) + tilt, with D the divided difference of V
        // and the tilt m·(t − e)/L that makes the two ends' levels meet (see `Piece::tilt_rate`).
        // (At a placed end the excess is its offset ε − V(e), and no tilt.)
        let (d, scale) = divided_difference(v, a, e, sx, cx);
        let excess = end.excess + offset;
        (
            excess - sx * d + piece.tilt_rate * signed,
            end.excess_error
                + 4.0 * EPS * (excess.abs() + sx.abs() * scale + (piece.tilt_rate * signed).abs()),
        )
    };
    let abs_err = abs_err + near * gap.abs() + residual;
    let (gap, abs_err) = match end.sharp {
        Some(sharp) if near == 0.0 && abs_err > sharp.threshold * gap => {
            // (Within 1e-30 of V of the end the double's divided difference is the sharper.)
            sharp_gap(
                v,
                &sharp,
                end.excess_error + residual,
                piece.tilt_rate * signed,
                sx,
                cx,
            )
            .filter(|&(_, sharp_err)| sharp_err < abs_err)
            .unwrap_or((gap, abs_err))
        }
        _ => (gap, abs_err),
    };
    if gap <= 0.0 || !gap.is_finite() {
        return Err(AtlasError::NotPeriodic {
            reason: "a quadrature node fell outside the allowed set (ε ≤ V there)",
        });
    }
    let dt = root_of_ratio(red.reduced_inertia, 1.0, 2.0 * gap) * node.jacobian;
    Ok(weighted(v, a, &red, dt, node.jacobian, abs_err / gap))
}

/// The gap ε − V at the node `sx` = sin(t − e), `cx` = cos(t − e) from the end `sharp`, in
/// double-double: its level plus `tilt` less V(t), with a bound on its error (the end's
/// `excess_error`, both values' double-double errors, the tilt's rounding, and two ulps of
/// the gap: its rounding to a double, and the node's angle, atan2(sx, cx), within 2u of
/// t − e relative to it, which moves a gap that grows like t − e by as much).
fn sharp_gap<S: Shape>(
    v: &EffectivePotential<'_, S>,
    sharp: &SharpEnd,
    excess_error: f64,
    tilt: f64,
    sx: f64,
    cx: f64,
) -> Option<(f64, f64)> {
    let (sin, cos) = sharp.rotated(sx, cx);
    let (value, error) = v.value_double_double_on_circle(sin, cos)?;
    let gap = sharp.level.add_f64(tilt).sub(value).to_f64();
    let bound = excess_error + sharp.error + error + EPS * (tilt.abs() + 2.0 * gap.abs());
    Some((gap, bound))
}

/// Bound on the relative rounding of an integrand of [`precise_sample`] beyond that of its gap,
/// counted twice as [`INTEGRAND_ROUNDING`] is: the node's own position (its offset from the end
/// rounded, and that offset's sine and cosine from libm: about 3u of the offset, which moves an
/// integrand ∝ 1/√gap by up to about 1.5 times as much), dθ/dτ's rounding (u), and the values'
/// rounding to doubles (u/2): 6u in all.
pub(super) const PRECISE_NODE_ROUNDING: f64 = 6.0 * EPS;

/// The integrands at a node of the cosine rule's plain map with U, B, J, the gap and the
/// integrands themselves in double-double ([`crate::body::Body::reduction_double_double`]),
/// from the nearer end's sharp pair; their rounding bound is the gap's error and
/// [`PRECISE_NODE_ROUNDING`] (issue 23: in double each integrand carries up to
/// [`INTEGRAND_ROUNDING`], which summed over ∫ |ψ̇| dt in the drift's phases kept the drift
/// from tolerances below about 3e-14 on the standard slice). The node in double ([`sample`]
/// of `piece`) is taken where this one is not to be had (a shape with no double-double form,
/// an end with no sharp pair, a node within a placed end's shift, an overflow), or where the
/// two differ by more than the double one's bound (of `plain`, the piece with its gaps in
/// double: that would be a fault here). `known` is that node in double where it was taken
/// already (the level's nodes before they are taken again): it is not computed twice.
fn precise_sample<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    plain: &Piece,
    energy: f64,
    node: IntervalNode,
    known: Option<NodeSample>,
) -> Result<NodeSample> {
    if let Some(precise) = precise_node(v, piece, node) {
        // (Checked against the node in double with its gap in double: the cheaper one.)
        let double = match known {
            Some(double) => double,
            None => sample(v, plain, energy, node)?,
        };
        let within = |a: f64, b: f64| (a - b).abs() <= 0.5 * double.rounding * b.abs();
        if within(precise.dt, double.dt) && within(precise.dpsi, double.dpsi) {
            return Ok(precise);
        }
    }
    sample(v, piece, energy, node)
}

/// [`precise_sample`]'s node, where it is to be had: with the fused multiply-add in the
/// double-double products where the processor has it (without the target feature each
/// `mul_add` was a call to a library function, which took most of a node's time).
fn precise_node<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    node: IntervalNode,
) -> Option<NodeSample> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor has the fused multiply-add (just checked).
        return unsafe { precise_node_with_fma(v, piece, node) };
    }
    precise_node_in(v, piece, node)
}

/// [`precise_node_in`] compiled with the fused multiply-add.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
fn precise_node_with_fma<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    node: IntervalNode,
) -> Option<NodeSample> {
    precise_node_in(v, piece, node)
}

/// [`precise_node`]'s work (inlined into each caller, so that the double-double operations
/// take the caller's target features).
#[inline(always)]
fn precise_node_in<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    node: IntervalNode,
) -> Option<NodeSample> {
    let (end, signed) = piece.nearer_end(node);
    let sharp = end.sharp.as_ref()?;
    let (signed, residual) = match end.placed {
        Some(placed) if signed.abs() > placed.shift.abs() => {
            (signed + placed.shift, placed.residual)
        }
        Some(_) => return None,
        None => (signed, 0.0),
    };
    let (sx, cx) = libm::sincos(signed);
    let (sin, cos) = sharp.rotated(sx, cx);
    let red = v.body.reduction_double_double(sin, cos)?;
    // V = κ²/(2 sin²θ) + U, with w = κ / sinθ.
    let inv_sin = DoubleDouble::from_f64(1.0).div(sin);
    let w = inv_sin.mul_f64(v.kappa);
    let (value, value_error) = with_wall(red.potential, red.potential_error, w);
    let tilt = piece.tilt_rate * signed;
    let gap = sharp.level.add_f64(tilt).sub(value);
    let gap_error = end.excess_error + residual + sharp.error + value_error + EPS * tilt.abs();
    if !(gap.hi > 0.0 && gap.hi.is_finite()) {
        return None;
    }
    // dt/dτ / J = √(B / (2 gap J²)) dθ/dτ (η B over η J²: one quotient), J = √(η J² / η);
    // ψ̇ dt/dτ = −(κ / sinθ)(cosθ / sinθ) dt/dτ / J.
    let dt_over_j = red
        .scaled_inertia
        .div(gap.mul(red.scaled_integral_factor_sq).mul_f64(2.0))
        .sqrt()
        .mul_f64(node.jacobian);
    let integral_factor = red.scaled_integral_factor_sq.mul(v.inverse_eta).sqrt();
    let dt = dt_over_j.mul(integral_factor);
    let w3_dt = w.mul(dt_over_j);
    let dpsi = w3_dt.mul(cos).mul(inv_sin).neg();
    let potential = red.potential.to_f64();
    let sample = NodeSample {
        dt: dt.to_f64(),
        dpsi: dpsi.to_f64(),
        along: potential * w3_dt.to_f64(),
        across: potential * node.jacobian,
        rounding: gap_error / gap.hi + PRECISE_NODE_ROUNDING,
    };
    (sample.dt.is_finite() && sample.dpsi.is_finite() && sample.along.is_finite()).then_some(sample)
}

/// V = κ²/(2 sin²θ) + U in double-double from U (with the bound `error` on it) and
/// w = κ / sin θ, with the bound on V's error.
#[inline(always)]
fn with_wall(u: DoubleDouble, error: f64, w: DoubleDouble) -> (DoubleDouble, f64) {
    let wall = w.mul(w).mul_f64(0.5);
    (wall.add(u), error + crate::dd::RELATIVE_ERROR * wall.hi)
}

/// The (sine, cosine) pair of `a` in double-double, scaled onto the unit circle.
fn on_circle(a: Angle) -> (DoubleDouble, DoubleDouble) {
    DoubleDouble::onto_circle(DoubleDouble::from_f64(a.sin), DoubleDouble::from_f64(a.cos))
}

/// √(a·b/c) for a, b, c > 0, also where the quotient overflows (B = 1/η + |r|² up to
/// 1.8e308 at the smallest η, over a gap below 1: the root is still a double).
#[inline]
pub(super) fn root_of_ratio(a: f64, b: f64, c: f64) -> f64 {
    let ratio = a * b / c;
    if ratio.is_finite() {
        ratio.sqrt()
    } else {
        a.sqrt() * (b.sqrt() / c.sqrt())
    }
}

/// Relative rounding of an integrand beyond that of the gap (B, J, sin θ, the square root
/// and the products: a few ulps each), counted twice as [`NodeSample::rounding`] is halved
/// where it is used; summed over the nodes it is the rounding floor of T and Δψ, a few eps
/// times the L1 size of their sums. The sums themselves are compensated ([`CompensatedSum`]):
/// they add an ulp of the sum and γ²ₙ of its L1 size (below 1e-25 for n ≤ 4096), where plain
/// summation over n nodes could add up to n ulps of the L1 size.
pub(super) const INTEGRAND_ROUNDING: f64 = 32.0 * EPS;

/// The integrands at an angle from dt/dτ = `dt` and dθ/dτ = `jacobian`: ψ̇ dt/dτ with
/// ψ̇ = −κ cosθ / (J sin²θ), U a dt/dτ with a = κ/(J sinθ), and U dθ/dτ.
#[inline]
fn weighted<S: Shape>(
    v: &EffectivePotential<'_, S>,
    a: Angle,
    red: &Reduction,
    dt: f64,
    jacobian: f64,
    rounding: f64,
) -> NodeSample {
    let (dpsi, along) = if v.kappa == 0.0 {
        (0.0, 0.0)
    } else {
        // ω3 dt / sin θ = κ dt / (J sin θ), with one division, κ times 1/(J sin θ) first:
        // κ dt may underflow where both are 1e-170 (a turning point that close to a pole).
        let inv_j_sin = 1.0 / (red.integral_factor * a.sin);
        let w3_dt = (v.kappa * inv_j_sin) * dt;
        let cot = a.cos * (inv_j_sin * red.integral_factor);
        (-w3_dt * cot, red.potential * w3_dt)
    };
    NodeSample {
        dt,
        dpsi,
        along,
        across: red.potential * jacobian,
        rounding: rounding + INTEGRAND_ROUNDING,
    }
}

/// The divided difference D(t, e) = (V(t) − V(e)) / sin(t − e) without cancellation, from
/// sin(t − e) = `sin_diff` and cos(t − e) = `cos_diff`: the κ² part is
/// −κ² sin(t + e) / (2 sin²e sin²t), the U part the shape's. Returns D and its rounding scale.
#[inline]
fn divided_difference<S: Shape>(
    v: &EffectivePotential<'_, S>,
    t: Angle,
    e: Angle,
    sin_diff: f64,
    cos_diff: f64,
) -> (f64, f64) {
    let (du, du_scale) = v
        .body
        .shape
        .potential_divided_difference(t, e, sin_diff, cos_diff);
    let dk = if v.kappa == 0.0 {
        0.0
    } else {
        let sin_sum = t.sin * e.cos + t.cos * e.sin;
        let sines = e.sin * t.sin;
        if sines > 1e-100 && v.kappa.abs() > 1e-100 {
            -v.kappa * v.kappa * sin_sum / (2.0 * sines * sines)
        } else {
            // κ² and the sines' product with their binary exponents apart, so that neither
            // under- nor overflows where the whole is a double: near a pole at the tiniest κ,
            // and at κ = 1e-200 by a turning point at 1e-50 (a sphere of radius 1e-300 given
            // as a profile), where (κ/sin e)(κ/sin t) = 1e-350 rounded to 0 and the turning
            // point came out at 2.7e-58.
            let (mk, ek) = libm::frexp(v.kappa);
            let (me, ee) = libm::frexp(e.sin);
            let (mt, et) = libm::frexp(t.sin);
            let q = mk / (me * mt);
            -0.5 * libm::scalbn(q * q * sin_sum, 2 * (ek - ee - et))
        }
    };
    (dk + du, dk.abs() + du_scale)
}

/// A root of f on [lo, hi] (f changes sign there), by Newton steps that stay in the bracket,
/// bisection otherwise, from `start` if it lies inside the bracket (else the midpoint); `f`
/// returns (value, derivative); `lo_negative` is the sign of f at `lo`.
fn safe_newton(
    f: impl Fn(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    lo_negative: bool,
    start: Option<f64>,
) -> f64 {
    let mut x = start
        .filter(|x| *x > lo.min(hi) && *x < lo.max(hi))
        .unwrap_or(0.5 * (lo + hi));
    let mut step_before = hi - lo;
    // Bisection alone needs up to ~1100 halvings from a pole to a turning point at 1e-300.
    for _ in 0..2200 {
        let (fx, dfx) = f(x);
        if fx == 0.0 {
            return x;
        }
        if (fx < 0.0) == lo_negative {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        // A slope that overflowed (V′ ∝ κ²/sin³θ beyond 1e308, at θ below 1e-103 for
        // κ ~ 1) gives no Newton step, only bisection: its zero step used to be taken for
        // convergence (θ_min stuck at 8.3e-104 for every ε above 1e207 at κ = 0.8).
        let usable = dfx != 0.0 && dfx.is_finite();
        // A Newton correction at the rounding level: x is the root to the last bit (without
        // this check the step would fall on a bracket end and restart bisection).
        if usable && (newton - x).abs() <= 2.0 * EPS * x.abs() {
            return newton;
        }
        let next = if usable && newton > lo && newton < hi && (newton - x).abs() < 0.5 * step_before
        {
            newton
        } else {
            0.5 * (lo + hi)
        };
        step_before = (next - x).abs();
        if next <= lo.min(hi) || next >= hi.max(lo) || next == x {
            return x;
        }
        if step_before <= 2.0 * EPS * x.abs() {
            return next;
        }
        x = next;
    }
    x
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
