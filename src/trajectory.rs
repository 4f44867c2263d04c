//! Trajectories over time (paper Figs. `res`, `xy`): θ, p, φ, ψ, the centre of mass and the
//! contact point, from the reduced system (`eqsys` with the quadratures `dfi`, `dpsi` and the
//! velocity of the centre of mass) or from the full system (`eqred`, `kin`).

use crate::body::{Body, Shape};
use crate::error::{AtlasError, Result, MAX_ENERGY};
use crate::full::{FullState, FullSystem, FULL_STATE_LEN};
use crate::ode::{integrate_sampled, Rate};
use crate::reduced::ReducedSystem;
use crate::torus::{Component, CriticalKind, CriticalPoint, EffectivePotential, MotionKind, Site};
use nalgebra::SVector;

/// Which equations are integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Model {
    /// The reduced system with its quadratures (6 equations).
    Reduced,
    /// The full redundant system of paper `eqred` with the kinematics (14 equations).
    Full,
}

/// Bytes of memory a trajectory takes per sample, at the peak, with a margin: measured 160 for
/// the reduced model and 210 for the full one (peak RSS over 3e6 samples, either file type).
/// The command line and the package refuse a request beyond the machine by this figure.
pub const MEMORY_PER_SAMPLE: f64 = 250.0;

/// How far outside its component a start may lie and still be held by it: the turning
/// points of a start at rest are found from ε = V(θ0) to within the rounding of V over
/// |V′|, far below this unless that level is lost in rounding.
pub const HOLD: f64 = 1e-6;

/// Where a trajectory starts: θ(0), θ̇(0), at φ = ψ = 0 and the centre of mass at the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    pub kappa: f64,
    pub theta0: f64,
    pub theta_dot0: f64,
}

impl Start {
    /// The start at the lower turning point θ_min of component `index` of the level set
    /// (κ, ε), with θ̇ = 0 (the start of docs/model.md's drift).
    pub fn at_energy<S: Shape>(
        body: &Body<S>,
        kappa: f64,
        energy: f64,
        index: usize,
    ) -> Result<Self> {
        let comps = EffectivePotential::new(body, kappa).components(energy)?;
        let count = comps.len();
        let c = comps.get(index).ok_or(AtlasError::InvalidParameter {
            name: "component",
            value: index as f64,
            reason: if count == 1 {
                "this level set has only component 0"
            } else {
                "this level set has fewer components"
            },
        })?;
        // A libration starts at its lower turning point at rest. A rotation (κ = 0, rolling
        // over the top) has no turning point: it starts at the top of U, where it is cut,
        // moving forwards with ½ B θ̇² = ε − U.
        let theta_dot0 = if c.kind == MotionKind::Rotation {
            let potential = EffectivePotential::new(body, kappa);
            let gap = energy - potential.value(crate::Angle::new(c.theta_min()));
            (2.0 * gap.max(0.0) / body.reduced_inertia(c.theta_min())).sqrt()
        } else {
            0.0
        };
        Ok(Self {
            kappa,
            theta0: c.theta_min(),
            theta_dot0,
        })
    }

    /// Checks that κ, θ(0) and θ̇(0) are finite, with 0 < θ(0) < π when κ ≠ 0.
    pub fn check(&self) -> Result<()> {
        crate::error::check_kappa(self.kappa)?;
        let t = self.theta0;
        if !(t.is_finite() && (self.kappa == 0.0 || (t > 0.0 && t < std::f64::consts::PI))) {
            return Err(AtlasError::InvalidInitialAngle {
                theta0: t,
                reason: "must be finite, and 0 < theta0 < pi when kappa != 0",
            });
        }
        if !self.theta_dot0.is_finite() {
            return Err(AtlasError::InvalidParameter {
                name: "theta-dot0",
                value: self.theta_dot0,
                reason: "must be a finite number",
            });
        }
        Ok(())
    }

    /// The energy of this start.
    pub fn energy<S: Shape>(&self, body: &Body<S>) -> f64 {
        ReducedSystem::new(body, self.kappa).energy(self.theta0, self.theta_dot0)
    }

    /// The energy of this start among V's levels as `potential` holds them: where it lies
    /// below V's lowest critical level by no more than V's rounding (8 eps of its scale at
    /// θ(0) or there), the start is at rest on that level's minimum (or neutral
    /// equilibrium), and its level is that one. V(θ(0)) and the minimum are two roundings of
    /// one level there: on a sphere centred on its centre of mass (U ≡ 1, every θ a minimum
    /// of V at κ = 0) the start at rest at θ(0) = π/2, κ = 1e-3 had ε = 1.0000004999999998
    /// under the minimum 1.0000005, and `cell --theta0` refused it as "no motion".
    pub fn level<S: Shape>(&self, potential: &EffectivePotential<'_, S>) -> f64 {
        let energy = self.energy(potential.body);
        // (The lowest critical level: where U′ ≡ 0 on an arc, its points are neutral
        // equilibria, not minima.)
        let bottom = potential
            .critical_points()
            .iter()
            .map(|p| p.value)
            .fold(f64::INFINITY, f64::min);
        if !bottom.is_finite() {
            return energy;
        }
        let scale = potential
            .value_scale(Site::at(self.circle_angle()).angle())
            .max(bottom.abs());
        if energy < bottom && bottom - energy <= 8.0 * f64::EPSILON * scale {
            bottom
        } else {
            energy
        }
    }

    /// The energy of this start, refused (naming θ(0), θ̇(0) or κ) where it lies beyond 1e300
    /// in size or overflows, as every surface refuses an energy given directly.
    pub fn checked_energy<S: Shape>(&self, body: &Body<S>) -> Result<f64> {
        let energy = self.energy(body);
        if energy.abs() <= MAX_ENERGY {
            return Ok(energy);
        }
        let potential = ReducedSystem::new(body, self.kappa).effective_potential(self.theta0);
        let potential_fits = potential.abs() <= MAX_ENERGY;
        if !potential_fits && 0.5 * self.kappa * self.kappa <= MAX_ENERGY {
            // The wall κ²/(2 sin²θ0) alone is beyond: θ0 is that near a pole.
            return Err(AtlasError::InvalidInitialAngle {
                theta0: self.theta0,
                reason: "so near a pole that the energy kappa^2/(2 sin^2 theta0) exceeds 1e300",
            });
        }
        let (name, value) = if self.theta_dot0 != 0.0 && potential_fits {
            ("theta-dot0", self.theta_dot0)
        } else {
            ("kappa", self.kappa)
        };
        Err(AtlasError::InvalidParameter {
            name,
            value,
            reason:
                "gives an energy B theta_dot^2/2 + V above 1e300 in size (the largest a cell takes)",
        })
    }

    /// The component of the level set that holds θ(0).
    pub fn component<S: Shape>(&self, body: &Body<S>) -> Result<Component> {
        self.component_in(&EffectivePotential::new(body, self.kappa))
    }

    /// The component that holds θ(0), among those of `potential` at this start's energy (the
    /// nearest one, against rounding at its ends).
    pub fn component_in<S: Shape>(
        &self,
        potential: &EffectivePotential<'_, S>,
    ) -> Result<Component> {
        let comps = potential.components(self.level(potential))?;
        let nearest = comps
            .into_iter()
            .min_by(|a, b| self.distance_to(a).total_cmp(&self.distance_to(b)));
        nearest.ok_or(AtlasError::NotPeriodic {
            reason: "no component holds theta0",
        })
    }

    /// How far θ(0) lies outside `component`. At κ = 0, θ is an angle on the circle: θ(0)
    /// and θ(0) − 2πk are one start (6.5 lies in the torus [−0.22, 0.22], not in the nearer
    /// [2.46, 3.83] of the lifted line). The components of the lifted circle lie within
    /// [−2π, 3π].
    fn distance_to(&self, component: &Component) -> f64 {
        let theta0 = self.circle_angle();
        if self.kappa != 0.0 {
            return component.distance_to(theta0);
        }
        [-1.0, 0.0, 1.0]
            .iter()
            .map(|k| component.distance_to(theta0 + k * std::f64::consts::TAU))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether `component` (from [`Self::component_in`]) is this start's motion as far as
    /// doubles can tell. It must hold θ(0), up to [`HOLD`]. And a start at rest with κ ≠ 0,
    /// off a minimum, is a turning point, found again from ε = V(θ0) only to within
    /// min(δε/|V′|, √(2δε/|V″|)), δε the rounding of V (4 eps of its scale): that must be
    /// within [`HOLD`] too. On a ball's sphere, where U′ ≡ 0 and only the κ term moves the
    /// body, κ² below an ulp of U leaves V flat in doubles: the level set of ε = V(θ0) is
    /// then not the start's (it was [κ, π/2], a `separatrix`, at κ = 1e-8).
    pub fn is_resolved_by<S: Shape>(
        &self,
        potential: &EffectivePotential<'_, S>,
        component: &Component,
    ) -> bool {
        if self.distance_to(component) > HOLD {
            return false;
        }
        if self.kappa == 0.0 || self.theta_dot0 != 0.0 || component.kind == MotionKind::FixedPoint {
            return true;
        }
        let a = Site::at(self.circle_angle()).angle();
        let rounding = 4.0 * f64::EPSILON * potential.value_scale(a);
        let by_slope = rounding / potential.slope(a).abs();
        let by_curvature = (2.0 * rounding / potential.curvature_at(a).abs()).sqrt();
        by_slope.min(by_curvature) <= HOLD
    }

    /// The unstable equilibrium this start rests on, if it does: θ̇(0) = 0 at κ = 0 on the
    /// level of a maximum (or inflection) of V within 1e-7 of θ(0) on the circle, or where
    /// V′(θ(0)) vanishes exactly off a minimum (a neutral equilibrium on an arc where U′ ≡ 0:
    /// a cut ball with α = 0 resting on its sphere). The body then stays there, even where the
    /// level's other motions land on a face (the upright disk at rest): it is the separatrix's
    /// equilibrium, not a motion onto the face.
    pub fn rest_on_saddle<S: Shape>(
        &self,
        potential: &EffectivePotential<'_, S>,
        component: &Component,
        energy: f64,
    ) -> Option<CriticalPoint> {
        if self.kappa != 0.0 || self.theta_dot0 != 0.0 {
            return None;
        }
        let theta = self.circle_angle();
        let saddle = component
            .saddles()
            .find(|p| energy == p.value && circle_distance(theta, p.site.theta) <= 1e-7)
            .copied();
        saddle.or_else(|| {
            let site = Site::at(theta);
            let flat = component.kind != MotionKind::FixedPoint
                && potential.slope(site.angle()) == 0.0
                && potential.curvature_at(site.angle()) == 0.0;
            flat.then(|| CriticalPoint {
                site,
                value: energy,
                scale: potential.value_scale(site.angle()),
                curvature: 0.0,
                kind: CriticalKind::Inflection,
            })
        })
    }

    /// θ(0), at κ = 0 (θ an angle on the circle) taken within π of 0 when it lies beyond:
    /// atan2 of its sine and cosine is that angle to the last bit (their argument reduction
    /// is exact; θ(0) − 2πk in doubles is not, and at θ(0) = 1e10 kept no digit).
    fn circle_angle(&self) -> f64 {
        if self.kappa == 0.0 && self.theta0.abs() > std::f64::consts::PI {
            let (s, c) = self.theta0.sin_cos();
            s.atan2(c)
        } else {
            self.theta0
        }
    }

    /// The θ-period of the component that holds θ(0), from the quadrature of [`crate::torus`].
    pub fn period<S: Shape>(&self, body: &Body<S>, tol: f64) -> Result<f64> {
        let potential = EffectivePotential::new(body, self.kappa);
        let comp = self.component_in(&potential)?;
        if !self.is_resolved_by(&potential, &comp) {
            return Err(AtlasError::NotPeriodic {
                reason: "the level of the start is not resolved in double precision at \
                         theta0 (kappa's term lost in rounding); give --t-end",
            });
        }
        if comp.kind == MotionKind::FixedPoint {
            return Err(AtlasError::NotPeriodic {
                reason: "the start is a fixed point (a permanent rotation); give --t-end",
            });
        }
        let energy = self.energy(body);
        if crate::cell::separatrix(&comp, energy).is_some() {
            return Err(AtlasError::NotPeriodic {
                reason: "the start is on a separatrix (an unstable equilibrium or an orbit \
                         asymptotic to one): its period is infinite; give --t-end",
            });
        }
        // (A node where ε − V rounds to ≤ 0 inside the turning points: κ and ε so large that
        // their difference has no digit left there. A failed computation, not a bad input:
        // at β = 1e150, ε = 1e300 it exited 2.)
        match potential.integrate(energy, &comp, tol, false) {
            Ok(integrals) => Ok(integrals.period),
            Err(AtlasError::NotPeriodic { .. }) => Err(AtlasError::Unresolved {
                what: "the theta-period",
                reason: "epsilon - V has no digit left in double precision inside the turning \
                         points (kappa and the energy too large); give --t-end",
            }),
            Err(e) => Err(e),
        }
    }
}

/// How long a trajectory runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Duration {
    /// This many θ-periods of the start's component.
    Periods(f64),
    /// Up to this time.
    Until(f64),
}

/// Where a trajectory starts, as a user gives it: at an energy (the lower turning point of
/// a component, at rest), or at θ(0), θ̇(0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StartAt {
    Energy { energy: f64, component: usize },
    Angle { theta0: f64, theta_dot0: f64 },
}

/// A whole trajectory request, checked as one (the `trajectory` command and the Python
/// package's `trajectory`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    pub kappa: f64,
    pub start: StartAt,
    pub duration: Duration,
    /// Samples after t = 0 (≥ 1): `samples + 1` equally spaced times.
    pub samples: usize,
    pub model: Model,
    /// The integrator's tolerance, 1e-15 <= tol <= 0.1.
    pub tol: f64,
    /// Refuse a request whose integration needs more integrator steps than this (estimated
    /// from its first θ-period): [`STEP_BUDGET`] unless the caller insists (None).
    pub step_budget: Option<f64>,
}

/// The integrator steps a trajectory may take unless the caller insists: some 40 minutes of
/// one core (2.6 µs a step measured on the reduced model at tol 1e-12).
pub const STEP_BUDGET: f64 = 1e9;

impl Request {
    /// The checked start of this request on `body`.
    pub fn start<S: Shape>(&self, body: &Body<S>) -> Result<Start> {
        crate::error::check_kappa(self.kappa)?;
        let start = match self.start {
            StartAt::Energy { energy, component } => {
                crate::error::check_energy(energy)?;
                Start::at_energy(body, self.kappa, energy, component)?
            }
            StartAt::Angle { theta0, theta_dot0 } => {
                let start = Start {
                    kappa: self.kappa,
                    theta0,
                    theta_dot0,
                };
                start.check()?;
                // (An energy beyond 1e300 is refused naming the start; NaN, from B = ∞
                // times θ̇ = 0, is the overflow below.)
                if !start.energy(body).is_nan() {
                    start.checked_energy(body)?;
                }
                start
            }
        };
        // B = 1/η + U² + U′² beyond a double at the start (β = 1e150 with a turning point at
        // 6e-151, where U′ ≈ β²θ): its energy, ½ B θ̇² + V, was NaN, and the refusal named
        // "energy = NaN" (an adversary pass). Valid input that doubles cannot integrate: a
        // failed computation, whichever way the start was given.
        if !body.reduced_inertia(start.theta0).is_finite() {
            return Err(AtlasError::Integration {
                time: 0.0,
                reason: format!(
                    "B = 1/eta + U^2 + U'^2 overflows at the start (theta = {:e}): this motion \
                     cannot be followed in double precision",
                    start.theta0
                ),
            });
        }
        Ok(start)
    }

    /// Checks the request and integrates it on `body`: the start and the samples.
    pub fn run<S: Shape>(&self, body: &Body<S>) -> Result<(Start, Trajectory)> {
        self.run_until(body, &|| false)
    }

    /// [`Request::run`], giving up with [`AtlasError::Stopped`] when `stop` says so (it is
    /// asked at least every 100,000 integrator steps).
    pub fn run_until<S: Shape>(
        &self,
        body: &Body<S>,
        stop: &dyn Fn() -> bool,
    ) -> Result<(Start, Trajectory)> {
        let tol = self.tol;
        // As the cell solver's: below 1e-15 DOP853 asks for steps under the rounding of t.
        if !(1e-15..=0.1).contains(&tol) {
            return Err(AtlasError::InvalidParameter {
                name: "tol",
                value: tol,
                reason: "must satisfy 1e-15 <= tol <= 0.1",
            });
        }
        crate::error::check_samples(self.samples)?;
        let start = self.start(body)?;
        // A planar motion onto a face ends there (docs/bodies.md): no trajectory to follow.
        // A body at rest on an unstable equilibrium of such a level stays there, until
        // rounding moves it off (checked below).
        let mut at_rest_by_a_face = false;
        if start.kappa == 0.0 && body.shape.faces() != [false, false] {
            let potential = crate::torus::EffectivePotential::new(body, 0.0);
            let component = start.component_in(&potential)?;
            if crate::cell::reaches_face(&potential, &component) {
                if start
                    .rest_on_saddle(&potential, &component, start.energy(body))
                    .is_none()
                {
                    return Err(AtlasError::Unsupported {
                        what: "trajectory",
                        reason: "kappa = 0 and this motion reaches a flat face of the body, \
                                 where it ends (the body lands on the face); start away from \
                                 it or with kappa != 0",
                    });
                }
                at_rest_by_a_face = true;
            }
        }
        // (A subnormal length is refused as a subnormal κ is: below 2.2e-308 the integrator's
        // first step is below the rounding of t, and the run failed blaming the motion.)
        let positive = |name, value| {
            crate::error::check_range(
                name,
                value,
                Some((f64::MIN_POSITIVE, true)),
                None,
                "must be a finite number >= 2.2250738585072014e-308 (the least normal double)",
            )
        };
        let (t_end, period) = match self.duration {
            Duration::Periods(k) => {
                let k = positive("periods", k)?;
                let period = start.period(body, 1e-13)?;
                if k * period < f64::MIN_POSITIVE {
                    return Err(AtlasError::InvalidParameter {
                        name: "periods",
                        value: k,
                        reason: "gives a length below 2.2250738585072014e-308 (the least \
                                 normal double)",
                    });
                }
                (k * period, Some(period))
            }
            Duration::Until(t) => (positive("t-end", t)?, None),
        };
        if let Some(budget) = self.step_budget {
            // (A start with no period is piloted over t_end/1000.)
            let period =
                period.unwrap_or_else(|| start.period(body, 1e-13).unwrap_or(f64::INFINITY));
            self.check_work(body, &start, t_end, period, budget, stop)?;
        }
        let traj = integrate(body, &start, self.model, t_end, self.samples, tol, stop)?;
        if at_rest_by_a_face {
            check_still_at_rest(&start, &traj)?;
        }
        Ok((start, traj))
    }

    /// Refuses, in one line with the estimate, an integration to `t_end` that needs more
    /// than `budget` steps: the steps of a pilot run over the first θ-`period` (or over
    /// t_end/1000 where it is shorter, or the start has none: ∞) scaled to `t_end`.
    fn check_work<S: Shape>(
        &self,
        body: &Body<S>,
        start: &Start,
        t_end: f64,
        period: f64,
        budget: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<()> {
        let span = period.min(1e-3 * t_end);
        if !(span > 0.0 && span < t_end) {
            return Ok(());
        }
        let pilot = integrate(body, start, self.model, span, 1, self.tol, stop)?;
        let steps = pilot.steps as f64 * (t_end / span);
        if steps > budget {
            let asked = match self.duration {
                Duration::Periods(k) => format!("periods = {}", crate::error::show(k)),
                Duration::Until(t) => format!("t-end = {}", crate::error::show(t)),
            };
            return Err(AtlasError::TooLarge {
                reason: format!(
                    "{asked} needs about {:.1e} integrator steps at tol {}, more than the {:.0e} \
                     allowed (some 40 minutes): ask for less, or insist with --allow-large",
                    steps,
                    crate::error::show(self.tol),
                    budget
                ),
            });
        }
        Ok(())
    }
}

/// How far apart two angles lie on the circle, in [0, π].
fn circle_distance(a: f64, b: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let d = (a - b).rem_euclid(tau);
    d.min(tau - d)
}

/// A start at rest on an unstable equilibrium whose level reaches a face stays at rest; the
/// integrator's rounding grows like e^(λt) and, once θ is 1e-3 off, the body follows the
/// separatrix onto the face within a few 1/λ, where the motion ends: refused from there.
/// (θ on the circle, and up to its sign: the full model's θ is the axis's angle in [0, π].)
fn check_still_at_rest(start: &Start, traj: &Trajectory) -> Result<()> {
    let Some(i) = traj.theta.iter().position(|&t| {
        let off = circle_distance(t, start.theta0).min(circle_distance(t, -start.theta0));
        off.is_nan() || off > 1e-3
    }) else {
        return Ok(());
    };
    Err(AtlasError::Integration {
        time: traj.t[i],
        reason: format!(
            "the start is an unstable equilibrium (the body stays at rest there), but \
             rounding moved it off by t = {} and it then lands on a flat face, where the \
             motion ends: ask for a t-end below that",
            crate::error::show(traj.t[i])
        ),
    })
}

/// Samples of a trajectory, one entry per time.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    pub phi: Vec<f64>,
    pub psi: Vec<f64>,
    pub x_c: Vec<f64>,
    pub y_c: Vec<f64>,
    pub z_c: Vec<f64>,
    pub x_p: Vec<f64>,
    pub y_p: Vec<f64>,
    /// The largest |ε(t) − ε(0)| / (1 + |ε(0)|) over the samples: how well the integrator
    /// kept the energy (refused beyond max(1e3·tol, 1e-6)).
    pub energy_drift: f64,
    /// The integrator's accepted steps.
    pub steps: usize,
}

impl Trajectory {
    /// Column names and columns, in output order.
    pub fn columns(&self) -> Vec<(&'static str, &[f64])> {
        vec![
            ("t", &self.t),
            ("theta", &self.theta),
            ("theta_dot", &self.theta_dot),
            ("phi", &self.phi),
            ("psi", &self.psi),
            ("x_c", &self.x_c),
            ("y_c", &self.y_c),
            ("z_c", &self.z_c),
            ("x_p", &self.x_p),
            ("y_p", &self.y_p),
        ]
    }
}

/// Reduced state [θ, p, φ, ψ, x_c, y_c].
type ReducedState = SVector<f64, 6>;

impl<S: Shape> Rate<6> for ReducedSystem<'_, S> {
    fn rate(&self, y: &ReducedState) -> ReducedState {
        let (theta, p, psi) = (y[0], y[1], y[3]);
        let (vx, vy) = self.centre_velocity(theta, p, psi);
        ReducedState::from([
            p,
            self.theta_acceleration(theta, p),
            self.phi_rate(theta),
            self.psi_rate(theta),
            vx,
            vy,
        ])
    }
}

impl<S: Shape> Rate<FULL_STATE_LEN> for FullSystem<'_, S> {
    fn rate(&self, y: &FullState) -> FullState {
        FullSystem::rate(self, y)
    }
}

/// The largest drift of the energy along a trajectory, relative to 1 + |ε(0)|, that is not
/// taken for a lost trajectory: a thousand times the tolerance, and never below 1e-6.
fn energy_drift_allowed(tol: f64) -> f64 {
    (1e3 * tol).max(1e-6)
}

/// Integrates from `start` to `t_end` with DOP853 at tolerance `tol`, sampling `samples + 1`
/// equally spaced times. The energy ε (`eqsys`; in the full model the first integral
/// T − ⟨r, γ⟩) is checked at every sample: a drift beyond [`energy_drift_allowed`] means the
/// steps no longer resolve the motion (ε = 1e300 ended a period at θ = 0.9, not at
/// θ_min = 8e-104), and the trajectory is refused rather than returned wrong.
pub fn integrate<S: Shape>(
    body: &Body<S>,
    start: &Start,
    model: Model,
    t_end: f64,
    samples: usize,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> Result<Trajectory> {
    let mut out = Trajectory::default();
    let mut energies = Vec::with_capacity(samples + 1);
    match model {
        Model::Reduced => {
            let sys = ReducedSystem::new(body, start.kappa);
            // Integrated from θ(0) on the circle ([`Start::circle_angle`]), shifted back.
            let theta0 = start.circle_angle();
            let shift = start.theta0 - theta0;
            let y0 = ReducedState::from([theta0, start.theta_dot0, 0.0, 0.0, 0.0, 0.0]);
            let sol = integrate_sampled(&sys, y0, t_end, samples, tol, stop)?;
            out.steps = sol.steps;
            for (t, y) in sol.times.iter().zip(&sol.states) {
                energies.push(sys.energy(y[0], y[1]));
                let (dx, dy) = sys.contact_offset(y[0], y[3]);
                out.t.push(*t);
                out.theta.push(y[0] + shift);
                out.theta_dot.push(y[1]);
                out.phi.push(y[2]);
                out.psi.push(y[3]);
                out.x_c.push(y[4]);
                out.y_c.push(y[5]);
                out.z_c.push(body.shape.potential(y[0]));
                out.x_p.push(y[4] + dx);
                out.y_p.push(y[5] + dy);
            }
        }
        Model::Full => {
            let sys = FullSystem::new(body);
            let y0 = sys.state_from_reduced(
                start.kappa,
                start.theta0,
                start.theta_dot0,
                0.0,
                0.0,
                0.0,
                0.0,
            );
            let sol = integrate_sampled(&sys, y0, t_end, samples, tol, stop)?;
            out.steps = sol.steps;
            let mut prev: Option<(f64, f64)> = None;
            for (t, y) in sol.times.iter().zip(&sol.states) {
                energies.push(sys.integrals(y).energy);
                let (theta, phi, psi) = FullSystem::<S>::euler_angles(y);
                // Unwrap φ and ψ so that they are continuous in time like the reduced ones.
                let (phi, psi) = match prev {
                    Some((p0, s0)) => (unwrap_near(phi, p0), unwrap_near(psi, s0)),
                    None => (phi, psi),
                };
                prev = Some((phi, psi));
                // θ̇ from γ̇3 = −sinθ θ̇ is singular at the poles; use the body-frame formula
                // θ̇ = ω1 cosφ − ω2 sinφ, which follows from `w12`.
                let theta_dot = y[0] * phi.cos() - y[1] * phi.sin();
                let (xp, yp) = sys.contact_position(y);
                out.t.push(*t);
                out.theta.push(theta);
                out.theta_dot.push(theta_dot);
                out.phi.push(phi);
                out.psi.push(psi);
                out.x_c.push(y[12]);
                out.y_c.push(y[13]);
                out.z_c.push(sys.centre_height(y));
                out.x_p.push(xp);
                out.y_p.push(yp);
            }
        }
    }
    let scale = 1.0 + energies[0].abs();
    out.energy_drift = energies
        .iter()
        .map(|e| (e - energies[0]).abs() / scale)
        .fold(0.0, f64::max);
    let allowed = energy_drift_allowed(tol);
    if let Some(i) = energies.iter().position(|e| {
        let d = (e - energies[0]).abs();
        d.is_nan() || d > allowed * scale
    }) {
        return Err(AtlasError::Integration {
            time: out.t[i],
            reason: format!(
                "the energy drifted from {} to {} (more than {} of 1 + |energy|): the steps \
                 no longer resolve the motion",
                crate::error::show(energies[0]),
                crate::error::show(energies[i]),
                crate::error::show(allowed)
            ),
        });
    }
    Ok(out)
}

/// The representative of `angle` + 2πk nearest to `reference`.
fn unwrap_near(angle: f64, reference: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    angle + tau * ((reference - angle) / tau).round()
}
