//! Dual numbers: a value and its derivatives along `P` directions at once (forward-mode
//! differentiation). A formula written generic over [`Real`] (or [`Scalar`](crate::real::Scalar))
//! runs on [`Dual`] unchanged and returns, beside its value, the exact derivatives of what it
//! computed: the directional derivatives `Σ_j ∂f/∂x_j d_j` of each of the `P` seeds. The forward
//! sensitivities of a run (`crate::sensitivity`) differentiate the equations of motion this
//! way, with no derivative written by hand (Griewank & Walther, *Evaluating Derivatives*, 2nd
//! ed., SIAM 2008, §3.1).
//!
//! The value is computed by the very `f64` operations of the plain formula, in the same order,
//! so it is bit for bit the plain result. The `P` derivatives are a fixed-size array: with
//! `P = 8` each of their operations is one AVX-512 instruction, or two AVX2 ones (the
//! directions of a block run in lanes); with `FUSED` a product's are fused multiply-adds.

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::real::{sum_of_squares_is_safe, Real};

/// `v + Σ_j d_j ε_j` with `ε_i ε_j = 0`. With `FUSED`, the derivatives of a product are a
/// product and a fused multiply-add per direction (of `mul_add`, two fused multiply-adds):
/// for the formulas compiled inside an instruction set's copy with FMA (a run's rates,
/// `crate::sensitivity`), not for those that run out of line, compiled for the baseline,
/// where each would be a call into software.
///
/// The derivatives come first, on a 32-byte boundary: eight of them are two AVX2 vectors that
/// never straddle two cache lines (after the value, at 8 bytes into a 72-byte number, most
/// did).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Dual<const P: usize, const FUSED: bool = false> {
    /// The derivatives along the `P` directions.
    pub d: [f64; P],
    /// The value.
    pub v: f64,
}

impl<const P: usize, const F: bool> Default for Dual<P, F> {
    #[inline(always)]
    fn default() -> Self {
        Dual {
            v: 0.0,
            d: [0.0; P],
        }
    }
}

impl<const P: usize> Dual<P> {
    /// The value `v` with the derivatives `d` (not fused: `Dual { v, d }` for a fused one).
    #[inline(always)]
    pub fn new(v: f64, d: [f64; P]) -> Self {
        Dual { v, d }
    }
}

impl<const P: usize, const F: bool> Dual<P, F> {
    /// `self` times the constant `c` (value and derivatives).
    #[inline(always)]
    fn scaled(self, c: f64) -> Self {
        let mut d = self.d;
        for x in d.iter_mut() {
            *x *= c;
        }
        Dual { v: self.v * c, d }
    }
}

impl<const P: usize, const F: bool> Add for Dual<P, F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        let mut d = self.d;
        for (a, b) in d.iter_mut().zip(o.d) {
            *a += b;
        }
        Dual { v: self.v + o.v, d }
    }
}

impl<const P: usize, const F: bool> Sub for Dual<P, F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        let mut d = self.d;
        for (a, b) in d.iter_mut().zip(o.d) {
            *a -= b;
        }
        Dual { v: self.v - o.v, d }
    }
}

impl<const P: usize, const F: bool> Mul for Dual<P, F> {
    type Output = Self;
    /// `(uv)' = u'v + uv'`.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut d = self.d;
        for (a, b) in d.iter_mut().zip(o.d) {
            *a = if F {
                a.mul_add(o.v, self.v * b)
            } else {
                *a * o.v + self.v * b
            };
        }
        Dual { v: self.v * o.v, d }
    }
}

impl<const P: usize, const F: bool> Div for Dual<P, F> {
    type Output = Self;
    /// `(u/v)' = (u' − (u/v) v')/v` (the derivatives times `1/v`: one division, not one per
    /// direction).
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        let r = 1.0 / o.v;
        let mut d = self.d;
        for (a, b) in d.iter_mut().zip(o.d) {
            *a = if F { (-q).mul_add(b, *a) } else { *a - q * b } * r;
        }
        Dual { v: q, d }
    }
}

impl<const P: usize, const F: bool> Neg for Dual<P, F> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Dual {
            v: -self.v,
            d: self.d.map(|x| -x),
        }
    }
}

impl<const P: usize, const F: bool> Real for Dual<P, F> {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Dual { v: x, d: [0.0; P] }
    }
    /// `(c u)' = c u'`: the product by `splat(c)` without its zero derivatives' terms (the
    /// same numbers, up to the sign of a zero).
    #[inline(always)]
    fn scale(self, c: f64) -> Self {
        self.scaled(c)
    }
    /// `(√u)' = u'/(2√u)` (infinite at 0, as the derivative is).
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        let c = 0.5 / s;
        Dual {
            v: s,
            d: self.d.map(|x| x * c),
        }
    }
    /// `|u|' = sign(u) u'` (the derivative from the side of the sign bit at zero).
    #[inline(always)]
    fn abs(self) -> Self {
        if self.v.is_sign_negative() {
            -self
        } else {
            self
        }
    }
    /// Piecewise constant: derivative 0.
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        Self::splat(self.v.round_ties_even())
    }
    /// Piecewise constant: derivative 0.
    #[inline(always)]
    fn trunc(self) -> Self {
        Self::splat(self.v.trunc())
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let mut d = b.d;
        for (j, x) in d.iter_mut().enumerate() {
            *x = if F {
                self.v.mul_add(a.d[j], a.v.mul_add(self.d[j], *x))
            } else {
                *x + (self.v * a.d[j] + a.v * self.d[j])
            };
        }
        Dual {
            v: self.v.mul_add(a.v, b.v),
            d,
        }
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        if self.v.is_sign_negative() == sign.v.is_sign_negative() {
            self
        } else {
            -self
        }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self.v < o.v
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self.v <= o.v
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self.v > o.v
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self.v >= o.v
    }
    #[inline(always)]
    fn equal(self, o: Self) -> bool {
        self.v == o.v
    }
    #[inline(always)]
    fn unequal(self, o: Self) -> bool {
        self.v != o.v
    }
    /// Zero with zero derivatives.
    #[inline(always)]
    fn vanishes(self) -> bool {
        self.v == 0.0 && self.d.iter().all(|x| *x == 0.0)
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    /// `√(a² + b²)` as `f64` takes it (the plain sum of squares or `hypot`), and its
    /// derivative `(a a' + b b')/r`.
    #[inline(always)]
    fn norm2(a: Self, b: Self, _plain: &mut bool) -> Self {
        let s = a.v * a.v + b.v * b.v;
        if sum_of_squares_is_safe(s) {
            return (a * a + b * b).sqrt();
        }
        let r = a.v.hypot(b.v);
        if r == 0.0 {
            return Self::splat(0.0);
        }
        let (ca, cb) = (a.v / r, b.v / r);
        let mut out = a.scaled(ca) + b.scaled(cb);
        out.v = r;
        out
    }
    /// `sin' = cos`, `cos' = −sin`.
    #[inline(always)]
    fn sin_cos_std(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (
            Dual {
                v: s,
                d: self.d.map(|x| x * c),
            },
            Dual {
                v: c,
                d: self.d.map(|x| -x * s),
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::real::sin_cos;

    /// A formula generic over `Real`, its derivative against the hand-written one and against
    /// central differences (two independent routes), and its value bit for bit the `f64` one.
    #[test]
    fn a_generic_formula_gets_its_exact_derivatives() {
        fn f<T: Real>(x: T, y: T) -> T {
            let (s, c) = sin_cos(x * y);
            (x * x + y).sqrt() / (T::splat(2.0) + c) - s * y.abs()
        }
        for (x, y) in [(0.3, 1.7), (-1.2, -0.4), (2.5, 0.01), (-0.7, 3.1)] {
            let dx = f(Dual::new(x, [1.0, 0.0]), Dual::new(y, [0.0, 1.0]));
            assert_eq!(dx.v.to_bits(), f(x, y).to_bits());
            let (s, c) = (x * y).sin_cos();
            let r = (x * x + y).sqrt();
            let fx = x / r / (2.0 + c) + r * y * s / (2.0 + c).powi(2) - c * y * y.abs();
            let fy = 0.5 / r / (2.0 + c) + r * x * s / (2.0 + c).powi(2)
                - c * x * y.abs()
                - s * y.signum();
            assert!((dx.d[0] - fx).abs() < 1e-14 * (1.0 + fx.abs()), "{x} {y}");
            assert!((dx.d[1] - fy).abs() < 1e-14 * (1.0 + fy.abs()), "{x} {y}");
            let h = 1e-6;
            let cx = (f(x + h, y) - f(x - h, y)) / (2.0 * h);
            assert!((dx.d[0] - cx).abs() < 1e-8 * (1.0 + cx.abs()));
        }
    }

    /// Fused products give the same value bit for bit and the same derivatives to round-off
    /// (each checked against the hand-written derivative of the same formula).
    #[test]
    fn fused_products_give_the_same_derivatives() {
        fn f<T: Real>(x: T, y: T) -> T {
            (x * y).mul_add(x, y) / (x - y * y) + x * x * y
        }
        for (x, y) in [(0.3, 1.7), (-1.2, -0.4), (2.5, 0.01), (-0.7, 3.1)] {
            let plain = f(Dual::new(x, [1.0, 0.0]), Dual::new(y, [0.0, 1.0]));
            let fused = f(
                Dual::<2, true> {
                    v: x,
                    d: [1.0, 0.0],
                },
                Dual::<2, true> {
                    v: y,
                    d: [0.0, 1.0],
                },
            );
            assert_eq!(fused.v.to_bits(), plain.v.to_bits());
            assert_eq!(fused.v.to_bits(), f(x, y).to_bits());
            let (n, m) = (x * x * y + y, x - y * y);
            let fx = (2.0 * x * y * m - n) / (m * m) + 2.0 * x * y;
            let fy = ((x * x + 1.0) * m + 2.0 * y * n) / (m * m) + x * x;
            for (j, exact) in [fx, fy].into_iter().enumerate() {
                for d in [plain.d[j], fused.d[j]] {
                    assert!(
                        (d - exact).abs() < 1e-13 * (1.0 + exact.abs()),
                        "{x} {y} {j}"
                    );
                }
            }
        }
    }

    #[test]
    fn norm2_differentiates_both_branches() {
        let mut plain = true;
        for (a, b) in [(3.0, 4.0), (3e200, 4e200), (3e-200, 4e-200)] {
            let r = Dual::<2>::norm2(
                Dual::new(a, [1.0, 0.0]),
                Dual::new(b, [0.0, 1.0]),
                &mut plain,
            );
            assert_eq!(r.v, f64::hypot(a, b));
            assert!((r.d[0] - 0.6).abs() < 1e-15 && (r.d[1] - 0.8).abs() < 1e-15);
        }
    }
}
