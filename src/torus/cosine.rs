//! Librations with no saddle or tangency inside, by the cosine substitution
//! θ = θ_min + L (1 − cos φ)/2. It removes the 1/√ singularities of both turning points, so
//! the integrands of T and Δψ become smooth and 2π-periodic in φ and the trapezoid rule
//! converges geometrically; Δζ follows from the Fourier coefficients of the same samples.
//! Where the convergence is slow (a saddle just beyond an end, a pole near a turning point
//! at small κ) it stops early and the tanh-sinh path of the parent module takes over.

use super::{
    cautious_error, interleave, sample, weighted, Component, DriftEstimate, EffectivePotential, NodeSample,
    PeriodIntegrals, Piece, EPS,
};
use crate::body::Shape;
use crate::error::Result;
use crate::quadrature::{real_fft, real_inverse_fft, IntervalNode, FINEST_COSINE_INTERVALS};
use rustfft::num_complex::Complex;
use std::f64::consts::{PI, TAU};

/// φ-steps on [0, π] of the first level.
const FIRST_INTERVALS: usize = 4;
/// φ-steps on [0, π] before the level differences are trusted: the coarsest of the three
/// levels compared then has 4 steps.
const MIN_INTERVALS: usize = 16;
/// φ-steps on [0, π] beyond which the tanh-sinh rule is cheaper.
const LAST_INTERVALS: usize = 128;
const _: () = assert!(LAST_INTERVALS <= FINEST_COSINE_INTERVALS);

/// T, Δψ and (if `with_drift`) Δζ of a libration that is one piece (see the parent's
/// `integrate`), or `None` when the trapezoid rule would need more than [`LAST_INTERVALS`]
/// steps (or a turning point is too flat for the substitution to make the integrand smooth).
pub(super) fn integrate<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    energy: f64,
    component: &Component,
    tol: f64,
    with_drift: bool,
) -> Result<Option<PeriodIntegrals>> {
    let Some(mut samples) = Samples::new(v, piece, energy) else {
        return Ok(None);
    };
    loop {
        let period = 2.0 * samples.sum(1, |n| n.dt);
        let t_error = 2.0 * samples.error(|n| n.dt);
        let psi_error = 2.0 * samples.error(|n| n.dpsi);
        let mut done = samples.intervals >= MIN_INTERVALS
            && t_error <= 0.5 * tol * period
            && psi_error / TAU <= 0.5 * tol;
        // The drift (the costly part) only once T and Δψ have converged.
        let drift = (done && with_drift).then(|| samples.drift());
        done &= drift.is_none_or(|d| d.error <= tol * d.scale);
        if done {
            let psi_advance = 2.0 * samples.sum(1, |n| n.dpsi);
            let (saddle_t, saddle_psi) = v.saddle_conditioning(energy, component, period, 2.0);
            let period_rounding = 2.0 * samples.rounding(|n| n.dt);
            let psi_rounding = 2.0 * samples.rounding(|n| n.dpsi);
            let period_error = t_error + period_rounding + saddle_t;
            let psi_advance_error = psi_error + psi_rounding + saddle_psi;
            let drift = drift.map(|mut d| {
                // Rounding in T and Δψ enters the drift through the phases and the weights.
                let phase = period_rounding / period + psi_rounding + saddle_psi;
                d.error += phase * d.scale;
                d
            });
            return Ok(Some(PeriodIntegrals {
                period,
                psi_advance,
                period_error,
                psi_advance_error,
                drift,
                work: samples.nodes.len(),
                converged: period_error <= tol * period && psi_advance_error / TAU <= tol,
            }));
        }
        let hopeless = samples.intervals >= LAST_INTERVALS
            || !samples.reaches(|n| n.dt, 0.5 * tol * period)
            || !samples.reaches(|n| n.dpsi, 0.25 * tol * TAU);
        if hopeless {
            return Ok(None);
        }
        let at = |node| sample(v, piece, energy, node);
        if samples.refine(piece.length, at).is_err() {
            return Ok(None);
        }
    }
}

/// The samples at φ_j = jπ/n, j = 0 … n, with n = `intervals`; the levels below are every
/// second and every fourth node.
struct Samples {
    intervals: usize,
    nodes: Vec<NodeSample>,
}

impl Samples {
    fn new<S: Shape>(v: &EffectivePotential<'_, S>, piece: &Piece, energy: f64) -> Option<Self> {
        let n = FIRST_INTERVALS;
        let mut nodes = Vec::with_capacity(2 * LAST_INTERVALS + 1);
        nodes.push(end_sample(v, piece, true)?);
        for j in 1..n {
            let node = IntervalNode::cosine_tabulated(n, j, piece.length);
            nodes.push(sample(v, piece, energy, node).ok()?);
        }
        nodes.push(end_sample(v, piece, false)?);
        Some(Self {
            intervals: n,
            nodes,
        })
    }

    /// The trapezoid sum over [0, π] of `f` on every `stride`-th node (ends weighted ½).
    fn sum(&self, stride: usize, f: impl Fn(&NodeSample) -> f64) -> f64 {
        let last = self.nodes.len() - 1;
        let inner: f64 = self.nodes[stride..last]
            .iter()
            .step_by(stride)
            .map(&f)
            .sum();
        let ends = 0.5 * (f(&self.nodes[0]) + f(&self.nodes[last]));
        PI * stride as f64 / self.intervals as f64 * (inner + ends)
    }

    /// Error of the sum of `f` on n steps, from the sums on n, n/2 and n/4 steps (see
    /// [`cautious_error`]: the trapezoid rule's E(n) = C ρⁿ would allow d₁²/d₂, but not an
    /// integrand with singularities at several distances from the real axis).
    fn error(&self, f: impl Fn(&NodeSample) -> f64 + Copy) -> f64 {
        let (i0, i1, i2) = (self.sum(1, f), self.sum(2, f), self.sum(4, f));
        cautious_error((i0 - i1).abs(), (i1 - i2).abs()).max(8.0 * EPS * i0.abs())
    }

    /// Whether the geometric convergence seen so far reaches `target` within
    /// [`LAST_INTERVALS`]: with d₁ ≈ E(n/2) and d₂ ≈ E(n/4), E(m) ≈ d₁ (d₁/d₂)^{(m − n/2)/(n/4)}.
    /// Only judged from 16 steps on (before that the convergence may not have set in).
    fn reaches(&self, f: impl Fn(&NodeSample) -> f64 + Copy, target: f64) -> bool {
        if self.intervals < 16 {
            return true;
        }
        let (i0, i1, i2) = (self.sum(1, f), self.sum(2, f), self.sum(4, f));
        let (d1, d2) = ((i0 - i1).abs(), (i1 - i2).abs());
        if d1 <= target || d2 == 0.0 {
            return true;
        }
        let ratio = d1 / d2;
        if ratio >= 0.5 {
            return false;
        }
        let n = self.intervals as f64;
        let doublings_left = (LAST_INTERVALS as f64 - 0.5 * n) / (0.25 * n);
        d1 * ratio.powf(doublings_left) <= target
    }

    /// Σ ½ (relative gap error) |f| over the nodes with the trapezoid weights.
    fn rounding(&self, f: impl Fn(&NodeSample) -> f64) -> f64 {
        self.sum(1, |n| 0.5 * n.rounding * f(n).abs())
    }

    /// Halve the φ-step on an interval of length `length`, with `at` the integrands at a
    /// node: keep the old nodes (now the even ones) and add the odd ones.
    fn refine(
        &mut self,
        length: f64,
        at: impl Fn(IntervalNode) -> Result<NodeSample>,
    ) -> Result<()> {
        let n = 2 * self.intervals;
        self.nodes = interleave(&self.nodes, |j| {
            at(IntervalNode::cosine_tabulated(n, j, length))
        })?;
        self.intervals = n;
        Ok(())
    }

    /// Δζ on this level, with its error from the two levels below.
    fn drift(&self) -> DriftEstimate {
        let (fine, mid, coarse) = (
            fourier_drift(&self.nodes, 1),
            fourier_drift(&self.nodes, 2),
            fourier_drift(&self.nodes, 4),
        );
        let (d1, d2) = (
            (fine.0[0] - mid.0[0]).hypot(fine.0[1] - mid.0[1]),
            (mid.0[0] - coarse.0[0]).hypot(mid.0[1] - coarse.0[1]),
        );
        DriftEstimate {
            value: fine.0,
            error: cautious_error(d1, d2).max(8.0 * EPS * fine.1),
            scale: fine.1,
        }
    }
}

/// The limit of the integrands at a turning point, where φ = 0 (left) or π (right): with
/// ε − V ≈ g·(distance to the end), g = ∓V′ + tilt/L, dt/dφ → √(B L / (2 g)) and dθ/dφ → 0.
/// `None` when g is not safely positive (a nearly flat turning point: the substitution does
/// not make the integrand smooth there).
fn end_sample<S: Shape>(
    v: &EffectivePotential<'_, S>,
    piece: &Piece,
    left: bool,
) -> Option<NodeSample> {
    let end = if left { &piece.left } else { &piece.right };
    if end.excess != 0.0 {
        return None;
    }
    let a = end.angle;
    let red = v.body.reduction_at(a);
    let tilt = piece.tilt / piece.length;
    let slope = v.slope(a);
    let g = if left { tilt - slope } else { slope - tilt };
    let k2 = v.kappa * v.kappa;
    let terms = k2 * (a.cos / (a.sin * a.sin * a.sin)).abs()
        + v.body.shape.potential_prime_at(a).abs()
        + tilt.abs();
    let g_error = 8.0 * EPS * terms;
    if g.is_nan() || g <= 1e3 * g_error {
        return None;
    }
    let dt = (red.reduced_inertia * piece.length / (2.0 * g)).sqrt();
    Some(weighted(v, a, &red, dt, 0.0, g_error / g))
}

/// Δζ and the L1 size of its integrand from every `stride`-th node. The path over one period
/// is φ ∈ [0, 2π) (the way back mirrored: θ(2π − φ) = θ(φ), dθ/dφ odd, dt/dφ and ψ̇ dt/dφ
/// even). With ψ(φ) = νφ + ψ̃(φ), ν = Δψ/2π and ψ̃ periodic (its spectral antiderivative),
/// Δζ = −∫₀^{2π} e^{iψ} U (a dt/dφ + i dθ/dφ) dφ = ∫₀^{2π} e^{iνφ} P(φ) dφ with P periodic,
/// so Δζ = Σ_k P̂_k ∫₀^{2π} e^{i(ν+k)φ} dφ = 2 e^{iπν} sin(πν) Σ_k P̂_k / (ν + k): exact
/// but for the aliasing of P̂, which decays like the trapezoid error. ψ̃ is odd, so
/// P(−φ) = conj P(φ) and every P̂_k is real: R = |Σ_k P̂_k / (ν + k)|.
fn fourier_drift(nodes: &[NodeSample], stride: usize) -> ([f64; 2], f64) {
    let n = (nodes.len() - 1) / stride;
    let m = 2 * n;
    let node = |j: usize| &nodes[j.min(m - j) * stride];
    let mut values: Vec<f64> = (0..m).map(|j| node(j).dpsi).collect();
    let mut spectrum = vec![Complex::new(0.0, 0.0); n + 1];
    real_fft(&mut values, &mut spectrum);
    let nu = spectrum[0].re / m as f64;
    // ψ̃ = Σ_{k≠0} ĥ_k e^{ikφ} / (ik); the Nyquist term (odd in k) is dropped.
    spectrum[0] = Complex::new(0.0, 0.0);
    spectrum[n] = Complex::new(0.0, 0.0);
    for (k, c) in spectrum.iter_mut().enumerate().take(n).skip(1) {
        *c *= Complex::new(0.0, -1.0 / (k as f64 * m as f64));
    }
    let mut psi = vec![0.0; m];
    real_inverse_fft(&mut spectrum, &mut psi);
    // y_j = Re P_j + Im P_j: its real transform Y_k gives m P̂_{±k} = Re Y_k ∓ Im Y_k (the
    // even part Re P transforms to a real, the odd part Im P to an imaginary sequence).
    let mut scale = 0.0;
    for j in 0..=n {
        let s = node(j);
        scale += s.along.abs() + s.across.abs();
        let (sp, cp) = libm::sincos(psi[j] - psi[0]);
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
    real_fft(&mut values, &mut spectrum);
    // ν = δ − k₀ with |δ| ≤ ½: 2 e^{iπν} sin(πν) = 2 e^{iπδ} sin(πδ), and the k₀ term
    // is P̂_{k₀} · 2 e^{iπδ} sin(πδ)/δ, finite as δ → 0 (exact resonance: 2π P̂_{k₀}).
    let k0 = (-nu).round();
    let delta = nu + k0;
    let (sd, cd) = (PI * delta).sin_cos();
    let weight = |k: f64| {
        if k == k0 {
            if delta == 0.0 {
                PI
            } else {
                sd / delta
            }
        } else {
            sd / (nu + k)
        }
    };
    let mut sum = (spectrum[0].re - spectrum[0].im) * weight(0.0);
    for (k, c) in spectrum.iter().enumerate().skip(1) {
        sum += (c.re - c.im) * weight(k as f64);
        if k < n {
            sum += (c.re + c.im) * weight(-(k as f64));
        }
    }
    let drift = 2.0 * sum / m as f64;
    ([cd * drift, sd * drift], scale * PI / n as f64)
}
