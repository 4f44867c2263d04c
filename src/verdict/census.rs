//! A boundedness report for any body (docs/bodies.md, "Which integers N reaches"): the
//! integer resonances N = k found over the whole (κ, ε) plane, each with a point where the path
//! runs away, sampled as the verdict samples the ellipsoid's plane and closed by the limits of
//! [`crate::limits`]. It claims no boundedness: the paper's hypothesis is the ellipsoid's.

use super::{
    brackets, check_sampling, counterexamples, kappa_lines, search_beyond, Counterexample,
    Evidence, Sample, Sampler, EXTRA_KAPPA_LINES, KAPPA_FLOOR, ON_INTEGER_KAPPA,
};
use crate::body::{Body, Shape};
use crate::cell::CellOptions;
use crate::error::{AtlasError, Result};
use crate::limits::{golden_max, high_energy_rotation_number};
use crate::torus::ScanTable;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::SQRT_2;

/// How a census samples the plane: the cell solver's tolerance and the resolution (κ-lines
/// of each kind, base energies per line), as for the verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CensusOptions {
    pub tol: f64,
    pub resolution: usize,
}

impl Default for CensusOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            resolution: 64,
        }
    }
}

/// N∞(λ) over 0 < λ < √2 (the high-energy limit of [`crate::limits`]), scanned.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HighEnergyScan {
    /// lim N∞ as λ → 0, that is N at fixed κ as ε → ∞: (√B/J|₀ − √B/J|π)/2, not 0 only for
    /// a body with a face.
    pub at_small_lambda: f64,
    /// The smallest and largest N∞ and where (refined by golden sections; a limit at an end
    /// of (0, √2) is reported there).
    pub n_min: f64,
    pub lambda_at_min: f64,
    pub n_max: f64,
    pub lambda_at_max: f64,
    /// The λ where N∞ changes sign: an N = 0 resonance curve that runs to ε = ∞ along
    /// κ ≈ λ√ε (to 1e-12 in λ; the middle of the bracket of samples where that search fails).
    pub zeros: Vec<f64>,
    /// The largest error estimate of the N∞ values behind these.
    pub error: f64,
}

/// Integer resonances that a limit proves, beyond what the sampled lines show: every integer
/// from `lowest` to `highest`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitResonance {
    pub lowest: i64,
    pub highest: i64,
    pub reason: String,
}

/// Which integers N reaches over the (κ, ε) plane of one body.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Census {
    /// The integers N reaches where the path runs away, a point found on each
    /// (`counterexamples`). Ascending.
    pub integers: Vec<i64>,
    /// Further integers between the N of two neighbouring samples of one family (N − k of
    /// reliable signs on both; for a body that is its own mirror image, also a sample on one
    /// within its own error bar), for which no point was confirmed (beside a separatrix, where
    /// N runs to ±∞, N's own error grows beyond the tolerance; or beyond the six integers
    /// nearest 0 that are refined): ranges [lowest, highest] of consecutive integers, those
    /// within ±100 (`evidence.rotation_number_range` shows how far N goes).
    pub bracketed: Vec<[i64; 2]>,
    /// Points on them where the path runs away (N = k to the tolerance, |Δζ| above its
    /// error): up to two each for the six integers nearest 0 (more where the lines beyond
    /// κ = 1e4 are searched).
    pub counterexamples: Vec<Counterexample>,
    /// Integers N comes within the tolerance of (samples with N's error within it, away from
    /// κ → 0 and the bottom) with no sign change that proves N reaches them: a value, not a
    /// resonance, until a tighter tolerance decides. Within ±100.
    pub near_integers: Vec<i64>,
    /// Integers the high-energy limit proves (N = k at every large κ), as ranges.
    pub from_limits: Vec<LimitResonance>,
    /// true when a counterexample was found; null otherwise (no resonance found is not a
    /// proof of boundedness for these bodies).
    pub unbounded_motion: Option<bool>,
    /// For each integer in `integers`, its point nearest κ = 1 followed in the full
    /// equations, which see the body only through its contact point: how far the centre of
    /// mass runs in a few periods against that many |Δζ| (a check independent of the
    /// quadrature).
    pub full_model_checks: Vec<RunawayCheck>,
    pub high_energy: HighEnergyScan,
    pub evidence: Evidence,
}

/// Bracketed integers are listed up to this size (near a separatrix of an extreme body the
/// samples' N reach millions: every integer between is bracketed, and the list would be that
/// long); the sampled range of N in `evidence` shows how far N goes.
const BRACKETED_LISTED: i64 = 100;

/// A point of a resonance followed in the full equations (`eqred` with the contact point,
/// [`crate::trajectory`]) from θ_min at rest in θ for `periods` θ-periods.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunawayCheck {
    pub integer: i64,
    pub kappa: f64,
    pub energy: f64,
    pub periods: f64,
    /// How far the centre of mass ends from its start.
    pub distance: f64,
    /// periods · |Δζ| from the quadrature.
    pub expected: f64,
    /// |distance − expected| / expected: the full model's own accuracy is about 1e-6 of it.
    pub relative_gap: f64,
    /// Whether the gap is within [`FULL_MODEL_GAP`].
    pub agrees: bool,
}

/// θ-periods a point is followed in the full equations.
const CHECK_PERIODS: f64 = 5.0;
/// Output samples of that run (only its end is used).
const CHECK_SAMPLES: usize = 4;

/// The relative gap of a [`RunawayCheck`] within which the full model (tol 1e-12) agrees: its
/// own accuracy is about 1e-6 of the distance on ordinary bodies (measured 2e-11 … 6e-8);
/// beyond it (a pancake 2e6 wide and 2e-6 thick: 1.3e-2) the full model does not resolve the
/// body at that tolerance, and the point rests on the quadrature alone.
pub const FULL_MODEL_GAP: f64 = 1e-4;

/// The runaway of `point` in the full equations ([`RunawayCheck`]); None where the point's
/// cell or the trajectory cannot be computed (it is then not reported).
fn full_model_check<S: Shape>(
    body: &Body<S>,
    point: &Counterexample,
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<RunawayCheck> {
    use crate::trajectory::{integrate, Model, Start};
    let options = CellOptions {
        tol: 1e-12,
        ..CellOptions::default()
    };
    let cell = crate::cell::solve_cell(body, point.kappa, point.energy, &options).ok()?;
    let c = cell.components.get(point.component)?;
    if !(c.period.is_finite() && c.drift.is_finite()) {
        return None;
    }
    let start = Start {
        kappa: point.kappa,
        theta0: c.theta_min,
        theta_dot0: 0.0,
    };
    // A body the full model resolves only by millions of steps (a pancake 2e6 wide and 2e-6
    // thick took 12 s a point, a verdict 37 s; an adversary pass) is not followed: the
    // integrator asks `stop` once per output sample and per run of 1e5 steps, so this
    // budget is the samples and 4e5 steps beyond them.
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let over_budget =
        || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= CHECK_SAMPLES + 4;
    let t = integrate(
        body,
        &start,
        Model::Full,
        CHECK_PERIODS * c.period,
        CHECK_SAMPLES,
        1e-12,
        &|| stop() || over_budget(),
    )
    .ok()?;
    let n = t.t.len().checked_sub(1)?;
    let distance = (t.x_c[n] - t.x_c[0]).hypot(t.y_c[n] - t.y_c[0]);
    let expected = CHECK_PERIODS * c.drift;
    Some(RunawayCheck {
        integer: point.integer,
        kappa: point.kappa,
        energy: point.energy,
        periods: CHECK_PERIODS,
        distance,
        expected,
        relative_gap: (distance - expected).abs() / expected,
        agrees: (distance - expected).abs() <= FULL_MODEL_GAP * expected,
    })
}

/// λ samples of the high-energy scan over (0, √2), besides the small ones.
const SCAN: usize = 96;
/// Small λ scanned besides: N∞ reaches its λ → 0 limit as λ log λ with a face.
const SMALL_LAMBDAS: [f64; 4] = [1e-8, 1e-6, 1e-4, 1e-2];

/// N∞ over (0, √2), its λ → 0 limit, extrema and sign changes, to `tol`.
pub fn high_energy_scan<S: Shape>(
    body: &Body<S>,
    tol: f64,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<HighEnergyScan> {
    // Ctrl-C is heard before each λ (a profile of 2,000 points takes 0.3 s a λ).
    let at = |l: f64| {
        if stop() {
            return Err(AtlasError::Stopped);
        }
        high_energy_rotation_number(body, l, tol)
    };
    // λ = 0 stands for the limit λ → 0 (N∞ tends to it continuously; a wheel nearly its own
    // mirror image had its sign change below the smallest λ > 0 sampled).
    let mut lambdas: Vec<f64> = std::iter::once(0.0)
        .chain(SMALL_LAMBDAS)
        .chain((1..SCAN).map(|i| SQRT_2 * i as f64 / SCAN as f64))
        .collect();
    lambdas.sort_by(f64::total_cmp);
    let values = lambdas
        .par_iter()
        .map(|&l| at(l))
        .collect::<Result<Vec<_>>>()?;
    let mut error = values.iter().map(|v| v.error).fold(0.0, f64::max);
    // The extremum of sign·N∞: an interior sample refined, else the end it tends to (the
    // λ → 0 limit is sample 0; N∞ = 0 at λ = √2).
    let mut extremum = |sign: f64| -> Result<(f64, f64)> {
        let i = (0..values.len())
            .max_by(|&a, &b| (sign * values[a].value).total_cmp(&(sign * values[b].value)))
            .expect("the scan has points");
        let (best, at_zero) = (sign * values[i].value, sign * values[0].value);
        if at_zero >= best && at_zero >= 0.0 {
            return Ok((values[0].value, 0.0));
        }
        if 0.0 >= best {
            return Ok((0.0, SQRT_2));
        }
        if i == 0 || i + 1 == values.len() {
            return Ok((values[i].value, lambdas[i]));
        }
        let (l, _) = golden_max(
            |l| at(l).map_or(f64::NEG_INFINITY, |v| sign * v.value),
            lambdas[i - 1],
            lambdas[i + 1],
            1e-9,
        );
        let v = at(l)?;
        error = error.max(v.error);
        Ok((v.value, l))
    };
    let (n_max, lambda_at_max) = extremum(1.0)?;
    let (n_min, lambda_at_min) = extremum(-1.0)?;
    // Sign changes between samples whose signs are beyond their errors.
    let mut zeros = Vec::new();
    let reliable: Vec<usize> = (0..values.len())
        .filter(|&i| values[i].value.abs() > values[i].error.max(tol))
        .collect();
    for w in reliable.windows(2) {
        let (a, b) = (w[0], w[1]);
        if values[a].value.signum() != values[b].value.signum() {
            let root = crate::resonance::bracketed_root(
                |l| at(l).ok().map(|v| v.value),
                (lambdas[a], values[a].value),
                (lambdas[b], values[b].value),
                1e-12,
                0.0,
            );
            zeros.push(root.unwrap_or(0.5 * (lambdas[a] + lambdas[b])));
        }
    }
    Ok(HighEnergyScan {
        at_small_lambda: values[0].value,
        n_min,
        lambda_at_min,
        n_max,
        lambda_at_max,
        zeros,
        error,
    })
}

/// The integers the high-energy limit proves: N → N∞(λ) uniformly on compact λ-sets as
/// κ → ∞, so an integer strictly inside N∞'s range (beyond its error), and 0 where N∞
/// changes sign, is on a resonance curve at every large κ. The limit at λ → 0 and 0 at
/// λ = √2 are approached, not reached: an integer equal to one of them is not proved.
fn limit_resonances(h: &HighEnergyScan) -> Vec<LimitResonance> {
    let e = h.error;
    let mut out = Vec::new();
    if !h.zeros.is_empty() {
        out.push(LimitResonance {
            lowest: 0,
            highest: 0,
            reason: format!(
                "high energy: N_inf changes sign at lambda = {:?}, so N = 0 on a curve to energy = infinity along kappa ~ lambda sqrt(energy)",
                h.zeros
            ),
        });
    }
    let (lo, hi) = (h.n_min + e, h.n_max - e);
    if !(lo.is_finite() && hi.is_finite()) {
        return out;
    }
    // The integers strictly inside (lo, hi), 0 apart (taken above only where N∞ changes sign).
    let first = lo.floor() as i64 + 1;
    let last = hi.ceil() as i64 - 1;
    let reason = format!(
        "high energy: N_inf runs from {} to {}, so N reaches each of these at every large kappa",
        h.n_min, h.n_max
    );
    for (lowest, highest) in [(first, last.min(-1)), (first.max(1), last)] {
        if lowest <= highest {
            out.push(LimitResonance {
                lowest,
                highest,
                reason: reason.clone(),
            });
        }
    }
    out
}

/// Ascending integers as ranges of consecutive ones.
fn ranges(mut ks: Vec<i64>) -> Vec<[i64; 2]> {
    ks.sort_unstable();
    ks.dedup();
    let mut out: Vec<[i64; 2]> = Vec::new();
    for k in ks {
        match out.last_mut() {
            Some(r) if r[1] + 1 == k => r[1] = k,
            _ => out.push([k, k]),
        }
    }
    out
}

/// The census of one body (any shape), polled for `stop` between components.
pub fn census<S: Shape>(
    body: &Body<S>,
    options: &CensusOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Census> {
    check_sampling(options.tol, options.resolution)?;
    let stopped = || {
        if stop() {
            Err(AtlasError::Stopped)
        } else {
            Ok(())
        }
    };
    let high_energy = high_energy_scan(body, options.tol.min(1e-12), stop)?;
    stopped()?;
    // As for the verdict: beyond the η over which the sampling is checked the cells stop
    // converging (at η = 1e300 a disk's cell takes 16,515 evaluations and misses the
    // tolerance; a census took minutes): no lines, and the reason, at once.
    if let Some(reason) = super::outside_checked_range(1.0, body.eta) {
        let from_limits = limit_resonances(&high_energy);
        return Ok(Census {
            integers: Vec::new(),
            bracketed: Vec::new(),
            near_integers: Vec::new(),
            counterexamples: Vec::new(),
            from_limits,
            unbounded_motion: None,
            full_model_checks: Vec::new(),
            high_energy,
            evidence: Evidence {
                kappa_range: [f64::NAN; 2],
                kappa_lines: 0,
                energies_per_line: options.resolution,
                components_solved: 0,
                rotation_number_range: [f64::NAN; 2],
                integer_brackets: 0,
                refinement_failures: 0,
                limit_failure: None,
                undecided: Some(reason.replace("the verdict's", "the census's")),
                limits: Vec::new(),
            },
        });
    }
    let sampler = Sampler {
        body,
        scan: ScanTable::new(body),
        cell: CellOptions {
            tol: options.tol,
            drift: false,
            ..CellOptions::default()
        },
        energies: options.resolution,
        offset_energies: true,
        n_alone: true,
        sharpen: false,
        stop,
    };
    let symmetric = body.shape.symmetric_about_equator();
    let kappas = kappa_lines(KAPPA_FLOOR, 4.0, options.resolution);
    let mut lines: Vec<Vec<Sample>> = kappas.par_iter().map(|&k| sampler.line(k)).collect();
    stopped()?;
    let mut candidates = brackets(&lines, symmetric);
    let (mut found, mut failures) = counterexamples(&sampler, &candidates);
    stopped()?;
    let from_limits = limit_resonances(&high_energy);
    let mut kappa_top = *kappas.last().expect("lines");
    // A resonance the limit proves but the lines did not reach lies at larger κ.
    // The integer of each proved range nearest 0 (the refined ones are the nearest 0).
    let without_point = |l: &LimitResonance| {
        let k = l.lowest.max(0).min(l.highest);
        !found.iter().any(|c| c.integer == k)
    };
    if from_limits.iter().any(without_point) {
        kappa_top = *EXTRA_KAPPA_LINES.last().expect("lines");
        let last = lines.last().cloned().unwrap_or_default();
        let (extra, more, extra_failures) = search_beyond(&sampler, &last, symmetric, &mut found);
        failures += extra_failures;
        candidates.extend(more);
        lines.extend(extra);
    }
    stopped()?;
    found.sort_by(|a, b| {
        (a.integer.abs(), a.integer)
            .cmp(&(b.integer.abs(), b.integer))
            .then(a.kappa.total_cmp(&b.kappa))
    });
    let mut integers: Vec<i64> = found.iter().map(|c| c.integer).collect();
    integers.sort_unstable();
    integers.dedup();
    let bracketed = ranges(
        candidates
            .iter()
            .map(|c| c.k)
            .filter(|k| k.abs() <= BRACKETED_LISTED && !integers.contains(k))
            .collect(),
    );
    // Samples on an integer to the tolerance without a sign change that proves N reaches it
    // (a disk 1e-12 from its own mirror image: N = −1.6e-11 ± 3.5e-13 on whole families):
    // a value, not a resonance, until a tighter tolerance decides.
    let listed =
        |k: &i64| integers.contains(k) || bracketed.iter().any(|r| (r[0]..=r[1]).contains(k));
    let mut near_integers: Vec<i64> = lines
        .iter()
        .flatten()
        .filter(|s| {
            s.grid.is_some_and(|i| i > 0)
                && s.kappa >= ON_INTEGER_KAPPA
                && s.error <= options.tol
                && (s.n - s.n.round()).abs() <= options.tol
        })
        .map(|s| s.n.round() as i64)
        .filter(|k| k.abs() <= BRACKETED_LISTED && !listed(k))
        .collect();
    near_integers.sort_unstable();
    near_integers.dedup();
    let all: Vec<&Sample> = lines.iter().flatten().collect();
    let n_range = all.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |r, s| {
        [r[0].min(s.n), r[1].max(s.n)]
    });
    let unbounded_motion = (!found.is_empty()).then_some(true);
    stopped()?;
    let full_model_checks: Vec<RunawayCheck> = integers
        .par_iter()
        .filter_map(|&k| {
            let nearest = found
                .iter()
                .filter(|c| c.integer == k)
                .min_by(|a, b| a.kappa.ln().abs().total_cmp(&b.kappa.ln().abs()))?;
            full_model_check(body, nearest, stop)
        })
        .collect();
    stopped()?;
    let undecided = found.is_empty().then(|| {
        "no point where the path runs away was found; that is no proof of boundedness for a \
         body other than the ellipsoid"
            .to_string()
    });
    Ok(Census {
        integers,
        bracketed,
        near_integers,
        counterexamples: found,
        from_limits,
        unbounded_motion,
        full_model_checks,
        high_energy,
        evidence: Evidence {
            kappa_range: [kappas[0], kappa_top],
            kappa_lines: lines.len(),
            energies_per_line: options.resolution,
            components_solved: all.len(),
            rotation_number_range: n_range,
            integer_brackets: candidates.len(),
            refinement_failures: failures,
            limit_failure: None,
            undecided,
            limits: vec![
                "bottom: each line starts at the deepest minimum of V (the linearised N of the stable permanent rotation)",
                "high energy: each line runs to energy = V_low + 1e12 max(|V_low|, 1); beyond the last line N tends to N_inf(lambda) (limits::high_energy_rotation_number, for every body)",
                "kappa -> 0: below kappa = 1e-6 N tends to +-1/2 beside a smooth pole, to +-sqrt(B/J^2)/2 beside a face (its value at the pole), and to 0 across both poles; the first line (kappa = 1e-6) holds these",
                "separatrices: levels 1e-1 ... 1e-13 (relative) on both sides of every maximum of V, where N -> +-infinity: every integer of that sign lies on a resonance curve there, the listed ones are those the samples bracket",
            ],
        },
    })
}

/// A census with the body it is of, as `verdict --shape … --json` prints it and the Python
/// package's `census` returns it: `shape`, the shape's parameters by name, `nu`, `eta`, then
/// the census's fields.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CensusReport {
    pub shape: &'static str,
    #[serde(flatten)]
    pub parameters: std::collections::BTreeMap<&'static str, f64>,
    pub nu: f64,
    pub eta: f64,
    #[serde(flatten)]
    pub census: Census,
}

/// The census of `body` with its name and parameters.
pub fn census_report(
    body: &crate::body::AnyBody,
    options: &CensusOptions,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<CensusReport> {
    let census = crate::with_body!(body, b => census(b, options, stop))?;
    let (nu, eta) = crate::with_body!(body, b => (b.nu, b.eta));
    Ok(CensusReport {
        shape: body.shape_name(),
        parameters: body.shape_parameters().into_iter().collect(),
        nu,
        eta,
        census,
    })
}
