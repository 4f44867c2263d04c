//! The verdict on the paper's boundedness hypothesis (docs/hypothesis.md) for one body over the whole
//! (κ, ε) plane: integer resonances located to the solver's tolerance, with the limits of
//! [`crate::limits`] closing the plane at ε → ∞, at the bottom of each well and at κ → 0.
//!
//! The plane of one body is mapped onto a compact set: κ-lines from the smallest κ of the
//! hypothesis's region to [`KAPPA_CEIL`] (log-spaced, plus evenly spaced ones where the
//! critical set lives), and on each line the energy ε = V_low/(1 − q)², q ∈ [0, 1), with V_low
//! the bottom of V at that κ, so q = 0 is the bottom of the deepest well (the linearised N)
//! and q → 1 is ε → ∞ (N ≈ slope·κ/√ε → 0). Beyond the last line N tends to N∞(λ),
//! λ = κ/√ε (the high-energy limit, [`crate::limits`]). Levels just above and below every
//! separatrix are added: there the period grows like −log|ε − V(θ_s)| while ψ advances at
//! ψ̇(θ_s), so N → ∓∞ (unless ψ̇(θ_s) = 0) and every integer of that sign is crossed.
//!
//! On a connected family of tori N is continuous, so an integer k lies on a resonance curve
//! wherever two neighbouring samples of one family (same well, same gap between separatrix
//! levels) have N − k of opposite signs, or a sample has N = k within its error. Each such
//! pair is refined by regula falsi to N = k within the solver's tolerance, and the point is
//! solved again with the drift: a counterexample is a point with Δζ ≠ 0 there (the centre of
//! mass then runs away linearly, docs/model.md).
//!
//! The hypothesis (docs/hypothesis.md): case 1, β² < 1 + α: bounded for every κ ≠ 0; case 2,
//! β² > 1 + α and α > 0: bounded for κ > κ_max, the top (fold) of the N = 0 curve that hugs
//! σ_u. Other bodies (α = 0 with β ≥ 1, and β² = 1 + α exactly) are not covered.

use crate::body::{Body, Ellipsoid, Shape};

mod census;
use crate::cell::{solve_component, CellOptions, Status};
use crate::critical::{CriticalSet, DiagramType};
use crate::error::{check_range, AtlasError, Result};
use crate::limits::{golden_max, golden_max_settled, HighEnergyLimit};
use crate::resonance::{self, bracketed_root, ResonanceOptions};
use crate::torus::{CriticalKind, EffectivePotential, MotionKind, ScanTable};
use crate::EllipsoidBody;
pub use census::{
    census, census_report, high_energy_scan, Census, CensusOptions, CensusReport, HighEnergyScan,
    LimitResonance, RunawayCheck, FULL_MODEL_GAP,
};
use rayon::prelude::*;
use serde::Serialize;
use std::cell::RefCell;

/// The smallest κ-line of case 1: below it N has its κ → 0 limits (±1/2 near one pole,
/// O(κ) across both, and between them in a band of width ~κ √|U″| round the level of a pole
/// where U has a maximum), see [`crate::limits::small_kappa_limit`].
pub const KAPPA_FLOOR: f64 = 1e-6;
/// The largest κ-line: above it N differs from N∞(λ) by O(1/ε) ≤ O(1/κ²) = 1e-8.
pub const KAPPA_CEIL: f64 = 1e4;
/// 1 − q on the last energies of each line: ε up to 1e12 V_low.
const HIGH_ENERGY_TAIL: [f64; 3] = [1e-3, 1e-4, 1e-6];
/// Relative offsets of the energies probed on either side of every separatrix level.
const SEPARATRIX_PROBES: [f64; 8] = [1e-1, 1e-2, 1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13];
/// The bodies the verdict decides: β and η within these bounds (α ∈ [0, 1) and ν ∈ (0, 2]
/// throughout). There the κ-lines from [`KAPPA_FLOOR`] to [`KAPPA_CEIL`] span the critical set
/// and the resonances the limits do not cover, and a verdict takes about a second at most
/// (`cargo bench --bench verdict`, docs/hypothesis.md). Beyond them the body's features move
/// off that range (the critical set's κ grows like √β, its ε like β) and the sampling no
/// longer rests on anything checked: the verdict is `undecided`, with the reason, at once.
pub const BETA_RANGE: [f64; 2] = [1e-3, 1e3];
pub const ETA_RANGE: [f64; 2] = [1e-3, 1e3];

/// Why the verdict does not decide a body outside [`BETA_RANGE`] × [`ETA_RANGE`], if so.
pub fn outside_checked_range(beta: f64, eta: f64) -> Option<String> {
    let outside = |name: &str, value: f64, [lo, hi]: [f64; 2]| {
        (!(lo..=hi).contains(&value)).then(|| {
            format!(
                "{name} = {} is outside {lo:e} <= {name} <= {hi:e}, the bodies over which the verdict's sampling is checked",
                crate::error::show(value)
            )
        })
    };
    outside("beta", beta, BETA_RANGE).or_else(|| outside("eta", eta, ETA_RANGE))
}

/// At most this many counterexamples per integer, and integers reported.
const PER_INTEGER: usize = 2;
const INTEGERS_REPORTED: usize = 6;

/// Which part of the hypothesis covers a body (docs/hypothesis.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Case {
    /// β² < 1 + α: bounded for every κ ≠ 0.
    #[serde(rename = "1")]
    One,
    /// β² > 1 + α, α > 0: bounded for κ > κ_max.
    #[serde(rename = "2")]
    Two,
    /// α = 0 with β ≥ 1, or β² = 1 + α exactly.
    #[serde(rename = "not_covered")]
    NotCovered,
}

impl Case {
    /// The case of an ellipsoid with α ≥ 0.
    pub fn of(alpha: f64, beta: f64) -> Self {
        let b2 = beta * beta;
        if b2 < 1.0 + alpha {
            Case::One
        } else if b2 > 1.0 + alpha && alpha > 0.0 {
            Case::Two
        } else {
            Case::NotCovered
        }
    }
}

/// How finely the plane is sampled, and how accurately each cell is solved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerdictOptions {
    /// The cell solver's tolerance (N at a counterexample equals the integer to this).
    pub tol: f64,
    /// κ-lines of each kind (log-spaced and evenly spaced) and base energies per line.
    pub resolution: usize,
    /// Refine the integer brackets into counterexamples (off: only the fail margin and the
    /// count of brackets, as the root-finding of [`boundaries`] needs).
    pub counterexamples: bool,
    /// Search at half the resolution first and stop there if it finds a counterexample
    /// (the `verdict` command; off for the scans of [`boundaries`], whose margins must all
    /// come from one resolution).
    pub coarse_first: bool,
}

impl Default for VerdictOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            resolution: 64,
            counterexamples: true,
            coarse_first: false,
        }
    }
}

/// A point on an integer resonance where the path runs away (docs/hypothesis.md contract).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Counterexample {
    pub kappa: f64,
    pub energy: f64,
    pub rotation_number: f64,
    pub theta_min: f64,
    pub theta_max: f64,
    /// The integer N is on.
    pub integer: i64,
    /// The solver's error estimate of N there.
    pub error_estimate: f64,
    /// |Δζ| over one θ-period, and its error estimate: the drift per period.
    pub drift: f64,
    pub drift_error: f64,
    /// The family of the torus it lies on.
    pub family: crate::family::Family,
    /// Its index among the cell's components in increasing θ_min (as `cell --json` lists
    /// them and `trajectory --component` takes it).
    pub component: usize,
    /// The cell's status there, as `cell` reports it: `ok` for a verdict; a census also takes
    /// a point whose N is within the tolerance while another output is not (T beside a
    /// separatrix), `tolerance_not_reached`.
    pub status: Status,
}

/// What a verdict rests on.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evidence {
    /// The κ range sampled by lines, [smallest, largest].
    pub kappa_range: [f64; 2],
    pub kappa_lines: usize,
    /// Base energies per line (plus the well bottoms, the high-energy tail and the levels
    /// around each separatrix).
    pub energies_per_line: usize,
    /// Components solved.
    pub components_solved: usize,
    /// [min, max] of N over the samples of the region and N∞.
    pub rotation_number_range: [f64; 2],
    /// Pairs of neighbouring samples with an integer between their N, and samples on an
    /// integer within their error bar: each one a point of an integer resonance curve.
    pub integer_brackets: usize,
    /// Brackets whose refinement did not give a counterexample (the drift vanished there, or
    /// the family changed shape between the samples).
    pub refinement_failures: usize,
    /// A failure the high-energy limit proves beyond the sampled lines (and why), when the
    /// lines themselves may not show it: close to a boundary the resonance moves off to
    /// κ → ∞.
    pub limit_failure: Option<String>,
    /// Why a covered body has no verdict (`holds` null), if so.
    pub undecided: Option<String>,
    /// The limits that close the plane beyond the samples.
    pub limits: Vec<&'static str>,
}

/// The verdict for one body (docs/hypothesis.md contract of `rubber-atlas verdict`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    pub alpha: f64,
    pub beta: f64,
    pub nu: f64,
    pub eta: f64,
    pub diagram_type: DiagramType,
    pub case: Case,
    /// true / false; None when the hypothesis does not cover the body, or (case 2) when
    /// κ_max could not be found and nothing beyond it fails (`evidence.undecided` says so).
    pub holds: Option<bool>,
    /// The fold of the N = 0 curve that hugs σ_u (case 2).
    pub kappa_max: Option<f64>,
    pub kappa_max_error: Option<f64>,
    pub counterexamples: Vec<Counterexample>,
    pub high_energy: HighEnergyLimit,
    /// The fail margin F = max(min(sup ñ, −inf ñ), N_max − 1, −1 − N_min) over the region
    /// (ñ = N √ε/κ, which has N's sign and stays finite where N → 0 at the edges): positive
    /// where N reaches an integer in the region, negative where it holds. Continuous in the
    /// body's parameters: the quantity `--boundaries` finds the roots of.
    pub fail_margin: f64,
    /// The terms of the fail margin (None when the body is not covered).
    pub margins: Option<Margins>,
    pub evidence: Evidence,
}

/// One solved component on a κ-line.
#[derive(Debug, Clone, Copy)]
struct Sample {
    kappa: f64,
    energy: f64,
    /// Index of the base energy grid (None for bottoms, tails and separatrix probes).
    grid: Option<usize>,
    /// Number of separatrix levels below ε.
    gap: usize,
    /// Rank (by θ) of the minimum of V the component surrounds, among the line's minima.
    well: usize,
    /// Numbers of minima and maxima of V on the line (the family's shape).
    shape: (usize, usize),
    n: f64,
    error: f64,
    /// The tolerance the cell was solved to (its sign is no surer than that).
    tol: f64,
}

/// The q of base energy i: clustered at both ends (the bottom and ε → ∞).
fn grid_q(i: usize, count: usize) -> f64 {
    0.5 * (1.0 - (std::f64::consts::PI * i as f64 / count as f64).cos())
}

/// The κ-lines: log-spaced from `lo` to [`KAPPA_CEIL`], and evenly spaced from `lo` to
/// `linear_top`, where the critical set lives.
pub fn kappa_lines(lo: f64, linear_top: f64, resolution: usize) -> Vec<f64> {
    let (l0, l1) = (lo.ln(), KAPPA_CEIL.ln());
    let mut k: Vec<f64> = (0..=resolution)
        .map(|i| {
            (l0 + (l1 - l0) * i as f64 / resolution as f64)
                .exp()
                .min(KAPPA_CEIL)
        })
        .chain((0..=resolution).map(|i| lo + (linear_top - lo) * i as f64 / resolution as f64))
        .filter(|&k| k >= lo && k <= KAPPA_CEIL)
        .collect();
    k.sort_by(f64::total_cmp);
    k.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    k
}

/// Points scanned per gap between neighbouring κ-lines for the extremes of N at the bottom
/// of a well ([`bottom_extreme_kappas`]).
const BOTTOM_SCAN: usize = 16;

/// The κ between the lines where N at the bottom of a well, the linearised
/// N_b(κ) = −ψ̇/ω of the stable permanent rotation ([`crate::limits::bottom_rotation_number`],
/// closed form), has a local extreme, smallest or largest over the wells, found by a scan of
/// [`BOTTOM_SCAN`] points (log-spaced) per gap and golden sections. Each is made a κ-line:
/// the bottom is the region's edge, along which the extreme search of the samples cannot go
/// (it moves along lines of fixed κ, ε or λ, each of which leaves the region there), and a
/// dip of N_b between two lines puts N beyond an integer in a sliver above the bottom that no
/// sample sees (α = 0.9, β = 1.6773, ν = 1.5, η = 5: N_b = −1.00009 at κ = 0.35 between
/// lines whose bottoms have −0.99 and −0.9994, and the verdict held: adversary pass 33).
///
/// Asked to `stop`, it scans no further and finds nothing (the caller then stops): at
/// resolution 1024 the scan takes seconds (Ctrl-C waited 1–5 s for it: adversary pass 34).
pub fn bottom_extreme_kappas<S: Shape>(
    body: &Body<S>,
    kappas: &[f64],
    stop: &(dyn Fn() -> bool + Sync),
) -> Vec<f64> {
    // (smallest, largest) N_b over the wells at κ; ±∞ where V has no minimum with N_b.
    let table = ScanTable::new(body);
    let bottoms = |kappa: f64| -> [f64; 2] {
        let potential = EffectivePotential::with_scan(body, kappa, &table);
        potential
            .critical_points()
            .iter()
            .filter_map(|c| crate::limits::bottom_rotation_number(&potential, c))
            .filter(|n| n.is_finite())
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], n| {
                [lo.min(n), hi.max(n)]
            })
    };
    let mut scan: Vec<f64> = kappas
        .windows(2)
        .flat_map(|w| {
            let ratio = w[1] / w[0];
            (0..BOTTOM_SCAN).map(move |i| w[0] * ratio.powf(i as f64 / BOTTOM_SCAN as f64))
        })
        .collect();
    scan.extend(kappas.last());
    let values: Option<Vec<[f64; 2]>> = scan
        .par_iter()
        .map(|&k| (!stop()).then(|| bottoms(k)))
        .collect();
    let Some(values) = values else {
        return Vec::new();
    };
    let mut found = Vec::new();
    for (slot, sign) in [(0, -1.0), (1, 1.0)] {
        let f = |k: f64| sign * bottoms(k)[slot];
        for i in 1..scan.len().saturating_sub(1) {
            let [l, c, r] = [i - 1, i, i + 1].map(|j| sign * values[j][slot]);
            // A local extreme standing out of its neighbours by more than the sign floor,
            // relative where |N_b| > 1 (below that it cannot move any verdict, and flat
            // stretches of N_b at large κ vary by roundings alone).
            if !(c.is_finite() && c > l.max(r) + SIGN_FLOOR * c.abs().max(1.0)) {
                continue;
            }
            let (x, _) = golden_max(|u| f(u.exp()), scan[i - 1].ln(), scan[i + 1].ln(), 1e-9);
            let x = x.exp();
            // Not beside a line already there (within the sections' reach, where N_b differs
            // from its extreme by its curvature times 1e-14 κ²).
            let near = |k: f64| (k - x).abs() <= 1e-7 * x;
            if !kappas.iter().chain(&found).any(|&k| near(k)) {
                found.push(x);
            }
        }
    }
    found
}

/// The κ-lines of [`kappa_lines`] with those at the extremes of N at the bottom
/// ([`bottom_extreme_kappas`]) added.
fn lines_with_bottom_extremes<S: Shape>(
    body: &Body<S>,
    lo: f64,
    linear_top: f64,
    resolution: usize,
    stop: &(dyn Fn() -> bool + Sync),
) -> Vec<f64> {
    let mut k = kappa_lines(lo, linear_top, resolution);
    let extra = bottom_extreme_kappas(body, &k, stop);
    k.extend(extra);
    k.sort_by(f64::total_cmp);
    k.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    k
}

/// The energy of base grid point i at the bottom `low`: ε = low / (1 − q)².
fn grid_energy(low: f64, q: f64) -> f64 {
    low / ((1.0 - q) * (1.0 - q))
}

struct Sampler<'a, S: Shape> {
    body: &'a Body<S>,
    /// The body's part of V's critical-point scan, made once for all lines.
    scan: ScanTable,
    cell: CellOptions,
    energies: usize,
    /// Base energies ε = V_low/(1 − q)² (the ellipsoid, whose V_low > 0), or, for any body,
    /// ε = V_low + max(|V_low|, 1)((1 − q)^{−2} − 1), which stays spread where V_low ≤ 0 or
    /// is tiny (the disk's U reaches 0 and below).
    offset_energies: bool,
    /// A point on a resonance needs only N's error within the tolerance, not every output's
    /// (the census: beside a separatrix T's relative error is the first to miss it, while N
    /// and the drift are sharp); the verdict asks for status ok.
    n_alone: bool,
    /// Solve again at [`SHARP_TOL`] an interior sample whose N is within the tolerance of an
    /// integer ([`Sampler::line`]); off where N is an integer on whole families (α = 0).
    sharpen: bool,
    /// Asked to stop: no new component is solved (the verdict then returns
    /// [`AtlasError::Stopped`]).
    stop: &'a (dyn Fn() -> bool + Sync),
}

impl<S: Shape> Sampler<'_, S> {
    /// The energy of base grid point q at the bottom `low` of a line.
    fn energy(&self, low: f64, q: f64) -> f64 {
        if self.offset_energies {
            let scale = low.abs().max(1.0);
            let floor = low - scale;
            floor + scale / ((1.0 - q) * (1.0 - q))
        } else {
            grid_energy(low, q)
        }
    }

    /// Every component at every sampled energy of the κ-line.
    fn line(&self, kappa: f64) -> Vec<Sample> {
        // (Before V's critical points and the line's energies: at resolution 4096 the lines
        // still queued after Ctrl-C took 0.5–1 s to set up and leave.)
        if (self.stop)() {
            return Vec::new();
        }
        let potential = EffectivePotential::with_scan(self.body, kappa, &self.scan);
        let minima = potential.minimum_sites();
        let levels = potential.separatrix_levels();
        let Some(low) = potential.lowest_minimum() else {
            return Vec::new();
        };
        let mut energies: Vec<(f64, Option<usize>)> = (0..self.energies)
            .map(|i| (self.energy(low, grid_q(i, self.energies)), Some(i)))
            .collect();
        energies.extend(
            HIGH_ENERGY_TAIL
                .iter()
                .map(|&t| (self.energy(low, 1.0 - t), None)),
        );
        energies.extend(
            potential
                .critical_points()
                .iter()
                .filter(|p| p.kind == CriticalKind::Minimum && p.value > low)
                .map(|p| (p.value, None)),
        );
        for &level in &levels {
            for d in SEPARATRIX_PROBES {
                let step = d * level.abs().max(1.0);
                energies.push((level - step, None));
                energies.push((level + step, None));
            }
        }
        energies.sort_by(|a, b| a.0.total_cmp(&b.0));
        let shape = (minima.len(), levels.len());
        let mut out = Vec::with_capacity(energies.len() * 2);
        for (energy, grid) in energies {
            if (self.stop)() {
                return out;
            }
            let Ok(components) = potential.components(energy) else {
                continue;
            };
            let gap = levels.iter().filter(|&&l| l < energy).count();
            for c in &components {
                if c.kind == MotionKind::Rotation {
                    continue;
                }
                let Some(m) = c.minimum() else { continue };
                let solved = |options: &CellOptions| {
                    solve_component(&potential, energy, c, options)
                        .ok()
                        .filter(|r| r.status != Status::Separatrix && r.rotation_number.is_finite())
                };
                let Some(mut r) = solved(&self.cell) else {
                    continue;
                };
                // N within the tolerance of an integer on the open plane: solved again to
                // SHARP_TOL, so that its sign is told where the cell's own estimate allows.
                // Beside the N = 0 boundary in β, N of 1e-11 at small κ and high energy (a
                // limit's value there, not a resonance) left the verdict undecided in a band
                // of 1e-3 in β (relative) at tol 1e-10, while the cells' estimates were 2e-14
                // (α = 0.5, β = 0.745: adversary pass 33).
                let mut tol = self.cell.tol;
                let near = r.error_estimate <= tol
                    && (r.rotation_number - r.rotation_number.round()).abs() <= tol;
                if self.sharpen
                    && near
                    && tol > SHARP_TOL
                    && kappa >= ON_INTEGER_KAPPA
                    && grid.is_some_and(|i| i > 0)
                {
                    let sharp = CellOptions {
                        tol: SHARP_TOL,
                        ..self.cell
                    };
                    if let Some(s) = solved(&sharp) {
                        (r, tol) = (s, SHARP_TOL);
                    }
                }
                let well = minima.iter().position(|&t| t == m.site.theta).unwrap_or(0);
                out.push(Sample {
                    kappa,
                    energy,
                    grid,
                    gap,
                    well,
                    shape,
                    n: r.rotation_number,
                    error: r.error_estimate,
                    tol,
                });
            }
        }
        out
    }

    /// N − k of the component around well `well` (rank by θ) at (κ, ε), if V there has the
    /// family's `shape` and ε lies in gap `gap`.
    fn offset(&self, kappa: f64, energy: f64, of: &Sample, k: f64) -> Option<f64> {
        self.solve(kappa, energy, of, false)
            .map(|(_, r)| r.rotation_number - k)
    }

    /// The component of `of`'s family at (κ, ε), solved to `of.tol`.
    fn solve(
        &self,
        kappa: f64,
        energy: f64,
        of: &Sample,
        drift: bool,
    ) -> Option<(usize, crate::cell::ComponentResult)> {
        if (self.stop)() {
            return None;
        }
        let potential = EffectivePotential::with_scan(self.body, kappa, &self.scan);
        let minima = potential.minimum_sites();
        let levels = potential.separatrix_levels();
        if (minima.len(), levels.len()) != of.shape {
            return None;
        }
        let gap = levels.iter().filter(|&&l| l < energy).count();
        if gap != of.gap {
            return None;
        }
        let theta = *minima.get(of.well)?;
        let components = potential.components(energy).ok()?;
        let (index, c) = components.iter().enumerate().find(|(_, c)| {
            c.kind != MotionKind::Rotation && c.minimum().map(|m| m.site.theta) == Some(theta)
        })?;
        // At the family's sample's own tolerance (SHARP_TOL for one solved again near an
        // integer, so that its neighbours keep the sign it told).
        let options = CellOptions {
            drift,
            tol: of.tol,
            ..self.cell
        };
        let r = solve_component(&potential, energy, c, &options).ok()?;
        (r.status != Status::Separatrix && r.rotation_number.is_finite()).then_some((index, r))
    }
}

/// A bracket of an integer between two samples of one family, or a sample on it.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    a: Sample,
    b: Option<Sample>,
    k: i64,
}

/// Below this, |N − k| is not a reliable sign whatever the error estimate says.
const SIGN_FLOOR: f64 = 1e-13;
/// On-integer samples are taken only from lines at κ ≥ this: closer to κ = 0, N → 0 as κ·f(ε)
/// (a limit, not a resonance) and falls below the solver's tolerance.
const ON_INTEGER_KAPPA: f64 = 1e-3;

/// The tolerance a sample near an integer is solved again to ([`Sampler::sharpen`]).
const SHARP_TOL: f64 = 1e-13;

/// The error bar within which N − k has no reliable sign: the solver's estimate, and never
/// less than the tolerance the sample was solved to (a cell solved to `tol` does not promise
/// the sign of a smaller difference).
fn ambiguity(s: &Sample) -> f64 {
    s.error.max(s.tol).max(SIGN_FLOOR)
}

/// Whether a sample's N is within its error bar ([`ambiguity`]) of an integer.
fn on_integer(s: &Sample) -> bool {
    (s.n - s.n.round()).abs() <= ambiguity(s)
}

/// Integers k strictly between the N of two samples whose N − k have reliable signs; with one
/// sample, the integer it is on within its error bar (a body whose symmetry makes N an
/// integer on a whole family, such as N ≡ 0 at α = 0). Only interior samples count alone: at
/// the bottom and at ε → ∞ N reaches 0 as a limit.
fn integers_between(a: &Sample, b: Option<&Sample>, interior: bool, out: &mut Vec<Candidate>) {
    match b {
        None => {
            let k = a.n.round();
            if interior
                && a.kappa >= ON_INTEGER_KAPPA
                && a.error <= a.tol
                && (a.n - k).abs() <= a.error
            {
                out.push(Candidate {
                    a: *a,
                    b: None,
                    k: k as i64,
                });
            }
        }
        Some(b) => {
            let (lo, hi) = (a.n.min(b.n), a.n.max(b.n));
            let first = lo.floor() as i64 + 1;
            let last = hi.ceil() as i64 - 1;
            // Near a separatrix N runs to ±∞: the integers nearest 0 are enough.
            let (first, last) = if last.saturating_sub(first) > 8 {
                let start = if first > 0 {
                    first
                } else if last < 0 {
                    last - 8
                } else {
                    -4
                };
                (start.max(first), (start + 8).min(last))
            } else {
                (first, last)
            };
            for k in first..=last {
                let kf = k as f64;
                if (a.n - kf).abs() > ambiguity(a) && (b.n - kf).abs() > ambiguity(b) {
                    out.push(Candidate {
                        a: *a,
                        b: Some(*b),
                        k,
                    });
                }
            }
        }
    }
}

/// A window of the (κ, ε) plane and the seed grid to trace in it.
type FoldWindow = ((f64, f64), (f64, f64), usize);

/// The windows in which the N = 0 curve hugging σ_u is traced for its fold, with their seed
/// grids: first a narrow one around the cusp (the fold lies a few per cent above κ_c for the
/// bodies tried), then a wide one (κ up to 2κ_c + 0.5, ε well above the cusp).
fn fold_windows(body: &EllipsoidBody, set: &CriticalSet) -> Vec<FoldWindow> {
    let Some(cusp) = set.cusp else {
        return Vec::new();
    };
    let top_of_u = set
        .theta_star
        .map_or(cusp.energy, |t| body.shape.potential(t));
    let mut out = Vec::new();
    let k0 = 0.5 * cusp.kappa;
    // (Not where the cusp is born, κ_c = 0 on the case line β² = 1 + α: a window from κ = 0
    // has no N to trace; the wide one below covers it.)
    let narrow = (k0 >= f64::MIN_POSITIVE)
        .then(|| EffectivePotential::new(body, k0).lowest_minimum())
        .flatten();
    if let Some(low) = narrow {
        let top = cusp.energy + (cusp.energy - top_of_u).max(0.05 * cusp.energy);
        out.push(((k0, 1.5 * cusp.kappa + 0.05), (low, top), 24));
    }
    if let Some(low) = EffectivePotential::new(body, 0.01).lowest_minimum() {
        let top = cusp.energy + 2.0 * (cusp.energy - low).max(1.0);
        out.push(((0.01, 2.0 * cusp.kappa + 0.5), (low, top), 48));
    }
    out
}

/// κ_max of case 2: the fold of the N = 0 curve of largest κ near σ_u, with its error. The
/// continuation of [`resonance::fold`] finds it; it is then solved from its definition
/// (N = 0, ∂N/∂ε = 0): M(κ) = max over ε of ±N(κ, ε) near the fold, and κ_max the root of
/// M, by Illinois regula falsi (the final bracket and the solver's tolerance through dM/dκ
/// bound the error).
fn kappa_max(
    body: &EllipsoidBody,
    set: &CriticalSet,
    tol: f64,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Option<(f64, f64)>> {
    // κ_max is solved at 1e-10 at the coarsest: at α = 1e-9, β = 3 N is ~1e-11 near the
    // fold, and at `--tol 1e-8` the trace and the polish at 1e-8 gave 2.1115 ± 2.1e-4 against
    // 1.6329617 ± 1.6e-4 (adversary pass 36).
    let cell = CellOptions {
        tol: tol.min(1e-10),
        drift: false,
        ..CellOptions::default()
    };
    // The curve is traced at tol 1e-10, the same at every finer tolerance: its top only
    // starts the polish below, which solves κ_max at the finer one. (Traced at 1e-13, at
    // α = 0.0061, β = 193 the curve ended at a corner 0.019 below the fold that 1e-10 found.)
    let trace = CellOptions { tol: 1e-10, ..cell };
    for (kappa, energy, grid) in fold_windows(body, set) {
        let options = ResonanceOptions {
            target: 0.0,
            kappa,
            energy,
            grid,
            cell: trace,
            max_points: 20_000,
            max_point_error: 1e-6,
            natural_scales: false,
        };
        if let Some(fold) = resonance::fold_until(body, &options, stop)? {
            // Where the top is not a smooth fold (∂N/∂ε ≠ 0 there: the curve meets a
            // separatrix or turns at a corner) the traced top stands, with the relative
            // error CORNER_ERROR.
            return Ok(Some(polish_fold(body, &fold, &cell).unwrap_or((
                fold.kappa_max,
                fold.kappa_error.max(CORNER_ERROR * fold.kappa_max),
            ))));
        }
    }
    Ok(None)
}

/// N of the component around the minimum of V nearest `well` at ε, on V at one κ (built
/// once per κ: its critical-point scan costs more than one cell).
fn n_near_well(
    potential: &EffectivePotential<'_, Ellipsoid>,
    energy: f64,
    well: f64,
    cell: &CellOptions,
) -> Option<f64> {
    resonance::evaluate(potential, energy, well, cell).map(|p| p.rotation_number)
}

/// The most evaluations of M(κ) one polish of κ_max makes (each four golden sections; at
/// most 23 on the bodies of the tests, 109 at α = 1e-6, β = 3, ν = 0.01, η = 1000 where M
/// jumps between features and no root holds).
const M_EVALUATIONS: usize = 64;

/// Relative error bar of a κ_max that could not be solved from N = 0, ∂N/∂ε = 0.
const CORNER_ERROR: f64 = 1e-4;

/// M(κ) of [`polish_fold`] at one κ: the best maximum of ±N over its windows, the height
/// above the well's bottom where it lies, and the spread of N over its section's last bracket
/// (how far M may lie above the value found).
#[derive(Debug, Clone, Copy)]
struct RidgePoint {
    kappa: f64,
    m: f64,
    height: f64,
    spread: f64,
}

fn polish_fold(
    body: &EllipsoidBody,
    fold: &resonance::Fold,
    cell: &CellOptions,
) -> Option<(f64, f64)> {
    let width = 1e-3 * (1.0 + fold.energy.abs());
    let (e0, e1) = (fold.energy - width, fold.energy + width);
    let table = ScanTable::new(body);
    let potential_at = |kappa: f64| EffectivePotential::with_scan(body, kappa, &table);
    // The sign of the extremum: N just above the fold stays on one side of 0.
    let probe = potential_at(fold.kappa_max * (1.0 + 1e-4));
    let side: Vec<f64> = (0..=8)
        .filter_map(|i| n_near_well(&probe, e0 + (e1 - e0) * i as f64 / 8.0, fold.well, cell))
        .collect();
    let sign = if side.iter().all(|&n| n < 0.0) {
        1.0
    } else if side.iter().all(|&n| n > 0.0) {
        -1.0
    } else {
        return None;
    };
    // M(κ) is at least the best of local maxima: golden sections over the whole window and
    // over windows 1e-2, 1e-3 and 1e-4 as wide (near the top the inside of the curve is a
    // tongue far narrower than the window). The windows follow the ridge of the tongue: they
    // are centred at the height above the well's bottom, ε − V_min(κ), of the maximum found
    // at the nearest κ where it is inside the curve (M > 0, a smooth maximum: its section's
    // spread finite), at first the traced top's. The bottom moves with κ (dV_min/dκ ≈ 14 at
    // α = 0.0061, β = 193, where the tongue is 1e-5 wide in ε): windows fixed in ε lost the ridge between two κ 1e-11 apart, M jumped from
    // +0.03 to −6e-4 there and the root was that jump, 1.3e-3 below the fold (adversary
    // pass 29).
    // The bottom of V at κ: its minimum nearest the fold's well (the well n_near_well takes).
    let well_bottom = |potential: &EffectivePotential<'_, Ellipsoid>| {
        potential.minimum_nearest(fold.well).map(|p| p.value)
    };
    let height_at_top = fold.energy - well_bottom(&potential_at(fold.kappa_max))?;
    let evaluations: RefCell<Vec<RidgePoint>> = RefCell::new(Vec::new());
    let m = |kappa: f64| -> Result<f64> {
        let not_found = AtlasError::NotPeriodic {
            reason: "no torus of the fold's family near it",
        };
        // (A budget: M jumping between features, its root never checked, is no fold.)
        if evaluations.borrow().len() >= M_EVALUATIONS {
            return Err(not_found);
        }
        let potential = potential_at(kappa);
        let bottom = well_bottom(&potential).ok_or(not_found.clone())?;
        let height = evaluations
            .borrow()
            .iter()
            .filter(|p| p.m > 0.0 && p.spread.is_finite())
            .min_by(|p, q| (p.kappa - kappa).abs().total_cmp(&(q.kappa - kappa).abs()))
            .map_or(height_at_top, |p| p.height);
        let centre = bottom + height;
        let at = |e: f64| {
            n_near_well(&potential, e, fold.well, cell).map_or(f64::NEG_INFINITY, |n| sign * n)
        };
        // Each section goes on until the values on its bracket agree to the tolerance: at a
        // tongue 1e-5 wide, N'' ~ 1e8 and a bracket of 1e-10 ε left M 1e-8 low.
        let (energy, v, spread) = [1.0, 1e-2, 1e-3, 1e-4]
            .iter()
            .map(|&share| {
                let (lo, hi) = (centre - share * width, centre + share * width);
                golden_max_settled(at, lo, hi, 1e-10 * (1.0 + centre.abs()), cell.tol)
            })
            .fold((f64::NAN, f64::NEG_INFINITY, f64::NAN), |best, w| {
                if w.1 > best.1 {
                    w
                } else {
                    best
                }
            });
        if !v.is_finite() {
            return Err(not_found);
        }
        evaluations.borrow_mut().push(RidgePoint {
            kappa,
            m: v,
            height: energy - bottom,
            spread,
        });
        Ok(v)
    };
    // A bracket [a, b] around the root, M(a) > 0 > M(b), only close to the traced top
    // (further off, M is not the fold's): from (a, b), a stepped down while M(a) ≤ 0 and b up
    // while M(b) ≥ 0, the steps doubling.
    let (floor, ceiling) = (fold.kappa_max * 0.99, fold.kappa_max * 1.01);
    let bracket = |(mut a, mut fa): (f64, f64), (mut b, mut fb): (f64, f64)| {
        let mut step = 1e-6 * fold.kappa_max;
        for _ in 0..30 {
            if fa > 0.0 && fb < 0.0 || a < floor || b > ceiling {
                break;
            }
            if fa <= 0.0 {
                a -= step;
                fa = m(a).ok()?;
            }
            if fb >= 0.0 {
                b += step;
                fb = m(b).ok()?;
            }
            step *= 2.0;
        }
        (fa > 0.0 && fb < 0.0 && a >= floor && b <= ceiling).then_some(((a, fa), (b, fb)))
    };
    let top = (fold.kappa_max, m(fold.kappa_max).ok()?);
    let ((mut a, mut fa), (mut b, mut fb)) = bracket(top, top)?;
    let mut root = f64::NAN;
    // The innermost evaluations on either side of a root, M(lower) > 0 > M(upper).
    let innermost = |root: f64| {
        let all = evaluations.borrow();
        let lower = *all
            .iter()
            .filter(|p| p.m > 0.0 && p.kappa <= root)
            .max_by(|p, q| p.kappa.total_cmp(&q.kappa))?;
        let upper = *all
            .iter()
            .filter(|p| p.m < 0.0 && p.kappa >= root)
            .min_by(|p, q| p.kappa.total_cmp(&q.kappa))?;
        // M(lower) > 0 is a value of N, proof enough that the curve reaches that κ; M(upper)
        // < 0 holds only as far as the section's spread bounds how far the maximum lies
        // above the value found. A maximum at an end of its window or beside points where N
        // fails (a separatrix) has no such bound: no smooth fold, the traced top stands.
        upper.spread.is_finite().then_some((lower, upper))
    };
    // M(b) < 0 is only as good as the windows at b: where they were centred before the ridge
    // near the root was known, M(b) can be a false negative and the root a jump of M. So the
    // root is checked from just above it, its windows now on the ridge; M > 0 there goes on
    // upward from that κ.
    for _ in 0..8 {
        // To M's own resolution, the tolerance through its slope (no finer than 4 ulps).
        let resolution = 4.0 * cell.tol / ((fb - fa) / (b - a)).abs() / b.abs();
        let xtol = resolution.clamp(4.0 * f64::EPSILON, 1e-12);
        let width;
        (root, width) = illinois(m, (a, fa), (b, fb), xtol).ok()?;
        let above = root + 2.0 * width.max(1e-12 * root);
        let m_above = m(above).ok()?;
        if m_above < 0.0 {
            break;
        }
        ((a, fa), (b, fb)) = bracket((above, m_above), (above, m_above))?;
        root = f64::NAN;
    }
    if !root.is_finite() {
        return None;
    }
    // The root is the secant's between the innermost evaluations, within the larger of its
    // distances to them and M's own error (the tolerance and the sections' spread) through
    // the slope.
    let (lower, upper) = innermost(root)?;
    let slope = (upper.m - lower.m) / (upper.kappa - lower.kappa);
    let root = lower.kappa - lower.m / slope;
    let error = (root - lower.kappa).max(upper.kappa - root)
        + (cell.tol + upper.spread) / slope.abs().max(f64::MIN_POSITIVE);
    // M(κ) ≥ ±N(κ, ε) at every ε: where N at the traced top's energy, a little below its κ,
    // already has the sign of the inside of the curve, the root lies above that κ, and a
    // root below it is a maximum found off the curve's tongue, not M. (α = 0.075, β = 27.84:
    // the tongue of N > 0 by the fold is 1e-3 wide in ε, the golden section over ±0.04 missed
    // it, and κ_max came out 1.8e-3 low against an error of 5.8e-12, unbounded paths above
    // it; adversary pass 28.) The traced top then stands, with that step in its error.
    let below = fold.kappa_max - (16.0 * fold.kappa_error).max(1e-9 * fold.kappa_max);
    if root < below
        && n_near_well(&potential_at(below), fold.energy, fold.well, cell)
            .is_some_and(|n| sign * n > cell.tol)
    {
        return Some((fold.kappa_max, fold.kappa_max - below + fold.kappa_error));
    }
    Some((root, error))
}

/// The solver's tolerance (1e-13 … 1e-4) and the resolution (8 … 4096) of a verdict's or a
/// census's sampling, refused in one line naming the value.
fn check_sampling(tol: f64, resolution: usize) -> Result<()> {
    check_range(
        "tol",
        tol,
        Some((1e-13, true)),
        Some((1e-4, true)),
        "must satisfy 1e-13 <= tol <= 1e-4",
    )?;
    if !(8..=4096).contains(&resolution) {
        return Err(AtlasError::InvalidParameter {
            name: "resolution",
            value: resolution as f64,
            reason: "must be between 8 and 4096",
        });
    }
    // The samples of every line are held until the brackets are found: refused in one line
    // where they would not fit (at resolution 4096 under a 1 GB limit the allocator aborted
    // the process, and the Python interpreter with it: adversary pass of 2026-11-28).
    if let Some(short) = crate::machine::memory_short(sampling_memory(resolution)) {
        return Err(AtlasError::Atlas {
            path: format!("resolution {resolution}"),
            reason: format!(
                "needs {short}: ask for a smaller resolution (its samples grow as its square)"
            ),
        });
    }
    Ok(())
}

/// The memory a verdict's or a census's sampling takes at its peak, in bytes, as the
/// address-space limit counts it: 2 (r + 1) κ-lines of r base energies, about 1.2 components
/// each with their [`Sample`] and a reference to it, their vectors' growth, and 100 MB for
/// the program and its threads' allocator arenas. (Measured at resolution 256, 512 and 1024
/// on the paper's body: 28, 67 and 202 MB resident; under `ulimit -v` 350–450 MB the run at
/// 1024 still aborted, where the check counted 241 MB: adversary pass of 2026-11-28.)
pub fn sampling_memory(resolution: usize) -> f64 {
    samples_memory(resolution) + 100e6
}

/// [`sampling_memory`] less what the program takes whatever it samples: one body's samples
/// (the package samples one body a thread at once).
pub fn samples_memory(resolution: usize) -> f64 {
    let r = resolution as f64;
    let per_point = 1.6 * (std::mem::size_of::<Sample>() + std::mem::size_of::<&Sample>()) as f64;
    2.0 * (r + 1.0) * r * per_point
}

/// The verdict for one body with α ≥ 0.
pub fn verdict(body: &EllipsoidBody, options: &VerdictOptions) -> Result<Verdict> {
    verdict_until(body, options, &|| false)
}

/// Refuses α < 0: the verdict is computed for α ≥ 0 (α < 0 is the mirror image θ → π − θ).
pub fn check_alpha(alpha: f64) -> Result<()> {
    if alpha < 0.0 {
        return Err(AtlasError::InvalidParameter {
            name: "alpha",
            value: alpha,
            reason: "the verdict is computed for alpha >= 0; alpha < 0 is its mirror image theta -> pi - theta",
        });
    }
    Ok(())
}

/// [`verdict`], given up when `stop` says so (polled between components and phases): then
/// [`AtlasError::Stopped`].
pub fn verdict_until(
    body: &EllipsoidBody,
    options: &VerdictOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Verdict> {
    let stopped = || -> Result<()> {
        if stop() {
            Err(AtlasError::Stopped)
        } else {
            Ok(())
        }
    };
    let (alpha, beta) = (body.shape.alpha, body.shape.beta);
    check_alpha(alpha)?;
    check_sampling(options.tol, options.resolution)?;
    let case = Case::of(alpha, beta);
    // Beyond the checked bodies even the limit is not computed (at β = 1e10 its quadrature
    // takes a minute and means nothing): its values are null there.
    let outside = outside_checked_range(beta, body.eta);
    let high_energy = match outside {
        Some(_) => HighEnergyLimit::not_computed(),
        None => HighEnergyLimit::of_until(body, options.tol.min(1e-12), stop)?,
    };
    let diagram_type = DiagramType::of(alpha, beta);
    let mut verdict = Verdict {
        alpha,
        beta,
        nu: body.nu,
        eta: body.eta,
        diagram_type,
        case,
        holds: None,
        kappa_max: None,
        kappa_max_error: None,
        counterexamples: Vec::new(),
        high_energy,
        fail_margin: f64::NAN,
        margins: None,
        evidence: Evidence {
            kappa_range: [f64::NAN; 2],
            kappa_lines: 0,
            energies_per_line: 0,
            components_solved: 0,
            rotation_number_range: [f64::NAN; 2],
            integer_brackets: 0,
            refinement_failures: 0,
            limit_failure: None,
            undecided: None,
            limits: Vec::new(),
        },
    };
    if case == Case::NotCovered {
        return Ok(verdict);
    }
    if let Some(reason) = outside {
        verdict.evidence.undecided = Some(reason);
        return Ok(verdict);
    }
    let cell = CellOptions {
        tol: options.tol,
        drift: false,
        ..CellOptions::default()
    };
    // α = 0: V is symmetric about the equator and N ≡ 0 on every torus.
    let symmetric = alpha == 0.0;
    // The critical set, untruncated (its cusp bounds the fold's window).
    stopped()?;
    let set = CriticalSet::of(body, 400, 1e6)?;
    let cusp_kappa = set.cusp.map(|c| c.kappa);
    // Case 2 has the cusp of type (c), above which κ_max lies. Where the sampled critical
    // set does not resolve it (α → 0: σ_u shrinks into a sliver beside θ = π/2), the region
    // of the hypothesis is unknown and no line can be placed in it.
    if case == Case::Two && cusp_kappa.is_none() {
        verdict.evidence.undecided = Some(
            "the cusp of diagram type (c) is not resolved by the sampled critical set (sigma_u \
             is too narrow at this alpha), so kappa_max and the region of the hypothesis are \
             unknown"
                .to_string(),
        );
        return Ok(verdict);
    }
    // The region of the hypothesis: κ > 0 (case 1) or κ > κ_max (case 2).
    let mut undecided = None;
    let lo = match case {
        Case::Two => match kappa_max(body, &set, options.tol, stop)? {
            Some((k, err)) if k.is_finite() && err.is_finite() => {
                verdict.kappa_max = Some(k);
                verdict.kappa_max_error = Some(err);
                // Just above the fold: its own error, and a relative step past it.
                k + 4.0 * err + 1e-6 * k
            }
            // No fold found: the region of the hypothesis is unknown below some κ. Only the
            // lines beyond every window tried are examined, and only a failure there (or one
            // the high-energy limit proves) decides; otherwise the verdict is undecided.
            unresolved => {
                undecided = Some(match unresolved {
                    Some((k, _)) => format!(
                        "kappa_max not resolved: the N = 0 curve beside sigma_u tops out near kappa = {} without a finite error bar",
                        crate::error::show(k)
                    ),
                    None => "kappa_max not found: no N = 0 fold was traced beside sigma_u near the cusp"
                        .to_string(),
                });
                2.0 * cusp_kappa.unwrap_or(1.0) + 1.0
            }
        },
        _ => KAPPA_FLOOR,
    };
    if lo >= KAPPA_CEIL {
        verdict.evidence.undecided = Some(format!(
            "the region of the hypothesis starts at kappa = {}, above the last kappa-line ({KAPPA_CEIL:e})",
            crate::error::show(lo)
        ));
        return Ok(verdict);
    }
    let linear_top = (3.0 * lo).max(4.0).max(3.0 * cusp_kappa.unwrap_or(0.0));
    // A failure needs one confirmed counterexample: with `coarse_first`, half the
    // resolution is searched first, and the full one only if that finds none (a verdict that
    // holds always rests on the full sampling).
    let mut resolution = options.resolution;
    let mut coarse = None;
    if options.coarse_first && options.counterexamples && resolution >= 16 {
        let half = resolution / 2;
        let kappas = lines_with_bottom_extremes(body, lo, linear_top, half, stop);
        let sampler = Sampler {
            body,
            scan: ScanTable::new(body),
            cell,
            energies: half,
            offset_energies: false,
            n_alone: false,
            sharpen: !symmetric,
            stop,
        };
        let lines: Vec<Vec<Sample>> = kappas.par_iter().map(|&k| sampler.line(k)).collect();
        // (Before the brackets: over the lines sampled up to Ctrl-C they took up to 1.6 s at
        // resolution 4096.)
        stopped()?;
        if !counterexamples(&sampler, &brackets(&lines, symmetric))
            .0
            .is_empty()
        {
            resolution = half;
            coarse = Some((kappas, lines));
        }
    }
    stopped()?;
    let sampler = Sampler {
        body,
        scan: ScanTable::new(body),
        cell,
        energies: resolution,
        offset_energies: false,
        n_alone: false,
        sharpen: !symmetric,
        stop,
    };
    let (kappas, lines) = coarse.unwrap_or_else(|| {
        let kappas = lines_with_bottom_extremes(body, lo, linear_top, resolution, stop);
        let lines: Vec<Vec<Sample>> = kappas.par_iter().map(|&k| sampler.line(k)).collect();
        (kappas, lines)
    });
    stopped()?;
    let candidates = brackets(&lines, symmetric);
    let all: Vec<&Sample> = lines.iter().flatten().collect();
    let ((n_lo, n_hi), extremes) = rotation_number_range(&sampler, &lines, &high_energy);
    let (mut found, mut refinement_failures) = if options.counterexamples {
        counterexamples(&sampler, &candidates)
    } else {
        (Vec::new(), 0)
    };
    let mut integer_brackets = candidates.len();
    let mut path_crossings = Vec::new();
    // An extreme of N beyond −1 or 1 that no bracket of the samples holds: the crossing on the
    // way to it (the ellipsoid α = 1 − 1e-12, β = 10.417, ν = η = 0.5 held with N_min =
    // −1.0000815 at κ just above κ_max, where the path runs away: adversary pass 32). Where
    // it cannot be confirmed the body is undecided.
    for (extreme, k) in extremes.iter().zip([-1i64, 1]) {
        let Some(extreme) = extreme else { continue };
        let n = k.signum() as f64 * extreme.value;
        let beyond = (n - k as f64) * k as f64 > options.tol.max(SIGN_FLOOR);
        if !beyond || found.iter().any(|c| c.integer == k) {
            continue;
        }
        let crossing = crossing_on_path(&sampler, extreme, k);
        if options.counterexamples {
            let (more, failures) = counterexamples(&sampler, crossing.as_slice());
            found.extend(more);
            refinement_failures += failures;
        }
        let crossed = crossing.is_some();
        integer_brackets += usize::from(crossed);
        path_crossings.extend(crossing);
        let shown = if options.counterexamples {
            found.iter().any(|c| c.integer == k)
        } else {
            crossed
        };
        if !shown && undecided.is_none() {
            undecided = Some(format!(
                "N reaches {} beyond the integer {k} (its smallest or largest over the region, refined between the samples, which do not reach it), but no crossing of {k} on the way there could be confirmed",
                crate::error::show(n),
            ));
        }
    }

    // The limit κ → ∞ decides what lies beyond the last line.
    let bottom_sign = lines
        .last()
        .and_then(|l| l.iter().find(|s| s.grid == Some(0)))
        .filter(|s| s.n.abs() > ambiguity(s))
        .map_or(0.0, |s| s.n.signum());
    let limit_failure = limit_failure(&high_energy, bottom_sign);
    let mut kappa_top = *kappas.last().expect("lines");
    if let Some((_, k)) = &limit_failure {
        if options.counterexamples && !found.iter().any(|c| c.integer == *k) {
            // The resonance it proves lies at larger κ: two more lines, as far as double
            // precision resolves ε − V (κ² ≲ 1e12).
            kappa_top = *EXTRA_KAPPA_LINES.last().expect("lines");
            let (_, more, extra_failures) = search_beyond(
                &sampler,
                lines.last().map_or(&[][..], |l| &l[..]),
                symmetric,
                &mut found,
            );
            integer_brackets += more.len();
            refinement_failures += extra_failures;
        }
    }
    verdict.counterexamples = found;
    let resonant = if options.counterexamples {
        !verdict.counterexamples.is_empty()
    } else {
        !candidates.is_empty() || !path_crossings.is_empty()
    };
    if !resonant && limit_failure.is_none() && undecided.is_none() {
        undecided = limit_undecided(&high_energy).or_else(|| {
            all.iter()
                .find(|s| {
                    s.grid.is_some_and(|i| i > 0)
                        && s.kappa >= ON_INTEGER_KAPPA
                        && on_integer(s)
                })
                .map(|s| {
                    format!(
                        "N = {} +- {} at kappa = {}, energy = {} is within its error bar of the integer {}: whether N reaches it there cannot be told at tol = {}",
                        crate::error::show(s.n),
                        crate::error::show(ambiguity(s)),
                        crate::error::show(s.kappa),
                        crate::error::show(s.energy),
                        // (As a whole number: −0.0 printed "the integer -0".)
                        s.n.round() as i64,
                        crate::error::show(s.tol),
                    )
                })
        });
    }
    verdict.holds = if resonant || limit_failure.is_some() {
        Some(false)
    } else if undecided.is_some() {
        None
    } else {
        Some(true)
    };
    stopped()?;
    let margins = fail_margin(&sampler, &lines, &high_energy, (n_lo, n_hi));
    stopped()?;
    verdict.fail_margin = margins.value();
    verdict.margins = Some(margins);
    verdict.evidence = Evidence {
        kappa_range: [kappas[0], kappa_top],
        kappa_lines: kappas.len(),
        energies_per_line: resolution,
        components_solved: all.len(),
        rotation_number_range: [n_lo, n_hi],
        integer_brackets,
        refinement_failures,
        limit_failure: limit_failure.map(|(reason, _)| reason),
        undecided: if verdict.holds.is_none() { undecided } else { None },
        limits: [
            "bottom: each line starts at the deepest minimum of V (the linearised N of the stable permanent rotation, limits::bottom_rotation_number), and a line is added at each local extreme of that N between lines",
            "high energy: each line runs to epsilon = 1e12 V_low, where N = slope kappa / sqrt(epsilon) + O(1/epsilon); beyond the last line, N = N_inf(lambda) + O(1/kappa^2) (limits::HighEnergyLimit)",
            "kappa -> 0 (case 1): below kappa = 1e-6, N -> +1/2 or -1/2 near one pole and O(kappa) across both, between them (+-1/4 at the level of a pole where U has a maximum) in a band of epsilon of width about kappa sqrt|U''| there, with no integer (limits::small_kappa_limit, tested against cells)",
            "separatrices: levels 1e-1 ... 1e-13 (relative) on both sides of every maximum of V, where N -> +-infinity",
        ]
        .into_iter()
        .filter(|l| case == Case::One || !l.starts_with("kappa -> 0"))
        .collect(),
    };
    Ok(verdict)
}

/// A refined extreme ([`refined_extreme`]): its value and the way the search took to it.
struct Extreme {
    /// `sign` · `value` at the extreme.
    value: f64,
    /// The sample the search started from (it gives the family).
    start: Sample,
    /// The points (κ, ε) the search moved through, the start's first: each step is one line
    /// search's improvement along log ε at fixed λ = κ/√ε, log κ at fixed ε or log ε at fixed
    /// κ, a straight segment in (ln κ, ln ε).
    path: Vec<(f64, f64)>,
}

/// The largest `sign` · `value` over the samples that pass `eligible`, refined round the best
/// of them by golden sections until it stops growing (below), so that it follows the true
/// extremum rather than the grid. `value(N, κ, ε)`; None without an eligible sample.
fn refined_extreme<S: Shape>(
    sampler: &Sampler<'_, S>,
    lines: &[Vec<Sample>],
    sign: f64,
    eligible: &dyn Fn(&Sample) -> bool,
    value: &dyn Fn(f64, f64, f64) -> f64,
) -> Option<Extreme> {
    let of = |s: &Sample| sign * value(s.n, s.kappa, s.energy);
    let (j, i, s) = lines
        .iter()
        .enumerate()
        .flat_map(|(j, l)| l.iter().enumerate().map(move |(i, s)| (j, i, s)))
        .filter(|(_, _, s)| eligible(s))
        .max_by(|a, b| of(a.2).total_cmp(&of(b.2)))?;
    let mut best = of(s);
    let same = |t: &Sample| t.gap == s.gap && t.well == s.well;
    let line = &lines[j];
    let prev = line[..i]
        .iter()
        .rev()
        .find(|t| same(t))
        .map_or(s.energy, |t| t.energy);
    let next = line[i + 1..]
        .iter()
        .find(|t| same(t))
        .map_or(s.energy, |t| t.energy);
    // Whether a round of the search below found any value: where none of its cells tells N's
    // sign (a nearly symmetric body's N of 1e-11 at tol 1e-10), the box grew by a line each
    // round, 64 rounds of three golden sections (12 s of a 13 s verdict at α = 3e-3,
    // β = 0.3, ν = 1e-10, η = 1e-3: adversary pass of 2026-11-28).
    let seen = std::cell::Cell::new(false);
    let at = |kappa: f64, energy: f64| -> f64 {
        let v = sampler
            .solve(kappa, energy, s, false)
            .map(|(_, r)| r)
            .filter(|r| (r.rotation_number).abs() > r.error_estimate.max(s.tol).max(SIGN_FLOOR))
            .map_or(f64::NEG_INFINITY, |r| {
                sign * value(r.rotation_number, kappa, energy)
            });
        seen.set(seen.get() || v.is_finite());
        v
    };
    let log_golden = |f: &dyn Fn(f64) -> f64, a: f64, b: f64| -> (f64, f64) {
        if a == b {
            return (a, f(a));
        }
        let (x, v) = golden_max(|u| f(u.exp()), a.ln(), b.ln(), 1e-7);
        (x.exp(), v)
    };
    // The next line beyond a κ, downwards or upwards, if any (a line within rounding of it,
    // or with no samples, is passed over: the linear and the log-spaced lines can nearly
    // coincide).
    let line_beyond = |k: f64, up: bool| -> Option<f64> {
        let mut ks = lines.iter().filter_map(|l| l.first().map(|t| t.kappa));
        if up {
            ks.find(|&q| q > k * (1.0 + 1e-9))
        } else {
            ks.rev().find(|&q| q < k * (1.0 - 1e-9))
        }
    };
    let mut k_lo = line_beyond(s.kappa, false).unwrap_or(s.kappa);
    let mut k_hi = line_beyond(s.kappa, true).unwrap_or(s.kappa);
    let (mut e_lo, mut e_hi) = (prev.min(next).min(s.energy), prev.max(next).max(s.energy));
    // The family's next sample on the best line beyond an ε, downwards or upwards, if any.
    let energy_beyond = |e: f64, up: bool| -> Option<f64> {
        let es = line.iter().filter(|t| same(t)).map(|t| t.energy);
        if up {
            es.filter(|&q| q > e * (1.0 + 1e-9)).reduce(f64::min)
        } else {
            es.filter(|&q| q < e * (1.0 - 1e-9)).reduce(f64::max)
        }
    };
    // Coordinate search to convergence inside the box of the neighbouring samples and lines:
    // along log ε at fixed λ = κ/√ε, along log κ at fixed ε, along log ε at fixed κ. Far out
    // N is chiefly a function of λ, so the first two are nearly independent; line searches
    // in κ and ε alone stopped short in the valley along λ (at α = 0.9 the N = −1 boundary
    // still moved by 1.3e-3 in β from resolution 64 to 128).
    // Moves the box's edge that `x` sits on (within the golden sections' 1e-7) to the next
    // sample `beyond` it; false where there is none or `x` is inside.
    // Each time in a row an edge grows, by twice as many samples (up to `steps` of them):
    // an extreme at the end of a long slope (N → ∓½ as κ → 0 by a pole) was followed a line
    // at a time, three golden sections a line (10 s of a verdict at α = 3e-3, β = 0.3,
    // ν = 1e-10, η = 1e-3: adversary pass of 2026-11-28).
    let grow = |x: f64,
                (lo, hi): (&mut f64, &mut f64),
                beyond: &dyn Fn(f64, bool) -> Option<f64>,
                steps: &mut usize| {
        let (edge, up) = if x <= *lo * (1.0 + 1e-6) {
            (lo, false)
        } else if x >= *hi * (1.0 - 1e-6) {
            (hi, true)
        } else {
            *steps = 1;
            return false;
        };
        let mut grown = false;
        for _ in 0..*steps {
            match beyond(*edge, up) {
                Some(b) => (*edge, grown) = (b, true),
                None => break,
            }
        }
        *steps *= 2;
        grown
    };
    let (mut kappa_steps, mut energy_steps) = (1, 1);
    let (mut kappa, mut energy) = (s.kappa, s.energy);
    let mut path = vec![(kappa, energy)];
    for _ in 0..64 {
        let before = best;
        seen.set(false);
        let lambda = kappa / energy.sqrt();
        let (lo, hi) = (
            e_lo.max((k_lo / lambda).powi(2)),
            e_hi.min((k_hi / lambda).powi(2)),
        );
        if lo < hi {
            let (e, v) = log_golden(&|e| at(lambda * e.sqrt(), e), lo, hi);
            if v > best {
                (kappa, energy, best) = (lambda * e.sqrt(), e, v);
                path.push((kappa, energy));
            }
        }
        let (k, v) = log_golden(&|k| at(k, energy), k_lo, k_hi);
        if v > best {
            (kappa, best) = (k, v);
            path.push((kappa, energy));
        }
        // And along ε at fixed κ: the way along the region's edge, where λ cannot be kept.
        let (e, v) = log_golden(&|e| at(kappa, e), e_lo, e_hi);
        if v > best {
            (energy, best) = (e, v);
            path.push((kappa, energy));
        }
        if best - before <= 1e-13 * best.abs() {
            if !seen.get() {
                break;
            }
            // An extreme on the box's κ edge lies beyond it, or on the region's edge (the
            // first line, κ_max in case 2): the box grows by a line and the search goes on.
            // Likewise on the box's ε edge, by the family's next sample on the best line.
            let grown_kappa = grow(
                kappa,
                (&mut k_lo, &mut k_hi),
                &line_beyond,
                &mut kappa_steps,
            );
            let grown_energy = grow(
                energy,
                (&mut e_lo, &mut e_hi),
                &energy_beyond,
                &mut energy_steps,
            );
            if !(grown_kappa || grown_energy) {
                break;
            }
        }
    }
    Some(Extreme {
        value: best,
        start: *s,
        path,
    })
}

/// Where the refined extreme of N lies beyond the integer `k` by more than its error bar
/// while no bracket of the samples holds k (every sample on one side: the resonance lies in
/// a sliver of the plane that the grid steps over, as beside the N = −1 boundary in β), the
/// crossing on the search's path from the start to the extreme: the first step of the path
/// whose ends have N on both sides of k, as a bracket for [`counterexamples`]. None where the
/// path's points do not show it (their N is recomputed, each within its family).
fn crossing_on_path<S: Shape>(
    sampler: &Sampler<'_, S>,
    extreme: &Extreme,
    k: i64,
) -> Option<Candidate> {
    let points: Vec<Sample> = extreme
        .path
        .iter()
        .map(|&(kappa, energy)| {
            sampler
                .solve(kappa, energy, &extreme.start, false)
                .map(|(_, r)| Sample {
                    kappa,
                    energy,
                    grid: None,
                    n: r.rotation_number,
                    error: r.error_estimate,
                    ..extreme.start
                })
        })
        .collect::<Option<_>>()?;
    points.windows(2).find_map(|pair| {
        let mut found = Vec::new();
        integers_between(&pair[0], Some(&pair[1]), false, &mut found);
        found.into_iter().find(|c| c.k == k)
    })
}

/// The fail margin of the verdict (see [`Verdict::fail_margin`]). The extreme ñ and N of the
/// samples are refined ([`refined_extreme`]): a margin that follows the grid would move its
/// root, the boundary, with the resolution (N_min by 9.8e-4 in β from resolution 16 to 64 at
/// α = 0.5). The edge κ → ∞ contributes N∞(λ)/λ and N∞'s extrema.
fn fail_margin<S: Shape>(
    sampler: &Sampler<'_, S>,
    lines: &[Vec<Sample>],
    high_energy: &HighEnergyLimit,
    (n_lo, n_hi): (f64, f64),
) -> Margins {
    // The edge κ → ∞: Ñ = N∞/(λ x₀²), N's sign there, with its exact extrema.
    let edge = [high_energy.normalized_max, high_energy.normalized_min];
    let reliable = |s: &Sample| (s.n).abs() > ambiguity(s);
    // ñ = N √ε / κ: N's sign, finite where N → 0 at ε → ∞ (slope), κ → 0 (lim N/κ), κ → ∞.
    let normalized = |n: f64, kappa: f64, energy: f64| n * energy.sqrt() / kappa;
    // (sign · extreme, whether it is the edge's).
    let extreme = |sign: f64| -> (f64, bool) {
        let edge_best = edge
            .iter()
            .map(|v| sign * v)
            .fold(f64::NEG_INFINITY, f64::max);
        let sampled = refined_extreme(sampler, lines, sign, &reliable, &normalized)
            .map_or(f64::NEG_INFINITY, |e| e.value);
        (sampled.max(edge_best), edge_best >= sampled)
    };
    let (sup, sup_edge) = extreme(1.0);
    let (neg_inf, inf_edge) = extreme(-1.0);
    let both_signs = sup.min(neg_inf);
    let (n_lo_edge, n_hi_edge) = (n_lo == high_energy.n_min, n_hi == high_energy.n_max);
    Margins {
        both_signs,
        to_plus_one: n_hi - 1.0,
        to_minus_one: -1.0 - n_lo,
        from_limit: [
            if sup <= neg_inf { sup_edge } else { inf_edge },
            n_hi_edge,
            n_lo_edge,
        ],
    }
}

/// The smallest and the largest N over the samples, each refined ([`refined_extreme`]), and
/// over the high-energy limit's N∞ (κ → ∞).
/// Also the sampled extremes themselves (smallest, largest), with the way to them.
fn rotation_number_range<S: Shape>(
    sampler: &Sampler<'_, S>,
    lines: &[Vec<Sample>],
    high_energy: &HighEnergyLimit,
) -> ((f64, f64), [Option<Extreme>; 2]) {
    let n = |n: f64, _: f64, _: f64| n;
    let any = |_: &Sample| true;
    let hi = refined_extreme(sampler, lines, 1.0, &any, &n);
    let lo = refined_extreme(sampler, lines, -1.0, &any, &n);
    let value = |e: &Option<Extreme>| e.as_ref().map_or(f64::NEG_INFINITY, |e| e.value);
    (
        (
            (-value(&lo)).min(high_energy.n_min),
            value(&hi).max(high_energy.n_max),
        ),
        [lo, hi],
    )
}

/// The terms of the fail margin: each positive exactly when its resonance exists.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Margins {
    /// min(sup ñ, −inf ñ): N takes both signs (an N = 0 resonance).
    pub both_signs: f64,
    /// N_max − 1 (an N = 1 resonance).
    pub to_plus_one: f64,
    /// −1 − N_min (an N = −1 resonance).
    pub to_minus_one: f64,
    /// Whether each term (in the order above) is decided by the high-energy limit (the edge
    /// κ → ∞) rather than by a sampled cell.
    pub from_limit: [bool; 3],
}

impl Margins {
    /// The terms in order.
    pub fn terms(&self) -> [f64; 3] {
        [self.both_signs, self.to_plus_one, self.to_minus_one]
    }

    /// The same terms from the high-energy limit alone.
    pub fn of_limit(h: &HighEnergyLimit) -> [f64; 3] {
        [
            h.normalized_max.min(-h.normalized_min),
            h.n_max - 1.0,
            -1.0 - h.n_min,
        ]
    }
}

impl Margins {
    /// F, the largest term.
    pub fn value(&self) -> f64 {
        self.both_signs.max(self.to_plus_one).max(self.to_minus_one)
    }

    /// The names of the terms.
    pub const NAMES: [&'static str; 3] =
        ["N takes both signs (N = 0)", "N reaches 1", "N reaches -1"];
}

/// The lines searched beyond [`KAPPA_CEIL`] when the high-energy limit proves a resonance
/// that the regular lines did not reach.
const EXTRA_KAPPA_LINES: [f64; 3] = [3e4, 1e5, 1e6];

/// What the limit κ → ∞ proves, if anything: N → N∞(λ) uniformly on compact λ-sets, so an
/// integer k ≠ 0 inside N∞'s range, both signs of N∞ (Ñ), or a sign of Ñ against the sign of
/// N at the bottom of the largest line (which N_b keeps as κ → ∞) puts a resonance N = k on
/// every κ-line beyond some κ. Returns the reason and k.
fn limit_failure(h: &HighEnergyLimit, bottom_sign: f64) -> Option<(String, i64)> {
    let e = h.extrema_error.max(h.slope_error);
    if h.n_min < -1.0 - e {
        return Some((
            format!(
                "high energy: min N_inf = {} < -1, so N = -1 at every large kappa",
                h.n_min
            ),
            -1,
        ));
    }
    if h.n_max > 1.0 + e {
        return Some((
            format!(
                "high energy: max N_inf = {} > 1, so N = 1 at every large kappa",
                h.n_max
            ),
            1,
        ));
    }
    if h.normalized_min < -e && h.normalized_max > e {
        return Some((
            format!(
                "high energy: N_inf takes both signs (N_inf/(lambda x0^2) from {} to {}), so N = 0 at every large kappa",
                h.normalized_min, h.normalized_max
            ),
            0,
        ));
    }
    let against =
        (bottom_sign < 0.0 && h.normalized_max > e) || (bottom_sign > 0.0 && h.normalized_min < -e);
    against.then(|| {
        (
            format!(
                "high energy: N at the bottom has sign {bottom_sign} while N_inf/(lambda x0^2) reaches {}, so N = 0 at every large kappa",
                if bottom_sign < 0.0 { h.normalized_max } else { h.normalized_min }
            ),
            0,
        )
    })
}

/// Why the high-energy limit cannot support a verdict that holds, if it cannot: the extremes
/// of N∞ within their error of −1 or 1, or N∞'s sign not told apart from 0 (a sign change
/// would be an N = 0 resonance at every large κ; [`limit_failure`] takes the proven ones).
fn limit_undecided(h: &HighEnergyLimit) -> Option<String> {
    let e = h.extrema_error.max(h.slope_error);
    let show = crate::error::show;
    if h.n_min.is_nan() || e.is_nan() || h.n_min <= -1.0 + e {
        return Some(format!(
            "high energy: min N_inf = {} is within its error {} of -1",
            show(h.n_min),
            show(e)
        ));
    }
    if h.n_max.is_nan() || h.n_max >= 1.0 - e {
        return Some(format!(
            "high energy: max N_inf = {} is within its error {} of 1",
            show(h.n_max),
            show(e)
        ));
    }
    let one_sign = h.normalized_max < -e || h.normalized_min > e;
    (!one_sign).then(|| {
        format!(
            "high energy: N_inf/(lambda x0^2) runs from {} to {} (error {}): its sign is not told apart from 0",
            show(h.normalized_min),
            show(h.normalized_max),
            show(e)
        )
    })
}

/// The lines beyond the last regular one ([`EXTRA_KAPPA_LINES`]), searched when a limit
/// proves a resonance the regular lines did not reach (it lies at larger κ, as far as double
/// precision resolves ε − V: κ² ≲ 1e12). Their new counterexamples are added to `found`;
/// returns the lines, their brackets (with the `last` regular line) and the refinements that
/// failed.
fn search_beyond<S: Shape>(
    sampler: &Sampler<'_, S>,
    last: &[Sample],
    symmetric: bool,
    found: &mut Vec<Counterexample>,
) -> (Vec<Vec<Sample>>, Vec<Candidate>, usize) {
    let extra: Vec<Vec<Sample>> = EXTRA_KAPPA_LINES
        .par_iter()
        .map(|&k| sampler.line(k))
        .collect();
    let mut joined = vec![last.to_vec()];
    joined.extend(extra.iter().cloned());
    let more = brackets(&joined, symmetric);
    let (extra_found, failures) = counterexamples(sampler, &more);
    for c in extra_found {
        if !found
            .iter()
            .any(|f| f.integer == c.integer && f.kappa == c.kappa)
        {
            found.push(c);
        }
    }
    (extra, more, failures)
}

/// Integer brackets along each line (same family: gap and well) and across neighbouring
/// lines at the same base energy index. Along a line, a sample is paired with the next one of
/// its family whose N is off every integer by more than its error bar, so that a sample that
/// lands on a crossing does not hide it. Single samples on an integer count only for a body
/// whose symmetry makes N an integer on whole families (`symmetric`, α = 0: N ≡ 0); elsewhere
/// N near an integer is a value, not a resonance, until a bracket proves one.
fn brackets(lines: &[Vec<Sample>], symmetric: bool) -> Vec<Candidate> {
    let mut candidates = Vec::new();
    let interior = |s: &Sample| symmetric && s.grid.is_some_and(|i| i > 0);
    for line in lines {
        for (i, a) in line.iter().enumerate() {
            integers_between(a, None, interior(a), &mut candidates);
            if let Some(b) = line[i + 1..]
                .iter()
                .find(|b| b.gap == a.gap && b.well == a.well && !on_integer(b))
            {
                integers_between(a, Some(b), false, &mut candidates);
            }
        }
    }
    for pair in lines.windows(2) {
        for a in pair[0].iter().filter(|s| s.grid.is_some()) {
            if let Some(b) = pair[1].iter().find(|b| {
                b.grid == a.grid && b.gap == a.gap && b.well == a.well && b.shape == a.shape
            }) {
                integers_between(a, Some(b), false, &mut candidates);
            }
        }
    }
    candidates
}

/// Refines the brackets into counterexamples, per integer (those nearest 0 first): first the
/// bracket nearest κ = 1 (the most tractable to check with a trajectory), then the one of
/// largest κ (how far the resonance reaches). Returns them and the number of failed
/// refinements.
fn counterexamples<S: Shape>(
    sampler: &Sampler<'_, S>,
    candidates: &[Candidate],
) -> (Vec<Counterexample>, usize) {
    let mut integers: Vec<i64> = candidates.iter().map(|c| c.k).collect();
    integers.sort_by_key(|&k| (k.abs(), k));
    integers.dedup();
    integers.truncate(INTEGERS_REPORTED);
    let mut failures = 0;
    let mut out = Vec::new();
    for &k in &integers {
        let mut of_k: Vec<&Candidate> = candidates.iter().filter(|c| c.k == k).collect();
        of_k.sort_by(|x, y| x.a.kappa.ln().abs().total_cmp(&y.a.kappa.ln().abs()));
        let largest = of_k
            .iter()
            .copied()
            .max_by(|x, y| x.a.kappa.total_cmp(&y.a.kappa));
        let mut order: Vec<&Candidate> = of_k.iter().copied().take(1).collect();
        order.extend(largest);
        order.extend(of_k.iter().copied().skip(1).take(2));
        let mut found: Vec<Counterexample> = Vec::new();
        for c in order {
            if found.len() == PER_INTEGER {
                break;
            }
            match refine(sampler, c) {
                Some(x) if !found.iter().any(|f| f.kappa == x.kappa) => found.push(x),
                Some(_) => {}
                None => failures += 1,
            }
        }
        out.extend(found);
    }
    (out, failures)
}

/// The bracket refined to N = k by regula falsi (along ε on one line, or along the segment
/// between two lines at one base energy index), then solved with the drift: a counterexample
/// if the drift over a period exceeds its error.
fn refine<S: Shape>(sampler: &Sampler<'_, S>, c: &Candidate) -> Option<Counterexample> {
    let k = c.k as f64;
    // To the finer tolerance of the two ends: between samples solved again near the integer
    // (SHARP_TOL) a root to the sampler's tolerance stopped at the first probe, anywhere in
    // the bracket (review of adversary pass 33's fix).
    let tol = c.b.map_or(c.a.tol, |b| b.tol.min(c.a.tol));
    let family = Sample { tol, ..c.a };
    let c = &Candidate { a: family, ..*c };
    let (kappa, energy) = match c.b {
        None => (c.a.kappa, c.a.energy),
        Some(b) if b.kappa == c.a.kappa => {
            let f = |e: f64| sampler.offset(c.a.kappa, e, &c.a, k);
            let e = bracketed_root(
                f,
                (c.a.energy, c.a.n - k),
                (b.energy, b.n - k),
                1e-15 * b.energy.abs(),
                0.5 * tol,
            )?;
            (c.a.kappa, e)
        }
        Some(b) if c.a.grid.is_none() || b.grid != c.a.grid => {
            // A step of a refined extreme's search ([`crossing_on_path`]): straight in
            // (ln κ, ln ε).
            let at = |t: f64| {
                let between = |x: f64, y: f64| (x.ln() + t * (y.ln() - x.ln())).exp();
                (between(c.a.kappa, b.kappa), between(c.a.energy, b.energy))
            };
            let f = |t: f64| {
                let (kappa, energy) = at(t);
                sampler.offset(kappa, energy, &c.a, k)
            };
            let t = bracketed_root(f, (0.0, c.a.n - k), (1.0, b.n - k), 1e-15, 0.5 * tol)?;
            at(t)
        }
        Some(b) => {
            // Along κ at the base energy index of both: ε = V_low(κ) / (1 − q)².
            let q = grid_q(c.a.grid?, sampler.energies);
            let at = |t: f64| -> Option<(f64, f64)> {
                let kappa = c.a.kappa + t * (b.kappa - c.a.kappa);
                let low = EffectivePotential::with_scan(sampler.body, kappa, &sampler.scan)
                    .lowest_minimum()?;
                Some((kappa, sampler.energy(low, q)))
            };
            let f = |t: f64| {
                let (kappa, energy) = at(t)?;
                sampler.offset(kappa, energy, &c.a, k)
            };
            let t = bracketed_root(f, (0.0, c.a.n - k), (1.0, b.n - k), 1e-15, 0.5 * tol)?;
            at(t)?
        }
    };
    // Only a value the solver vouches for: status ok (every error within the tolerance), or
    // for a census N's own error within it; and N on the integer within that tolerance. At
    // the finer tolerance first; where the cell does not reach it, at the sampler's.
    let vouched = |(_, r): &(usize, crate::cell::ComponentResult), tol: f64| {
        let solved = if sampler.n_alone {
            r.status != Status::Separatrix && r.error_estimate <= tol
        } else {
            r.status == Status::Ok
        };
        solved && (r.rotation_number - k).abs() <= tol + r.error_estimate
    };
    let coarse = Sample {
        tol: sampler.cell.tol,
        ..c.a
    };
    let (component, r) = sampler
        .solve(kappa, energy, &c.a, true)
        .filter(|x| vouched(x, tol))
        .or_else(|| {
            (tol < sampler.cell.tol)
                .then(|| sampler.solve(kappa, energy, &coarse, true))
                .flatten()
                .filter(|x| vouched(x, sampler.cell.tol))
        })?;
    if r.bounded != Some(false) {
        return None;
    }
    Some(Counterexample {
        kappa,
        energy,
        rotation_number: r.rotation_number,
        theta_min: r.theta_min,
        theta_max: r.theta_max,
        integer: c.k,
        error_estimate: r.error_estimate,
        drift: r.drift,
        drift_error: r.errors.drift,
        family: r.family,
        component,
        status: r.status,
    })
}

/// Where the verdict changes along β at one α, and the quantity that decides it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Boundary {
    pub beta: f64,
    /// Bound on the error of `beta`.
    pub error: f64,
    /// What changes sign there: `case` (β² = 1 + α), a quantity of the high-energy limit
    /// (`high_energy.normalized_max`, `high_energy.n_min + 1`, …), or `verdict` (bisection
    /// on the sampled verdict, when no limit explains the change).
    pub quantity: String,
    pub case_below: Case,
    pub holds_below: Option<bool>,
    pub case_above: Case,
    pub holds_above: Option<bool>,
}

/// One β of the scan behind the boundaries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScanPoint {
    pub beta: f64,
    pub case: Case,
    pub holds: Option<bool>,
    pub kappa_max: Option<f64>,
    pub counterexamples: usize,
    pub high_energy: HighEnergyLimit,
}

/// The boundaries of the verdict along β at one α (docs/hypothesis.md contract of `verdict
/// --boundaries`), with the scan they were found from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Boundaries {
    pub alpha: f64,
    pub nu: f64,
    pub eta: f64,
    pub beta_range: [f64; 2],
    pub boundaries: Vec<Boundary>,
    pub scan: Vec<ScanPoint>,
}

/// The scan densities [`boundaries`] takes.
pub const BOUNDARY_SCANS: std::ops::RangeInclusive<usize> = 4..=10_000;

/// The β range and the scan density of [`boundaries`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryOptions {
    pub beta_min: f64,
    pub beta_max: f64,
    /// Log-spaced β of the scan (the case line β² = 1 + α is added on both sides), in
    /// [`BOUNDARY_SCANS`].
    pub scan: usize,
    pub verdict: VerdictOptions,
}

impl Default for BoundaryOptions {
    fn default() -> Self {
        Self {
            beta_min: 0.05,
            beta_max: 50.0,
            scan: 48,
            verdict: VerdictOptions::default(),
        }
    }
}

/// Relative width to which a boundary is located on the sampled plane.
const BOUNDARY_XTOL: f64 = 1e-5;

/// Least relative distance from a boundary at which its sides are judged (the labels
/// `holds_below`, `holds_above`); at least [`SIDE_BARS`] times the boundary's error bar.
const SIDE_REACH: f64 = 1e-6;

/// Error bars from a boundary at which its sides are judged (at least [`SIDE_REACH`]): just
/// beyond the bar, so that a band beside the boundary a few bars wide is not stepped over.
const SIDE_BARS: f64 = 1.5;

/// Changes beyond one per scan step that [`boundaries`] locates (where a step holds several).
const MORE_CHANGES: usize = 64;

/// Illinois regula falsi on a bracket, to a relative width `xtol`: the root and the final
/// bracket's width (a bound on its error).
fn illinois(
    f: impl Fn(f64) -> Result<f64>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    xtol: f64,
) -> Result<(f64, f64)> {
    let mut side = 0;
    for _ in 0..100 {
        if (b - a).abs() <= xtol * a.abs().max(b.abs()) {
            break;
        }
        let c = (a * fb - b * fa) / (fb - fa);
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c)?;
        if fc == 0.0 || !fc.is_finite() {
            return Ok((c, if fc == 0.0 { 0.0 } else { (b - a).abs() }));
        }
        if (fc > 0.0) == (fb > 0.0) {
            (b, fb) = (c, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    Ok((0.5 * (a + b), 0.5 * (b - a).abs()))
}

/// How far a root of a margin term on the sampled plane (`root`, in the bracket (lo, hi))
/// moves when the plane is sampled at half the resolution (`coarse`): the sampling's part of
/// the boundary's error bar (at convergence of order p ≥ 1 in the sampling step, the move
/// from half resolution is (2^p − 1) times the error left at full resolution, so at least
/// that error). Where the coarse sampling does not see the change in (lo, hi), the whole
/// bracket is the term.
fn resolution_term(
    coarse: impl Fn(f64) -> Result<f64>,
    lo: f64,
    hi: f64,
    root: f64,
    xtol: f64,
) -> Result<f64> {
    let (fa, fb) = (coarse(lo)?, coarse(hi)?);
    if !(fa.is_finite() && fb.is_finite() && (fa > 0.0) != (fb > 0.0)) {
        return Ok((hi - lo).abs());
    }
    let (coarse_root, width) = illinois(coarse, (lo, fa), (hi, fb), xtol)?;
    Ok((coarse_root - root).abs() + width)
}

fn key(v: &Verdict) -> (Case, Option<bool>) {
    (v.case, v.holds)
}

/// The β in (β_min, β_max) at which the verdict (case and holds) changes at this α. The
/// scan solves the full verdict at log-spaced β; each change is then located by root-finding
/// (Illinois regula falsi) on the fail-margin term that changes sign across it, or by bisection
/// on the verdict itself where none does. Its labels are the verdicts a few error bars (at
/// least [`SIDE_REACH`] relative) on either side of the root; where one differs from the step's
/// end on that side, the step holds another change, located in turn.
pub fn boundaries(alpha: f64, nu: f64, eta: f64, options: &BoundaryOptions) -> Result<Boundaries> {
    boundaries_until(alpha, nu, eta, options, &|| false)
}

/// How far a boundary search ([`boundaries_with`]) has come, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundarySearch {
    /// `done` of the `of` verdicts of the β scan are in.
    Scanned { done: usize, of: usize },
    /// Locating the `index`-th (from 1) of the `of` changes the scan found.
    Locating { index: usize, of: usize },
}

/// [`boundaries`], given up when `stop` says so: then [`AtlasError::Stopped`].
pub fn boundaries_until(
    alpha: f64,
    nu: f64,
    eta: f64,
    options: &BoundaryOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Boundaries> {
    boundaries_with(alpha, nu, eta, options, stop, &|_| {})
}

/// [`boundaries_until`], telling `progress` how far it has come.
pub fn boundaries_with(
    alpha: f64,
    nu: f64,
    eta: f64,
    options: &BoundaryOptions,
    stop: &(dyn Fn() -> bool + Sync),
    progress: &(dyn Fn(BoundarySearch) + Sync),
) -> Result<Boundaries> {
    let (b0, b1) = (options.beta_min, options.beta_max);
    if !(b0.is_finite() && b0 > 0.0) {
        return Err(AtlasError::InvalidParameter {
            name: "beta-min",
            value: b0,
            reason: "must be a finite number > 0",
        });
    }
    // Only bodies the verdict decides: a boundary is a change between two decided verdicts.
    // Each end is checked on its own before their order, so that the end out of range is the
    // one named (beta-min = 2⁵³ + 1 was blamed on the default beta-max).
    for (name, value) in [("beta-min", b0), ("beta-max", b1)] {
        if !(BETA_RANGE[0]..=BETA_RANGE[1]).contains(&value) {
            return Err(AtlasError::InvalidParameter {
                name,
                value,
                reason:
                    "must lie in 1e-3 ... 1e3, the bodies the verdict decides (docs/hypothesis.md)",
            });
        }
    }
    if b1 <= b0 {
        return Err(AtlasError::InvalidParameter {
            name: "beta-max",
            value: b1,
            reason: "must be above beta-min",
        });
    }
    if !(ETA_RANGE[0]..=ETA_RANGE[1]).contains(&eta) {
        return Err(AtlasError::InvalidParameter {
            name: "eta",
            value: eta,
            reason: "must lie in 1e-3 ... 1e3 for the boundaries, the bodies the verdict decides (docs/hypothesis.md)",
        });
    }
    // A boundary's error bar holds the move of its root from half the resolution; below 32
    // both can miss the same extremum (at α = 0.5 the N = −1 boundary is 9e-4 off at 16 and
    // 2e-4 at 8, where their difference is 1.4e-4).
    if !(32..=4096).contains(&options.verdict.resolution) {
        return Err(AtlasError::InvalidParameter {
            name: "resolution",
            value: options.verdict.resolution as f64,
            reason: "must be between 32 and 4096 for the boundaries (coarser sampling misses \
                     the extrema they are found on, by more than its error bar shows)",
        });
    }
    if !BOUNDARY_SCANS.contains(&options.scan) {
        return Err(AtlasError::InvalidParameter {
            name: "scan",
            value: options.scan as f64,
            reason: "must be between 4 and 10000",
        });
    }
    // Validates α, ν, η once.
    EllipsoidBody::ellipsoid(alpha, 1.0, nu, eta)?;
    let verdict_at = |beta: f64, verdict: &VerdictOptions| -> Result<Verdict> {
        verdict_until(
            &EllipsoidBody::ellipsoid(alpha, beta, nu, eta)?,
            verdict,
            stop,
        )
    };
    boundaries_by((alpha, nu, eta), options, &verdict_at, progress)
}

/// [`boundaries_with`] on checked input, with the verdict of the body at a β from
/// `verdict_at` (a stand-in in the tests of the search itself). Public for those tests only:
/// it checks none of its input.
#[doc(hidden)]
pub fn boundaries_by(
    (alpha, nu, eta): (f64, f64, f64),
    options: &BoundaryOptions,
    verdict_at: &(dyn Fn(f64, &VerdictOptions) -> Result<Verdict> + Sync),
    progress: &(dyn Fn(BoundarySearch) + Sync),
) -> Result<Boundaries> {
    let (b0, b1) = (options.beta_min, options.beta_max);
    let body = |beta: f64| EllipsoidBody::ellipsoid(alpha, beta, nu, eta);
    let run = |beta: f64| -> Result<Verdict> { verdict_at(beta, &options.verdict) };
    // Inside the root-finding only the margin is needed.
    let margin_only = VerdictOptions {
        counterexamples: false,
        ..options.verdict
    };
    let margin = |beta: f64| -> Result<Verdict> { verdict_at(beta, &margin_only) };
    // The same at half the resolution: how far a boundary on the sampled plane moves with
    // the sampling is part of its error bar.
    let coarse_only = VerdictOptions {
        resolution: (options.verdict.resolution / 2).max(8),
        ..margin_only
    };
    let coarse_margin = |beta: f64| -> Result<Verdict> { verdict_at(beta, &coarse_only) };
    // (The ends exactly as given: exp(ln 8) is 7.999999999999998.)
    let last = options.scan - 1;
    let mut betas: Vec<f64> = (0..options.scan)
        .map(|i| match i {
            0 => b0,
            i if i == last => b1,
            i => (b0.ln() + (b1.ln() - b0.ln()) * i as f64 / last as f64).exp(),
        })
        .collect();
    let case_line = (1.0 + alpha).sqrt();
    if case_line > b0 && case_line < b1 {
        betas.push(case_line * (1.0 - 1e-9));
        betas.push(case_line * (1.0 + 1e-9));
    }
    betas.sort_by(f64::total_cmp);
    // (A range a few ulps wide spaced the same β several times: adversary pass 35.)
    betas.dedup();
    let scanned = std::sync::atomic::AtomicUsize::new(0);
    let verdicts: Vec<Verdict> = betas
        .par_iter()
        .map(|&b| {
            let v = run(b);
            let done = scanned.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(BoundarySearch::Scanned {
                done,
                of: betas.len(),
            });
            v
        })
        .collect::<Result<_>>()?;
    // A change of the verdict in (lo.β, hi.β) by bisection on the verdict itself, to
    // [`BOUNDARY_XTOL`].
    let bisect_verdict = |lo: &Verdict, hi: &Verdict| -> Result<(f64, f64, String)> {
        let (mut a, mut b) = (lo.beta, hi.beta);
        while b - a > BOUNDARY_XTOL * b {
            let m = (a * b).sqrt();
            if key(&margin(m)?) == key(lo) {
                a = m;
            } else {
                b = m;
            }
        }
        Ok(((a * b).sqrt(), 0.5 * (b - a), "verdict".into()))
    };
    // Where in (lo.β, hi.β) the verdict changes, to what error, and what decides it.
    let locate_change = |lo: &Verdict, hi: &Verdict| -> Result<(f64, f64, String)> {
        if lo.case != hi.case {
            return Ok((
                case_line,
                4.0 * f64::EPSILON * case_line,
                "case: beta^2 = 1 + alpha".into(),
            ));
        }
        if let (Some(ml), Some(mh)) = (lo.margins, hi.margins) {
            let (tl, th) = (ml.terms(), mh.terms());
            // The term that changes sign across the pair decides; where the high-energy limit
            // gives it at both ends, it is root-found on the limit alone (cheap and exact).
            if let Some(t) = (0..3).find(|&t| (tl[t] > 0.0) != (th[t] > 0.0)) {
                let limit_only = ml.from_limit[t] && mh.from_limit[t];
                let tol = options.verdict.tol.min(1e-12);
                let f = |beta: f64| -> Result<f64> {
                    if limit_only {
                        Ok(Margins::of_limit(&HighEnergyLimit::of(&body(beta)?, tol)?)[t])
                    } else {
                        Ok(margin(beta)?.margins.map_or(f64::NAN, |m| m.terms()[t]))
                    }
                };
                let (fa, fb) = if limit_only {
                    (f(lo.beta)?, f(hi.beta)?)
                } else {
                    (tl[t], th[t])
                };
                if (fa > 0.0) != (fb > 0.0) && fa.is_finite() && fb.is_finite() {
                    let xtol = if limit_only { 1e-10 } else { BOUNDARY_XTOL };
                    let (root, width) = illinois(f, (lo.beta, fa), (hi.beta, fb), xtol)?;
                    let (source, error) = if limit_only {
                        ("high-energy limit", width)
                    } else {
                        let coarse = |beta: f64| -> Result<f64> {
                            Ok(coarse_margin(beta)?
                                .margins
                                .map_or(f64::NAN, |m| m.terms()[t]))
                        };
                        let moved = resolution_term(coarse, lo.beta, hi.beta, root, xtol)?;
                        ("sampled plane", width + moved)
                    };
                    let quantity = format!("fail_margin: {} ({source})", Margins::NAMES[t]);
                    return Ok((root, error, quantity));
                }
            }
        }
        bisect_verdict(lo, hi)
    };
    // The pairs of neighbouring verdicts that differ, each holding at least one change; a
    // pair whose located change is not the whole story (the verdict a few error bars from the
    // root differs from the pair's end on that side) gives the pair between them back here.
    let mut pairs: std::collections::VecDeque<(Verdict, Verdict)> = verdicts
        .windows(2)
        .filter(|p| key(&p[0]) != key(&p[1]))
        .map(|p| (p[0].clone(), p[1].clone()))
        .collect();
    let mut of = pairs.len();
    let mut found = Vec::new();
    let mut index = 0;
    while let Some((lo, hi)) = pairs.pop_front() {
        index += 1;
        progress(BoundarySearch::Locating { index, of });
        let (mut beta, mut error, mut quantity) = locate_change(&lo, &hi)?;
        // The labels are the verdicts just beyond the error bar on either side, not the
        // pair's ends: one scan step may hold two changes (at ν = 1.5, η = 5, α = 0.867 the
        // undecided band just above the case line and the N = −1 boundary at 1.7399), and a
        // band beside a boundary may be narrower than a few bars (at α = 0.1, ν = η = 0.5 an
        // undecided band 5e-6 wide just above the N = 0 boundary, whose bar is 2.4e-6; judged
        // at four bars it read "holds", adversary pass 35). (The case line's sides are the
        // scan's own β at (1 ∓ 1e-9) of it, nearer than the reach.)
        let reach_of = |beta: f64, error: f64| (SIDE_BARS * error).max(SIDE_REACH * beta);
        let sides = |beta: f64, error: f64| -> Result<(Verdict, Verdict)> {
            let reach = reach_of(beta, error);
            let side = |b: f64, end: &Verdict| -> Result<Verdict> {
                if (b - end.beta) * (beta - end.beta) > 0.0
                    && (b - beta).abs() < (end.beta - beta).abs()
                {
                    margin(b)
                } else {
                    Ok(end.clone())
                }
            };
            Ok((side(beta - reach, &lo)?, side(beta + reach, &hi)?))
        };
        let (mut below, mut above) = sides(beta, error)?;
        // A root of a fail margin that the verdict does not change across is no boundary:
        // the margin of a pair that is not holds/fails (an undecided end) need not change
        // sign where the verdict does (at α = 0.5, ν = 1e-300, η = 1e-3 a root at 1.41 ±
        // 0.045 between bodies that all fail, with the real N = −1 boundary at 1.2442 in
        // the same step; adversary pass 35). The change is then found on the verdict itself.
        // So is one whose bar reaches past an end of its step (at tol 1e-6, resolution 32
        // the same step gave 1.378 ± 0.2, "undecided below", over the band that holds).
        let unplaced = reach_of(beta, error) >= (beta - lo.beta).min(hi.beta - beta);
        if (key(&below) == key(&above) || unplaced) && quantity != "verdict" && lo.case == hi.case {
            (beta, error, quantity) = bisect_verdict(&lo, &hi)?;
            (below, above) = sides(beta, error)?;
        }
        for (a, b) in [(&lo, &below), (&above, &hi)] {
            if key(a) != key(b) && of < options.scan + MORE_CHANGES {
                of += 1;
                pairs.push_back((a.clone(), b.clone()));
            }
        }
        if key(&below) != key(&above) {
            found.push(Boundary {
                beta,
                error,
                quantity,
                case_below: below.case,
                holds_below: below.holds,
                case_above: above.case,
                holds_above: above.holds,
            });
        }
    }
    found.sort_by(|a, b| a.beta.total_cmp(&b.beta));
    Ok(Boundaries {
        alpha,
        nu,
        eta,
        beta_range: [b0, b1],
        boundaries: found,
        scan: verdicts
            .iter()
            .map(|v| ScanPoint {
                beta: v.beta,
                case: v.case,
                holds: v.holds,
                kappa_max: v.kappa_max,
                counterexamples: v.counterexamples.len(),
                high_energy: v.high_energy,
            })
            .collect(),
    })
}
