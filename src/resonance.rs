//! Resonance curves: the curves of the (κ, ε) plane on which the rotation number N of one
//! component equals p/q, traced by pseudo-arclength continuation with the cell solver (each
//! point solved to the solver's tolerance, not read off a grid), and the fold of the curve of
//! largest κ: N(κ, ε) = p/q, ∂N/∂ε = 0, which for N = 0 is κ_max of the boundedness
//! hypothesis (SPEC §4; paper §5).

use crate::body::Shape;
use crate::cell::{solve_component, CellOptions, Status};
use crate::error::{AtlasError, Result};
use crate::torus::{CriticalKind, EffectivePotential, MotionKind};
use crate::Body;
use serde::Serialize;

/// What to trace and where.
#[derive(Debug, Clone)]
pub struct ResonanceOptions {
    /// p/q: the rotation number of the curves.
    pub target: f64,
    /// The window of κ (κ > 0: at κ = 0, N = 0 identically) …
    pub kappa: (f64, f64),
    /// … and of ε.
    pub energy: (f64, f64),
    /// Rows of κ (and energies per row) of the seed scan.
    pub grid: usize,
    /// The cell solver's options (the drift is not needed).
    pub cell: CellOptions,
    /// At most this many points per curve.
    pub max_points: usize,
}

/// One point of a resonance curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    pub kappa: f64,
    pub energy: f64,
    /// N there (= p/q within the tolerance).
    pub rotation_number: f64,
    /// The cell solver's error estimate of N.
    pub error_estimate: f64,
    /// Which component of the cell (index in increasing θ_min, as `rubber-atlas cell`).
    pub component: usize,
    pub theta_min: f64,
    pub theta_max: f64,
    /// θ of the minimum of V (the permanent rotation) that the component surrounds.
    pub well: f64,
}

/// One traced curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    pub points: Vec<CurvePoint>,
    /// Whether the curve closes on itself.
    pub closed: bool,
}

/// The fold of the N = p/q curve of largest κ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fold {
    pub kappa_max: f64,
    pub energy: f64,
    pub rotation_number: f64,
    /// ∂N/∂ε at the fold (≈ 0), by central differences.
    pub dn_denergy: f64,
    /// ∂N/∂κ at the fold.
    pub dn_dkappa: f64,
    /// Estimated error of κ_max: the solver's tolerance carried through ∂N/∂κ, plus the
    /// spread of κ(ε) over the golden-section search's final bracket.
    pub kappa_error: f64,
    pub well: f64,
}

/// The component around the well nearest `well` at (κ, ε), solved.
fn evaluate<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    well: f64,
    options: &CellOptions,
) -> Option<CurvePoint> {
    let minimum = potential
        .critical_points()
        .iter()
        .filter(|p| p.kind == CriticalKind::Minimum)
        .map(|p| p.site.theta)
        .min_by(|a, b| (a - well).abs().total_cmp(&(b - well).abs()))?;
    let components = potential.components(energy).ok()?;
    let (index, component) = components
        .iter()
        .enumerate()
        .find(|(_, c)| c.theta_min() <= minimum && minimum <= c.theta_max())?;
    if component.kind != MotionKind::Libration {
        return None;
    }
    let r = solve_component(potential, energy, component, options).ok()?;
    if !r.rotation_number.is_finite() || r.status == Status::Separatrix {
        return None;
    }
    Some(CurvePoint {
        kappa: potential.kappa,
        energy,
        rotation_number: r.rotation_number,
        error_estimate: r.error_estimate,
        component: index,
        theta_min: r.theta_min,
        theta_max: r.theta_max,
        well: minimum,
    })
}

/// A root of `f` in [a, b] with f(a), f(b) of opposite signs (Illinois regula falsi), to
/// |b − a| ≤ `xtol` or |f| ≤ `ftol`; None if `f` fails on the way.
fn bracketed_root(
    mut f: impl FnMut(f64) -> Option<f64>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    xtol: f64,
    ftol: f64,
) -> Option<f64> {
    let mut side = 0;
    for _ in 0..200 {
        let c = if fa != fb {
            (a * fb - b * fa) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c)?;
        if fc.abs() <= ftol || (b - a).abs() <= xtol {
            return Some(c);
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    Some(0.5 * (a + b))
}

struct Tracer<'a, S: Shape> {
    body: &'a Body<S>,
    options: &'a ResonanceOptions,
    /// Scales of κ and ε: continuation runs in the window scaled to the unit square.
    scale: (f64, f64),
}

impl<S: Shape> Tracer<'_, S> {
    fn at(&self, kappa: f64, energy: f64, well: f64) -> Option<CurvePoint> {
        let potential = EffectivePotential::new(self.body, kappa);
        evaluate(&potential, energy, well, &self.options.cell)
    }

    fn inside(&self, kappa: f64, energy: f64) -> bool {
        let (k, e) = (self.options.kappa, self.options.energy);
        kappa >= k.0 && kappa <= k.1 && energy >= e.0 && energy <= e.1
    }

    /// ∇N in scaled coordinates, by central differences.
    fn gradient(&self, p: &CurvePoint) -> Option<(f64, f64)> {
        let h = 1e-6;
        let (hk, he) = (h * self.scale.0, h * self.scale.1);
        let kp = self.at(p.kappa + hk, p.energy, p.well)?;
        let km = self.at(p.kappa - hk, p.energy, p.well)?;
        let potential = EffectivePotential::new(self.body, p.kappa);
        let ep = evaluate(&potential, p.energy + he, p.well, &self.options.cell)?;
        let em = evaluate(&potential, p.energy - he, p.well, &self.options.cell)?;
        Some((
            (kp.rotation_number - km.rotation_number) / (2.0 * h),
            (ep.rotation_number - em.rotation_number) / (2.0 * h),
        ))
    }

    /// Newton along ∇N from (κ, ε) back onto N = p/q.
    fn correct(&self, kappa: f64, energy: f64, well: f64) -> Option<(CurvePoint, (f64, f64))> {
        let (mut k, mut e) = (kappa, energy);
        let tol = self.options.cell.tol.max(1e-13);
        for _ in 0..8 {
            if !self.inside(k, e) {
                return None;
            }
            let p = self.at(k, e, well)?;
            let f = p.rotation_number - self.options.target;
            let g = self.gradient(&p)?;
            if f.abs() <= tol.max(p.error_estimate) {
                return Some((p, g));
            }
            let norm = g.0 * g.0 + g.1 * g.1;
            if norm == 0.0 || !norm.is_finite() {
                return None;
            }
            k -= f * g.0 / norm * self.scale.0;
            e -= f * g.1 / norm * self.scale.1;
        }
        None
    }

    /// The curve through `seed` (on N = p/q), followed both ways until it leaves the window,
    /// ends (its component disappears or meets a separatrix) or closes.
    fn trace(&self, seed: CurvePoint, gradient: (f64, f64)) -> Curve {
        let (s_max, s_min) = (1.0 / self.options.grid as f64, 1e-7);
        let mut halves: [Vec<CurvePoint>; 2] = [Vec::new(), Vec::new()];
        let mut closed = false;
        for (half, sign) in halves.iter_mut().zip([1.0, -1.0]) {
            let mut p = seed;
            let mut t = tangent(gradient, sign);
            let mut s = 0.25 * s_max;
            while half.len() < self.options.max_points && s >= s_min {
                let k = p.kappa + s * t.0 * self.scale.0;
                let e = p.energy + s * t.1 * self.scale.1;
                let Some((q, g)) = self.correct(k, e, p.well) else {
                    s *= 0.5;
                    continue;
                };
                let t_new = tangent(g, 1.0);
                let t_new = if t_new.0 * t.0 + t_new.1 * t.1 < 0.0 {
                    (-t_new.0, -t_new.1)
                } else {
                    t_new
                };
                // Too sharp a turn, or a jump to another branch: a smaller step.
                let moved = self.distance(&p, &q);
                if t_new.0 * t.0 + t_new.1 * t.1 < 0.9 || moved > 2.0 * s {
                    s *= 0.5;
                    continue;
                }
                half.push(q);
                p = q;
                t = t_new;
                s = (1.5 * s).min(s_max);
                // Back at the seed, away from the window's edge: a closed curve.
                if half.len() > 3
                    && self.distance(&p, &seed) < 0.75 * s
                    && self.edge_distance(&seed) > 2.0 * s_max
                {
                    closed = true;
                    break;
                }
            }
            if closed {
                break;
            }
        }
        let [forward, backward] = halves;
        let mut points: Vec<CurvePoint> = backward.into_iter().rev().collect();
        points.push(seed);
        points.extend(forward);
        Curve { points, closed }
    }

    /// Distance of `p` from the window's edge, in scaled units.
    fn edge_distance(&self, p: &CurvePoint) -> f64 {
        let (k, e) = (self.options.kappa, self.options.energy);
        let u = ((p.kappa - k.0) / self.scale.0).min((k.1 - p.kappa) / self.scale.0);
        let v = ((p.energy - e.0) / self.scale.1).min((e.1 - p.energy) / self.scale.1);
        u.min(v)
    }

    fn distance(&self, a: &CurvePoint, b: &CurvePoint) -> f64 {
        ((a.kappa - b.kappa) / self.scale.0).hypot((a.energy - b.energy) / self.scale.1)
    }

    /// Points on N = p/q found on the rows of the seed grid: sign changes of N − p/q along ε
    /// for each well, refined to the tolerance.
    fn seeds(&self) -> Vec<(CurvePoint, (f64, f64))> {
        use rayon::prelude::*;
        let n = self.options.grid;
        let (k0, k1) = self.options.kappa;
        let (e0, e1) = self.options.energy;
        let target = self.options.target;
        (0..=n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let kappa = k0 + (k1 - k0) * i as f64 / n as f64;
                let potential = EffectivePotential::new(self.body, kappa);
                let wells: Vec<f64> = potential
                    .critical_points()
                    .iter()
                    .filter(|p| p.kind == CriticalKind::Minimum)
                    .map(|p| p.site.theta)
                    .collect();
                let mut found = Vec::new();
                for well in wells {
                    let f = |e: f64| {
                        evaluate(&potential, e, well, &self.options.cell)
                            .map(|p| p.rotation_number - target)
                    };
                    let mut previous: Option<(f64, f64)> = None;
                    for j in 0..=n {
                        let e = e0 + (e1 - e0) * j as f64 / n as f64;
                        let Some(fe) = f(e) else {
                            previous = None;
                            continue;
                        };
                        if let Some((ep, fp)) = previous {
                            if (fp > 0.0) != (fe > 0.0) {
                                let tol = self.options.cell.tol;
                                if let Some(root) =
                                    bracketed_root(&f, (ep, fp), (e, fe), 1e-15 * e.abs().max(1.0), tol)
                                {
                                    if let Some(p) = evaluate(&potential, root, well, &self.options.cell) {
                                        // A sign change across a separatrix is no root.
                                        if (p.rotation_number - target).abs() <= tol.max(p.error_estimate) {
                                            found.push(p);
                                        }
                                    }
                                }
                            }
                        }
                        previous = Some((e, fe));
                    }
                }
                found
            })
            .collect::<Vec<_>>()
            .into_iter()
            .filter_map(|p| self.gradient(&p).map(|g| (p, g)))
            .collect()
    }
}

fn tangent((gk, ge): (f64, f64), sign: f64) -> (f64, f64) {
    let norm = gk.hypot(ge);
    (-ge / norm * sign, gk / norm * sign)
}

fn check_window(options: &ResonanceOptions) -> Result<()> {
    let bad = |name: &'static str, value: f64, reason: &'static str| {
        Err(AtlasError::InvalidParameter {
            name,
            value,
            reason,
        })
    };
    let (k0, k1) = options.kappa;
    let (e0, e1) = options.energy;
    if !(k0.is_finite() && k0 > 0.0) {
        return bad("kappa_min", k0, "must be > 0 (at kappa = 0, N = 0 everywhere)");
    }
    if !(k1.is_finite() && k1 > k0) {
        return bad("kappa_max", k1, "must be finite and above kappa_min");
    }
    if !e0.is_finite() {
        return bad("energy_min", e0, "must be finite");
    }
    if !(e1.is_finite() && e1 > e0) {
        return bad("energy_max", e1, "must be finite and above energy_min");
    }
    if !options.target.is_finite() {
        return bad("rotation_number", options.target, "must be finite");
    }
    if options.grid < 4 {
        return bad("grid", options.grid as f64, "must be at least 4");
    }
    options.cell.validate()
}

/// Every curve of the window on which a component's N equals `options.target`, found from a
/// seed scan on a grid of `options.grid` κ-rows and traced by continuation. A curve that
/// crosses no row of the seed grid (a loop smaller than the grid) is not found.
pub fn trace_curves<S: Shape>(body: &Body<S>, options: &ResonanceOptions) -> Result<Vec<Curve>> {
    check_window(options)?;
    let tracer = Tracer {
        body,
        options,
        scale: (
            options.kappa.1 - options.kappa.0,
            options.energy.1 - options.energy.0,
        ),
    };
    let mut curves: Vec<Curve> = Vec::new();
    let near = 1.5 / options.grid as f64;
    for (seed, gradient) in tracer.seeds() {
        let known = curves.iter().any(|c| {
            c.points.iter().any(|p| {
                tracer.distance(p, &seed) < near && p.theta_min <= seed.well && seed.well <= p.theta_max
            })
        });
        if !known {
            curves.push(tracer.trace(seed, gradient));
        }
    }
    Ok(curves)
}

/// The fold of the N = p/q curve of largest κ: the point of largest κ on the traced curves,
/// refined by a golden-section search over ε of κ(ε), where κ(ε) solves N(κ, ε) = p/q. None
/// if no curve is found, or if the curve of largest κ leaves the window through κ_max.
pub fn fold<S: Shape>(body: &Body<S>, options: &ResonanceOptions) -> Result<Option<Fold>> {
    let curves = trace_curves(body, options)?;
    let Some(top) = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .max_by(|a, b| a.kappa.total_cmp(&b.kappa))
        .copied()
    else {
        return Ok(None);
    };
    let window = options.kappa.1 - options.kappa.0;
    if top.kappa >= options.kappa.1 - 2.0 * window / options.grid as f64 {
        return Ok(None);
    }
    let tracer = Tracer {
        body,
        options,
        scale: (window, options.energy.1 - options.energy.0),
    };
    let tol = options.cell.tol.max(1e-13);
    // κ(ε) on the curve near the top: the root of N − p/q in κ, bracketed within a few grid
    // steps of the top (∂N/∂κ ≠ 0 at a fold in κ, so the root is simple).
    let reach = 3.0 * window / options.grid as f64;
    let kappa_at = |energy: f64, _start: f64| -> Option<(f64, CurvePoint)> {
        let f = |k: f64| {
            tracer
                .at(k, energy, top.well)
                .map(|p| p.rotation_number - options.target)
        };
        let lo = (top.kappa - reach).max(options.kappa.0);
        let hi = top.kappa + reach;
        let (flo, fhi) = (f(lo)?, f(hi)?);
        if (flo > 0.0) == (fhi > 0.0) {
            return None;
        }
        let k = bracketed_root(f, (lo, flo), (hi, fhi), 1e-15 * hi, tol)?;
        Some((k, tracer.at(k, energy, top.well)?))
    };
    // Golden section for the largest κ(ε), in a bracket of a few curve steps around the top.
    let span = 4.0 * (options.energy.1 - options.energy.0) / options.grid as f64;
    let (mut a, mut b) = (top.energy - span, top.energy + span);
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let mut start = top.kappa;
    let value = |e: f64, start: &mut f64| -> f64 {
        match kappa_at(e, *start) {
            Some((k, _)) => {
                *start = k;
                k
            }
            None => f64::NEG_INFINITY,
        }
    };
    let (mut c, mut d) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut fc, mut fd) = (value(c, &mut start), value(d, &mut start));
    while (b - a).abs() > 1e-9 * (1.0 + top.energy.abs()) {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = value(c, &mut start);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = value(d, &mut start);
        }
    }
    let energy = 0.5 * (a + b);
    let Some((kappa, point)) = kappa_at(energy, start) else {
        return Ok(None);
    };
    let (gk, ge) = tracer.gradient(&point).unwrap_or((f64::NAN, f64::NAN));
    let (dn_dkappa, dn_denergy) = (gk / window, ge / (options.energy.1 - options.energy.0));
    // The solver's tolerance through ∂N/∂κ, plus the spread of κ over the final bracket.
    let kappa_error = tol.max(point.error_estimate) / dn_dkappa.abs() + (fc - fd).abs();
    Ok(Some(Fold {
        kappa_max: kappa,
        energy,
        rotation_number: point.rotation_number,
        dn_denergy,
        dn_dkappa,
        kappa_error,
        well: point.well,
    }))
}
