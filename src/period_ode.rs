//! The independent method for one cell: integrate the reduced system (`eqsys` with `dpsi` and
//! the velocity of the centre of mass) with DOP853 from θ_min, p = 0, ψ = 0 over one θ-period,
//! located as the event "p crosses zero upwards" (for a rotation: θ advances by 2π) and refined
//! by Newton's method on the event function. It shares nothing with the quadrature but the
//! model's formulas, and serves as the reference for every test of [`crate::torus`].

use crate::body::Shape;
use crate::error::{AtlasError, Result};
use crate::ode::{run_dop853, Steps};
use crate::reduced::ReducedSystem;
use crate::torus::{
    Component, DriftEstimate, EffectivePotential, MotionKind, PeriodIntegrals, SaddleTerms,
};
use nalgebra::SVector;
use ode_solvers::System;
use std::cell::RefCell;
use std::f64::consts::{PI, TAU};

/// State [(θ − θ₀)/ℓ_θ, p/ℓ_p, ψ, x_c, y_c, ∫ U (|a| + |p|) dt] with p = θ̇ and
/// a = κ/(J sinθ), in the component's own units ([`Units`]).
type State = SVector<f64, 6>;

/// The origin and units of θ and p in the state, and the longest step. DOP853's tolerance
/// weighs each variable by tol (1 + |y|): in raw θ and p a libration of width 6e-4 about π/2
/// was held only to tol/6e-4 of its width, and both runs (tol, tol/100) shared that bias
/// (T 7× its estimate off at tol 1e-5; an adversary pass). A libration is therefore measured
/// from the end nearer its pole, in the smallest of its width and that end's distance from
/// the pole, and p in its largest value; a rotation keeps θ and p as they are.
///
/// A step may move θ by at most a few times the narrowest feature the orbit sees (a needle's
/// Z round π/2, an oblate body's at the poles, a dip of B or of J; the widths the quadrature
/// sets its steps by), the tighter runs by fewer ([`ladder`]): runs at every tolerance
/// stepped over a needle's π/2 (β = 2.2e-5) alike and agreed on a T 1.3e-3 off.
#[derive(Clone, Copy)]
struct Units {
    /// θ₀.
    origin: f64,
    /// ℓ_θ.
    angle: f64,
    /// ℓ_p.
    rate: f64,
    /// The time θ takes at most to cross the narrowest feature (∞: none).
    feature_time: f64,
    /// The longest step in time (set per run: [`ladder`]).
    max_step: f64,
}

impl Units {
    fn of<S: Shape>(
        potential: &EffectivePotential<'_, S>,
        energy: f64,
        component: &Component,
    ) -> Self {
        let (low, high) = (component.theta_min(), component.theta_max());
        let width = high - low;
        // The largest θ̇ on the orbit, p² = 2 (ε − V)/B, sampled across it.
        let system = ReducedSystem::new(potential.body, potential.kappa);
        let peak = (0..=64)
            .map(|i| {
                let theta = low + width * i as f64 / 64.0;
                2.0 * (energy - system.effective_potential(theta))
                    / potential.body.reduced_inertia(theta)
            })
            .filter(|x| x.is_finite())
            .fold(0.0_f64, f64::max)
            .sqrt();
        // The shape's own scale where the orbit comes within ten of it of where it lies (its
        // feature angles, a needle's π/2, or else the poles, an oblate body's; a rotation
        // passes them all): an oblate body's 3e-5 applied to a libration 3e-3 from its poles
        // took an ODE cell from 0.05 s to 8.6 s (an adversary pass).
        let shape = potential.body.shape.angular_feature_scale();
        let angles = potential.body.shape.feature_angles();
        let poles = [0.0, PI];
        let near = |theta: &f64| *theta > low - 10.0 * shape && *theta < high + 10.0 * shape;
        let seen = shape < 1.0
            && (component.kind == MotionKind::Rotation
                || if angles.is_empty() {
                    poles.iter().any(near)
                } else {
                    angles.iter().any(near)
                });
        let feature = potential
            .dips_seen(low, high)
            .map(|(_, w)| w)
            .fold(if seen { shape } else { f64::INFINITY }, f64::min);
        let feature_time = if peak > 0.0 {
            feature / peak
        } else {
            f64::INFINITY
        };
        let unit = |x: f64| if x.is_finite() && x > 0.0 { x } else { 1.0 };
        if component.kind == MotionKind::Rotation {
            return Self {
                origin: 0.0,
                angle: 1.0,
                rate: 1.0,
                feature_time,
                max_step: f64::INFINITY,
            };
        }
        let to_pi = component.upper.from_pi.max(0.0);
        let (origin, to_pole) = if to_pi < low {
            (high, to_pi)
        } else {
            (low, low)
        };
        let angle = width.min(to_pole.max(1e-8 * width));
        Self {
            origin,
            angle: unit(angle),
            rate: unit(peak),
            feature_time,
            max_step: f64::INFINITY,
        }
    }

    fn theta(&self, y: &State) -> f64 {
        self.origin + self.angle * y[0]
    }

    fn theta_dot(&self, y: &State) -> f64 {
        self.rate * y[1]
    }
}

#[derive(Clone, Copy)]
enum EventKind {
    /// g = p (a libration returns to θ_min when p crosses 0 upwards).
    Momentum,
    /// g = θ − target (a rotation has turned once).
    Angle(f64),
}

/// What the step observer saw: the previous accepted step with its event value, and the
/// steps just before and just after the first upward crossing of g.
#[derive(Default)]
struct EventRecord {
    previous: Option<(f64, State, f64)>,
    crossing: Option<((f64, State), (f64, State))>,
}

struct PeriodSystem<'a, 'r, S: Shape> {
    system: ReducedSystem<'a, S>,
    units: Units,
    event: EventKind,
    /// Where the observer writes (None: plain integration, no event watching).
    record: Option<&'r RefCell<EventRecord>>,
}

impl<S: Shape> PeriodSystem<'_, '_, S> {
    fn rate(&self, y: &State) -> State {
        let (theta, p, psi) = (self.units.theta(y), self.units.theta_dot(y), y[2]);
        let (vx, vy) = self.system.centre_velocity(theta, p, psi);
        let u = self.system.body.shape.potential(theta);
        let along = if self.system.kappa == 0.0 {
            0.0
        } else {
            self.system.kappa / (self.system.body.integral_factor(theta) * theta.sin())
        };
        State::from([
            p / self.units.angle,
            self.system.theta_acceleration(theta, p) / self.units.rate,
            self.system.psi_rate(theta),
            vx,
            vy,
            // |U|: a disk whose centre of mass is off its plane has U < 0 near a pole.
            u.abs() * (along.abs() + p.abs()),
        ])
    }

    /// g(y) and dg/dt, in the state's units.
    fn event(&self, y: &State) -> (f64, f64) {
        let (theta, p) = (self.units.theta(y), self.units.theta_dot(y));
        match self.event {
            EventKind::Momentum => (
                y[1],
                self.system.theta_acceleration(theta, p) / self.units.rate,
            ),
            EventKind::Angle(target) => ((theta - target) / self.units.angle, p / self.units.angle),
        }
    }
}

impl<S: Shape> System<f64, State> for PeriodSystem<'_, '_, S> {
    fn system(&self, _t: f64, y: &State, dy: &mut State) {
        *dy = self.rate(y);
    }

    fn solout(&mut self, t: f64, y: &State, _dy: &State) -> bool {
        let Some(record) = self.record else {
            return false;
        };
        let g = self.event(y).0;
        let mut r = record.borrow_mut();
        if let Some((t0, y0, g0)) = r.previous {
            // g0 < 0 strictly: the start itself (p = 0 at θ_min) is not an event.
            if g0 < 0.0 && g >= 0.0 {
                r.crossing = Some(((t0, y0), (t, *y)));
                return true;
            }
        }
        r.previous = Some((t, *y, g));
        false
    }
}

/// Accepted steps one run over a period may take: the hardest cells of the declared domain
/// take a few hundred thousand (small κ at tol 1e-13); beyond this the run gives up, and
/// the component is `tolerance_not_reached` (at κ = 0.8, ε = 1e20 … 1e50 the steps shrink
/// at the pole until the run would take hours, and Ctrl-C in Python waits for the cell).
const STEPS_PER_PERIOD: u32 = 1_000_000;

/// Integrates from (t0, y0) to at most t1 at tolerance `tol`; returns the last state and
/// the number of accepted steps.
fn run<S: Shape>(
    system: PeriodSystem<'_, '_, S>,
    t0: f64,
    y0: State,
    t1: f64,
    tol: f64,
) -> Result<(State, usize)> {
    let steps = Steps {
        first: 0.0,
        longest: system.units.max_step,
        most: STEPS_PER_PERIOD,
    };
    let (t, y, steps) = run_dop853(system, (t0, t1), y0, tol, steps)?;
    if steps >= STEPS_PER_PERIOD as usize {
        return Err(AtlasError::Integration {
            time: t,
            reason: format!("gave up after {STEPS_PER_PERIOD} steps"),
        });
    }
    Ok((y, steps))
}

/// What one run over a θ-period measured.
struct PeriodRun {
    /// T.
    period: f64,
    /// Δψ.
    psi_advance: f64,
    /// Δζ = (Δx_c, Δy_c).
    drift: [f64; 2],
    /// ∫ U (|a| + |p|) dt, the path's length scale.
    scale: f64,
    /// Error of the event's time.
    timing: f64,
    /// |ε(end) − ε|.
    energy_error: f64,
    /// Whether the run failed to come back to θ_min (it strayed into another orbit).
    strayed: bool,
}

/// The spacing of the doubles at π (those of [2, 4)).
const PI_ULP: f64 = 2.0 * f64::EPSILON;

/// One run at tolerance `tol`, and the steps taken.
fn one_period<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    units: Units,
    (tol, widths_per_step): (f64, f64),
) -> Result<(PeriodRun, usize)> {
    let system = ReducedSystem::new(potential.body, potential.kappa);
    let theta0 = component.theta_min();
    let (p0, event) = match component.kind {
        MotionKind::Rotation => {
            let gap = energy - system.effective_potential(theta0);
            let b = potential.body.reduced_inertia(theta0);
            ((2.0 * gap / b).sqrt(), EventKind::Angle(theta0 + TAU))
        }
        _ => (0.0, EventKind::Momentum),
    };
    let units = Units {
        max_step: widths_per_step * units.feature_time,
        ..units
    };
    let plain = PeriodSystem {
        system,
        units,
        event,
        record: None,
    };
    let record = RefCell::new(EventRecord::default());
    let watched = PeriodSystem {
        record: Some(&record),
        ..plain
    };
    let y0 = State::from([
        (theta0 - units.origin) / units.angle,
        p0 / units.rate,
        0.0,
        0.0,
        0.0,
        0.0,
    ]);
    // Run until the event fires; the horizon is only a safeguard.
    let (_, mut steps) = run(watched, 0.0, y0, 1e7, tol)?;
    let ((ta, ya), (tb, yb)) = record
        .into_inner()
        .crossing
        .ok_or(AtlasError::NotPeriodic {
            reason: "the ODE run found no return to theta_min",
        })?;
    // Newton on g(y(ta + s)) for the offset s, each probe a fresh run from the step before.
    let (ga, gb) = (plain.event(&ya).0, plain.event(&yb).0);
    let mut s = (tb - ta) * ga / (ga - gb);
    let mut y = yb;
    for _ in 0..60 {
        let (y_s, n) = run(
            PeriodSystem {
                record: None,
                ..plain
            },
            ta,
            ya,
            ta + s,
            tol,
        )?;
        steps += n;
        y = y_s;
        let (g, dg) = plain.event(&y);
        let correction = g / dg;
        if !correction.is_finite() || correction.abs() <= 2.0 * f64::EPSILON * (ta + s) {
            break;
        }
        s -= correction;
    }
    // The event time is only as good as g's absolute accuracy (~ tol) over its rate, and
    // never better than the rounding of t itself (which matters where ψ̇ is huge: near a
    // pole at small κ, ψ̇ ~ 1/κ at θ_min).
    let (_, rate) = plain.event(&y);
    let (theta_end, p_end) = (units.theta(&y), units.theta_dot(&y));
    let timing = (tol * y[1].abs().max(1.0) / rate.abs().max(f64::MIN_POSITIVE))
        .max(2.0 * f64::EPSILON * (ta + s));
    // A libration's run must come back to θ_min: near a separatrix the energy error can carry
    // it over the saddle into the neighbouring well, and the event then marks another orbit
    // (far from θ_min; an event on the right orbit is off by ~ tol ε / V′(θ_min) only).
    let strayed = match event {
        EventKind::Momentum => {
            let length = component.theta_max() - component.theta_min();
            (theta_end - theta0).abs() > 1e-2 * length.max(f64::MIN_POSITIVE)
        }
        EventKind::Angle(_) => false,
    };
    let end_energy = 0.5 * potential.body.reduced_inertia(theta_end) * p_end * p_end
        + system.effective_potential(theta_end);
    let run = PeriodRun {
        period: ta + s,
        psi_advance: y[2],
        drift: [y[3], y[4]],
        scale: y[5],
        timing,
        energy_error: (end_energy - energy).abs(),
        strayed,
    };
    Ok((run, steps))
}

/// The tolerances of the three runs, `tol`, tol/10, tol/100 (or from 1e-13 down to 1e-15
/// where tol is below 1e-13: DOP853 is not asked below 1e-15), and how many of the
/// narrowest feature's widths one step may cross: 4, 2, 1.
fn ladder(tol: f64) -> [(f64, f64); 3] {
    let top = tol.max(1e-13);
    [(top, 4.0), (top * 0.1, 2.0), (top * 0.01, 1.0)]
}

/// How much the tightest run's difference from the middle one may be, relative to the middle
/// one's from the loosest, for the runs to count as converging: a tolerance-proportional
/// method shrinks it tenfold per step of the ladder.
const CONVERGING: f64 = 1.0 / 3.0;

/// The error estimate of the tightest run's value from the distances between the loose and
/// the middle run's values (`first`) and between the middle and the tight one's (`last`):
/// where the distances shrink at least threefold, their sum, the loose run's error, which a
/// run a hundred times tighter falls well below; else ten times the larger one (the runs are
/// not yet in their asymptotic regime, and agreement between two of them may be chance: two
/// runs at tol and tol/100 off T by the same 3e-5 agreed to 4e-7). The last distance alone
/// fell short of the error up to 18 times (random bodies at tol 1e-5).
fn ladder_error(first: f64, last: f64) -> f64 {
    if last <= CONVERGING * first {
        first + last
    } else {
        10.0 * first.max(last)
    }
}

/// T, Δψ and Δζ of a libration or rotation by three ODE runs at the tolerances of
/// [`ladder`]; the values are the tightest run's, their error estimates come from the
/// differences between the runs ([`ladder_error`]).
///
/// The estimate is not a bound: runs that step over the same narrow feature share their
/// error. It is what an independent check can give; the quadrature's estimates are bounds.
pub fn integrate<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    component: &Component,
    tol: f64,
    with_drift: bool,
) -> Result<PeriodIntegrals> {
    // The runs carry θ itself, whose doubles near π are 4.4e-16 apart: a turning point a
    // distance d from π has sin θ only to ulp(π)/d there, alike in both runs, so their
    // difference does not show it. At κ = 1e-15 the runs went through the pole as at κ = 0
    // (T twice the truth with an estimate of 1e-9); at d = 5e-8 and 5e-7 N was 1.15 and 1.3
    // times its estimate off, at 5e-6 within it (α = 0.5, β = 3; an adversary pass). Within
    // 1e10 ulps of π (4.4e-6) a component has no values by this method; the quadrature
    // holds the turning point as its distance from π.
    if potential.kappa != 0.0 && component.upper.from_pi < 1e10 * PI_ULP {
        return Err(AtlasError::Integration {
            time: 0.0,
            reason: "a turning point within 4.4e-6 (1e10 ulps) of pi: the ODE runs, which \
                     carry theta itself, cannot resolve it"
                .to_string(),
        });
    }
    // Where a narrow feature caps the steps, a rough run (tol 1e-3, no cap) first: T over the
    // time to cross the feature says how many steps the capped runs need. Beyond half the
    // budget the component gets no values at once (an oblate body at β = 2.9e4, 1.3e-4 from
    // its pole, had the three runs give up after 1e6 steps each: 16.6 s for nothing).
    let units = Units::of(potential, energy, component);
    let mut work = 0;
    if units.feature_time.is_finite() {
        let (rough, steps) =
            one_period(potential, energy, component, units, (1e-3, f64::INFINITY))?;
        work += steps;
        let needed: f64 = ladder(tol)
            .iter()
            .map(|&(_, widths)| rough.period / (widths * units.feature_time))
            .sum();
        if needed > 0.5 * STEPS_PER_PERIOD as f64 {
            return Err(AtlasError::Integration {
                time: 0.0,
                reason: format!(
                    "the orbit crosses a feature of the body too narrow for the ODE runs: \
                     about {needed:.1e} steps"
                ),
            });
        }
    }
    let [loose_tol, middle_tol, tight_tol] = ladder(tol);
    let (loose, n0) = one_period(potential, energy, component, units, loose_tol)?;
    let (middle, n1) = one_period(potential, energy, component, units, middle_tol)?;
    let (tight, n2) = one_period(potential, energy, component, units, tight_tol)?;
    work += n0 + n1 + n2;
    let runs = [&loose, &middle, &tight];
    // Each value's estimate from the three runs' values.
    let ladder_of = |value: &dyn Fn(&PeriodRun) -> [f64; 2]| {
        let distance = |a: &PeriodRun, b: &PeriodRun| {
            let (a, b) = (value(a), value(b));
            (a[0] - b[0]).hypot(a[1] - b[1])
        };
        ladder_error(distance(runs[0], runs[1]), distance(runs[1], runs[2]))
    };
    // Rounding accumulates over the steps of a run: a few ulps per step.
    let eps = 8.0 * f64::EPSILON * (n2 as f64).max(1.0);
    // The event's timing error moves the end of the period by dt: T by dt, Δψ by |ψ̇| dt,
    // Δζ by |ζ̇| dt (bounded by the path scale's mean rate).
    let timing = tight.timing;
    let theta0 = component.theta_min();
    let psi_rate = potential
        .psi_rate(crate::torus::Site::at(theta0).angle())
        .abs();
    // Near a saddle T is ill-conditioned in ε: the energy the runs drift off by moves T by
    // δε/(λ |ε − V_s|) per passage, which the differences of the runs need not show.
    let double = if component.kind == MotionKind::Rotation {
        1.0
    } else {
        2.0
    };
    let energy_error = runs.iter().map(|r| r.energy_error).fold(0.0, f64::max);
    let saddle =
        potential.saddle_conditioning(energy, component, tight.period, double, energy_error);
    let (saddle_t, saddle_psi) = (saddle.period, saddle.psi_advance);
    let mut period_error = ladder_of(&|r| [r.period, 0.0]) + eps * tight.period + timing + saddle_t;
    let mut psi_advance_error = ladder_of(&|r| [r.psi_advance, 0.0])
        + eps * tight.psi_advance.abs()
        + psi_rate * timing
        + saddle_psi;
    // A run that strayed into another orbit measured nothing of this one.
    let strayed = runs.iter().any(|r| r.strayed);
    if strayed {
        period_error = period_error.max(tight.period.abs());
        psi_advance_error = psi_advance_error.max(tight.psi_advance.abs()).max(TAU);
    }
    let drift = with_drift.then(|| {
        let error = ladder_of(&|r| r.drift)
            + eps * tight.scale
            + tight.scale / tight.period * (timing + saddle_t)
            + saddle.drift
            + tight.scale * saddle_psi;
        DriftEstimate {
            value: tight.drift,
            error: if strayed {
                error.max(tight.scale)
            } else {
                error
            },
            scale: tight.scale,
        }
    });
    Ok(PeriodIntegrals {
        period: tight.period,
        psi_advance: tight.psi_advance,
        period_error,
        psi_advance_error,
        drift,
        psi_variation: None,
        // (The runs' own energy drift, not a level offset: kept.)
        saddle: SaddleTerms::default(),
        level_residual: None,
        work,
        converged: true,
    })
}
