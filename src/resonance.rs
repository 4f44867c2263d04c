//! Resonance curves: the curves of the (κ, ε) plane on which the rotation number N of one
//! component equals p/q, traced by pseudo-arclength continuation with the cell solver (each
//! point solved to the solver's tolerance, not read off a grid), and the fold of the curve of
//! largest κ: N(κ, ε) = p/q, ∂N/∂ε = 0, which for N = 0 is κ_max of the boundedness
//! hypothesis (docs/hypothesis.md; paper §5).

use crate::body::Shape;
use crate::cell::{solve_component, within_rounding_of_separatrix, CellOptions, Status};
use crate::error::{check_range, AtlasError, Result, MAX_ENERGY, MAX_KAPPA};
use crate::torus::{CriticalKind, EffectivePotential, MotionKind, ScanTable};
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
    /// The largest error estimate of N accepted on a curve point (at least the tolerance).
    /// Curves that hug a separatrix (N → ±∞ there) are followed until N's conditioning,
    /// which grows like 1/|ε − ε_s|, makes its error estimate exceed this.
    pub max_point_error: f64,
    /// Search and follow the curves on their own scale where the window is much wider (κ
    /// beyond 2 max(1, κ), ε beyond 4 max(1, |ε|)): seed rows and energies at every scale
    /// from the window's bottom up, continuation steps of the curve's size
    /// ([`Tracer::scale_at`]). Off, everything is measured in the window's widths (the
    /// verdict's windows, fitted round the body's cusp).
    pub natural_scales: bool,
}

impl ResonanceOptions {
    /// The options of the `resonance` command (and of the Python package's `resonance`): N =
    /// `target` in the window κ ∈ `kappa`, ε ∈ [`energy_min`, `energy_max`], where a missing
    /// `energy_min` is the lowest minimum of V at the window's smallest κ (V grows with |κ|
    /// at every θ, so it is the lowest over the window).
    pub fn window<S: Shape>(
        body: &Body<S>,
        target: f64,
        kappa: (f64, f64),
        energy_min: Option<f64>,
        energy_max: f64,
        grid: usize,
        tol: f64,
    ) -> Self {
        let energy_min = energy_min.unwrap_or_else(|| {
            EffectivePotential::new(body, kappa.0.max(0.0))
                .critical_points()
                .iter()
                .map(|p| p.value)
                .fold(f64::INFINITY, f64::min)
        });
        Self {
            target,
            kappa,
            energy: (energy_min, energy_max),
            grid,
            cell: CellOptions {
                tol,
                drift: false,
                ..CellOptions::default()
            },
            max_points: 20_000,
            max_point_error: 1e-6,
            natural_scales: true,
        }
    }
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
    /// The family of tori of that component.
    pub family: crate::family::Family,
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

/// What the top of a curve (its point of largest κ) is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Top {
    /// A fold: the curve turns smoothly there, ∂N/∂ε = 0 (the curve's tangent is along ε).
    Fold,
    /// A corner or an end: the curve turns sharply there (at a cusp, where the separatrix it
    /// hugs ends) or cannot be followed further (it runs into a separatrix); ∂N/∂ε ≠ 0.
    Corner,
}

/// The fold of the N = p/q curve of largest κ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fold {
    /// Whether κ_max is a fold (∂N/∂ε = 0) or a corner of the curve.
    pub top: Top,
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
pub(crate) fn evaluate<S: Shape>(
    potential: &EffectivePotential<'_, S>,
    energy: f64,
    well: f64,
    options: &CellOptions,
) -> Option<CurvePoint> {
    let minimum = potential.minimum_nearest(well)?.site.theta;
    let components = potential.components(energy).ok()?;
    let (index, component) = components
        .iter()
        .enumerate()
        .find(|(_, c)| c.theta_min() <= minimum && minimum <= c.theta_max())?;
    if component.kind != MotionKind::Libration || within_rounding_of_separatrix(component, energy) {
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
        family: r.family,
        theta_min: r.theta_min,
        theta_max: r.theta_max,
        well: minimum,
    })
}

/// A root of `f` in [a, b] with f(a), f(b) of opposite signs (Illinois regula falsi), to
/// |b − a| ≤ `xtol` or |f| ≤ `ftol`; None if `f` fails on the way.
pub(crate) fn bracketed_root(
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

/// Where a point lies among the separatrices: the level nearest to it and on which side
/// (+1 above, −1 below), or None if there is no separatrix. Followed from κ to κ by the
/// nearest level (levels move continuously; at a cusp one ends, and then any side goes).
#[derive(Debug, Clone, Copy)]
struct Side {
    level: f64,
    above: bool,
}

fn side_of(levels: &[f64], energy: f64) -> Option<Side> {
    levels
        .iter()
        .min_by(|a, b| (*a - energy).abs().total_cmp(&(*b - energy).abs()))
        .map(|&level| Side {
            level,
            above: energy > level,
        })
}

/// The gap between separatrices at a new κ (`levels`) on the same side of the continuation
/// of `side`'s level: the interval in which the followed component keeps its shape.
fn gap_for(levels: &[f64], side: Option<Side>) -> (f64, f64) {
    let Some(side) = side else {
        return (f64::NEG_INFINITY, f64::INFINITY);
    };
    let Some(i) = (0..levels.len()).min_by(|&a, &b| {
        (levels[a] - side.level)
            .abs()
            .total_cmp(&(levels[b] - side.level).abs())
    }) else {
        return (f64::NEG_INFINITY, f64::INFINITY);
    };
    if side.above {
        (
            levels[i],
            levels.get(i + 1).copied().unwrap_or(f64::INFINITY),
        )
    } else {
        (
            i.checked_sub(1).map_or(f64::NEG_INFINITY, |j| levels[j]),
            levels[i],
        )
    }
}

/// Probe points in (lo, hi) around `around`, nearest first: steps `step`·2^j on either side,
/// then points that halve the distance to each finite end (down to 2⁻⁵² of it), so that a root
/// next to an end (a curve hugging a separatrix) is bracketed too.
fn probes(lo: f64, hi: f64, around: f64, step: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut d = step;
    while around + d < hi || around - d > lo {
        for x in [around + d, around - d] {
            if x > lo && x < hi {
                out.push(x);
            }
        }
        d *= 2.0;
        if !d.is_finite() || d > 1e6 {
            break;
        }
    }
    for (end, from) in [(hi, around), (lo, around)] {
        if end.is_finite() {
            for j in 1..=52 {
                let x = end - (end - from) * 0.5f64.powi(j);
                if x > lo && x < hi && x != end {
                    out.push(x);
                }
            }
        }
    }
    out.sort_by(|a, b| (a - around).abs().total_cmp(&(b - around).abs()));
    out.dedup();
    out
}

/// The root of `f` nearest `around` found on the probes (`f` is None where it is undefined),
/// refined by regula falsi to `tol`.
fn nearest_root(
    f: impl Fn(f64) -> Option<f64>,
    lo: f64,
    hi: f64,
    around: f64,
    step: f64,
    tol: f64,
) -> Option<f64> {
    let f0 = f(around)?;
    if f0.abs() <= tol {
        return Some(around);
    }
    // The last value seen on each side (above, below `around`).
    let mut last = [(around, f0), (around, f0)];
    let mut alive = [true, true];
    for x in probes(lo, hi, around, step) {
        let side = usize::from(x < around);
        if !alive[side] {
            continue;
        }
        let Some(fx) = f(x) else {
            alive[side] = false;
            if !alive[0] && !alive[1] {
                return None;
            }
            continue;
        };
        let (xp, fp) = last[side];
        if (fx > 0.0) != (fp > 0.0) {
            return bracketed_root(&f, (xp, fp), (x, fx), 1e-15 * x.abs().max(1e-300), tol);
        }
        last[side] = (x, fx);
    }
    None
}

struct Tracer<'a, S: Shape> {
    body: &'a Body<S>,
    /// The body's part of V's critical-point scan, made once for every κ of the trace.
    scan: ScanTable,
    options: &'a ResonanceOptions,
    /// The window's widths in κ and ε: the largest scales of [`Tracer::scale_at`].
    window: (f64, f64),
    /// Asked between seed rows and continuation steps: true gives up (Ctrl-C in Python).
    stop: &'a (dyn Fn() -> bool + Sync),
}

impl<'a, S: Shape> Tracer<'a, S> {
    fn new(
        body: &'a Body<S>,
        options: &'a ResonanceOptions,
        stop: &'a (dyn Fn() -> bool + Sync),
    ) -> Self {
        Self {
            body,
            scan: ScanTable::new(body),
            options,
            window: (
                options.kappa.1 - options.kappa.0,
                options.energy.1 - options.energy.0,
            ),
            stop,
        }
    }

    /// The scales of κ and ε at (κ, ε): continuation steps and distances are measured in
    /// units of these. The window's widths, but no more than 2 max(1, |κ|) and
    /// 4 max(1, |ε|): the curves' features have the body's unit of size where κ, ε are of
    /// order one and grow with κ and ε beyond (ε ≥ V ≥ κ²/2 − 1), so a window far wider than
    /// where a curve runs (ε up to 1e6, κ up to 1e150) still follows it in steps of its own
    /// size.
    fn scale_at(&self, kappa: f64, energy: f64) -> (f64, f64) {
        if !self.options.natural_scales {
            return self.window;
        }
        (
            self.window.0.min(2.0 * kappa.abs().max(1.0)),
            self.window.1.min(4.0 * energy.abs().max(1.0)),
        )
    }

    fn scale(&self, p: &CurvePoint) -> (f64, f64) {
        self.scale_at(p.kappa, p.energy)
    }

    fn at(&self, kappa: f64, energy: f64, well: f64) -> Option<CurvePoint> {
        let potential = EffectivePotential::with_scan(self.body, kappa, &self.scan);
        evaluate(&potential, energy, well, &self.options.cell)
    }

    fn tol(&self) -> f64 {
        self.options.cell.tol.max(1e-13)
    }

    /// Whether `p` is on N = p/q: within the tolerance, or within N's error estimate where
    /// that is larger (near a separatrix, where ε − V loses digits) but no more than
    /// `max_point_error`; beyond that the curve is taken to end at the separatrix.
    fn on_curve(&self, p: &CurvePoint) -> bool {
        p.error_estimate <= self.options.max_point_error.max(self.tol())
            && (p.rotation_number - self.options.target).abs() <= self.tol().max(p.error_estimate)
    }

    /// ∇N = (∂N/∂κ, ∂N/∂ε), by central differences with steps (in `p`'s scaled units)
    /// that stay well inside the point's gap between separatrices.
    fn gradient(&self, p: &CurvePoint) -> Option<(f64, f64)> {
        let potential = EffectivePotential::with_scan(self.body, p.kappa, &self.scan);
        let scale = self.scale(p);
        let distance = side_of(&potential.separatrix_levels(), p.energy)
            .map_or(f64::INFINITY, |s| (p.energy - s.level).abs());
        let h = (1e-7f64).min(0.01 * distance / scale.1).max(1e-15);
        let (hk, he) = (h * scale.0, h * scale.1);
        let kp = self.at(p.kappa + hk, p.energy, p.well)?;
        let km = self.at(p.kappa - hk, p.energy, p.well)?;
        let ep = evaluate(&potential, p.energy + he, p.well, &self.options.cell)?;
        let em = evaluate(&potential, p.energy - he, p.well, &self.options.cell)?;
        Some((
            (kp.rotation_number - km.rotation_number) / (2.0 * hk),
            (ep.rotation_number - em.rotation_number) / (2.0 * he),
        ))
    }

    /// Back onto N = p/q from the predicted (κ, ε), along ε at fixed κ when the curve runs
    /// more along κ, else along κ at fixed ε. The root is sought only on the previous
    /// point's side of its nearest separatrix, probing up to 2⁻⁵² of the way to it: a curve
    /// that hugs a separatrix is followed on its own side.
    fn correct(
        &self,
        kappa: f64,
        energy: f64,
        from: &CurvePoint,
        along_energy: bool,
        step: f64,
    ) -> Option<CurvePoint> {
        let (k, e) = (self.options.kappa, self.options.energy);
        let target = self.options.target;
        let tol = self.tol();
        let scale = self.scale(from);
        let side = side_of(
            &EffectivePotential::with_scan(self.body, from.kappa, &self.scan).separatrix_levels(),
            from.energy,
        );
        let in_gap = |levels: &[f64], x: f64| {
            let (lo, hi) = gap_for(levels, side);
            x > lo && x < hi
        };
        let point = if along_energy {
            if kappa < k.0 || kappa > k.1 {
                return None;
            }
            let potential = EffectivePotential::with_scan(self.body, kappa, &self.scan);
            let (lo, hi) = gap_for(&potential.separatrix_levels(), side);
            let (lo, hi) = (lo.max(e.0), hi.min(e.1));
            if lo >= hi {
                return None;
            }
            // Strictly inside the gap, by a rounding of its ends.
            let (inner_lo, inner_hi) = (lo + 1e-15 * lo.abs(), hi - 1e-15 * hi.abs());
            let around = if inner_lo < inner_hi {
                energy.clamp(inner_lo, inner_hi)
            } else {
                0.5 * (lo + hi)
            };
            let f = |x: f64| {
                evaluate(&potential, x, from.well, &self.options.cell)
                    .map(|p| p.rotation_number - target)
            };
            let root = nearest_root(f, lo, hi, around, step * scale.1 * 0.05, tol)?;
            evaluate(&potential, root, from.well, &self.options.cell)?
        } else {
            if energy < e.0 || energy > e.1 {
                return None;
            }
            let f = |x: f64| {
                let potential = EffectivePotential::with_scan(self.body, x, &self.scan);
                if !in_gap(&potential.separatrix_levels(), energy) {
                    return None;
                }
                evaluate(&potential, energy, from.well, &self.options.cell)
                    .map(|p| p.rotation_number - target)
            };
            let around = kappa.clamp(k.0, k.1);
            let root = nearest_root(f, k.0, k.1, around, step * scale.0 * 0.05, tol)?;
            self.at(root, energy, from.well)?
        };
        let potential = EffectivePotential::with_scan(self.body, point.kappa, &self.scan);
        (self.on_curve(&point) && in_gap(&potential.separatrix_levels(), point.energy))
            .then_some(point)
    }

    /// The curve through `seed` (on N = p/q, where ∇N = `gradient`), followed both ways
    /// until it leaves the window, ends (its component disappears, or it runs into a
    /// separatrix) or closes.
    fn trace(&self, seed: CurvePoint, gradient: (f64, f64)) -> Curve {
        // Steps below s_min end the curve: where a curve can no longer be followed (it runs
        // into a separatrix, where the points' positions are limited by N's conditioning)
        // crawling on would only add points that say nothing new.
        let s_max = 1.0 / self.options.grid as f64;
        let s_min = 1e-4 * s_max;
        let mut halves: [Vec<CurvePoint>; 2] = [Vec::new(), Vec::new()];
        let mut closed = false;
        for (half, sign) in halves.iter_mut().zip([1.0, -1.0]) {
            let mut p = seed;
            let scale = self.scale(&seed);
            let mut t = tangent((gradient.0 * scale.0, gradient.1 * scale.1), sign);
            let mut s = 0.25 * s_max;
            while half.len() < self.options.max_points && s >= s_min && !(self.stop)() {
                let scale = self.scale(&p);
                let k = p.kappa + s * t.0 * scale.0;
                let e = p.energy + s * t.1 * scale.1;
                // Solve along ε unless the curve runs nearly along ε: along ε the corrector
                // stays between the separatrices at the new κ, which a curve hugging one needs.
                let along_energy = t.0.abs() >= 0.2;
                let Some(q) = self.correct(k, e, &p, along_energy, s) else {
                    s *= 0.5;
                    continue;
                };
                // The corrected point should be about a step away: much nearer, the corrector
                // fell back onto the last point; much further, it jumped to another branch.
                let moved = self.distance(&p, &q);
                // … and on the same family of tori: where the followed well ends (at a cusp)
                // the component around the nearest other well, whose turning points lie
                // elsewhere, would glue another family's curve on (a wheel's N = −1 curve
                // jumped from θ ∈ [2.28, 2.39] to [1.79, 2.23] in one step).
                if moved < 0.25 * s || moved > 3.0 * s || !same_torus(&p, &q) {
                    s *= 0.5;
                    continue;
                }
                let t_new = (
                    (q.kappa - p.kappa) / scale.0 / moved,
                    (q.energy - p.energy) / scale.1 / moved,
                );
                // Too sharp a turn: a smaller step (not on the first step, whose direction
                // comes from a finite-difference gradient).
                if !half.is_empty() && t_new.0 * t.0 + t_new.1 * t.1 < 0.8 {
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
                    && same_torus(&p, &seed)
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

    /// Distance of `p` from the window's edge, in `p`'s scaled units.
    fn edge_distance(&self, p: &CurvePoint) -> f64 {
        let (k, e) = (self.options.kappa, self.options.energy);
        let scale = self.scale(p);
        let u = ((p.kappa - k.0) / scale.0).min((k.1 - p.kappa) / scale.0);
        let v = ((p.energy - e.0) / scale.1).min((e.1 - p.energy) / scale.1);
        u.min(v)
    }

    /// The distance from `a` to `b` in `a`'s scaled units.
    fn distance(&self, a: &CurvePoint, b: &CurvePoint) -> f64 {
        let scale = self.scale(a);
        ((a.kappa - b.kappa) / scale.0).hypot((a.energy - b.energy) / scale.1)
    }

    /// The κ of the seed rows: the grid's; where the window is much wider than the curves'
    /// features near κ_min (see [`Tracer::scale_at`]), [`natural_points`] from κ_min; and rows
    /// crowding towards every κ where the number of critical points of V changes (a cusp,
    /// where a separatrix ends): curves that hug a separatrix can be located in double
    /// precision only near its end, where N varies more slowly with the distance from it.
    fn seed_rows(&self) -> Vec<f64> {
        let n = self.options.grid;
        let (k0, k1) = self.options.kappa;
        let step = (k1 - k0) / n as f64;
        let count = |k: f64| {
            EffectivePotential::with_scan(self.body, k, &self.scan)
                .critical_points()
                .len()
        };
        let mut rows: Vec<f64> = (0..=n).map(|i| k0 + step * i as f64).collect();
        if self.options.natural_scales {
            rows.extend(natural_points(k0, k1, 2.0 * k0.max(1.0), n));
        }
        rows.sort_by(f64::total_cmp);
        rows.dedup();
        let counts: Vec<usize> = rows.iter().map(|&k| count(k)).collect();
        for i in 0..rows.len() - 1 {
            if counts[i] == counts[i + 1] {
                continue;
            }
            // Bisect for the change.
            let (mut a, mut b) = (rows[i], rows[i + 1]);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if count(m) == counts[i] {
                    a = m;
                } else {
                    b = m;
                }
            }
            // (On the change's own scale where the window is much wider.)
            let local = if self.options.natural_scales {
                step.min(2.0 * a.abs().max(1.0) / n as f64)
            } else {
                step
            };
            for j in 1..=12 {
                let d = local * 0.5f64.powi(j);
                rows.extend([a - d, b + d].into_iter().filter(|k| *k > k0 && *k < k1));
            }
        }
        rows
    }

    /// Points on N = p/q on the rows of the seed grid: for every well and every gap between
    /// critical levels, sign changes of N − p/q on the grid's energies, on
    /// [`natural_points`] from the gap's bottom where the window is much wider than that,
    /// and on points that approach the gap's ends geometrically, refined to the tolerance.
    fn seeds(&self) -> Vec<CurvePoint> {
        use rayon::prelude::*;
        let n = self.options.grid;
        let (e0, e1) = self.options.energy;
        let target = self.options.target;
        let tol = self.tol();
        (self.seed_rows())
            .into_par_iter()
            .flat_map_iter(|kappa| {
                if (self.stop)() {
                    return Vec::new();
                }
                let potential = EffectivePotential::with_scan(self.body, kappa, &self.scan);
                let levels = potential.separatrix_levels();
                let bottom = potential.lowest_minimum().unwrap_or(e0);
                let wells: Vec<f64> = potential
                    .critical_points()
                    .iter()
                    .filter(|p| p.kind == CriticalKind::Minimum)
                    .map(|p| p.site.theta)
                    .collect();
                let mut found = Vec::new();
                for well in wells {
                    // Asked to stop: no more cells (a profile of many points takes 30 ms a
                    // cell, and a row's scan ran on for 20 s after Ctrl-C).
                    let f = |e: f64| {
                        if (self.stop)() {
                            return None;
                        }
                        evaluate(&potential, e, well, &self.options.cell)
                            .map(|p| p.rotation_number - target)
                    };
                    let mut bounds = vec![f64::NEG_INFINITY];
                    bounds.extend(levels.iter().copied());
                    bounds.push(f64::INFINITY);
                    for gap in bounds.windows(2) {
                        let (lo, hi) = (gap[0].max(e0).max(bottom), gap[1].min(e1));
                        if lo >= hi {
                            continue;
                        }
                        let mut xs: Vec<f64> = (0..=n)
                            .map(|j| e0 + (e1 - e0) * j as f64 / n as f64)
                            .filter(|&x| x > lo && x < hi)
                            .collect();
                        if self.options.natural_scales {
                            // A gap far narrower than the window (a well's, below its
                            // separatrix) holding fewer than 4 of the window's energies gets
                            // `grid` of its own: a disk's N = 1 curve in a well 0.74 deep
                            // was missed from --energy-max 20 on (1 or 2 energies in it).
                            if xs.len() < 4 {
                                xs.extend((1..n).map(|j| lo + (hi - lo) * j as f64 / n as f64));
                            }
                            xs.extend(natural_points(lo, hi, 4.0 * lo.abs().max(1.0), n));
                        }
                        // Halving towards each end from half the gap, or from the end's
                        // own scale 4 max(1, |end|) where the gap is wider (a curve hugging
                        // a separatrix of level 3 in a window up to 1e300).
                        let half = 0.5 * (hi - lo);
                        let reach = |end: f64| half.min(4.0 * end.abs().max(1.0));
                        let (from_lo, from_hi) = (reach(lo), reach(hi));
                        for j in 1..=52 {
                            xs.push(hi - from_hi * 0.5f64.powi(j));
                            xs.push(lo + from_lo * 0.5f64.powi(j));
                        }
                        xs.retain(|&x| x > lo && x < hi);
                        xs.sort_by(f64::total_cmp);
                        xs.dedup();
                        // N − p/q with its sign, where the sign is certain: |N − p/q| above
                        // N's error estimate (far out, where N tends to p/q = 0, it is below
                        // it: its "sign changes" are rounding, and gave curves of noise).
                        let signed = |x: f64| {
                            if (self.stop)() {
                                return None;
                            }
                            evaluate(&potential, x, well, &self.options.cell).map(|p| {
                                let value = p.rotation_number - target;
                                (value, value.abs() > p.error_estimate)
                            })
                        };
                        let values: Vec<(f64, Option<(f64, bool)>)> =
                            xs.iter().map(|&x| (x, signed(x))).collect();
                        for w in values.windows(2) {
                            if let [(xa, Some((fa, true))), (xb, Some((fb, true)))] = w {
                                if (*fa > 0.0) != (*fb > 0.0) {
                                    if let Some(root) = bracketed_root(
                                        &f,
                                        (*xa, *fa),
                                        (*xb, *fb),
                                        1e-15 * xb.abs(),
                                        tol,
                                    ) {
                                        if let Some(p) =
                                            evaluate(&potential, root, well, &self.options.cell)
                                        {
                                            if self.on_curve(&p) {
                                                found.push(p);
                                            }
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
                found
            })
            .collect()
    }
}

/// Seed points in (lo, hi) on the scale `unit` of the features near `lo`, where the interval
/// is more than twice as wide (none otherwise: the grid's own points suffice): `grid` steps
/// over lo + (0, unit], then lo + unit·2^x up to `hi` for x four to an octave up to 8, one
/// an octave up to 64, one in eight octaves beyond (far out, at fixed κ, N tends to its
/// limit as ε → ∞ smoothly in log ε). A window of ε up to 1e300 takes about 200 points.
fn natural_points(lo: f64, hi: f64, unit: f64, grid: usize) -> Vec<f64> {
    if hi - lo <= 2.0 * unit || hi.is_nan() || lo.is_nan() {
        return Vec::new();
    }
    let mut out: Vec<f64> = (1..=grid)
        .map(|j| lo + unit * j as f64 / grid as f64)
        .collect();
    let octaves = (1..=32)
        .map(|i| f64::from(i) / 4.0)
        .chain((9..=64).map(f64::from))
        .chain((9..).map(|i| f64::from(8 * i)));
    out.extend(
        octaves
            .map(|x| lo + unit * x.exp2())
            .take_while(|&x| x < hi),
    );
    out
}

/// Whether two nearby points lie on the same family of tori: both turning points within
/// 0.1 rad (on the two sides of a separatrix the components, though close in (κ, ε), differ
/// by a whole well at one end).
fn same_torus(a: &CurvePoint, b: &CurvePoint) -> bool {
    (a.theta_min - b.theta_min).abs() < 0.1 && (a.theta_max - b.theta_max).abs() < 0.1
}

fn tangent((gk, ge): (f64, f64), sign: f64) -> (f64, f64) {
    let norm = gk.hypot(ge);
    (-ge / norm * sign, gk / norm * sign)
}

/// The seed scan's `grid`, as its refusal states it.
pub const GRID_RANGE: &str = "must be between 4 and 4096 (the seed scan solves about grid² cells)";

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
        return bad(
            "kappa_min",
            k0,
            "must be > 0 (at kappa = 0, N = 0 everywhere)",
        );
    }
    if !(k1.is_finite() && k1 > k0) {
        // Name both: kappa_max may be its default, not a value the user gave (a kappa_min of
        // 2.5 was blamed on "kappa_max = 2": adversary pass of 2026-11-28).
        return Err(AtlasError::Atlas {
            path: format!("invalid kappa_max = {}", crate::error::show(k1)),
            reason: format!(
                "must be finite and above kappa_min = {} (when not given, kappa_max is the \
                 default of the window)",
                crate::error::show(k0)
            ),
        });
    }
    // κ's and ε's ranges of every surface: the window's corners are cells.
    if k0 < f64::MIN_POSITIVE {
        return bad(
            "kappa_min",
            k0,
            "must be at least 2.2250738585072014e-308 (the least normal double)",
        );
    }
    if k1 > MAX_KAPPA {
        return bad(
            "kappa_max",
            k1,
            "must be at most 1e150 (kappa^2 would overflow)",
        );
    }
    for (name, e) in [("energy_min", e0), ("energy_max", e1)] {
        check_range(
            name,
            e,
            Some((-MAX_ENERGY, true)),
            Some((MAX_ENERGY, true)),
            "must be finite and at most 1e300 in size",
        )?;
    }
    if e1 <= e0 {
        // Name both: energy_min may be the window's bottom of V, not a value the user gave.
        return Err(AtlasError::Atlas {
            path: format!("invalid energy_max = {}", crate::error::show(e1)),
            reason: format!(
                "must be above energy_min = {} (when not given, the lowest minimum of V over \
                 the window): no motion lies below it, so raise energy_max (for β ≫ 1 the \
                 curves lie at large ε and κ: widen kappa_max too)",
                crate::error::show(e0)
            ),
        });
    }
    if !options.target.is_finite() {
        return bad("rotation_number", options.target, "must be finite");
    }
    // A curve's points have N = p/q to the tolerance: coarser, the band N = p/q ± tol is
    // wide enough to hold points of other curves, and the continuation wanders in it.
    check_range(
        "tol",
        options.cell.tol,
        None,
        Some((1e-4, true)),
        "must be at most 1e-4 for resonance curves (their points have N = P/Q to the tolerance)",
    )?;
    if !(4..=MAX_GRID).contains(&options.grid) {
        return bad("grid", options.grid as f64, GRID_RANGE);
    }
    options.cell.validate()
}

/// The largest seed grid: 4096² ≈ 1.7e7 cells, a few minutes on two cores (a grid of 1e10
/// asked for 80 GB and aborted).
pub const MAX_GRID: usize = 4096;

/// Every curve of the window on which a component's N equals `options.target`, found from a
/// seed scan on a grid of `options.grid` κ-rows and traced by continuation. A curve that
/// crosses no row of the seed grid (a loop smaller than the grid) is not found.
pub fn trace_curves<S: Shape>(body: &Body<S>, options: &ResonanceOptions) -> Result<Vec<Curve>> {
    trace_curves_until(body, options, &|| false)
}

/// [`trace_curves`], given up when `stop` says so (asked between seed rows and continuation
/// steps): then [`AtlasError::Stopped`].
pub fn trace_curves_until<S: Shape>(
    body: &Body<S>,
    options: &ResonanceOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Curve>> {
    check_window(options)?;
    let tracer = Tracer::new(body, options, stop);
    let stopped = || {
        if stop() {
            Err(AtlasError::Stopped)
        } else {
            Ok(())
        }
    };
    let mut curves: Vec<Curve> = Vec::new();
    let near = 1.5 / options.grid as f64;
    let seeds = tracer.seeds();
    stopped()?;
    for seed in seeds {
        stopped()?;
        let known = curves.iter().any(|c| {
            c.points
                .iter()
                .any(|p| tracer.distance(p, &seed) < near && same_torus(p, &seed))
        });
        // The gradient (four more solves) only for the seeds that start a curve.
        if !known {
            if let Some(gradient) = tracer.gradient(&seed) {
                curves.push(tracer.trace(seed, gradient));
            }
        }
    }
    stopped()?;
    // A curve traced from a seed that an earlier curve did not reach may run on over that
    // curve: keep the longer of two curves that mostly coincide.
    curves.sort_by_key(|c| std::cmp::Reverse(c.points.len()));
    let mut kept: Vec<Curve> = Vec::new();
    for c in curves {
        let covered = c
            .points
            .iter()
            .filter(|p| {
                kept.iter().any(|k| {
                    k.points
                        .iter()
                        .any(|q| tracer.distance(p, q) < near && same_torus(p, q))
                })
            })
            .count();
        if 2 * covered < c.points.len() {
            kept.push(c);
        }
    }
    Ok(stitched(&tracer, kept, near))
}

/// `curves` with every two open curves whose ends meet (within `near`, on the same torus)
/// joined into one: where the continuation cannot follow a curve through a sharp turn (its
/// component changing fast, by a cusp), the curve is traced again from a seed on the other
/// side and ends there too.
fn stitched<S: Shape>(tracer: &Tracer<'_, S>, mut curves: Vec<Curve>, near: f64) -> Vec<Curve> {
    let meet = |a: &CurvePoint, b: &CurvePoint| tracer.distance(a, b) < near && same_torus(a, b);
    'join: loop {
        for i in 0..curves.len() {
            for j in 0..curves.len() {
                if i == j || curves[i].closed || curves[j].closed {
                    continue;
                }
                // Ends of i (last, first) against ends of j (first, last).
                for (i_last, j_first) in
                    [(true, true), (true, false), (false, true), (false, false)]
                {
                    let (a, b) = (&curves[i].points, &curves[j].points);
                    let end_a = if i_last { a[a.len() - 1] } else { a[0] };
                    let end_b = if j_first { b[0] } else { b[b.len() - 1] };
                    if !meet(&end_a, &end_b) {
                        continue;
                    }
                    let mut second = curves.remove(j);
                    let first = &mut curves[if j < i { i - 1 } else { i }];
                    if !i_last {
                        first.points.reverse();
                    }
                    if !j_first {
                        second.points.reverse();
                    }
                    first.points.extend(second.points);
                    continue 'join;
                }
            }
        }
        return curves;
    }
}

/// The fold of the N = p/q curve of largest κ: the point of largest κ on the traced curves,
/// refined by a golden-section search over ε of κ(ε), where κ(ε) solves N(κ, ε) = p/q; its
/// [`Top`] says whether it is a fold (∂N/∂ε = 0) or a corner. None if no curve is found, if
/// the curve of largest κ leaves the window through κ_max, or if it is a single point.
pub fn fold<S: Shape>(body: &Body<S>, options: &ResonanceOptions) -> Result<Option<Fold>> {
    fold_until(body, options, &|| false)
}

/// [`fold`], given up when `stop` says so (asked while the curves are traced and at every
/// step of the search): then [`AtlasError::Stopped`].
pub fn fold_until<S: Shape>(
    body: &Body<S>,
    options: &ResonanceOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Option<Fold>> {
    let curves = trace_curves_until(body, options, stop)?;
    // The point of largest κ, with its neighbours on its curve.
    let Some((curve, index)) = curves
        .iter()
        .flat_map(|c| (0..c.points.len()).map(move |i| (c, i)))
        .max_by(|(c, i), (d, j)| c.points[*i].kappa.total_cmp(&d.points[*j].kappa))
    else {
        return Ok(None);
    };
    let top = curve.points[index];
    let window = options.kappa.1 - options.kappa.0;
    if top.kappa >= options.kappa.1 - 2.0 * window / options.grid as f64 {
        return Ok(None);
    }
    let tracer = Tracer::new(body, options, stop);
    let tol = options.cell.tol.max(1e-13);
    // κ(ε) on the curve near the top: the root of N − p/q in κ nearest the last one (the
    // line of constant ε may cross the curve again on its other branch, further off).
    let kappa_at = |energy: f64, start: f64| -> Option<(f64, CurvePoint)> {
        let f = |k: f64| {
            tracer
                .at(k, energy, top.well)
                .map(|p| p.rotation_number - options.target)
        };
        // (Probes on the top's own scale: in a window far wider, steps of the window's would
        // step over a curve that hugs a separatrix near the cusp.)
        let k = nearest_root(
            f,
            options.kappa.0,
            options.kappa.1,
            start,
            1e-7 * tracer.scale(&top).0,
            tol,
        )?;
        Some((k, tracer.at(k, energy, top.well)?))
    };
    // A top at an end of its curve: where it reaches the bottom of a well or runs into a
    // separatrix, κ(ε) has no maximum beyond it; where the continuation lost it just before a
    // fold (in a window far wider than the fold, adversary pass 6: 1.4291506 ± 1.4e-5 for
    // 1.4291530), it does. So the search runs over one step either side of the end, and a
    // fold found strictly inside, at least as high, stands; else the end does, a corner, its
    // error the curve's last step in κ (a search between the end and its one neighbour found
    // a maximum on another branch: 1.742 ± 0.93 for an end at 2.671).
    let at_end = !curve.closed && (index == 0 || index + 1 == curve.points.len());
    let end_corner = || -> Option<Fold> {
        let neighbour = curve.points[if index == 0 { 1 } else { index - 1 }];
        let (dn_dkappa, dn_denergy) = tracer.gradient(&top).unwrap_or((f64::NAN, f64::NAN));
        Some(Fold {
            top: Top::Corner,
            kappa_max: top.kappa,
            energy: top.energy,
            rotation_number: top.rotation_number,
            dn_denergy,
            dn_dkappa,
            kappa_error: (top.kappa - neighbour.kappa).abs(),
            well: top.well,
        })
    };
    // Golden section for the largest κ(ε) between the top's neighbours on the curve (or, at
    // an end, one step beyond it: where the search runs to that side's edge with κ still
    // above the end's, the step beyond is doubled, up to 16 steps. One step was short of a
    // fold 0.4 steps beyond an end that the continuation reached a little earlier once the
    // cells by a separatrix were sharper: 1.4291487 called a corner for 1.4291530).
    let neighbour_energy = |i: Option<usize>| i.and_then(|i| curve.points.get(i)).map(|p| p.energy);
    let inside = [
        neighbour_energy(index.checked_sub(1)),
        neighbour_energy(Some(index + 1)),
    ];
    let step_beyond = at_end.then(|| {
        let n = curve.points[if index == 0 {
            1.min(curve.points.len() - 1)
        } else {
            index - 1
        }];
        top.energy - n.energy
    });
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
    let mut reach = 1.0;
    let (bracket, energy, fc, fd) = loop {
        let bracket = inside
            .iter()
            .flatten()
            .copied()
            .chain(step_beyond.map(|step| top.energy + reach * step))
            .fold((top.energy, top.energy), |(lo, hi), e| {
                (lo.min(e), hi.max(e))
            });
        if bracket.0 == bracket.1 {
            return Ok(None);
        }
        let (mut a, mut b) = bracket;
        let (mut c, mut d) = (b - ratio * (b - a), a + ratio * (b - a));
        let (mut fc, mut fd) = (value(c, &mut start), value(d, &mut start));
        while (b - a).abs() > 1e-9 * (1.0 + top.energy.abs()) {
            if stop() {
                return Err(AtlasError::Stopped);
            }
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
        let beyond_edge = step_beyond.is_some_and(|step| {
            let edge = top.energy + reach * step;
            (energy - edge).abs() <= 1e-3 * (bracket.1 - bracket.0)
        });
        if beyond_edge && reach < 16.0 && fc.max(fd) >= top.kappa {
            reach *= 2.0;
            continue;
        }
        break (bracket, energy, fc, fd);
    };
    let Some((kappa, point)) = kappa_at(energy, start) else {
        return Ok(if at_end { end_corner() } else { None });
    };
    let (dn_dkappa, dn_denergy) = tracer.gradient(&point).unwrap_or((f64::NAN, f64::NAN));
    // The solver's tolerance through ∂N/∂κ, plus the spread of κ over the final bracket.
    let kappa_error = tol.max(point.error_estimate) / dn_dkappa.abs() + (fc - fd).abs();
    // A fold where the curve's tangent, (−∂N/∂ε, ∂N/∂κ) in scaled units, runs along ε to
    // within 3° (the finite differences of N solved to 1e-10 give the angle to ~1e-3), and
    // the top lies inside its curve.
    let scale = tracer.scale(&point);
    let (gk, ge) = (dn_dkappa * scale.0, dn_denergy * scale.1);
    let smooth = ge.abs() <= 0.05 * gk.hypot(ge);
    if at_end {
        let margin = 1e-3 * (bracket.1 - bracket.0);
        let within = energy > bracket.0 + margin && energy < bracket.1 - margin;
        if !(smooth && within && kappa >= top.kappa) {
            return Ok(end_corner());
        }
    }
    let top = if smooth { Top::Fold } else { Top::Corner };
    Ok(Some(Fold {
        top,
        kappa_max: kappa,
        energy,
        rotation_number: point.rotation_number,
        dn_denergy,
        dn_dkappa,
        kappa_error,
        well: point.well,
    }))
}
