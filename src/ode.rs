//! A thin wrapper around the DOP853 integrator of the `ode_solvers` crate: samples on a
//! uniform time grid, tolerances as one knob, failures as typed errors.

use crate::error::{AtlasError, Result};
use nalgebra::SVector;
use ode_solvers::{Dop853, OutputType, System};

/// A right-hand side ẏ = f(y) of an autonomous system of N equations.
pub trait Rate<const N: usize> {
    /// f(y).
    fn rate(&self, y: &SVector<f64, N>) -> SVector<f64, N>;
}

struct Adapter<'a, R>(&'a R);

impl<const N: usize, R: Rate<N>> System<f64, SVector<f64, N>> for Adapter<'_, R> {
    fn system(&self, _t: f64, y: &SVector<f64, N>, dy: &mut SVector<f64, N>) {
        *dy = self.0.rate(y);
    }
}

/// Samples of a solution on the grid t = 0, dt, 2 dt, …, t_end.
#[derive(Debug, Clone)]
pub struct SampledSolution<const N: usize> {
    pub times: Vec<f64>,
    pub states: Vec<SVector<f64, N>>,
    /// The integrator's accepted steps over the whole run.
    pub steps: usize,
}

/// The steps of one DOP853 run.
#[derive(Debug, Clone, Copy)]
pub struct Steps {
    /// The first step (0: automatic).
    pub first: f64,
    /// The longest step (∞: no bound but the run's length).
    pub longest: f64,
    /// The accepted steps after which the run stops short of its end (`u32::MAX`: none;
    /// the solver keeps every step it takes: bounding them bounds its memory).
    pub most: u32,
}

/// Runs DOP853 on `system` from (t0, y0) towards t1 (it may stop earlier when the system's
/// `solout` asks to) at relative and absolute tolerance `tol`, with the given `steps`.
/// Returns the last time and state and the number of accepted steps.
pub fn run_dop853<const N: usize, F: System<f64, SVector<f64, N>>>(
    system: F,
    (t0, t1): (f64, f64),
    y0: SVector<f64, N>,
    tol: f64,
    steps: Steps,
) -> Result<(f64, SVector<f64, N>, usize)> {
    let Steps {
        first: h0,
        longest: max_step,
        most: max_steps,
    } = steps;
    let mut solver = Dop853::from_param(
        system,
        t0,
        t1,
        t1 - t0,
        y0,
        tol,
        tol,
        0.9,
        0.0,
        0.333,
        6.0,
        max_step.min(t1 - t0),
        h0,
        max_steps,
        1000,
        OutputType::Sparse,
    );
    let steps =
        match solver.integrate() {
            Ok(stats) => stats.accepted_steps as usize,
            Err(ode_solvers::dop_shared::IntegrationError::MaxNumStepReached {
                n_step, ..
            }) if max_steps != u32::MAX => n_step as usize,
            Err(e) => {
                use ode_solvers::dop_shared::IntegrationError as Stop;
                let (time, reason) = match e {
                    Stop::StepSizeUnderflow { x } => (
                        x,
                        "the step fell below the rounding of t: the motion is too fast there \
                         for this tolerance (near a pole at high energy or tiny kappa; the \
                         full model may still resolve it)"
                            .to_string(),
                    ),
                    Stop::StiffnessDetected { x } => (x, "the equations became stiff".to_string()),
                    Stop::MaxNumStepReached { x, n_step } => {
                        (x, format!("more than {n_step} steps were needed"))
                    }
                };
                return Err(AtlasError::Integration { time, reason });
            }
        };
    let (ts, ys) = (solver.x_out(), solver.y_out());
    let (Some(&t_last), Some(y_last)) = (ts.last(), ys.last()) else {
        return Err(AtlasError::Integration {
            time: t0,
            reason: "the integrator returned no step".into(),
        });
    };
    Ok((t_last, *y_last, steps))
}

/// Accepted steps per solver run in [`integrate_sampled`]: a run stores every step
/// (`OutputType::Sparse`), so a long output interval (`--t-end 1e12` with 2000 samples) is
/// covered by runs of at most this many steps, each starting where the last stopped.
const STEPS_PER_RUN: u32 = 100_000;

/// Integrates ẏ = f(y) from y(0) = `y0` to `t_end` with DOP853 at relative and absolute
/// tolerance `tol`, returning the solution at `samples + 1` equally spaced times.
///
/// Each output interval is integrated on its own, ending exactly at its sample time, rather
/// than read from the method's dense output: the interpolant of `ode_solvers` 0.6 was measured
/// off by 6e-7 at the end of a long step (tol 1e-13), far above the step error. `stop` is
/// asked before every solver run (at most [`STEPS_PER_RUN`] steps): true gives
/// [`AtlasError::Stopped`].
pub fn integrate_sampled<const N: usize, R: Rate<N>>(
    rate: &R,
    y0: SVector<f64, N>,
    t_end: f64,
    samples: usize,
    tol: f64,
    stop: &dyn Fn() -> bool,
) -> Result<SampledSolution<N>> {
    let samples = samples.max(1);
    let mut times = Vec::with_capacity(samples + 1);
    let mut states = Vec::with_capacity(samples + 1);
    times.push(0.0);
    states.push(y0);
    let mut y = y0;
    let mut h_last = 0.0;
    let mut total = 0;
    for i in 1..=samples {
        let (t0, t1) = (
            t_end * (i - 1) as f64 / samples as f64,
            t_end * i as f64 / samples as f64,
        );
        // The previous interval's typical step seeds this one (0 = automatic choice).
        let (mut t, mut steps) = (t0, 0);
        loop {
            if stop() {
                return Err(AtlasError::Stopped);
            }
            let (t_last, y_last, run_steps) = run_dop853(
                Adapter(rate),
                (t, t1),
                y,
                tol,
                Steps {
                    first: h_last,
                    longest: f64::INFINITY,
                    most: STEPS_PER_RUN,
                },
            )?;
            steps += run_steps;
            let stalled = t_last <= t;
            (t, y) = (t_last, y_last);
            if (t - t1).abs() <= 1e-12 * t1.abs().max(1.0) {
                break;
            }
            if run_steps < STEPS_PER_RUN as usize || stalled {
                return Err(AtlasError::Integration {
                    time: t,
                    reason: format!("stopped before t = {t1}"),
                });
            }
            h_last = (t - t0) / steps.max(1) as f64;
        }
        h_last = (t1 - t0) / steps.max(1) as f64;
        total += steps;
        times.push(t1);
        states.push(y);
    }
    Ok(SampledSolution {
        times,
        states,
        steps: total,
    })
}
