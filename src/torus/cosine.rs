//! Librations with no saddle or tangency inside, by the cosine substitution
//! θ = θ_min + L (1 − cos φ)/2. It removes the 1/√ singularities of both turning points, so
//! the integrands of T and Δψ become smooth and 2π-periodic in φ and the trapezoid rule
//! converges geometrically; Δζ follows from the Fourier coefficients of the same samples.
//! Where the convergence is slow (a saddle just beyond an end, a pole near a turning point
//! at small κ) it stops early and the tanh-sinh path of the parent module takes over.

use super::{
    at_level_floor, interleave, largest_step, level_error, precise_sample, root_of_ratio, sample,
    weighted, Component, Convergence, DriftEstimate, EffectivePotential, LevelDrift, NodeSample,
    PeriodIntegrals, Piece, EPS, HIDDEN_PEAK, INTEGRAND_ROUNDING, LEVEL_FLOOR,
    PRECISE_NODE_ROUNDING,
};
use crate::body::{Angle, Shape};
use crate::dd::CompensatedSum;
use crate::error::Result;
use crate::quadrature::{real_fft, real_inverse_fft, IntervalNode, FINEST_COSINE_INTERVALS};
use rustfft::num_complex::Complex;
use std::cell::{OnceCell, RefCell};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::OnceLock;

/// φ-steps on [0, π] of the first level: 16, the fewest for which the level differences are
/// trusted (the coarsest of the three levels compared then has 4 steps), or 32 below tol
/// 1e-7, where the estimate (at most a digit beyond the last difference) hardly ever lets 16
/// steps pass and the level would only be overhead.
fn first_intervals(tol: f64) -> usize {
    if tol >= 1e-7 {
        16
    } else {
        32
    }
}
/// The fewest φ-steps whose level differences are trusted on a body with a narrow feature
/// of width w at θ_f: the shape's own where it has one ([`Shape::angular_feature_scale`]
/// below 1: a prolate ellipsoid's Z round θ = π/2, an oblate one's at the poles; where is
/// not known, the worst place of the libration is taken), or a dip of B where U′ crosses 0
/// (`EffectivePotential::dips_seen`, at a large η). The feature is a singularity about w off
/// the real θ-axis; the map's θ-step there is at most ℓ π/(2n), ℓ = L for the plain map and
/// sin θ_f L_s for Mercator's (dθ = sin θ ds), and the trapezoid sums on fewer than 4ℓ/w
/// steps can step over it and agree among themselves: at β = 0.0075, η = 0.098 (L = 1.5)
/// the levels of 32, 64 and 128 steps put N's error at 8e-10 where it was 4.8e-7
/// (adversary pass of 2026-11-27). With 4ℓ/w steps even the coarsest level compared (a
/// quarter of them) sees the feature, whose share of the error then falls by e^{−4} a
/// level. Beyond [`LAST_INTERVALS`] the general rule takes the libration, cut at a narrow
/// dip or, on a sharply curved shape, at its minima (`EffectivePotential::pieces`).
fn least_intervals<S: Shape>(v: &EffectivePotential<'_, S>, piece: &Piece, map: &Map) -> usize {
    let (lower, upper) = (piece.left.site.theta, piece.left.site.theta + piece.length);
    // ℓ at θ: the map's θ-step there per unit of φ-step, up to the factor sin φ/2.
    let reach = |theta: f64| match *map {
        Map::Plain { length } => length,
        Map::Mercator { length, .. } => length * theta.sin().abs(),
    };
    let widest = if lower < FRAC_PI_2 && upper > FRAC_PI_2 {
        reach(FRAC_PI_2)
    } else {
        reach(lower).max(reach(upper))
    };
    let shape = v.body.shape.angular_feature_scale();
    let mut least = if shape < 1.0 {
        4.0 * widest / shape
    } else {
        0.0
    };
    for (at, width) in v.dips_seen(lower, upper) {
        least = least.max(4.0 * reach(at) / width);
    }
    if least > LAST_INTERVALS as f64 {
        usize::MAX
    } else {
        least.ceil() as usize
    }
}

/// φ-steps on [0, π] beyond which the tanh-sinh rule is cheaper.
const LAST_INTERVALS: usize = 256;
/// The same where T and Δψ have converged and only the drift misses: one level more (256
/// nodes) costs less than taking the libration again by another map. (A disk's libration
/// 0.008 from both poles at κ = 0.01 had its drift 1.05e-10 of its scale at 256 steps, tol
/// 1e-10: the Mercator map and then the tanh-sinh rule took it again, 1,316 evaluations in
/// all; 513 with the level more.)
const DRIFT_LAST_INTERVALS: usize = 512;
const _: () = assert!(DRIFT_LAST_INTERVALS <= FINEST_COSINE_INTERVALS);

/// T, Δψ and (if `with_drift`) Δζ of a libration that is one piece (see the parent's
/// `integrate`), or, when the trapezoid rule would need more than [`LAST_INTERVALS`] steps
/// (or a turning point is too flat for the substitution to make the integrand smooth), the
/// integrand evaluations spent on finding that out (the other rule's work counts them).
pub(super) fn integrate<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    energy: f64,
    component: &Component,
    tol: f64,
    with_drift: bool,
) -> Result<std::result::Result<PeriodIntegrals, usize>> {
    let mut spent = 0;
    for map in Map::candidates(v, piece) {
        match integrate_on(v, piece, &map, energy, component, tol, with_drift)? {
            Ok(mut result) => {
                result.work += spent;
                return Ok(Ok(result));
            }
            Err(work) => spent += work,
        }
    }
    Ok(Err(spent))
}

/// [`integrate`] with one map.
fn integrate_on<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    map: &Map,
    energy: f64,
    component: &Component,
    tol: f64,
    with_drift: bool,
) -> Result<std::result::Result<PeriodIntegrals, usize>> {
    let least = least_intervals(v, piece, map);
    if least > LAST_INTERVALS {
        return Ok(Err(0));
    }
    // The gaps in double first; in double-double (where the piece's ends allow it) only
    // once the rounding of the gaps is all that keeps the values from the tolerance.
    let plain = piece.in_double();
    let mut resampled = false;
    let residual = super::level_residual(component, std::slice::from_ref(piece));
    // Whether the resampled nodes have their integrands in double-double too: decided where
    // the nodes are taken again.
    let mut precise = false;
    let precise_ends = OnceCell::new();
    let Some(mut samples) = Samples::new(v, &plain, map, energy, first_intervals(tol)) else {
        // (A node of the first level outside the allowed set: at most that level spent.)
        return Ok(Err(first_intervals(tol) + 1));
    };
    loop {
        let sums = samples.level_sums();
        let (t_sums, psi_sums) = (sums.t, sums.psi);
        let period = 2.0 * t_sums[0];
        let one_rate =
            single_rate(sums.t_coarsest, t_sums) && single_rate(sums.psi_coarsest, psi_sums);
        let rate = if one_rate {
            map.convergence()
        } else {
            Convergence::Unknown
        };
        let t_error = 2.0 * level_error(t_sums, rate);
        let psi_error = 2.0 * level_error(psi_sums, rate);
        // The quadrature gets what the tolerance leaves of the whole error estimate after the
        // rounding of the gap and the conditioning near a saddle, which refining cannot
        // reduce (when those alone exceed it, a tenth of them: the status then says so).
        let saddle = v.placed_saddle_conditioning(energy, component, period, 2.0, residual);
        let (saddle_t, saddle_psi) = (saddle.period, saddle.psi_advance);
        let extra_t = 2.0 * sums.t_rounding + saddle_t;
        let extra_psi = 2.0 * sums.psi_rounding + saddle_psi;
        let budget = |allowed: f64, extra: f64| (allowed - extra).max(0.1 * extra);
        // Where the differences may be taken as the error: the plain map's (one geometric
        // strip); the Mercator map's only where its last four levels show one rate and the
        // last differences fall as [`mercator_falling`] asks.
        let trusted = map.convergence() == Convergence::Geometric
            || (one_rate
                && mercator_falling(sums.t_coarsest, t_sums)
                && mercator_falling(sums.psi_coarsest, psi_sums));
        // A sum at the floor of `level_error` has nothing left for refinement to gain: where
        // that floor with the rounding misses the tolerance (tol ≲ 1e-14), refining on to
        // LAST_INTERVALS steps and then by the tanh-sinh rule only bought the same estimate
        // at 2–4 times the nodes.
        let mut done = samples.intervals >= least
            && trusted
            && (t_error <= budget(tol * period, extra_t) || at_level_floor(t_sums, rate))
            && (psi_error <= budget(tol * TAU, extra_psi) || at_level_floor(psi_sums, rate));
        let period_error = t_error + extra_t;
        let psi_advance_error = psi_error + extra_psi;
        // Rounding in T and Δψ enters the drift through the phases and the weights, and the
        // time spent by a saddle at the speed there (`saddle.drift`).
        let phase = (extra_t - saddle_t) / period + extra_psi;
        let drift_extra = |d: &DriftEstimate| phase * d.scale + saddle.drift;
        // The rounding the sums would carry with the nodes taken again (below), once: with
        // their integrands in double-double where the plain map's nodes (offsets and dθ/dφ a
        // table value times L) are on a shape that gives the reduction in double-double
        // ([`precise_sample`]), else with every gap to a few ulps. (Whether the shape gives
        // it is asked once a libration, and only where it matters.)
        let can_resample = !resampled && piece.left.sharp.is_some();
        let can_be_precise = || {
            can_resample
                && matches!(map, Map::Plain { .. })
                && *precise_ends.get_or_init(|| v.end_gives_precise_nodes(&piece.left))
        };
        // (The floors of T, of Δψ and of the drift's phases at `per_node`.)
        let floors = |per_node: f64| {
            let floor_t = per_node * t_sums[0] + saddle_t;
            let floor_nodes_psi = per_node * sums.psi_variation + saddle_psi;
            let floor_phase = (floor_t - saddle_t) / period + floor_nodes_psi;
            (floor_t, floor_nodes_psi, floor_phase)
        };
        // What the drift's quadrature may keep of the tolerance: what the phases' rounding
        // leaves; where that leaves nothing but the double-double nodes' rounding would leave
        // room and steps are left, that room (the drift refined so far, the nodes then taken
        // again: at tol 1e-14, 229 librations of the standard slice by its saddle stopped at
        // 128 steps with the drift's quadrature at 0.3–0.5 of the tolerance and the phases'
        // floor at 0.64).
        let steps_left = samples.intervals < LAST_INTERVALS;
        let drift_budget = |d: &DriftEstimate| {
            let (allowed, extra) = (tol * d.scale, drift_extra(d));
            if allowed - extra < 0.1 * extra && steps_left && can_be_precise() {
                let floor = floors(PRECISE_NODE_ROUNDING + EPS).2 * d.scale + saddle.drift;
                if allowed - floor > 0.1 * floor {
                    return allowed - floor;
                }
            }
            budget(allowed, extra)
        };
        // The drift (the costly part) only once T and Δψ have converged.
        let drift = (done && with_drift).then(|| samples.drift(rate));
        done &=
            drift.is_none_or(|d| d.error <= drift_budget(&d) || d.error <= LEVEL_FLOOR * d.scale);
        let drift = drift.map(|mut d| {
            d.error += drift_extra(&d);
            d
        });
        // Where the gaps' rounding is what keeps the converged sums from the tolerance, and
        // the sums' rounding with every gap to a few ulps (½ (INTEGRAND_ROUNDING + 4 eps) of
        // the L1 sizes of T and Δψ, over the whole period) would leave room for it, or would
        // be a quarter of it or less: the nodes again, with the gaps in double-double. (Also
        // where the rounding alone exceeds the tolerance, which `done` accepts: a narrow well
        // deep below a large ε, its gaps 5e-13 off in double, had T's estimate at 3e-13 of
        // it, and 6e-15 with them in double-double.)
        let over = t_error + extra_t > tol * period
            || psi_error + extra_psi > tol * TAU
            || drift.is_some_and(|d| d.error > tol * d.scale);
        if (!done || over) && can_resample {
            let can_be_precise = can_be_precise();
            let per_node = if can_be_precise {
                PRECISE_NODE_ROUNDING + EPS
            } else {
                INTEGRAND_ROUNDING + 4.0 * EPS + map.node_rounding()
            };
            let (floor_t, floor_psi, floor_phase) = floors(per_node);
            let converged = samples.intervals >= least
                && trusted
                && t_error <= 0.5 * tol * period
                && psi_error <= 0.5 * tol * TAU;
            // (Each of T, Δψ and the drift that misses the tolerance would meet it with the
            // floor; one that meets it needs no room: with N alone at tol 1e-14, T missing and
            // Δψ's floor a hair above half the tolerance had kept 300 librations of the
            // standard slice from it.)
            let frees = |error: f64, extra: f64, floor: f64, allowed: f64| {
                error + extra <= allowed || error + floor <= allowed
            };
            let drift_freed = match drift {
                Some(d) => {
                    let scale = d.scale.max(f64::MIN_POSITIVE);
                    let quadrature = (d.error - drift_extra(&d)) / scale;
                    let saddle_part = saddle.drift / scale;
                    frees(
                        quadrature,
                        phase + saddle_part,
                        floor_phase + saddle_part,
                        tol,
                    )
                }
                None => !with_drift || phase <= 0.5 * tol || floor_phase <= 0.5 * tol,
            };
            let within = frees(t_error, extra_t, floor_t, tol * period)
                && frees(psi_error, extra_psi, floor_psi, tol * TAU)
                && drift_freed;
            let improves = floor_t <= 0.25 * extra_t || floor_psi <= 0.25 * extra_psi;
            // (Only to sharpen an estimate where the drift can still meet the tolerance: at
            // 1e-14 its phases' floor misses it, and resampling every component there for T's
            // estimate alone took the work to 1.53 times that at 1e-13.)
            if converged && (within || (improves && drift_freed)) {
                resampled = true;
                precise = can_be_precise;
                match samples.taken_again(v, piece, map, energy, precise) {
                    Some(resampled) => samples = resampled,
                    None => return Ok(Err(2 * samples.nodes.len())),
                }
                continue;
            }
        }
        // (T and Δψ done, the drift not: `drift` is made only once they are.)
        let drift_alone_misses = drift.is_some() && !done;
        let last = if drift_alone_misses {
            DRIFT_LAST_INTERVALS
        } else {
            LAST_INTERVALS
        };
        let hopeless = samples.intervals >= last
            || !reaches(samples.intervals, t_sums, 0.5 * tol * period)
            || !reaches(samples.intervals, psi_sums, 0.5 * tol * TAU);
        // With a turning point beyond the tanh-sinh rule's last node (which would hide the ψ̇
        // peak there, an error of up to π in Δψ), the values reached here are kept with
        // their estimates even where they have not converged: the status then says so.
        let beyond_tanh_sinh = v.kappa != 0.0
            && piece.left.site.theta.min(piece.right.site.from_pi) < HIDDEN_PEAK * piece.length;
        // (Only sums already `settled`: each level ten times closer, the last difference
        // bounding the error.)
        if done
            || (hopeless
                && beyond_tanh_sinh
                && samples.intervals >= least
                && settled(t_sums)
                && settled(psi_sums))
        {
            let drift = match drift {
                None if with_drift => {
                    let mut d = samples.drift(rate);
                    d.error += drift_extra(&d);
                    Some(d)
                }
                d => d,
            };
            let psi_advance = 2.0 * psi_sums[0];
            return Ok(Ok(PeriodIntegrals {
                period,
                psi_advance,
                period_error,
                psi_advance_error,
                drift,
                psi_variation: Some(2.0 * sums.psi_variation),
                saddle,
                level_residual: residual,
                work: samples.nodes.len(),
                converged: true,
            }));
        }
        if hopeless {
            return Ok(Err(samples.nodes.len()));
        }
        let current = if resampled { piece } else { &plain };
        let at = |node| {
            if resampled && precise {
                precise_sample(v, piece, &plain, energy, node, None)
            } else {
                sample(v, current, energy, node)
            }
        };
        if samples.refine(map, at).is_err() {
            return Ok(Err(samples.nodes.len()));
        }
    }
}

/// What [`Samples::level_sums`] gives: the half-period sums of T and Δψ on three levels and
/// their rounding bounds.
#[derive(Default)]
struct LevelSums {
    t: [f64; 3],
    psi: [f64; 3],
    /// The same sums on a fourth, coarser level (n/8 steps), to check the convergence's rate.
    t_coarsest: f64,
    psi_coarsest: f64,
    t_rounding: f64,
    psi_rounding: f64,
    /// The sum of |ψ̇ dt/dφ| on n steps: ∫ |ψ̇| dt over half a period.
    psi_variation: f64,
}

/// The samples at φ_j = jπ/n, j = 0 … n, with n = `intervals`; the levels below are every
/// second and every fourth node.
struct Samples {
    intervals: usize,
    nodes: Vec<NodeSample>,
    /// The relative rounding of each node's place and weight beyond [`NodeSample::rounding`]:
    /// [`Map::node_rounding`].
    node_rounding: f64,
    /// Δζ and its path scale already computed on a level, by its number of steps (a level's
    /// nodes never change, so a refinement reuses them as its two coarser levels).
    drifts: Vec<(usize, LevelDrift)>,
}

impl Samples {
    /// The nodes of `piece` on `intervals` steps, in double.
    fn new<S: Shape>(
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        map: &Map,
        energy: f64,
        intervals: usize,
    ) -> Option<Self> {
        Self::taken(v, piece, map, intervals, |_, node| {
            sample(v, piece, energy, node)
        })
    }

    /// The same nodes taken again for `piece` (with its sharp ends), in double-double where
    /// `precise` ([`precise_sample`], checked against these nodes, which are its nodes in
    /// double: the same sites, the gaps in double), else in double with the sharp gaps.
    fn taken_again<S: Shape>(
        &self,
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        map: &Map,
        energy: f64,
        precise: bool,
    ) -> Option<Self> {
        if !precise {
            return Self::new(v, piece, map, energy, self.intervals);
        }
        let in_double = piece.in_double();
        Self::taken(v, piece, map, self.intervals, |j, node| {
            precise_sample(v, piece, &in_double, energy, node, Some(self.nodes[j]))
        })
    }

    /// The two ends' samples and `at(j, node)` at each interior node j of `intervals` steps.
    fn taken<S: Shape>(
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
        map: &Map,
        intervals: usize,
        at: impl Fn(usize, IntervalNode) -> Result<NodeSample>,
    ) -> Option<Self> {
        let n = intervals;
        let mut nodes = Vec::with_capacity(2 * LAST_INTERVALS + 1);
        nodes.push(end_sample(v, piece, map, true)?);
        for j in 1..n {
            nodes.push(at(j, map.node(n, j)).ok()?);
        }
        nodes.push(end_sample(v, piece, map, false)?);
        Some(Self {
            intervals: n,
            nodes,
            node_rounding: map.node_rounding(),
            drifts: Vec::new(),
        })
    }

    /// In one pass over the nodes: the trapezoid sums over [0, π] of dt/dφ and of ψ̇ dt/dφ on
    /// n, n/2 and n/4 steps (finest first), and the bounds on their rounding on n steps,
    /// Σ ½ (relative gap error) |f| with the trapezoid weights.
    fn level_sums(&self) -> LevelSums {
        let mut sums = LevelSums::default();
        let mut t = [CompensatedSum::default(); 4];
        let mut psi = [CompensatedSum::default(); 4];
        let last = self.nodes.len() - 1;
        for (j, node) in self.nodes.iter().enumerate() {
            let w = if j == 0 || j == last { 0.5 } else { 1.0 };
            for (level, stride) in [1, 2, 4, 8].into_iter().enumerate() {
                if j % stride == 0 {
                    t[level].add(w * node.dt);
                    psi[level].add(w * node.dpsi);
                }
            }
            let r = 0.5 * w * (node.rounding + self.node_rounding);
            sums.t_rounding += r * node.dt.abs();
            sums.psi_rounding += r * node.dpsi.abs();
            sums.psi_variation += w * node.dpsi.abs();
        }
        let h = PI / self.intervals as f64;
        for (level, stride) in [1.0, 2.0, 4.0].into_iter().enumerate() {
            sums.t[level] = t[level].value() * (h * stride);
            sums.psi[level] = psi[level].value() * (h * stride);
        }
        sums.t_coarsest = t[3].value() * (h * 8.0);
        sums.psi_coarsest = psi[3].value() * (h * 8.0);
        sums.t_rounding *= h;
        sums.psi_rounding *= h;
        sums.psi_variation *= h;
        sums
    }

    /// Halve the φ-step of `map`, with `at` the integrands at a node: keep the old nodes
    /// (now the even ones) and add the odd ones.
    fn refine(&mut self, map: &Map, at: impl Fn(IntervalNode) -> Result<NodeSample>) -> Result<()> {
        let n = 2 * self.intervals;
        interleave(&mut self.nodes, |j| at(map.node(n, j)))?;
        self.intervals = n;
        Ok(())
    }

    /// Δζ on this level, with its error from the two levels below, each computed from
    /// scratch (its own ψ̃ and phases: reusing this level's would hide ψ̃'s aliasing, which
    /// Δψ's estimate does not bound, ĥ₀ converging faster than the higher coefficients).
    fn drift(&mut self, rate: Convergence) -> DriftEstimate {
        let fine = self.level_drift(1);
        let mid = self.level_drift(2);
        DriftEstimate::from_levels(fine, mid, self.level_drift(4), rate)
    }
}

impl Samples {
    /// [`fourier_drift`] on every `stride`-th node, computed once per level.
    fn level_drift(&mut self, stride: usize) -> LevelDrift {
        let intervals = self.intervals / stride;
        if let Some((_, known)) = self.drifts.iter().find(|(n, _)| *n == intervals) {
            return *known;
        }
        let value = fourier_drift(&self.nodes, stride);
        self.drifts.push((intervals, value));
        value
    }
}

/// Whether the level differences of the sums on n/8, n/4, n/2 and n steps (`coarsest`, then
/// `sums` finest first) fit one geometric rate: under E(m) = C ρᵐ each ratio r = d₁/d₂ is
/// about the square of the one before. A last ratio far below that square (16 times) means
/// the error the earlier levels saw has died out and what is left decays at a rate they did
/// not show (issue 22, adversary pass 4: a κ = 0 libration across a pole at β = 0.2, where
/// B = 1/η + |r|² dips to 0.1 at θ = ±π/2 and has complex zeros 0.066 off the real axis: the
/// ratios 0.25, 0.042, 1.4e-5 were followed by 0.33 instead of a thousandth, and the error
/// of T at n = 256 was 3.3 times its estimate). Such levels are not trusted beyond d₁.
pub(super) fn single_rate(coarsest: f64, sums: [f64; 3]) -> bool {
    let (d1, d2, d3) = level_differences(coarsest, sums);
    if d2 == 0.0 || d3 == 0.0 {
        return true;
    }
    let (r1, r2) = (d1 / d2, d2 / d3);
    r1 >= r2 * r2 / 16.0
}

/// Whether the Mercator map's last level difference, d₁, may be taken as the error of the
/// finest sum (`coarsest`, then `sums` finest first): it falls tenfold from the one before and
/// is not slowing ([`not_slowing`]), or the sums sit on their floor. A disk at ν = 9e-4,
/// κ = −7e-4 (turning points 1e-4 from its faces) had Δψ's 1.1e-4, 4.5e-5, 1.1e-5, then
/// 2.3e-8, its error 12 times that last one; one at ν = 7e-4 had 1.2e-4, 2.9e-5, 1.4e-5,
/// slowing down, its error 2.7 times the last (adversary pass of 2026-11-27). In a pole well
/// of an oblate body (β = 225, κ = 1.2e-12, ε 3.7e-5 above the pole's level; adversary pass
/// 31) T's differences were 6.6e-7, 3.3e-10, 2.6e-16 (above the 1.6e-16 the rate predicted),
/// and the sums then crept on, 5.5e-16 from the truth at 64 steps, twice the last
/// difference: T `ok` at tol 1e-12, 1.8 times its estimate off.
pub(super) fn mercator_falling(coarsest: f64, sums: [f64; 3]) -> bool {
    (settled(sums) && not_slowing(coarsest, sums)) || at_level_floor(sums, Convergence::Unknown)
}

/// Whether the last level difference of `sums` (finest first) is a tenth of the one before
/// or less.
fn settled(sums: [f64; 3]) -> bool {
    let [i0, i1, i2] = sums;
    (i0 - i1).abs() <= 0.1 * (i1 - i2).abs()
}

/// Whether the last level difference is no larger than one rate through the two before
/// predicts, d₁ ≤ d₂²/d₃ (`coarsest`, then `sums` finest first, as for [`single_rate`]): the
/// sums are not slowing down.
fn not_slowing(coarsest: f64, sums: [f64; 3]) -> bool {
    let (d1, d2, d3) = level_differences(coarsest, sums);
    d3 == 0.0 || d1 * d3 <= d2 * d2
}

/// |d₁|, |d₂|, |d₃|: the differences of the sums on n and n/2, n/2 and n/4, n/4 and n/8 steps.
fn level_differences(coarsest: f64, sums: [f64; 3]) -> (f64, f64, f64) {
    let [i0, i1, i2] = sums;
    ((i0 - i1).abs(), (i1 - i2).abs(), (i2 - coarsest).abs())
}

/// Whether the geometric convergence seen in `sums` (on n = `intervals`, n/2 and n/4 steps)
/// brings the error within `target` by [`LAST_INTERVALS`] steps: with d₁ ≈ E(n/2),
/// d₂ ≈ E(n/4) and r = d₁/d₂, E(m) ≈ d₁ r^{(m − n/2)/(n/4)}.
fn reaches(intervals: usize, sums: [f64; 3], target: f64) -> bool {
    let [i0, i1, i2] = sums;
    let (d1, d2) = ((i0 - i1).abs(), (i1 - i2).abs());
    if d1 <= target || d2 == 0.0 {
        return true;
    }
    let ratio = d1 / d2;
    if ratio >= 0.5 {
        return false;
    }
    let n = intervals as f64;
    let quarters_left = (LAST_INTERVALS as f64 - 0.5 * n) / (0.25 * n);
    d1 * ratio.powf(quarters_left) <= target
}

/// [`Map::node_rounding`] of Mercator's map: 2 × 20 ulps.
const MERCATOR_NODE_ROUNDING: f64 = 40.0 * EPS;

/// How φ ∈ [0, π] covers a libration [θ_min, θ_max] (and how a Clenshaw–Curtis piece's
/// variable covers the piece).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Map {
    /// θ = θ_min + L (1 − cos φ)/2.
    Plain { length: f64 },
    /// The same in the Mercator coordinate s = ln tan(θ/2) (dθ/ds = sin θ): it sends the
    /// poles θ = 0, π to s = ∓∞, and V = κ²/(2 sin²θ) + U, with sin θ = sech s and
    /// cos θ = −tanh s, is analytic in the strip |Im s| < π/2 whatever the distance of a
    /// turning point to a pole, where in θ the pole at distance θ_min narrows the strip of
    /// convergence to ~√(θ_min/L).
    Mercator {
        /// tan(θ/2) at the left end and tan((π − θ)/2) at the right one: each end seen from
        /// its own pole (s ↦ −s mirrors the map), so neither overflows nor rounds away.
        tan_half: [f64; 2],
        /// s_max − s_min.
        length: f64,
    },
}

impl Map {
    /// How far the map's level differences may be trusted ([`Convergence`]).
    fn convergence(&self) -> Convergence {
        match self {
            Map::Plain { .. } => Convergence::Geometric,
            Map::Mercator { .. } => Convergence::Unknown,
        }
    }

    /// The maps to try in turn: the plain one, then (κ ≠ 0 and a turning point closer to
    /// its pole than the libration is long) Mercator's. Mercator's coarsens the middle of a
    /// long libration, where the shape's own singularities may lie close to the real axis
    /// (the ellipsoid's at θ = π/2 ± i artanh(1/β) for β > 1), so it comes second.
    fn candidates<S: Shape>(
        v: &EffectivePotential<'_, S>,
        piece: &Piece,
    ) -> impl Iterator<Item = Map> {
        let pole_distance = piece.left.site.theta.min(piece.right.site.from_pi);
        let near_pole = v.kappa != 0.0 && pole_distance < piece.length;
        // Far below the plain map's first node (a ψ̇ peak as narrow as the distance to the
        // pole, which the plain sums would step over and look converged): Mercator's only.
        let unresolved = pole_distance < 1e-6 * piece.length;
        let plain = (!(near_pole && unresolved)).then_some(Map::Plain {
            length: piece.length,
        });
        let mercator = near_pole.then(|| Map::mercator(piece));
        plain.into_iter().chain(mercator)
    }

    pub(super) fn mercator(piece: &Piece) -> Self {
        // tan(θ/2) = sin θ / (1 + cos θ) = (1 − cos θ) / sin θ, whichever has no cancellation.
        let tan_half = |a: Angle| {
            if a.cos >= 0.0 {
                a.sin / (1.0 + a.cos)
            } else {
                (1.0 - a.cos) / a.sin
            }
        };
        let mirror = |a: Angle| Angle {
            sin: a.sin,
            cos: -a.cos,
        };
        // A placed end lies `shift` = δ beyond its double:
        // tan((θ + δ)/2) = (t + tan(δ/2)) / (1 − t tan(δ/2)), tan(δ/2) = δ/2 to 1e-28 of it.
        let moved = |t: f64, end: &super::PieceEnd, sign: f64| {
            end.placed.map_or(t, |p| {
                let half = 0.5 * sign * p.shift;
                (t + half) / (1.0 - t * half)
            })
        };
        let tan_half = [
            moved(tan_half(piece.left.angle), &piece.left, 1.0),
            moved(tan_half(mirror(piece.right.angle)), &piece.right, -1.0),
        ];
        Map::Mercator {
            tan_half,
            // s_max − s_min = ln tan(θ_max/2) − ln tan(θ_min/2).
            length: -(tan_half[0].ln() + tan_half[1].ln()),
        }
    }

    /// The relative rounding of a node's place and weight that [`INTEGRAND_ROUNDING`] does not
    /// hold, counted twice as it is: none for the plain map (its offsets and dθ/dφ are a table
    /// value times L); Mercator's carry expm1, a quotient and atan in the offset (about 6 ulps
    /// of it, which move an integrand by up to twice as much) and a quotient, L_s and the
    /// table's weight in dθ/dφ (about 8 ulps). Without it a pole well of an oblate body
    /// (β = 50, κ = −2.9e-12, ε 4e-4 above the pole's level) had T `ok` at tol 1e-12, 40 ulps
    /// off, 1.07 times its estimate (adversary pass 31).
    pub(super) fn node_rounding(&self) -> f64 {
        match self {
            Map::Plain { .. } => 0.0,
            Map::Mercator { .. } => MERCATOR_NODE_ROUNDING,
        }
    }

    /// Node j of the grid of `intervals` φ-steps, with θ measured from the nearer end.
    fn node(&self, intervals: usize, j: usize) -> IntervalNode {
        match *self {
            Map::Plain { length } => IntervalNode::cosine_tabulated(intervals, j, length),
            Map::Mercator { .. } => self.place(IntervalNode::cosine_tabulated(intervals, j, 1.0)),
        }
    }

    /// A node of a rule on the unit interval (its distances to the ends, and dx/dv for the
    /// rule's variable v) placed on the piece: x = θ for the plain map (scaled by L), and
    /// x = (s − s_min)/L_s for Mercator's, which makes dθ/dv = sin θ L_s dx/dv.
    pub(super) fn place(&self, unit: IntervalNode) -> IntervalNode {
        match *self {
            Map::Plain { length } => unit.scaled(length),
            Map::Mercator { tan_half, length } => {
                // From each end, in its own pole's coordinate: s − s_end = L_s u with u the
                // unit distance to that end; with q = e^{L_s u} and t = tan(θ_end/2) (for the
                // right end, of π − θ_end): |θ − θ_end| = 2 atan(t (q − 1) / (1 + t² q)) and
                // sin θ = 2 t q / (1 + t² q²). Both distances are computed from their own end:
                // most of the s-range may lie within rounding of one end in θ.
                let from = |t: f64, u: f64| {
                    let q_minus_1 = (length * u).exp_m1();
                    let q = 1.0 + q_minus_1;
                    // t q first: t alone may be 1e-300, whose square underflows.
                    let tq = t * q;
                    let distance = 2.0 * (t * q_minus_1 / (1.0 + t * tq)).atan();
                    (distance, 2.0 * tq / (1.0 + tq * tq))
                };
                let (from_left, sin_left) = from(tan_half[0], unit.from_left);
                let (from_right, sin_right) = from(tan_half[1], unit.from_right);
                let sin_theta = if unit.from_left <= unit.from_right {
                    sin_left
                } else {
                    sin_right
                };
                IntervalNode {
                    from_left,
                    from_right,
                    jacobian: sin_theta * length * unit.jacobian,
                }
            }
        }
    }

    /// ℓ with θ − θ_end ≈ ℓ φ²/4 near an end (φ measured from that end): L, or sin θ_end L_s.
    pub(super) fn end_length(&self, piece: &Piece, left: bool) -> f64 {
        match *self {
            Map::Plain { length } => length,
            Map::Mercator { length, .. } => {
                let end = if left { &piece.left } else { &piece.right };
                end.angle.sin * length
            }
        }
    }
}

/// The limit of the integrands at a turning point, where φ = 0 (left) or π (right): with
/// ε − V ≈ g·(distance to the end), g = ∓V′ + tilt/L, θ − θ_end ≈ ℓ φ²/4 (see
/// [`Map::end_length`]), dt/dφ → √(B ℓ / (2 g)) and dθ/dφ → 0.
/// `None` when g is not safely positive (a nearly flat turning point: the substitution does
/// not make the integrand smooth there).
fn end_sample<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    map: &Map,
    left: bool,
) -> Option<NodeSample> {
    end_sample_with_length(v, piece, map.end_length(piece, left), left)
}

/// [`end_sample`] of a substitution with θ − θ_end ≈ ℓ φ²/4 near the end, ℓ = `end_length`.
pub(super) fn end_sample_with_length<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    end_length: f64,
    left: bool,
) -> Option<NodeSample> {
    let end = if left { &piece.left } else { &piece.right };
    if end.excess != 0.0 {
        return None;
    }
    // (A placed end lies `shift` beyond its double: the limit is taken there, as ψ̇ ∝ 1/sin²θ
    // and V′ move with it by shift/θ near a pole, a 3e-12 relative step of ψ̇ at θ = 3.5e-5
    // in a shift of 5e-17; whole-domain seed 12. The shift is below 1e-9 of θ: its square is
    // far below an ulp of the pair.)
    let a = match end.placed {
        Some(placed) => Angle {
            sin: end.angle.sin + end.angle.cos * placed.shift,
            cos: end.angle.cos - end.angle.sin * placed.shift,
        },
        None => end.angle,
    };
    let red = v.body.reduction_at(a);
    let tilt = piece.tilt_rate;
    let slope = v.slope(a);
    let g = if left { tilt - slope } else { slope - tilt };
    let w = v.kappa / a.sin;
    let terms =
        w * w * (a.cos / a.sin).abs() + v.body.shape.potential_prime_scale_at(a) + tilt.abs();
    let g_error = 8.0 * EPS * terms;
    // Where the wall's slope and U′ nearly cancel (a turning point by a saddle, a narrow
    // well below a large ε), g in double is off by up to 8 ulps of their sizes, and the
    // limit, weighted half a step, carried most of T's rounding bound at tol 1e-14. At a
    // placed end the slope comes from V in double-double instead.
    let (g, g_error) = match (end.placed, end.sharp) {
        (Some(placed), Some(_)) if g_error > 4.0 * EPS * g.abs() => {
            sharp_slope(v, piece, &placed, left)
                .filter(|&(_, sharp_error)| sharp_error < g_error)
                .unwrap_or((g, g_error))
        }
        _ => (g, g_error),
    };
    if g.is_nan() || g <= 1e3 * g_error {
        return None;
    }
    let dt = root_of_ratio(red.reduced_inertia, end_length, 2.0 * g);
    Some(weighted(v, a, &red, dt, 0.0, g_error / g))
}

/// |V′| at the placed end e + shift of `piece` (`left` or right) from V in double-double: with
/// V at e + shift and a step x = 1e-12 min(θ_e, π − θ_e, L) inwards, |V′| = −ΔV/x + V″x/2 (V″
/// in double), within the double-double errors over x, an ulp of the V″ term, and a
/// millionth of it for the terms beyond (V‴ below 3e6 V″/min(θ_e, π − θ_e, L)). `None`
/// where V is not given so or the difference is not a descent.
fn sharp_slope<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    placed: &super::Placed,
    left: bool,
) -> Option<(f64, f64)> {
    let end = if left { &piece.left } else { &piece.right };
    let chart = end.site.theta.abs().min(end.site.from_pi.abs());
    let step = 1e-12 * chart.min(piece.length);
    let inwards = if left { step } else { -step };
    let (at_end, end_error) = (placed.value, placed.value_error);
    let (sin, cos) = super::turned(placed.sin, placed.cos, inwards);
    let (inside, inside_error) = v.value_double_double_on_circle(sin, cos)?;
    let fall = -inside.sub(at_end).to_f64();
    let curvature = v.curvature_at(end.angle);
    let g = fall / step + 0.5 * curvature * step;
    let error = 2.0 * (end_error + inside_error) / step
        + EPS * fall.abs() / step
        + (EPS + 1e-6) * (curvature * step).abs();
    (g.is_finite() && fall > 0.0 && g > 0.0).then_some((g, error))
}

/// ν (the mean of ψ̇ dt/dφ over the circle, Δψ/2π) and ψ̃ at every `stride`-th node
/// (ψ̃(0) = 0), ψ̃ the spectral antiderivative of ψ̇ dt/dφ − ν on the circle of that level:
/// ψ̃ = Σ_{k≠0} ĥ_k e^{ikφ} / (ik), the Nyquist term (odd in k) dropped. ψ̃ is odd, so the
/// way out holds all of it. Written into `values` (2n long; the first n + 1 entries are the
/// result), with `spectrum` (n + 1 long) as scratch.
fn antiderivative(
    nodes: &[NodeSample],
    stride: usize,
    values: &mut [f64],
    spectrum: &mut [Complex<f64>],
) -> f64 {
    let n = (nodes.len() - 1) / stride;
    let m = 2 * n;
    for (j, node) in nodes.iter().step_by(stride).enumerate() {
        values[j] = node.dpsi;
        if j > 0 && j < n {
            values[m - j] = node.dpsi;
        }
    }
    real_fft(values, spectrum);
    let nu = spectrum[0].re / m as f64;
    spectrum[0] = Complex::new(0.0, 0.0);
    spectrum[n] = Complex::new(0.0, 0.0);
    let reciprocals = reciprocals();
    let inv_m = 1.0 / m as f64;
    for (c, inv_k) in spectrum[1..n].iter_mut().zip(&reciprocals[1..n]) {
        *c *= Complex::new(0.0, -inv_k * inv_m);
    }
    real_inverse_fft(spectrum, values);
    let start = values[0];
    values[..=n].iter_mut().for_each(|v| *v -= start);
    nu
}

/// 1/k for k = 0 … [`DRIFT_LAST_INTERVALS`] (k = 0 unused), made once.
fn reciprocals() -> &'static [f64] {
    static TABLE: OnceLock<Vec<f64>> = OnceLock::new();
    TABLE.get_or_init(|| (0..=DRIFT_LAST_INTERVALS).map(|k| 1.0 / k as f64).collect())
}

/// Per-thread buffers of [`fourier_drift`]: ψ̃, the transform's input and its spectrum.
struct DriftBuffers {
    psi: Vec<f64>,
    values: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
}

thread_local! {
    static DRIFT_BUFFERS: RefCell<DriftBuffers> = const {
        RefCell::new(DriftBuffers {
            psi: Vec::new(),
            values: Vec::new(),
            spectrum: Vec::new(),
        })
    };
}

/// Δζ and the L1 size of its integrand from every `stride`-th node. The path over one period
/// is φ ∈ [0, 2π) (the way back mirrored: θ(2π − φ) = θ(φ), dθ/dφ odd, dt/dφ and ψ̇ dt/dφ
/// even). With ψ(φ) = νφ + ψ̃(φ), ν = Δψ/2π and ψ̃ periodic (its spectral antiderivative),
/// Δζ = −∫₀^{2π} e^{iψ} U (a dt/dφ + i dθ/dφ) dφ = ∫₀^{2π} e^{iνφ} P(φ) dφ with P periodic,
/// so Δζ = Σ_k P̂_k ∫₀^{2π} e^{i(ν+k)φ} dφ = 2 e^{iπν} sin(πν) Σ_k P̂_k / (ν + k): exact
/// but for the aliasing of P̂, which decays like the trapezoid error. ψ̃ is odd, so
/// P(−φ) = conj P(φ) and every P̂_k is real: R = |Σ_k P̂_k / (ν + k)|.
fn fourier_drift(nodes: &[NodeSample], stride: usize) -> LevelDrift {
    DRIFT_BUFFERS.with(|buffers| {
        let buffers = &mut *buffers.borrow_mut();
        let n = (nodes.len() - 1) / stride;
        buffers.psi.resize(2 * n, 0.0);
        buffers.values.resize(2 * n, 0.0);
        buffers.spectrum.resize(n + 1, Complex::new(0.0, 0.0));
        fourier_drift_in(
            nodes,
            stride,
            &mut buffers.psi[..2 * n],
            &mut buffers.values[..2 * n],
            &mut buffers.spectrum[..=n],
        )
    })
}

/// [`fourier_drift`] with its buffers.
fn fourier_drift_in(
    nodes: &[NodeSample],
    stride: usize,
    psi: &mut [f64],
    values: &mut [f64],
    spectrum: &mut [Complex<f64>],
) -> LevelDrift {
    let n = (nodes.len() - 1) / stride;
    let m = 2 * n;
    let node = |j: usize| &nodes[j * stride];
    // ν: the mean of ψ̇ dt/dφ over the circle, on this level.
    let nu = antiderivative(nodes, stride, psi, spectrum);
    // (ψ̃ is odd about both ends: its steps on the way out are all of them.)
    let phase_step = largest_step(&psi[..=n]);
    // y_j = Re P_j + Im P_j: its real transform Y_k gives m P̂_{±k} = Re Y_k ∓ Im Y_k (the
    // even part Re P transforms to a real, the odd part Im P to an imaginary sequence).
    let mut scale = 0.0;
    for j in 0..=n {
        let s = node(j);
        scale += s.along.abs() + s.across.abs();
        let (sp, cp) = libm::sincos(psi[j]);
        // P = −e^{iψ̃} (along + i across)
        let (re, im) = (
            -(cp * s.along - sp * s.across),
            -(sp * s.along + cp * s.across),
        );
        values[j] = re + im;
        if j > 0 && j < n {
            values[m - j] = re - im;
        }
    }
    // Every node but the two ends stands for two points of the circle.
    let ends = [node(0), node(n)];
    scale = 2.0 * scale
        - ends
            .iter()
            .map(|s| s.along.abs() + s.across.abs())
            .sum::<f64>();
    real_fft(values, spectrum);
    // ν = δ − k₀ with |δ| ≤ ½: 2 e^{iπν} sin(πν) = 2 e^{iπδ} sin(πδ), and the k₀ term
    // is P̂_{k₀} · 2 e^{iπδ} sin(πδ)/δ, finite as δ → 0 (exact resonance: 2π P̂_{k₀}).
    let k0 = (-nu).round();
    let delta = nu + k0;
    let (sd, cd) = libm::sincos(PI * delta);
    let term = |p: f64, k: f64| {
        if k == k0 {
            p * if delta == 0.0 { PI } else { sd / delta }
        } else {
            p * sd / (nu + k)
        }
    };
    let mut sum = term(spectrum[0].re - spectrum[0].im, 0.0) + term(spectrum[n].re, n as f64);
    for (k, c) in spectrum.iter().enumerate().take(n).skip(1) {
        let (plus, minus, k) = (c.re - c.im, c.re + c.im, k as f64);
        sum += if k == k0.abs() {
            term(plus, k) + term(minus, -k)
        } else {
            // m P̂_k/(ν + k) + m P̂_{−k}/(ν − k) with one division (|ν ± k| ≥ ½ here).
            sd * (plus * (nu - k) + minus * (nu + k)) / ((nu - k) * (nu + k))
        };
    }
    let drift = 2.0 * sum / m as f64;
    LevelDrift {
        value: [cd * drift, sd * drift],
        scale: scale * PI / n as f64,
        phase_step,
    }
}
