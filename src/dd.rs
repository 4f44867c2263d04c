//! Double-double arithmetic: a value held as an unevaluated sum hi + lo of two doubles, about
//! 106 bits. Used where a few quantities must be known far below an ulp of double precision:
//! the level V of a turning point, whose offset from ε decides how the integrals of a cell
//! respond to the rounding of their ends ([`crate::cell`]).

/// hi + lo with |lo| ≤ ½ ulp(hi).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoubleDouble {
    /// The double nearest the value.
    pub hi: f64,
    /// The rest.
    pub lo: f64,
}

/// Relative error of the operations below: a few u² each, u = 2⁻⁵³ (Joldes, Muller and
/// Popescu 2017 bound the sum by 3u² + 4u³ and this product by about 5–7u²); 1e-30 is about
/// 80u², so a chain of a dozen of them stays below it.
pub const RELATIVE_ERROR: f64 = 1e-30;

/// a + b = s + e exactly (Knuth's TwoSum).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a + b = s + e exactly when |a| ≥ |b| (Dekker's FastTwoSum).
#[inline(always)]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// a b = p + e exactly (with a fused multiply-add).
#[inline(always)]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Σ xᵢ by Ogita, Rump and Oishi's Sum2 (2005): TwoSum's rounding errors are summed apart
/// and added once at the end, so the result is within u|Σ xᵢ| + γ²ₙ₋₁ Σ|xᵢ| of the exact
/// sum (γₙ = nu/(1 − nu)), as if summed in twice the precision and rounded once. The plain
/// loop's bound is γₙ₋₁ Σ|xᵢ|: over the ~850 nodes of a deep tanh-sinh level, 1.9e-13 of
/// Σ|xᵢ|, far beyond the few ulps the quadrature's rounding bounds allow it.
#[derive(Debug, Clone, Copy, Default)]
pub struct CompensatedSum {
    sum: f64,
    carry: f64,
}

impl CompensatedSum {
    /// Adds x.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let (s, e) = two_sum(self.sum, x);
        self.sum = s;
        self.carry += e;
    }

    /// The sum, rounded once.
    #[inline]
    pub fn value(self) -> f64 {
        self.sum + self.carry
    }
}

impl std::iter::Sum<f64> for CompensatedSum {
    fn sum<I: Iterator<Item = f64>>(iter: I) -> Self {
        let mut total = Self::default();
        iter.for_each(|x| total.add(x));
        total
    }
}

impl DoubleDouble {
    /// A double, exactly.
    #[inline(always)]
    pub const fn from_f64(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }

    /// The double nearest the value.
    #[inline(always)]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Sum (Joldes–Muller–Popescu's accurate DWPlusDW).
    #[allow(clippy::should_implement_trait)]
    #[inline(always)]
    pub fn add(self, other: Self) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        let (t, f) = two_sum(self.lo, other.lo);
        let (s, e) = fast_two_sum(s, e + t);
        let (hi, lo) = fast_two_sum(s, e + f);
        Self { hi, lo }
    }

    /// Sum of two values of the same sign (or zero), by the shorter algorithm
    /// (Joldes–Muller–Popescu's SloppyDWPlusDW): without cancellation its relative error is
    /// within 3u² as the accurate [`add`](Self::add)'s is; with it, unbounded (not to be used there).
    #[inline(always)]
    pub fn add_same_sign(self, other: Self) -> Self {
        debug_assert!(
            self.hi * other.hi >= 0.0,
            "add_same_sign of {self:?} and {other:?}"
        );
        let (s, e) = two_sum(self.hi, other.hi);
        let (hi, lo) = fast_two_sum(s, e + (self.lo + other.lo));
        Self { hi, lo }
    }

    /// The value plus a double.
    #[inline(always)]
    pub fn add_f64(self, b: f64) -> Self {
        let (s, e) = two_sum(self.hi, b);
        let (hi, lo) = fast_two_sum(s, e + self.lo);
        Self { hi, lo }
    }

    /// Negation, exactly.
    #[allow(clippy::should_implement_trait)]
    #[inline(always)]
    pub fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    /// Difference.
    #[allow(clippy::should_implement_trait)]
    #[inline(always)]
    pub fn sub(self, other: Self) -> Self {
        self.add(other.neg())
    }

    /// The pair (`sin`, `cos`) scaled onto the unit circle: for a pair within a few ulps of
    /// it, δ = sin² + cos² − 1 and 1/√(1 + δ) = 1 − δ/2 + O(δ²) (δ² below 1e-30 for
    /// |δ| ≤ 1e-15); otherwise by the root and two quotients.
    #[inline(always)]
    pub fn onto_circle(sin: Self, cos: Self) -> (Self, Self) {
        let radius_sq = sin.mul(sin).add_same_sign(cos.mul(cos));
        let delta = radius_sq.add_f64(-1.0).to_f64();
        if delta.abs() <= 1e-15 {
            let f = -0.5 * delta;
            (sin.add(sin.mul_f64(f)), cos.add(cos.mul_f64(f)))
        } else {
            let radius = radius_sq.sqrt();
            (sin.div(radius), cos.div(radius))
        }
    }

    /// Product (DWTimesDW).
    #[allow(clippy::should_implement_trait)]
    #[inline(always)]
    pub fn mul(self, other: Self) -> Self {
        let (p, e) = two_prod(self.hi, other.hi);
        let t = self.hi.mul_add(other.lo, self.lo * other.hi);
        let (hi, lo) = fast_two_sum(p, e + t);
        Self { hi, lo }
    }

    /// The value times a double.
    #[inline(always)]
    pub fn mul_f64(self, b: f64) -> Self {
        let (p, e) = two_prod(self.hi, b);
        let (hi, lo) = fast_two_sum(p, self.lo.mul_add(b, e));
        Self { hi, lo }
    }

    /// Quotient: a first quotient and two corrections from its remainder (itself computed to
    /// about u²). The corrections take the divisor's reciprocal (one division in all): each is
    /// within 2u of itself, the first about u of the quotient and the second about 2u of the
    /// first, so they add about 4u³.
    #[allow(clippy::should_implement_trait)]
    #[inline(always)]
    pub fn div(self, other: Self) -> Self {
        let q1 = self.hi / other.hi;
        let reciprocal = 1.0 / other.hi;
        let r = self.sub(other.mul_f64(q1));
        let q2 = r.hi * reciprocal;
        let r = r.sub(other.mul_f64(q2));
        let q3 = r.hi * reciprocal;
        let (hi, lo) = fast_two_sum(q1, q2);
        Self { hi, lo }.add_f64(q3)
    }

    /// sin x and cos x of a double x with |x| ≤ 8, to about 1e-31: x less the nearest
    /// multiple k of π/2 (π/2 in three doubles, exact to 1e-49), then the Taylor series of
    /// both on |r| ≤ π/4 to terms below 1e-34 (r²⁷/27! at most).
    pub fn sin_cos(x: f64) -> (Self, Self) {
        const HALF_PI: [f64; 3] = [
            std::f64::consts::FRAC_PI_2,
            6.123_233_995_736_766e-17,
            -1.497_384_904_859_169_8e-33,
        ];
        let k = (x / HALF_PI[0]).round();
        let r = HALF_PI.iter().fold(Self::from_f64(x), |r, &part| {
            let (p, e) = two_prod(k, part);
            r.sub(Self { hi: p, lo: 0.0 }.add_f64(e))
        });
        let square = r.mul(r);
        let (mut sin, mut cos) = (r, Self::from_f64(1.0));
        let (mut sin_term, mut cos_term) = (r, Self::from_f64(1.0));
        for n in (2..28).step_by(2) {
            let n = n as f64;
            cos_term = cos_term.mul(square).div(Self::from_f64(-(n - 1.0) * n));
            sin_term = sin_term.mul(square).div(Self::from_f64(-n * (n + 1.0)));
            cos = cos.add(cos_term);
            sin = sin.add(sin_term);
            if cos_term.hi.abs() < 1e-34 && sin_term.hi.abs() < 1e-34 {
                break;
            }
        }
        match (k as i64).rem_euclid(4) {
            0 => (sin, cos),
            1 => (cos, sin.neg()),
            2 => (sin.neg(), cos.neg()),
            _ => (cos.neg(), sin),
        }
    }

    /// Square root of a value ≥ 0: one Newton step from the double root.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Self::from_f64(0.0);
        }
        let x = self.hi.sqrt();
        // √a ≈ x + (a − x²)/(2x), with a − x² from the exact square.
        let residual = self.sub(Self::from_f64(x).mul_f64(x));
        Self::from_f64(x).add_f64(residual.hi / (2.0 * x))
    }
}
