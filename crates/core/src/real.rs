//! Numbers one at a time or many at a time: the [`Real`] trait lets a formula be written once
//! and run on `f64` (a single evaluation) or on [`Wide`] (`N` members in lanes: structure of
//! arrays, the member loop innermost, eight lanes per AVX-512 instruction).
//!
//! Nothing here is a formula of the physics. Every operation of [`Wide`] is the `f64`
//! operation lane by lane (IEEE arithmetic, `sqrt` and comparisons are exact per lane, and
//! Rust never contracts or reassociates floating point), so a lane computes bit for bit what
//! the same generic code computes on `f64`, whatever instruction set runs it. Branches become
//! selections ([`Real::select`]) between values both computed; a loop whose length depends on
//! the data runs until no lane needs another step, a lane that has finished keeping its values
//! (its own run's result).
//!
//! The sine and cosine ([`sin_cos_small`], and [`sin_cos`] with its argument reduced) are
//! polynomials and selections, so that they run in lanes too.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A lane mask: `bool` for `f64`, [`WideMask`] for [`Wide`].
pub trait Mask:
    Copy
    + Default
    + std::fmt::Debug
    + PartialEq
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
{
    /// Every lane `b`.
    fn splat(b: bool) -> Self;
    /// Whether some lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
}

impl Mask for bool {
    #[inline(always)]
    fn splat(b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
}

/// Real numbers in lanes (one lane for `f64`). The operations are IEEE double precision lane
/// by lane.
pub trait Real:
    Copy
    + Default
    + std::fmt::Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Mask;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// The nearest integer, ties to even.
    fn round_ties_even(self) -> Self;
    /// The integer part (towards zero).
    fn trunc(self) -> Self;
    /// `|self|` with the sign of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// `self · a + b` with one rounding (fused multiply–add).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `self · c` for a constant `c`: `self * Self::splat(c)`, the same numbers (dual numbers
    /// skip the products of the constant's zero derivatives).
    #[inline(always)]
    fn scale(self, c: f64) -> Self {
        self * Self::splat(c)
    }
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn equal(self, o: Self) -> Self::Mask;
    fn unequal(self, o: Self) -> Self::Mask;
    /// Whether `self` is zero and stays zero to first order: its value, and on dual numbers
    /// its derivatives too. A formula that skips a term whose coefficient vanishes (a spring
    /// with no damper) asks this, not `equal(0)`, so that a derivative along the coefficient
    /// keeps the skipped term's.
    #[inline(always)]
    fn vanishes(self) -> Self::Mask {
        self.equal(Self::splat(0.0))
    }
    /// Lane by lane, `a` where `m` is set, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `√(a² + b²)`. For `f64`, the square root of the sum where the squares neither overflow
    /// nor underflow, else `hypot`; in lanes the square root of the sum, and `plain` cleared
    /// in the lanes where `f64` would take `hypot` (they are evaluated one at a time).
    fn norm2(a: Self, b: Self, plain: &mut Self::Mask) -> Self;
    /// `(sin x, cos x)` by the standard library, lane by lane (on dual numbers with their
    /// derivatives): the plain formulas that take them from it, generic.
    fn sin_cos_std(self) -> (Self, Self);
}

/// A [`Real`] one number at a time (its comparisons are plain `bool`): `f64`, and the dual
/// numbers of [`crate::dual`]. Formulas that branch on their data (the forces' switches, a
/// slack tether) are generic over it.
pub trait Scalar: Real<Mask = bool> {}

impl<T: Real<Mask = bool>> Scalar for T {}

/// `a x² − b y²` to nearly full relative precision however close the two terms are (the
/// products and squares carried as unevaluated sums of two numbers with fused multiply–adds,
/// Ogita, Rump & Oishi 2005; the difference of the leading parts is exact where it cancels,
/// Sterbenz), with the sum of the terms' magnitudes: the distance of a motion from the
/// separatrix, `a² − 2k I2`, which sets the parameter's complement `1 − m` near it.
/// `a = a_hi + a_lo`, `b = b_hi + b_lo`.
#[inline(always)]
pub fn squares_difference<T: Real>(a: (T, T), x: T, b: (T, T), y: T) -> (T, T) {
    let (p, p_lo) = scaled_square(a, x);
    let (q, q_lo) = scaled_square(b, y);
    ((p - q) + (p_lo - q_lo), p.abs() + q.abs())
}

/// `c z²` as `(hi, lo)` for `c = c_hi + c_lo` ([`squares_difference`]'s terms; a function,
/// not a closure: the compiler left the closure out of line, compiled for the baseline, where
/// the lanes ran it in SSE2 with `fma` a library call).
#[inline(always)]
fn scaled_square<T: Real>((c, c_lo): (T, T), z: T) -> (T, T) {
    let s = z * z;
    let s_lo = z.mul_add(z, -s);
    let p = c * s;
    let p_lo = c.mul_add(s, -p) + c * s_lo + c_lo * s;
    (p, p_lo)
}

/// `x · y` as an unevaluated sum `(hi, lo)`, `hi = fl(x y)` (a fused multiply–add).
#[inline(always)]
pub fn two_product<T: Real>(x: T, y: T) -> (T, T) {
    let hi = x * y;
    (hi, x.mul_add(y, -hi))
}

/// `c (a − b)` as an unevaluated sum `(hi, lo)`: the difference itself carried exactly
/// (Knuth's TwoSum; it rounds where `a` and `b` are more than a factor of two apart, as
/// `I2 − I1` of a body with `I1 < I2/2`), then the product ([`two_product`]), its low part
/// with `c` times the difference's.
#[inline(always)]
pub fn two_product_of_difference<T: Real>(c: T, a: T, b: T) -> (T, T) {
    let d = a - b;
    let bv = d - a;
    let d_lo = (a - (d - bv)) + (-b - bv);
    let (hi, lo) = two_product(c, d);
    (hi, lo + c * d_lo)
}

/// Whether `√(a² + b²)` may be taken as the square root of the sum `s = a² + b²`.
#[inline(always)]
pub(crate) fn sum_of_squares_is_safe(s: f64) -> bool {
    s.is_normal() && s < 1e300
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn round_ties_even(self) -> f64 {
        f64::round_ties_even(self)
    }
    #[inline(always)]
    fn trunc(self) -> f64 {
        f64::trunc(self)
    }
    #[inline(always)]
    fn copysign(self, sign: f64) -> f64 {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn lt(self, o: f64) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: f64) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: f64) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: f64) -> bool {
        self >= o
    }
    #[inline(always)]
    fn equal(self, o: f64) -> bool {
        self == o
    }
    #[inline(always)]
    fn unequal(self, o: f64) -> bool {
        self != o
    }
    #[inline(always)]
    fn select(m: bool, a: f64, b: f64) -> f64 {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn norm2(a: f64, b: f64, _plain: &mut bool) -> f64 {
        let s = a * a + b * b;
        if sum_of_squares_is_safe(s) {
            s.sqrt()
        } else {
            a.hypot(b)
        }
    }
    #[inline(always)]
    fn sin_cos_std(self) -> (f64, f64) {
        self.sin_cos()
    }
}

/// Lanes of [`Wide`] by default: thirty-two doubles, four AVX-512 registers (eight AVX2
/// ones) per value, so that four independent vector instructions hide each other's latency
/// (measured faster than 8, 16 or 64 lanes for the exact torque-free motion).
pub const WIDTH: usize = 32;

/// `N` doubles, one per lane, on whole cache lines.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wide<const N: usize = WIDTH>(pub [f64; N]);

impl<const N: usize> Default for Wide<N> {
    fn default() -> Self {
        Wide([0.0; N])
    }
}

/// `N` lane flags, each all ones (set) or all zeros, as vector compares make them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideMask<const N: usize = WIDTH>(pub [u64; N]);

impl<const N: usize> Default for WideMask<N> {
    fn default() -> Self {
        WideMask([0; N])
    }
}

impl<const N: usize> WideMask<N> {
    /// Lane `l` set.
    #[inline(always)]
    pub fn get(self, l: usize) -> bool {
        self.0[l] != 0
    }
    /// Lane `l` cleared where `b` is false.
    #[inline(always)]
    pub fn and_lane(&mut self, l: usize, b: bool) {
        self.0[l] &= flag(b);
    }
}

#[inline(always)]
fn flag(b: bool) -> u64 {
    (b as u64).wrapping_neg()
}

impl<const N: usize> Wide<N> {
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Wide<N> {
        let mut out = [0.0; N];
        for l in 0..N {
            out[l] = f(self.0[l]);
        }
        Wide(out)
    }
    #[inline(always)]
    fn zip(self, o: Wide<N>, f: impl Fn(f64, f64) -> f64) -> Wide<N> {
        let mut out = [0.0; N];
        for l in 0..N {
            out[l] = f(self.0[l], o.0[l]);
        }
        Wide(out)
    }
    #[inline(always)]
    fn test(self, o: Wide<N>, f: impl Fn(f64, f64) -> bool) -> WideMask<N> {
        let mut out = [0; N];
        for l in 0..N {
            out[l] = flag(f(self.0[l], o.0[l]));
        }
        WideMask(out)
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const N: usize> $tr for Wide<N> {
            type Output = Wide<N>;
            #[inline(always)]
            fn $f(self, o: Wide<N>) -> Wide<N> {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl<const N: usize> Neg for Wide<N> {
    type Output = Wide<N>;
    #[inline(always)]
    fn neg(self) -> Wide<N> {
        self.map(|a| -a)
    }
}

impl<const N: usize> BitAnd for WideMask<N> {
    type Output = WideMask<N>;
    #[inline(always)]
    fn bitand(self, o: WideMask<N>) -> WideMask<N> {
        let mut out = [0; N];
        for l in 0..N {
            out[l] = self.0[l] & o.0[l];
        }
        WideMask(out)
    }
}

impl<const N: usize> BitOr for WideMask<N> {
    type Output = WideMask<N>;
    #[inline(always)]
    fn bitor(self, o: WideMask<N>) -> WideMask<N> {
        let mut out = [0; N];
        for l in 0..N {
            out[l] = self.0[l] | o.0[l];
        }
        WideMask(out)
    }
}

impl<const N: usize> Not for WideMask<N> {
    type Output = WideMask<N>;
    #[inline(always)]
    fn not(self) -> WideMask<N> {
        let mut out = [0; N];
        for l in 0..N {
            out[l] = !self.0[l];
        }
        WideMask(out)
    }
}

impl<const N: usize> Mask for WideMask<N> {
    #[inline(always)]
    fn splat(b: bool) -> WideMask<N> {
        WideMask([flag(b); N])
    }
    #[inline(always)]
    fn any(self) -> bool {
        let mut any = 0;
        for l in 0..N {
            any |= self.0[l];
        }
        any != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        let mut all = !0;
        for l in 0..N {
            all &= self.0[l];
        }
        all != 0
    }
}

impl<const N: usize> Real for Wide<N> {
    type Mask = WideMask<N>;
    #[inline(always)]
    fn splat(x: f64) -> Wide<N> {
        Wide([x; N])
    }
    #[inline(always)]
    fn sqrt(self) -> Wide<N> {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Wide<N> {
        self.map(f64::abs)
    }
    #[inline(always)]
    fn round_ties_even(self) -> Wide<N> {
        self.map(f64::round_ties_even)
    }
    #[inline(always)]
    fn trunc(self) -> Wide<N> {
        self.map(f64::trunc)
    }
    #[inline(always)]
    fn copysign(self, sign: Wide<N>) -> Wide<N> {
        self.zip(sign, f64::copysign)
    }
    #[inline(always)]
    fn mul_add(self, a: Wide<N>, b: Wide<N>) -> Wide<N> {
        let mut out = [0.0; N];
        for l in 0..N {
            out[l] = self.0[l].mul_add(a.0[l], b.0[l]);
        }
        Wide(out)
    }
    #[inline(always)]
    fn lt(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a <= b)
    }
    #[inline(always)]
    fn gt(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a > b)
    }
    #[inline(always)]
    fn ge(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a >= b)
    }
    #[inline(always)]
    fn equal(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a == b)
    }
    #[inline(always)]
    fn unequal(self, o: Wide<N>) -> WideMask<N> {
        self.test(o, |a, b| a != b)
    }
    #[inline(always)]
    fn select(m: WideMask<N>, a: Wide<N>, b: Wide<N>) -> Wide<N> {
        let mut out = [0.0; N];
        for l in 0..N {
            out[l] = f64::from_bits((a.0[l].to_bits() & m.0[l]) | (b.0[l].to_bits() & !m.0[l]));
        }
        Wide(out)
    }
    #[inline(always)]
    fn norm2(a: Wide<N>, b: Wide<N>, plain: &mut WideMask<N>) -> Wide<N> {
        let s = a * a + b * b;
        for l in 0..N {
            plain.and_lane(l, sum_of_squares_is_safe(s.0[l]));
        }
        s.sqrt()
    }
    #[inline(always)]
    fn sin_cos_std(self) -> (Wide<N>, Wide<N>) {
        (self.map(f64::sin), self.map(f64::cos))
    }
}

/// Python's `max(a, b)`: `a` unless `b > a`.
#[inline(always)]
pub fn py_max<T: Real>(a: T, b: T) -> T {
    T::select(b.gt(a), b, a)
}

/// Python's `min(a, b)`: `a` unless `b < a`.
#[inline(always)]
pub fn py_min<T: Real>(a: T, b: T) -> T {
    T::select(b.lt(a), b, a)
}

/// fdlibm's coefficients, with the digits its sources give them.
#[allow(clippy::excessive_precision, clippy::approx_constant)]
mod fdlibm {
    // fdlibm's kernel polynomials (musl's `__sin` and `__cos`, with no tail `y`)
    pub const S1: f64 = -1.666_666_666_666_663_243_48e-01;
    pub const S2: f64 = 8.333_333_333_322_489_461_24e-03;
    pub const S3: f64 = -1.984_126_982_985_794_931_34e-04;
    pub const S4: f64 = 2.755_731_370_707_006_767_89e-06;
    pub const S5: f64 = -2.505_076_025_340_686_341_95e-08;
    pub const S6: f64 = 1.589_690_995_211_550_102_21e-10;
    pub const C1: f64 = 4.166_666_666_666_660_190_37e-02;
    pub const C2: f64 = -1.388_888_888_887_410_957_49e-03;
    pub const C3: f64 = 2.480_158_728_947_672_941_78e-05;
    pub const C4: f64 = -2.755_731_435_139_066_330_35e-07;
    pub const C5: f64 = 2.087_572_321_298_174_827_90e-09;
    pub const C6: f64 = -1.135_964_755_778_819_482_65e-11;

    // fdlibm's `__rem_pio2`: 2/π, and π/2 in three parts of 33, 33 and 53 bits (the first two
    // times an integer below 2²⁰ are exact)
    pub const INV_PIO2: f64 = 6.366_197_723_675_813_824_33e-01;
    pub const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
    pub const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
    pub const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
    pub const PIO2_3T: f64 = 8.478_427_660_368_899_569_97e-32;

    // fdlibm's `atan` (`s_atan.c`): atan of the breakpoints 0.5, 1, 1.5, ∞ (high and low parts)
    // and the polynomial of the reduced argument
    pub const ATAN_HI: [f64; 4] = [
        4.636_476_090_008_060_935_15e-01,
        7.853_981_633_974_482_789_99e-01,
        9.827_937_232_473_290_540_82e-01,
        1.570_796_326_794_896_558_00e+00,
    ];
    pub const ATAN_LO: [f64; 4] = [
        2.269_877_745_296_168_709_24e-17,
        3.061_616_997_868_383_017_93e-17,
        1.390_331_103_123_099_845_16e-17,
        6.123_233_995_736_766_035_87e-17,
    ];
    pub const AT: [f64; 11] = [
        3.333_333_333_333_293_180_27e-01,
        -1.999_999_999_987_648_324_76e-01,
        1.428_571_427_250_346_637_11e-01,
        -1.111_111_040_546_235_578_80e-01,
        9.090_887_133_436_506_561_96e-02,
        -7.691_876_205_044_829_994_95e-02,
        6.661_073_137_387_531_206_69e-02,
        -5.833_570_133_790_573_486_45e-02,
        4.976_877_994_615_932_360_17e-02,
        -3.653_157_274_421_691_552_70e-02,
        1.628_582_011_536_578_236_23e-02,
    ];
}
use fdlibm::*;

/// `(sin x, cos x)` for `|x| ≤ π/4` (a little beyond is fine), within an ulp: fdlibm's kernel
/// polynomials (Sun Microsystems' `__kernel_sin`, `__kernel_cos`, as musl writes them), which
/// need no argument reduction and no branch, so that they run in lanes.
#[inline(always)]
pub fn sin_cos_small<T: Real>(x: T) -> (T, T) {
    let c = T::splat;
    let z = x * x;
    let w = z * z;
    // sin x = x + x³ (S1 + z r)
    let r = c(S2) + z * (c(S3) + z * c(S4)) + z * w * (c(S5) + z * c(S6));
    let v = z * x;
    let sin = x + v * (c(S1) + z * r);
    // cos x = 1 − z/2 + z r, with 1 − z/2 rounded once and its error carried
    let r = z * (c(C1) + z * (c(C2) + z * c(C3))) + w * w * (c(C4) + z * (c(C5) + z * c(C6)));
    let hz = c(0.5) * z;
    let one_minus = c(1.0) - hz;
    let cos = one_minus + (((c(1.0) - one_minus) - hz) + z * r);
    (sin, cos)
}

/// `(sin x, cos x)` for the angles of a step, `|x| < 2²⁰ π/2` (1.6·10⁶): within two ulps
/// away from the zeros of sin and cos, and within 2⁻⁵² of the true values everywhere (tested
/// against the standard library):
/// `x = n π/2 + r` with `n` the nearest integer to `2x/π` and `r` formed with π/2 in three
/// parts (fdlibm's `__rem_pio2` for medium arguments, every product `n · part` exact), then
/// [`sin_cos_small`] of `r` and the quadrant `n mod 4` chosen by selection, so that it runs in
/// lanes. For `|x| ≤ π/4`, `n = 0` and this is [`sin_cos_small`] itself. Beyond 2²⁰ π/2 the
/// reduction loses digits: the reduced angle is then held to [−π/4, π/4], so that the pair is
/// still a point of the unit circle (`sin² + cos² = 1` to round-off: a rotation by a huge
/// angle stays a rotation), though not the true one. Infinities and NaN give NaN.
#[inline(always)]
pub fn sin_cos<T: Real>(x: T) -> (T, T) {
    let c = T::splat;
    let n = (x * c(INV_PIO2)).round_ties_even();
    let r = (((x - n * c(PIO2_1)) - n * c(PIO2_2)) - n * c(PIO2_3)) - n * c(PIO2_3T);
    // within an ulp of ±π/4 but for arguments beyond the reduction's range (NaN stays NaN)
    let quarter = c(std::f64::consts::FRAC_PI_4);
    let r = T::select(r.abs().gt(quarter), quarter.copysign(r), r);
    let (s, co) = sin_cos_small(r);
    // n mod 4 in 0..4: floor(n/4) is the nearest integer to n/4 − 3/8
    let q = n - c(4.0) * (n * c(0.25) - c(0.375)).round_ties_even();
    let (q1, q2, q3) = (q.equal(c(1.0)), q.equal(c(2.0)), q.equal(c(3.0)));
    let sin = T::select(q1, co, T::select(q2, -s, T::select(q3, -co, s)));
    let cos = T::select(q1, -s, T::select(q2, -co, T::select(q3, s, co)));
    (sin, cos)
}

/// `atan x` for any `x`, within an ulp: fdlibm's `atan` (Sun Microsystems, `s_atan.c`) with
/// its five argument ranges chosen by selection instead of branches, so that it runs in lanes
/// (one division for the reduced argument).
#[inline(always)]
pub fn atan<T: Real>(x: T) -> T {
    let c = T::splat;
    let ax = x.abs();
    // ranges: |x| < 7/16 (none), < 11/16 (0.5), < 19/16 (1), < 39/16 (1.5), beyond (∞)
    let r0 = ax.ge(c(0.4375));
    let r1 = ax.ge(c(0.6875));
    let r2 = ax.ge(c(1.1875));
    let r3 = ax.ge(c(2.4375));
    // reduced argument: (2x − 1)/(2 + x), (x − 1)/(x + 1), (x − 1.5)/(1 + 1.5x), −1/x
    let num = T::select(
        r3,
        c(-1.0),
        T::select(
            r2,
            ax - c(1.5),
            T::select(r1, ax - c(1.0), c(2.0) * ax - c(1.0)),
        ),
    );
    let den = T::select(
        r3,
        ax,
        T::select(
            r2,
            c(1.0) + c(1.5) * ax,
            T::select(r1, ax + c(1.0), c(2.0) + ax),
        ),
    );
    let t = T::select(r0, num / den, x);
    let z = t * t;
    let w = z * z;
    let s1 = z
        * (c(AT[0])
            + w * (c(AT[2]) + w * (c(AT[4]) + w * (c(AT[6]) + w * (c(AT[8]) + w * c(AT[10]))))));
    let s2 = w * (c(AT[1]) + w * (c(AT[3]) + w * (c(AT[5]) + w * (c(AT[7]) + w * c(AT[9])))));
    let small = t - t * (s1 + s2);
    // atan of the range's breakpoint, high and low parts
    let hi = T::select(
        r3,
        c(ATAN_HI[3]),
        T::select(
            r2,
            c(ATAN_HI[2]),
            T::select(r1, c(ATAN_HI[1]), c(ATAN_HI[0])),
        ),
    );
    let lo = T::select(
        r3,
        c(ATAN_LO[3]),
        T::select(
            r2,
            c(ATAN_LO[2]),
            T::select(r1, c(ATAN_LO[1]), c(ATAN_LO[0])),
        ),
    );
    let reduced = hi - ((t * (s1 + s2) - lo) - t);
    T::select(r0, reduced.copysign(x), small)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite doubles of one sign.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        assert!(a.signum() == b.signum(), "{a} {b}");
        (a.abs().to_bits() as i64 - b.abs().to_bits() as i64).unsigned_abs()
    }

    /// The kernel polynomials against the standard library's sine and cosine (correctly
    /// rounded to within half an ulp) over |x| ≤ 1.01 π/4, densely and at the ends.
    #[test]
    fn sin_cos_small_is_within_an_ulp_of_std() {
        let top = 1.01 * std::f64::consts::FRAC_PI_4;
        let n = 400_000;
        let mut worst = (0, 0);
        let mut xs: Vec<f64> = (0..=n).map(|i| top * i as f64 / n as f64).collect();
        xs.extend([
            1e-300,
            5e-324,
            1e-9,
            3e-8,
            1e-4,
            top,
            std::f64::consts::FRAC_PI_4,
        ]);
        // irregular points too
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            xs.push(top * (s >> 11) as f64 / (1u64 << 53) as f64);
        }
        for &x in &xs {
            for x in [x, -x] {
                let (sn, cs) = sin_cos_small(x);
                let (a, b) = (ulps(sn, x.sin()), ulps(cs, x.cos()));
                worst = (worst.0.max(a), worst.1.max(b));
            }
        }
        assert!(worst.0 <= 1 && worst.1 <= 1, "{worst:?}");
        eprintln!("sin_cos_small: worst (sin, cos) ulps {worst:?}");
        assert_eq!(sin_cos_small(0.0), (0.0, 1.0));
    }

    /// The reduced sine and cosine against the standard library's over the angles of a step
    /// (log-uniform up to 10⁶, near multiples of π/2, the quadrants' edges), and equal to
    /// the kernel polynomials where no reduction is needed; lanes give the same bits.
    #[test]
    fn sin_cos_is_within_two_ulps_of_std() {
        let mut xs: Vec<f64> = Vec::new();
        let mut s = 0x1234_5678_9abc_def1u64;
        for _ in 0..300_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            xs.push(10f64.powf(-8.0 + 14.0 * u)); // 1e-8 … 1e6
            xs.push(20.0 * u); // the first quadrants, densely
        }
        for k in 1..200 {
            let m = k as f64 * std::f64::consts::FRAC_PI_2;
            for d in -3..=3 {
                xs.push(f64::from_bits(m.to_bits().wrapping_add_signed(d)));
            }
            xs.push(m * 1000.0);
        }
        xs.extend([0.0, 5e-324, 1e-300, std::f64::consts::FRAC_PI_4, 1.6e6]);
        // everywhere within 2⁻⁵² of the correctly rounded values (near a zero of sin or cos
        // the absolute error is what the reduction bounds), and within two ulps away from
        // the zeros; the kernel polynomials themselves where no reduction is needed
        for &x in &xs {
            for x in [x, -x] {
                let (sn, cs) = sin_cos(x);
                assert!((sn - x.sin()).abs() <= f64::EPSILON, "{x}");
                assert!((cs - x.cos()).abs() <= f64::EPSILON, "{x}");
                if x.abs() <= std::f64::consts::FRAC_PI_4 {
                    assert_eq!((sn, cs), sin_cos_small(x), "{x}");
                }
            }
        }
        let mut worst_ulps = (0u64, 0u64);
        for &x in &xs {
            let (sn, cs) = sin_cos(x);
            if x.sin().abs() > 1e-3 {
                worst_ulps.0 = worst_ulps.0.max(ulps(sn, x.sin()));
            }
            if x.cos().abs() > 1e-3 {
                worst_ulps.1 = worst_ulps.1.max(ulps(cs, x.cos()));
            }
        }
        assert!(worst_ulps.0 <= 2 && worst_ulps.1 <= 2, "{worst_ulps:?}");
        eprintln!("sin_cos: worst ulps {worst_ulps:?}");
        assert!(sin_cos(f64::INFINITY).0.is_nan() && sin_cos(f64::NAN).1.is_nan());
        let lanes = Wide::<WIDTH>(std::array::from_fn(|l| {
            xs[131 * l] * if l % 3 == 0 { -1.0 } else { 1.0 }
        }));
        let (sw, cw) = sin_cos(lanes);
        for l in 0..WIDTH {
            let (a, b) = sin_cos(lanes.0[l]);
            assert_eq!(
                (sw.0[l].to_bits(), cw.0[l].to_bits()),
                (a.to_bits(), b.to_bits())
            );
        }
    }

    /// Every lane computes what `f64` computes, bit for bit.
    #[test]
    fn lanes_compute_what_f64_computes() {
        let x8 = [0.3, -1.7, 2.5e-300, 1e300, 0.0, -0.0, 7.25, 0.5];
        let y8 = [1.1, 3.0, -4.0, 1e-300, 2.0, 5e-324, -7.25, 0.5];
        let xs: [f64; WIDTH] = std::array::from_fn(|l| x8[l % 8] * (1 + l / 8) as f64);
        let ys: [f64; WIDTH] = std::array::from_fn(|l| y8[(l + l / 8) % 8]);
        let (x, y) = (Wide(xs), Wide(ys));
        let mut plain = WideMask::splat(true);
        let n = Wide::norm2(x, y, &mut plain);
        let (sn, cs) = sin_cos_small(x * Wide::splat(0.1));
        for l in 0..WIDTH {
            let (a, b) = (xs[l], ys[l]);
            assert_eq!((x + y).0[l].to_bits(), (a + b).to_bits());
            assert_eq!((x / y).0[l].to_bits(), (a / b).to_bits());
            assert_eq!(x.sqrt().0[l].to_bits(), a.sqrt().to_bits());
            assert_eq!(x.round_ties_even().0[l], a.round_ties_even());
            assert_eq!(x.copysign(y).0[l].to_bits(), a.copysign(b).to_bits());
            assert_eq!(py_max(x, y).0[l].to_bits(), py_max(a, b).to_bits());
            assert_eq!(x.lt(y).get(l), a < b);
            // the lanes where f64 takes hypot are flagged, the others equal
            assert_eq!(
                plain.get(l),
                sum_of_squares_is_safe(a * a + b * b),
                "{a} {b}"
            );
            if plain.get(l) {
                let n1 = f64::norm2(a, b, &mut true);
                assert_eq!(n.0[l].to_bits(), n1.to_bits());
            }
            // (1e299 squares to inf: NaN, whose sign bit is not specified)
            let (s1, c1) = sin_cos_small(a * 0.1);
            let same = |x: f64, y: f64| x.to_bits() == y.to_bits() || x.is_nan() && y.is_nan();
            assert!(same(sn.0[l], s1) && same(cs.0[l], c1), "{a}");
        }
    }

    /// fdlibm's atan in lanes against the standard library's (correctly rounded to within
    /// half an ulp) across the ranges, their breakpoints and the extremes.
    #[test]
    fn atan_is_within_an_ulp_of_std() {
        let mut xs: Vec<f64> = Vec::new();
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..400_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            xs.push(10f64.powf(-20.0 + 40.0 * u)); // log-uniform over 1e-20 … 1e20
            xs.push(4.0 * u); // the ranges' breakpoints
        }
        for b in [0.4375f64, 0.6875, 1.1875, 2.4375, 1.0, 0.5, 1.5] {
            for k in -3..=3 {
                xs.push(f64::from_bits(b.to_bits().wrapping_add_signed(k)));
            }
        }
        xs.extend([
            0.0,
            5e-324,
            1e-300,
            1e300,
            f64::MAX,
            f64::INFINITY,
            2f64.powi(66),
        ]);
        let mut worst = 0;
        for &x in &xs {
            for x in [x, -x] {
                worst = worst.max(ulps(atan(x), x.atan()));
            }
        }
        assert!(worst <= 1, "{worst}");
        eprintln!("atan: worst ulps {worst}");
        // lanes: the same bits
        let lanes = Wide::<WIDTH>(std::array::from_fn(|l| {
            xs[97 * l] * if l % 3 == 0 { -1.0 } else { 1.0 }
        }));
        let got = atan(lanes);
        for l in 0..WIDTH {
            assert_eq!(got.0[l].to_bits(), atan(lanes.0[l]).to_bits());
        }
        assert!(atan(f64::NAN).is_nan());
    }

    /// Beyond the reduction's range the pair stays on the unit circle, so that a rotation by
    /// a huge angle (an absurd step) is still a rotation; NaN and infinities give NaN.
    #[test]
    fn sin_cos_stays_on_the_circle_for_huge_arguments() {
        for &x in &[1e7, 1e12, 1e15, 1e17, 3.7e19, -1e22, 1e300] {
            let (s, c) = sin_cos(x);
            assert!((s * s + c * c - 1.0).abs() < 4e-16, "{x}: {s} {c}");
        }
        let r = crate::so3::exp_so3([0.3e17, -0.7e17, 0.64e17]);
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((d - want).abs() < 1e-15, "{i} {j} {d}");
            }
        }
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
    }
}
