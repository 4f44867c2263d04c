//! The independent method for one cell: integrate the reduced system (`eqsys` with `dpsi` and
//! the velocity of the centre of mass) with DOP853 from θ_min, p = 0, ψ = 0 over one θ-period,
//! located as the event "p crosses zero upwards" (for a rotation: θ advances by 2π) and refined
//! by Newton's method on the event function. It shares nothing with the quadrature but the
//! model's formulas, and serves as the reference for every test of [`crate::torus`].

use crate::body::Shape;
use crate::error::{AtlasError, Result};
use crate::ode::run_dop853;
use crate::reduced::ReducedSystem;
use crate::torus::{
    Component, DriftEstimate, EffectivePotential, MotionKind, PeriodIntegrals, SaddleTerms,
};
use nalgebra::SVector;
use ode_solvers::System;
use std::cell::RefCell;
use std::f64::consts::TAU;

/// State [θ, p, ψ, x_c, y_c, ∫ U (|a| + |p|) dt] with a = κ/(J sinθ).
type State = SVector<f64, 6>;

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
    event: EventKind,
    /// Where the observer writes (None: plain integration, no event watching).
    record: Option<&'r RefCell<EventRecord>>,
}

impl<S: Shape> PeriodSystem<'_, '_, S> {
    fn rate(&self, y: &State) -> State {
        let (theta, p, psi) = (y[0], y[1], y[2]);
        let (vx, vy) = self.system.centre_velocity(theta, p, psi);
        let u = self.system.body.shape.potential(theta);
        let along = if self.system.kappa == 0.0 {
            0.0
        } else {
            self.system.kappa / (self.system.body.integral_factor(theta) * theta.sin())
        };
        State::from([
            p,
            self.system.theta_acceleration(theta, p),
            self.system.psi_rate(theta),
            vx,
            vy,
            // |U|: a disk whose centre of mass is off its plane has U < 0 near a pole.
            u.abs() * (along.abs() + p.abs()),
        ])
    }

    /// g(y) and dg/dt.
    fn event(&self, y: &State) -> (f64, f64) {
        match self.event {
            EventKind::Momentum => (y[1], self.system.theta_acceleration(y[0], y[1])),
            EventKind::Angle(target) => (y[0] - target, y[1]),
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
    let (t, y, steps) = run_dop853(system, t0, t1, y0, tol, 0.0, STEPS_PER_PERIOD)?;
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
    tol: f64,
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
    let plain = PeriodSystem {
        system,
        event,
        record: None,
    };
    let record = RefCell::new(EventRecord::default());
    let watched = PeriodSystem {
        system,
        event,
        record: Some(&record),
    };
    let y0 = State::from([theta0, p0, 0.0, 0.0, 0.0, 0.0]);
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
    let timing = (tol * y[1].abs().max(1.0) / rate.abs().max(f64::MIN_POSITIVE))
        .max(2.0 * f64::EPSILON * (ta + s));
    // A libration's run must come back to θ_min: near a separatrix the energy error can carry
    // it over the saddle into the neighbouring well, and the event then marks another orbit
    // (far from θ_min; an event on the right orbit is off by ~ tol ε / V′(θ_min) only).
    let strayed = match event {
        EventKind::Momentum => {
            let length = component.theta_max() - component.theta_min();
            (y[0] - theta0).abs() > 1e-2 * length.max(f64::MIN_POSITIVE)
        }
        EventKind::Angle(_) => false,
    };
    let end_energy =
        0.5 * potential.body.reduced_inertia(y[0]) * y[1] * y[1] + system.effective_potential(y[0]);
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

/// T, Δψ and Δζ of a libration or rotation by two ODE runs, at `tol` and at tol/100; the
/// values are the tighter run's and the error estimates the difference between the two.
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
    let (loose, n1) = one_period(potential, energy, component, tol)?;
    let (tight, n2) = one_period(potential, energy, component, (tol * 1e-2).max(1e-15))?;
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
    // δε/(λ |ε − V_s|) per passage, which the difference of the two runs need not show.
    let double = if component.kind == MotionKind::Rotation {
        1.0
    } else {
        2.0
    };
    let energy_error = tight.energy_error.max(loose.energy_error);
    let saddle =
        potential.saddle_conditioning(energy, component, tight.period, double, energy_error);
    let (saddle_t, saddle_psi) = (saddle.period, saddle.psi_advance);
    let mut period_error =
        (tight.period - loose.period).abs() + eps * tight.period + timing + saddle_t;
    let mut psi_advance_error = (tight.psi_advance - loose.psi_advance).abs()
        + eps * tight.psi_advance.abs()
        + psi_rate * timing
        + saddle_psi;
    // A run that strayed into another orbit measured nothing of this one.
    let strayed = tight.strayed || loose.strayed;
    if strayed {
        period_error = period_error.max(tight.period.abs());
        psi_advance_error = psi_advance_error.max(tight.psi_advance.abs()).max(TAU);
    }
    let drift = with_drift.then(|| {
        let error = (tight.drift[0] - loose.drift[0]).hypot(tight.drift[1] - loose.drift[1])
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
        work: n1 + n2,
        converged: true,
    })
}
