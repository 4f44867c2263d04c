//! The two numerical rules the cell solver is built on: the tanh-sinh (double-exponential)
//! rule on an interval, which absorbs integrable end singularities and clusters its nodes at
//! near-singular ends, and the spectral antiderivative on its uniform τ-grid, which gives the
//! cumulative integrals (ψ along the orbit) from the same nodes to the same accuracy.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use std::cell::RefCell;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Half-width of the τ-interval: at τ = 4 the nodes lie within e^{−86} ≈ 1e-37 of the ends
/// (relative to the interval), far enough for 1/√x and near-logarithmic end behaviour.
pub const TAU_MAX: f64 = 4.0;

/// One node of the tanh-sinh rule on an interval [a, a + L]:
/// x = a + L/2 (1 + tanh(π/2 sinh τ)), dx/dτ = L/2 · (π/2) cosh τ / cosh²(π/2 sinh τ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TanhSinhNode {
    /// x − a, to full relative precision however close to a.
    pub from_left: f64,
    /// a + L − x, to full relative precision however close to the right end.
    pub from_right: f64,
    /// dx/dτ at the node (multiply by the step to get the quadrature weight).
    pub jacobian: f64,
}

impl TanhSinhNode {
    /// The node at τ on an interval of length `length`.
    #[inline]
    pub fn at(tau: f64, length: f64) -> Self {
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
}

/// The finest level [`TanhSinhNode::table`] holds.
pub const FINEST_LEVEL: u32 = 10;

impl TanhSinhNode {
    /// Node j of level `level` (≤ [`FINEST_LEVEL`]) on an interval of length `length`, from a
    /// table of the unit-interval nodes built once (the node positions scale with the length).
    #[inline]
    pub fn tabulated(level: u32, j: usize, length: f64) -> Self {
        let unit = Self::table()[j << (FINEST_LEVEL - level)];
        Self {
            from_left: unit.from_left * length,
            from_right: unit.from_right * length,
            jacobian: unit.jacobian * length,
        }
    }

    fn table() -> &'static [TanhSinhNode] {
        static TABLE: std::sync::OnceLock<Vec<TanhSinhNode>> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| {
            let finest = TanhSinhLevel::new(FINEST_LEVEL);
            (0..finest.count)
                .map(|j| TanhSinhNode::at(finest.tau(j), 1.0))
                .collect()
        })
    }
}

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

thread_local! {
    static PLANNER: RefCell<FftPlanner<f64>> = RefCell::new(FftPlanner::new());
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
    let m = n.next_power_of_two();
    let mut buf: Vec<Complex<f64>> = values
        .iter()
        .map(|&v| Complex::new(v, 0.0))
        .chain(std::iter::repeat_n(Complex::new(0.0, 0.0), m - n))
        .collect();
    let (forward, inverse) = PLANNER.with(|p| {
        let mut p = p.borrow_mut();
        (p.plan_fft_forward(m), p.plan_fft_inverse(m))
    });
    forward.process(&mut buf);
    let mean = buf[0].re;
    // c_k = ĝ_k m / (2πi k′) with k′ the signed frequency; the Nyquist term is dropped.
    let mut offset = Complex::new(0.0, 0.0);
    buf[0] = Complex::new(0.0, 0.0);
    buf[m / 2] = Complex::new(0.0, 0.0);
    for (k, c) in buf.iter_mut().enumerate().skip(1) {
        let signed = if k < m / 2 {
            k as f64
        } else {
            k as f64 - m as f64
        };
        *c *= Complex::new(0.0, -(m as f64) / (TAU * signed));
        offset += *c;
    }
    inverse.process(&mut buf);
    let scale = step / m as f64;
    (0..n)
        .map(|j| scale * (mean * j as f64 + (buf[j] - offset).re))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tanh_sinh_integrates_end_singularities() {
        // ∫_0^2 dx / √(x (2 − x)) = π, with both ends singular.
        let level = TanhSinhLevel::new(5);
        let sum: f64 = (0..level.count)
            .map(|j| {
                let node = TanhSinhNode::at(level.tau(j), 2.0);
                node.jacobian / (node.from_left * node.from_right).sqrt()
            })
            .sum::<f64>()
            * level.step;
        assert!((sum - std::f64::consts::PI).abs() < 1e-14, "{sum}");
    }

    #[test]
    fn spectral_antiderivative_matches_a_closed_form() {
        // g = sech² τ on the tanh-sinh grid of ∫_0^1 2x dx: G(x) = x², compared at each node.
        let level = TanhSinhLevel::new(5);
        let nodes: Vec<_> = (0..level.count)
            .map(|j| TanhSinhNode::at(level.tau(j), 1.0))
            .collect();
        let g: Vec<f64> = nodes
            .iter()
            .map(|n| 2.0 * n.from_left * n.jacobian)
            .collect();
        let cumulative = spectral_antiderivative(&g, level.step);
        for (node, value) in nodes.iter().zip(&cumulative) {
            let exact = node.from_left * node.from_left;
            assert!((value - exact).abs() < 1e-13, "{value} vs {exact}");
        }
    }
}
