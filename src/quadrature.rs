//! The numerical rules the cell solver is built on: the periodic trapezoid rule after the
//! cosine substitution x = a + L (1 − cos φ)/2, geometrically convergent for an integrand
//! whose only end singularities are inverse square roots; the tanh-sinh (double-exponential)
//! rule, which absorbs any integrable end singularity and clusters its nodes at near-singular
//! ends; the Clenshaw–Curtis rule for the pieces of a libration cut at kinks (beside a turning
//! point after θ − θ_t = ±L u²); and the spectral and Chebyshev antiderivatives and FFTs that
//! give cumulative integrals (ψ along the orbit) from the same nodes to the same accuracy.

use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::num_complex::Complex;
use std::cell::RefCell;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::Arc;
use std::sync::OnceLock;
use std::thread::LocalKey;

/// Half-width of the τ-interval: at τ = 4 the nodes lie within e^{−86} ≈ 1e-37 of the ends
/// (relative to the interval), far enough for 1/√x and near-logarithmic end behaviour.
pub const TAU_MAX: f64 = 4.0;

/// One node of a rule on an interval [a, a + L], placed by a substitution x(τ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalNode {
    /// x − a, to full relative precision however close to a.
    pub from_left: f64,
    /// a + L − x, to full relative precision however close to the right end.
    pub from_right: f64,
    /// dx/dτ at the node (multiply by the step to get the quadrature weight).
    pub jacobian: f64,
}

impl IntervalNode {
    /// The tanh-sinh node at τ on an interval of length `length`:
    /// x = a + L/2 (1 + tanh(π/2 sinh τ)), dx/dτ = L/2 · (π/2) cosh τ / cosh²(π/2 sinh τ).
    #[inline]
    pub fn tanh_sinh(tau: f64, length: f64) -> Self {
        let (sh, ch) = (tau.sinh(), tau.cosh());
        let s = FRAC_PI_2 * sh;
        // L/(1 + e^{∓2s}) without cancellation on either side.
        let e = (-2.0 * s.abs()).exp();
        let (near, far) = (length * e / (1.0 + e), length / (1.0 + e));
        let (from_left, from_right) = if s < 0.0 { (near, far) } else { (far, near) };
        // sech²(s) = 4 e^{−2|s|} / (1 + e^{−2|s|})².
        let sech2 = 4.0 * e / ((1.0 + e) * (1.0 + e));
        Self {
            from_left,
            from_right,
            jacobian: 0.5 * length * FRAC_PI_2 * ch * sech2,
        }
    }

    /// The node at φ of the cosine substitution x = a + L (1 − cos φ)/2, φ ∈ [0, π]:
    /// x − a = L sin²(φ/2), a + L − x = L cos²(φ/2), dx/dφ = (L/2) sin φ. An integrand
    /// g(x) / √((x − a)(a + L − x)) with g smooth becomes g(x(φ))/… smooth and, continued
    /// evenly, 2π-periodic in φ.
    #[inline]
    pub fn cosine(phi: f64, length: f64) -> Self {
        let (s, c) = (0.5 * phi).sin_cos();
        Self {
            from_left: length * s * s,
            from_right: length * c * c,
            jacobian: length * s * c,
        }
    }

    /// Scales a node of the unit interval to an interval of length `length`.
    #[inline]
    pub(crate) fn scaled(self, length: f64) -> Self {
        Self {
            from_left: self.from_left * length,
            from_right: self.from_right * length,
            jacobian: self.jacobian * length,
        }
    }

    /// Node j of tanh-sinh level `level` (≤ [`FINEST_LEVEL`]) on an interval of length
    /// `length`, from a table of the unit-interval nodes built once.
    #[inline]
    pub fn tanh_sinh_tabulated(level: u32, j: usize, length: f64) -> Self {
        static TABLE: OnceLock<Vec<IntervalNode>> = OnceLock::new();
        let table = TABLE.get_or_init(|| {
            let finest = TanhSinhLevel::new(FINEST_LEVEL);
            (0..finest.count)
                .map(|j| IntervalNode::tanh_sinh(finest.tau(j), 1.0))
                .collect()
        });
        table[j << (FINEST_LEVEL - level)].scaled(length)
    }

    /// Node j of the cosine substitution with `intervals` (a power of two, at most
    /// [`FINEST_COSINE_INTERVALS`]) steps of π/`intervals` in φ, on an interval of length
    /// `length`, from a table built once.
    #[inline]
    pub fn cosine_tabulated(intervals: usize, j: usize, length: f64) -> Self {
        static TABLE: OnceLock<Vec<IntervalNode>> = OnceLock::new();
        let table = TABLE.get_or_init(|| {
            let n = FINEST_COSINE_INTERVALS;
            (0..=n)
                .map(|j| IntervalNode::cosine(PI * j as f64 / n as f64, 1.0))
                .collect()
        });
        table[j * (FINEST_COSINE_INTERVALS / intervals)].scaled(length)
    }
}

/// The finest tanh-sinh level the node table holds.
pub const FINEST_LEVEL: u32 = 10;

/// The finest φ-grid of the cosine substitution the node table holds (intervals on [0, π]).
pub const FINEST_COSINE_INTERVALS: usize = 1024;

/// The τ-grid of one level: `count` nodes τ_j = −TAU_MAX + j·step, j = 0 … count − 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TanhSinhLevel {
    /// Grid step in τ.
    pub step: f64,
    /// Number of nodes, 2·TAU_MAX/step + 1.
    pub count: usize,
}

impl TanhSinhLevel {
    /// Level k has step 2^{−k}: level 1 has 17 nodes, each level doubles the intervals.
    pub fn new(level: u32) -> Self {
        let step = 0.5f64.powi(level as i32);
        Self {
            step,
            count: (2.0 * TAU_MAX / step).round() as usize + 1,
        }
    }

    /// τ of node j.
    #[inline]
    pub fn tau(&self, j: usize) -> f64 {
        -TAU_MAX + j as f64 * self.step
    }
}

type RealPlans = (Arc<dyn RealToComplex<f64>>, Arc<dyn ComplexToReal<f64>>);

thread_local! {
    static REAL_PLANNER: RefCell<RealFftPlanner<f64>> = RefCell::new(RealFftPlanner::new());
    /// Real-data plans for the power-of-two sizes, by log₂ of the size.
    static REAL_PLANS: RefCell<Vec<Option<RealPlans>>> = const { RefCell::new(Vec::new()) };
}

/// The plans for a power-of-two size `n` from a per-thread cache, made by `make` on first
/// use (the planners' own lookups cost more than the small transforms here).
fn cached<P: Clone + 'static>(
    cache: &'static LocalKey<RefCell<Vec<Option<P>>>>,
    n: usize,
    make: impl FnOnce() -> P,
) -> P {
    assert!(
        n.is_power_of_two(),
        "FFTs are planned for powers of two only"
    );
    cache.with(|cache| {
        let mut cache = cache.borrow_mut();
        let slot = n.trailing_zeros() as usize;
        if cache.len() <= slot {
            cache.resize(slot + 1, None);
        }
        cache[slot].get_or_insert_with(make).clone()
    })
}

/// The real-data plans for a power-of-two size, made once per thread.
fn real_plans(n: usize) -> RealPlans {
    cached(&REAL_PLANS, n, || {
        REAL_PLANNER.with(|p| {
            let mut p = p.borrow_mut();
            (p.plan_fft_forward(n), p.plan_fft_inverse(n))
        })
    })
}

/// The DFT of real `input` (a power of two long; used as scratch): `output[k]` =
/// Σ_j x_j e^{−2πi jk/n} for k = 0 … n/2.
pub fn real_fft(input: &mut [f64], output: &mut [Complex<f64>]) {
    let plan = real_plans(input.len()).0;
    with_scratch(plan.get_scratch_len(), |scratch| {
        plan.process_with_scratch(input, output, scratch)
            .expect("buffer lengths match the plan")
    });
}

/// Runs `f` on a per-thread scratch buffer of `len` complex numbers.
fn with_scratch<R>(len: usize, f: impl FnOnce(&mut [Complex<f64>]) -> R) -> R {
    thread_local! {
        static SCRATCH: RefCell<Vec<Complex<f64>>> = const { RefCell::new(Vec::new()) };
    }
    SCRATCH.with(|scratch| {
        let mut scratch = scratch.borrow_mut();
        if scratch.len() < len {
            scratch.resize(len, Complex::new(0.0, 0.0));
        }
        f(&mut scratch[..len])
    })
}

/// The inverse of [`real_fft`], unnormalised: `output[j]` = Σ_k X_k e^{2πi jk/n} over the
/// Hermitian spectrum whose k = 0 … n/2 half is `spectrum` (used as scratch; X_0 and X_{n/2}
/// must be real).
pub fn real_inverse_fft(spectrum: &mut [Complex<f64>], output: &mut [f64]) {
    let plan = real_plans(output.len()).1;
    with_scratch(plan.get_scratch_len(), |scratch| {
        plan.process_with_scratch(spectrum, output, scratch)
            .expect("buffer lengths match the plan and the ends of the spectrum are real")
    });
}

/// Cumulative integrals on a uniform grid of a function that vanishes (with its derivatives)
/// at both ends of the grid, as tanh-sinh integrands do: G_j = ∫ from τ_0 to τ_j of g, from
/// the trigonometric interpolant of the zero-padded samples (spectrally accurate).
/// `values[j]` = g(τ_j); `step` = grid step. Returns G_0 = 0, …, G_{n−1} ≈ step·Σ g.
pub fn spectral_antiderivative(values: &[f64], step: f64) -> Vec<f64> {
    let n = values.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let m = n.next_power_of_two().max(2);
    let mut padded: Vec<f64> = values
        .iter()
        .copied()
        .chain(std::iter::repeat_n(0.0, m - n))
        .collect();
    let mut spectrum = vec![Complex::new(0.0, 0.0); m / 2 + 1];
    real_fft(&mut padded, &mut spectrum);
    let mean = spectrum[0].re;
    // c_k = ĝ_k m / (2πi k) for 0 < k < m/2 (the negative frequencies are their conjugates,
    // so Σ_{k≠0} c_k = 2 Re Σ c_k); the Nyquist term is dropped.
    let mut offset = 0.0;
    spectrum[0] = Complex::new(0.0, 0.0);
    spectrum[m / 2] = Complex::new(0.0, 0.0);
    for (k, c) in spectrum.iter_mut().enumerate().take(m / 2).skip(1) {
        *c *= Complex::new(0.0, -(m as f64) / (TAU * k as f64));
        offset += 2.0 * c.re;
    }
    real_inverse_fft(&mut spectrum, &mut padded);
    let scale = step / m as f64;
    (0..n)
        .map(|j| scale * (mean * j as f64 + padded[j] - offset))
        .collect()
}

/// Which part of a Clenshaw–Curtis rule a piece of a libration uses (see
/// [`ChebyshevLevel`]): the whole rule on x ∈ [−1, 1] for a piece with no turning point,
/// θ = θ_l + L (1 + x)/2; or, for a piece with a turning point at one end, its half on
/// u ∈ [0, 1] with θ − θ_turning = ±L u², whose integrands (dt/du ∝ u/√(ε − V), with
/// ε − V ∝ u²) are even in u and analytic: the rule on [−1, 1] integrates them twice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChebyshevPiece {
    /// No turning point: x = −cos(iπ/N), node i = 0 … N from the left end.
    Regular,
    /// The left end a turning point: u = sin(iπ/N), i = 0 … N/2 (node 0 the turning point).
    TurningLeft,
    /// The right end a turning point: u = cos(iπ/N), i = 0 … N/2 (node N/2 the turning point).
    TurningRight,
}

impl ChebyshevPiece {
    /// Nodes of level `level` (N = 2^level intervals on [−1, 1]).
    #[inline]
    pub fn count(self, level: u32) -> usize {
        match self {
            ChebyshevPiece::Regular => (1 << level) + 1,
            _ => (1 << (level - 1)) + 1,
        }
    }

    /// Index of the node at the turning point, if the piece has one.
    #[inline]
    pub fn turning_node(self, level: u32) -> Option<usize> {
        match self {
            ChebyshevPiece::Regular => None,
            ChebyshevPiece::TurningLeft => Some(0),
            ChebyshevPiece::TurningRight => Some(1 << (level - 1)),
        }
    }

    /// Index j of node i in the Chebyshev points x_j = cos(jπ/N) of [−1, 1].
    #[inline]
    pub fn chebyshev_index(self, level: u32, i: usize) -> usize {
        match self {
            ChebyshevPiece::Regular => (1 << level) - i,
            ChebyshevPiece::TurningLeft => (1 << (level - 1)) - i,
            ChebyshevPiece::TurningRight => i,
        }
    }
}

/// The Clenshaw–Curtis rule with N = 2^level intervals on [−1, 1], nodes x_j = cos(jπ/N):
/// Σ_j w_j f(x_j) = ∫ p over [−1, 1], p the polynomial interpolating f at the nodes
/// (geometrically convergent for f analytic on [−1, 1]; the levels nest, level k's nodes
/// being every second of level k + 1's).
pub struct ChebyshevLevel {
    /// w_j, weights of ∫ over [−1, 1] (all positive).
    pub whole: Vec<f64>,
    /// v_j, weights of ∫ over [0, 1] (those of [−1, 0] are v_{N−j}).
    pub upper_half: Vec<f64>,
    /// The weights of each kind of piece by node (left to right), the turning point's halved:
    /// [Regular, TurningLeft, TurningRight].
    pub piece: [Vec<f64>; 3],
    /// For a [`ChebyshevPiece::TurningLeft`] node i (u_i = x_j): v_{N−j}, the weight its
    /// mirror image −u_i has in ∫ over [0, 1], the turning point's halved.
    pub turning_left_mirror: Vec<f64>,
}

/// The finest level of the Clenshaw–Curtis tables (N = 1024).
pub const FINEST_CHEBYSHEV_LEVEL: u32 = 10;
const _: () = assert!(1 << FINEST_CHEBYSHEV_LEVEL == FINEST_COSINE_INTERVALS);

impl ChebyshevLevel {
    /// The rule of `level` (1 … [`FINEST_CHEBYSHEV_LEVEL`]), from tables built once.
    pub fn get(level: u32) -> &'static ChebyshevLevel {
        static TABLES: [OnceLock<ChebyshevLevel>; FINEST_CHEBYSHEV_LEVEL as usize + 1] =
            [const { OnceLock::new() }; FINEST_CHEBYSHEV_LEVEL as usize + 1];
        TABLES[level as usize].get_or_init(|| Self::new(level))
    }

    fn new(level: u32) -> Self {
        let n = 1usize << level;
        // ∫ T_k over [−1, 1] and over [0, 1]; T_m(0) = cos(mπ/2).
        let t_at_zero = |m: usize| match m % 4 {
            0 => 1.0,
            2 => -1.0,
            _ => 0.0,
        };
        let whole_moment = |k: usize| {
            if k % 2 == 1 {
                0.0
            } else {
                2.0 / (1.0 - (k * k) as f64)
            }
        };
        let half_moment = |k: usize| match k {
            0 => 1.0,
            1 => 0.5,
            _ => {
                let (up, down) = (2.0 * (k + 1) as f64, 2.0 * (k - 1) as f64);
                (1.0 - t_at_zero(k + 1)) / up - (1.0 - t_at_zero(k - 1)) / down
            }
        };
        // w_j = (2/N) h_j Σ''_k cos(jkπ/N) I_k (h_j and the sum's end terms halved), from
        // p = Σ''_k c_k T_k with c_k = (2/N) Σ''_j f_j cos(jkπ/N).
        let cosines: Vec<f64> = (0..2 * n)
            .map(|m| (PI * m as f64 / n as f64).cos())
            .collect();
        let weights = |moment: &dyn Fn(usize) -> f64| -> Vec<f64> {
            let end = |m: usize| if m == 0 || m == n { 0.5 } else { 1.0 };
            let moments: Vec<f64> = (0..=n).map(|k| end(k) * moment(k)).collect();
            (0..=n)
                .map(|j| {
                    let sum: f64 = (0..=n)
                        .map(|k| cosines[(j * k) % (2 * n)] * moments[k])
                        .sum();
                    2.0 / n as f64 * end(j) * sum
                })
                .collect()
        };
        let (whole, upper_half) = (weights(&whole_moment), weights(&half_moment));
        let piece = [
            ChebyshevPiece::Regular,
            ChebyshevPiece::TurningLeft,
            ChebyshevPiece::TurningRight,
        ]
        .map(|kind| {
            if level == 0 && kind != ChebyshevPiece::Regular {
                return Vec::new();
            }
            (0..kind.count(level))
                .map(|i| {
                    let j = kind.chebyshev_index(level, i);
                    // The half rule: ½ ∫ over [−1, 1] of an even function.
                    match kind {
                        ChebyshevPiece::Regular => whole[j],
                        _ if 2 * j == n => 0.5 * whole[j],
                        _ => whole[j],
                    }
                })
                .collect()
        });
        let turning_left_mirror = if level == 0 {
            Vec::new()
        } else {
            let kind = ChebyshevPiece::TurningLeft;
            (0..kind.count(level))
                .map(|i| {
                    let j = kind.chebyshev_index(level, i);
                    let half = if 2 * j == n { 0.5 } else { 1.0 };
                    half * upper_half[n - j]
                })
                .collect()
        };
        Self {
            whole,
            upper_half,
            piece,
            turning_left_mirror,
        }
    }
}

impl IntervalNode {
    /// Node i of a piece of kind `kind` with 2^`level` intervals of the Clenshaw–Curtis rule
    /// on an interval of length `length` (see [`ChebyshevPiece`]); `jacobian` is dθ/dx or
    /// dθ/du (0 at a turning point).
    #[inline]
    pub fn chebyshev_tabulated(kind: ChebyshevPiece, level: u32, i: usize, length: f64) -> Self {
        match kind {
            ChebyshevPiece::Regular => {
                // x = −cos φ with φ = iπ/N: θ − θ_l = L sin²(φ/2), θ_r − θ = L cos²(φ/2).
                let node = Self::cosine_tabulated(1 << level, i, length);
                Self {
                    jacobian: 0.5 * length,
                    ..node
                }
            }
            _ => {
                // θ − θ_l = L sin²(iπ/N), θ_r − θ = L cos²(iπ/N): the cosine nodes at φ = 2iπ/N;
                // dθ/du = 2 L u with u² the distance to the turning point over L.
                let node = Self::cosine_tabulated(1 << (level - 1), i, length);
                let from_turning = if kind == ChebyshevPiece::TurningLeft {
                    node.from_left
                } else {
                    node.from_right
                };
                Self {
                    jacobian: 2.0 * (length * from_turning).sqrt(),
                    ..node
                }
            }
        }
    }
}

/// ∫ from −1 to x_j of the polynomial interpolating `values` (f at x_j = cos(jπ/N),
/// j = 0 … N, N a power of two ≥ 2) into `out` (N + 1 long), from its Chebyshev
/// coefficients (a DCT-I by a real FFT of 2N points) integrated term by term:
/// ∫ T_k = T_{k+1}/(2(k+1)) − T_{k−1}/(2(k−1)).
pub fn chebyshev_antiderivative(values: &[f64], out: &mut [f64]) {
    let n = values.len() - 1;
    debug_assert!(n >= 2 && n.is_power_of_two() && out.len() == n + 1);
    let m = 2 * n;
    with_buffers(m, n + 1, |buffer, spectrum| {
        buffer[..=n].copy_from_slice(values);
        for j in 1..n {
            buffer[m - j] = values[j];
        }
        real_fft(buffer, spectrum);
        // c_k = F_k / N, the ends halved.
        let inv_n = 1.0 / n as f64;
        let c = |k: usize| -> f64 {
            if k > n {
                0.0
            } else if k == 0 || k == n {
                0.5 * spectrum[k].re * inv_n
            } else {
                spectrum[k].re * inv_n
            }
        };
        // b_k, k = 1 … N + 1; T_{N+1} equals T_{N−1} at the nodes.
        let mut b: Vec<f64> = (0..=n + 1)
            .map(|k| match k {
                0 => 0.0,
                1 => c(0) - 0.5 * c(2),
                _ => (c(k - 1) - c(k + 1)) / (2 * k) as f64,
            })
            .collect();
        let last = b[n + 1];
        b[n - 1] += last;
        // Q(x_j) = Σ_k b_k cos(kjπ/N) by the inverse real FFT of the spectrum X_k = b_k/2,
        // X_N = b_N.
        for (k, s) in spectrum.iter_mut().enumerate() {
            let x = if k == n { b[n] } else { 0.5 * b[k] };
            *s = Complex::new(x, 0.0);
        }
        real_inverse_fft(spectrum, buffer);
        let start = buffer[n];
        for (o, q) in out.iter_mut().zip(&buffer[..=n]) {
            *o = q - start;
        }
    });
}

/// Runs `f` on per-thread buffers of `real` reals and `complex` complex numbers.
fn with_buffers<R>(
    real: usize,
    complex: usize,
    f: impl FnOnce(&mut [f64], &mut [Complex<f64>]) -> R,
) -> R {
    thread_local! {
        static BUFFERS: RefCell<(Vec<f64>, Vec<Complex<f64>>)> =
            const { RefCell::new((Vec::new(), Vec::new())) };
    }
    BUFFERS.with(|buffers| {
        let (reals, complexes) = &mut *buffers.borrow_mut();
        if reals.len() < real {
            reals.resize(real, 0.0);
        }
        if complexes.len() < complex {
            complexes.resize(complex, Complex::new(0.0, 0.0));
        }
        f(&mut reals[..real], &mut complexes[..complex])
    })
}
